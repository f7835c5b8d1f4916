// demo: a wire-free scene (lit, slowly turning cylinders and boxes on a ground plane) that exercises the
// platform, gfx and scene layers. Windowed where there is a display, headless (EGL + PNG frames) otherwise.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "engine/gfx/debug.hpp"
#include "engine/gfx/lit_renderer.hpp"
#include "engine/gfx/mesh.hpp"
#include "engine/platform/capture.hpp"
#include "engine/platform/context.hpp"
#include "engine/scene/camera.hpp"
#include "engine/scene/frustum.hpp"

namespace gfx = engine::gfx;
namespace platform = engine::platform;
namespace scene = engine::scene;

namespace {

struct Options {
    bool headless = false;
    int frames = 0;  // 0: headless 60, window until closed
    std::filesystem::path out_dir = "out/demo";
    int width = 1280;
    int height = 720;
    bool gl_debug = false;
};

struct Object {
    const gfx::GpuMesh* mesh = nullptr;
    glm::vec3 position{0.0f};
    glm::vec3 albedo{1.0f};
    float spin_rad_per_s = 0.0f;
    bool lying = false;  // cylinder on its side, rolling about the vertical
    float bound_radius_m = 1.0f;
};

std::string frame_name(const char* stem, int index) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s_%04d.png", stem, index);
    return buf;
}

}  // namespace

int main(int argc, char** argv) {
    Options opt;
    CLI::App app{"demo: lit cylinders and boxes on a ground plane (engine platform/gfx/scene smoke test)"};
    app.add_flag("--headless", opt.headless,
                 "Render off-screen with EGL (automatic when there is no display)");
    app.add_option("--frames", opt.frames, "Frames to render (headless default 60; window: until closed)")
        ->check(CLI::Range(1, 1000000000));
    app.add_option("--out", opt.out_dir, "Directory for PNG frames and screenshots")->capture_default_str();
    app.add_option("--width", opt.width, "Framebuffer width in pixels")
        ->check(CLI::Range(16, 8192))
        ->capture_default_str();
    app.add_option("--height", opt.height, "Framebuffer height in pixels")
        ->check(CLI::Range(16, 8192))
        ->capture_default_str();
    app.add_flag("--gl-debug", opt.gl_debug, "Log GL debug output (KHR_debug) to stderr");
    app.footer("Window keys: F12 or P screenshot, arrows orbit the camera, Esc quits.");
    CLI11_PARSE(app, argc, argv);

    auto created = platform::create_context({
        .backend = opt.headless ? platform::Backend::headless : platform::Backend::automatic,
        .width = opt.width,
        .height = opt.height,
        .title = "wires demo",
        .debug = opt.gl_debug,
    });
    if (!created) {
        std::fprintf(stderr, "demo: %s\n", created.error().message.c_str());
        return 1;
    }
    platform::Context& ctx = **created;
    std::printf("demo: %s, GL %s on %s\n", ctx.headless() ? "headless" : "window", ctx.gl_version().c_str(),
                ctx.gl_renderer().c_str());
    if (opt.gl_debug) gfx::enable_debug_output();

    auto renderer = gfx::LitRenderer::create();
    if (!renderer) {
        std::fprintf(stderr, "demo: %s\n", renderer.error().message.c_str());
        return 1;
    }
    auto ground = gfx::upload_mesh(gfx::make_plane_mesh(40.0f), "ground");
    auto cylinder = gfx::upload_mesh(
        gfx::make_cylinder_mesh({.radius_m = 0.5f, .half_height_m = 0.75f, .sides = 48}), "cylinder");
    auto box = gfx::upload_mesh(gfx::make_box_mesh(glm::vec3(0.5f)), "box");
    for (const auto* m : {&ground, &cylinder, &box}) {
        if (!*m) {
            std::fprintf(stderr, "demo: %s\n", m->error().message.c_str());
            return 1;
        }
    }

    const std::vector<Object> objects = {
        {&*cylinder, {-2.2f, 0.75f, 0.0f}, {0.85f, 0.45f, 0.20f}, 0.6f, false, 0.9f},
        {&*cylinder, {0.0f, 0.5f, -1.2f}, {0.25f, 0.55f, 0.85f}, -0.4f, true, 0.9f},
        {&*cylinder, {2.3f, 0.75f, 0.6f}, {0.35f, 0.75f, 0.35f}, 0.3f, false, 0.9f},
        {&*box, {-0.6f, 0.5f, 1.6f}, {0.80f, 0.80f, 0.75f}, 0.5f, false, 0.87f},
        {&*box, {1.2f, 0.5f, -2.8f}, {0.75f, 0.25f, 0.30f}, -0.7f, false, 0.87f},
    };
    const gfx::DirectionalLight light{.to_light = {0.5f, 1.0f, 0.35f}, .ambient = 0.2f};

    const int frame_count = opt.frames > 0 ? opt.frames : (ctx.headless() ? 60 : 0);
    float orbit_rad = 0.3f;
    float elevation_m = 3.0f;
    int screenshots = 0;
    std::vector<std::string> written;
    const auto start = std::chrono::steady_clock::now();

    for (int frame = 0; frame_count == 0 || frame < frame_count; ++frame) {
        ctx.poll_events();
        if (ctx.should_close()) break;
        const platform::Input& in = ctx.input();
        if (in.pressed(platform::Key::escape)) ctx.request_close();
        if (in.down(platform::Key::left)) orbit_rad -= 0.02f;
        if (in.down(platform::Key::right)) orbit_rad += 0.02f;
        if (in.down(platform::Key::up)) elevation_m = std::min(elevation_m + 0.05f, 10.0f);
        if (in.down(platform::Key::down)) elevation_m = std::max(elevation_m - 0.05f, 0.3f);

        // Headless runs on a fixed 60 Hz clock so its frames are reproducible.
        const float t_s =
            ctx.headless() ? static_cast<float>(frame) / 60.0f
                           : std::chrono::duration<float>(std::chrono::steady_clock::now() - start).count();
        const platform::Extent size = ctx.framebuffer_size();
        if (size.width == 0 || size.height == 0) continue;  // minimized
        scene::Camera camera{
            .position = {8.0f * std::sin(orbit_rad + 0.1f * t_s), elevation_m,
                         8.0f * std::cos(orbit_rad + 0.1f * t_s)},
            .target = {0.0f, 0.6f, 0.0f},
            .fov_y_rad = glm::radians(50.0f),
            .aspect = static_cast<float>(size.width) / static_cast<float>(size.height),
            .near_m = 0.1f,
            .far_m = 100.0f,
        };
        const glm::mat4 clip_from_world = camera.view_projection();
        const scene::Frustum frustum = scene::Frustum::from_view_projection(clip_from_world);

        ctx.begin_frame();
        gfx::clear({0.55f, 0.68f, 0.85f, 1.0f});
        renderer->begin(clip_from_world, light);
        renderer->draw(*ground, glm::mat4(1.0f), glm::vec3(0.45f, 0.45f, 0.42f));
        for (const Object& o : objects) {
            if (!frustum.intersects_sphere(o.position, o.bound_radius_m)) continue;
            glm::mat4 m = glm::translate(glm::mat4(1.0f), o.position);
            m = glm::rotate(m, o.spin_rad_per_s * t_s, glm::vec3(0.0f, 1.0f, 0.0f));
            if (o.lying) m = glm::rotate(m, glm::half_pi<float>(), glm::vec3(1.0f, 0.0f, 0.0f));
            renderer->draw(*o.mesh, m, o.albedo);
        }

        // Capture before end_frame(): a window's back buffer is undefined after the swap.
        std::filesystem::path shot;
        // A run with a known length (headless, or a window with --frames) writes its first and last frames.
        if (frame_count > 0 && (frame == 0 || frame == frame_count - 1)) {
            shot = opt.out_dir / frame_name("frame", frame);
        } else if (!ctx.headless() && (in.pressed(platform::Key::f12) || in.pressed(platform::Key::p))) {
            shot = opt.out_dir / frame_name("screenshot", screenshots++);
            std::printf("demo: wrote %s\n", shot.string().c_str());
        }
        if (!shot.empty()) {
            if (engine::Status s = platform::capture_png(ctx, shot); !s) {
                std::fprintf(stderr, "demo: %s\n", s.message.c_str());
                return 1;
            }
            written.push_back(shot.string());
        }
        ctx.end_frame();
    }

    if (frame_count > 0) {
        std::printf("demo: rendered %d frames of %dx%d, wrote %zu file(s):\n", frame_count,
                    ctx.framebuffer_size().width, ctx.framebuffer_size().height, written.size());
        for (const std::string& f : written) std::printf("  %s\n", f.c_str());
    }
    return 0;
}
