// bullet_ropes: Bullet soft-body ropes and cables drawn by the wire renderer (docs/bullet.md,
// "A physics engine feeding the wires"). In a window where there is a display, otherwise
// headless writing PNGs.
#include "rope_scene.hpp"

#include <wire/systems/systems.hpp>

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <string>

namespace {

struct Options {
    bool headless = false;
    bool window = false;
    int frames = 0;          // 0: headless 240, window until closed
    int capture_every = 60;  // 0: none
    std::filesystem::path out_dir = "out/bullet_ropes";
    int width = 1280;
    int height = 720;
    double dt_s = 1.0 / 60.0;
    std::string path = "auto";  // wire upload path: auto, nodes, cpu or gpu
    bool set_nodes = false;     // nodes path: wire entities (set_nodes) instead of the node stream
};

std::string frame_name(int frame) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "frame_%04d.png", frame);
    return buf;
}

}  // namespace

int main(int argc, char** argv) {
    Options opt;
    CLI::App app{
        "bullet_ropes: Bullet soft-body ropes and cables (BulletSoftBody) hanging, swinging and colliding "
        "with a floor and a box, their nodes handed to wire entities every frame and drawn by the wire "
        "renderer"};
    app.add_flag("--headless", opt.headless,
                 "Render off-screen with EGL (automatic when there is no display)");
    app.add_flag("--window", opt.window, "Require a window (fail without a display)")->excludes("--headless");
    app.add_option("--frames", opt.frames, "Frames to run (headless default 240; window: until closed)")
        ->check(CLI::Range(1, 100000000));
    app.add_option(
           "--capture-every", opt.capture_every,
           "Write every K-th frame (and the last) as DIR/frame_NNNN.png; 0: only the last headless, none "
           "in a window")
        ->check(CLI::Range(0, 100000000))
        ->capture_default_str();
    app.add_option("--out", opt.out_dir, "Directory for PNG frames")->capture_default_str();
    app.add_option("--width", opt.width, "Framebuffer width in pixels")
        ->check(CLI::Range(16, 8192))
        ->capture_default_str();
    app.add_option("--height", opt.height, "Framebuffer height in pixels")
        ->check(CLI::Range(16, 8192))
        ->capture_default_str();
    app.add_option("--dt", opt.dt_s, "Frame time step in seconds (Bullet steps at 1/240 s inside)")
        ->check(CLI::Range(1e-4, 0.1))
        ->capture_default_str();
    app.add_option("--path", opt.path,
                   "Wire upload path: auto (nodes where the GL context has compute shaders, else cpu; logged), "
                   "nodes (the ropes' nodes only: curve, LOD and rings in compute shaders), cpu (meshes: the "
                   "portable reference); gpu, retired, draws on nodes")
        ->check(CLI::IsMember({"auto", "cpu", "gpu", "nodes"}))
        ->capture_default_str();
    app.add_flag("--set-nodes", opt.set_nodes,
                 "On the nodes path, hand the nodes to wire entities (wire::systems::set_nodes) instead of writing "
                 "Bullet's node records straight into the renderer's node stream (the default there)");
    app.footer("Window keys: F12 saves a screenshot to the --out directory, Esc quits.");
    CLI11_PARSE(app, argc, argv);

    namespace platform = engine::platform;
    auto created = platform::create_context({
        .backend = opt.headless ? platform::Backend::headless
                                : (opt.window ? platform::Backend::window : platform::Backend::automatic),
        .width = opt.width,
        .height = opt.height,
        .title = "wires: Bullet ropes",
    });
    if (!created) {
        std::fprintf(stderr, "bullet_ropes: %s\n", created.error().message.c_str());
        return 1;
    }
    platform::Context& ctx = **created;
    std::printf("bullet_ropes: %s, GL %s on %s\n", ctx.headless() ? "headless" : "window",
                ctx.gl_version().c_str(), ctx.gl_renderer().c_str());

    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    wire::systems::WireContext wires;
    wires.on_error = [](const wire::systems::ErrorReport& e) {
        std::fprintf(stderr, "bullet_ropes: %s\n", e.message.c_str());
    };
    wire::systems::install(schedule, wires);
    bullet_ropes::RopeScene scene(registry);
    auto view = bullet_ropes::RopeView::create(scene);
    if (!view) {
        std::fprintf(stderr, "bullet_ropes: %s\n", view.error().message.c_str());
        return 1;
    }
    if (const std::string_view note = wire::retired_path_note(opt.path); !note.empty())
        std::fprintf(stderr, "bullet_ropes: %s\n", std::string(note).c_str());
    wires.path = opt.path == "auto" ? view->preferred_path() : *wire::parse_upload_path(opt.path);
    if (wires.path == wire::UploadPath::gpu_nodes && !opt.set_nodes) {
        // The nodes path: Bullet's node records go straight into the renderer's mapped memory (the node stream).
        if (engine::Status st = scene.stream_to(view->node_stream()); !st) {
            std::fprintf(stderr, "bullet_ropes: the node stream: %s\n", st.message.c_str());
            return 1;
        }
    }

    const int frames = opt.frames > 0 ? opt.frames : (ctx.headless() ? 240 : 0);
    int written = 0;
    for (int frame = 0; frames == 0 || frame < frames; ++frame) {
        ctx.poll_events();
        if (ctx.should_close()) break;
        if (ctx.input().pressed(platform::Key::escape)) ctx.request_close();
        const platform::Extent size = ctx.framebuffer_size();
        if (size.width == 0 || size.height == 0) continue;  // minimized

        scene.step(opt.dt_s);  // Bullet, then set_nodes on every rope's wire entity
        wires.camera = bullet_ropes::default_camera(size.width, size.height);
        wires.viewport_width_px = size.width;
        wires.viewport_height_px = size.height;
        schedule.run(registry, opt.dt_s);  // wire systems -> wires.draw_list

        ctx.begin_frame();
        view->draw(scene, wires.draw_list, wires.camera);
        const bool last = frames != 0 && frame + 1 == frames;
        const bool capture = (opt.capture_every > 0 && frame % opt.capture_every == 0) ||
                             (last && (ctx.headless() || opt.capture_every > 0)) ||
                             ctx.input().pressed(platform::Key::f12);
        if (capture) {
            const std::filesystem::path path = opt.out_dir / frame_name(frame);
            if (engine::Status s = platform::capture_png(ctx, path); !s) {
                std::fprintf(stderr, "bullet_ropes: %s\n", s.message.c_str());
                return 1;
            }
            std::printf("%s\n", path.c_str());
            ++written;
        }
        ctx.end_frame();
    }
    std::printf("bullet_ropes: %d ropes, %.2f s simulated, %d images\n",
                static_cast<int>(scene.ropes().size()), scene.time_s(), written);
    return 0;
}
