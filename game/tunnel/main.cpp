// build/bin/tunnel: the tunnel level. In a window: fly-through (Tab: free camera), debug panel, F12
// screenshot. Headless (--headless, or automatically without a display): renders N frames at a fixed step,
// writes PNGs of chosen frames and DIR/stats.json (see tunnel/stats_json.hpp). The level's assets are found
// relative to the executable (TUNNEL_ASSETS_FROM_EXE: bin/../share/wires/tunnel, installed or in the build tree), so
// an installed prefix can be moved; --assets DIR overrides.
//   tunnel [--headless] [--frames N] [--out DIR] [--capture-every K] [--width W] [--height H] [--assets DIR]
#include "tunnel/debug_ui.hpp"
#include "tunnel/level.hpp"
#include "tunnel/stats_json.hpp"

#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>

#include <CLI/CLI.hpp>
#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace {

namespace platform = engine::platform;

struct Args {
    bool headless = false;
    int frames = 120;
    std::string out = "out/tunnel";
    int capture_every = 0;
    int width = 1280;
    int height = 720;
    double dt_s = 1.0 / 30.0;
    int pieces = 16;
    uint32_t seed = 1;
    std::string path = "auto";
    std::string spline = "automatic";
    double lod_tolerance_px = 0.5;
    bool wireframe = false;
    bool no_shadows = false;
    bool frames_given = false;  // window: close after `frames` frames
    int screenshot_frame = -1;  // window: screenshot (with the panel) at this frame
    std::string assets;         // level assets; empty: found relative to the executable
};

#ifndef TUNNEL_ASSETS_FROM_EXE
#define TUNNEL_ASSETS_FROM_EXE "../share/wires/tunnel"
#endif

/// The folder of the running executable (/proc/self/exe; argv[0] where /proc is missing).
std::filesystem::path executable_dir(const char* argv0) {
    std::error_code ec;
    std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) exe = std::filesystem::absolute(argv0, ec);
    return exe.parent_path();
}

/// The level's assets: --assets, else TUNNEL_ASSETS_FROM_EXE relative to the executable (the same relative place in
/// the build tree and in an installed prefix; no absolute path is compiled in). Empty with a message if not found.
std::string find_assets(const Args& args, const char* argv0, std::string& error) {
    const std::filesystem::path dir =
        args.assets.empty() ? (executable_dir(argv0) / TUNNEL_ASSETS_FROM_EXE).lexically_normal()
                            : std::filesystem::path(args.assets);
    std::error_code ec;
    if (std::filesystem::is_regular_file(dir / "straight_section.glb", ec)) return dir.string();
    error = "no level assets in " + dir.string() + " (straight_section.glb missing); " +
            (args.assets.empty() ? "the executable expects them at " TUNNEL_ASSETS_FROM_EXE
                                   " relative to its folder, or pass --assets DIR"
                                 : "check --assets");
    return {};
}

std::string frame_png(const std::string& dir, uint64_t frame) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%04llu.png", static_cast<unsigned long long>(frame));
    return (std::filesystem::path(dir) / name).string();
}

// Mouse-look and WASD camera (right mouse button held to look; Q/E down/up; shift: faster).
struct FreeCamera {
    glm::dvec3 position{0.0};  // double, as engine::scene::Camera: 1 mm steps hold far from the origin
    float yaw = 0.0f;
    float pitch = 0.0f;

    void take(const engine::scene::Camera& c) {
        position = c.position;
        const glm::vec3 f(glm::normalize(c.target - c.position));
        pitch = std::asin(glm::clamp(f.y, -1.0f, 1.0f));
        yaw = std::atan2(f.x, -f.z);
    }
    void update(const platform::Input& in, double dt, bool mouse_free, bool keys_free,
                engine::scene::Camera& c) {
        if (mouse_free && in.down(platform::MouseButton::right)) {
            yaw += 0.003f * static_cast<float>(in.mouse_dx_px);
            pitch = glm::clamp(pitch - 0.003f * static_cast<float>(in.mouse_dy_px), -1.5f, 1.5f);
        }
        const glm::vec3 f(std::cos(pitch) * std::sin(yaw), std::sin(pitch), -std::cos(pitch) * std::cos(yaw));
        const glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
        if (keys_free) {
            const double speed = (in.down(platform::Key::left_shift) ? 12.0 : 3.0) * dt;
            using K = platform::Key;
            if (in.down(K::w) || in.down(K::up)) position += glm::dvec3(f) * speed;
            if (in.down(K::s) || in.down(K::down)) position -= glm::dvec3(f) * speed;
            if (in.down(K::d) || in.down(K::right)) position += glm::dvec3(r) * speed;
            if (in.down(K::a) || in.down(K::left)) position -= glm::dvec3(r) * speed;
            if (in.down(K::e)) position.y += speed;
            if (in.down(K::q)) position.y -= speed;
        }
        c.position = position;
        c.target = position + glm::dvec3(f);
        c.up = {0.0, 1.0, 0.0};
    }
};

double rope_radius_min(const tunnel::Level& level) {
    double r = 1e30;
    for (const tunnel::CableInfo& c : level.cables())
        if (c.hanging) r = std::min(r, static_cast<double>(c.radius_m));
    return r;
}

int run_headless(platform::Context& ctx, tunnel::Level& level, const Args& args) {
    // First, middle and last frames, and two close-ups (the default flight passes the right wall's festoon
    // and cables around frames 90-110).
    std::set<int> capture = {0, args.frames / 2, args.frames - 1};
    for (int f : {95, 105})
        if (f < args.frames) capture.insert(f);
    if (args.capture_every > 0)
        for (int f = 0; f < args.frames; f += args.capture_every) capture.insert(f);
    std::filesystem::create_directories(args.out);
    nlohmann::json frames = nlohmann::json::array();
    int non_finite = 0;
    std::vector<std::string> written;
    int inserted = 0;
    int removed = 0;
    double frame_ms_sum = 0.0;
    double max_turn = 0.0, max_penetration = 0.0, max_error = 0.0, rope_min = 1e30, cable_min = 1e30;
    std::size_t max_triangles = 0;
    std::vector<int> close_ups;  // frames with the eye within 0.5 m of a rope and of a wall cable
    for (int f = 0; f < args.frames; ++f) {
        ctx.begin_frame();
        const auto start = std::chrono::steady_clock::now();
        level.frame(args.dt_s);
        frame_ms_sum +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        frames.push_back(tunnel::frame_record(level.stats(), level.system_stats(), non_finite));
        inserted += level.stats().nodes_inserted;
        removed += level.stats().nodes_removed;
        const tunnel::LevelFrameStats& st = level.stats();
        max_turn = std::max(max_turn, st.rope_max_turn_deg);
        max_penetration = std::max(max_penetration, st.rope_penetration_m);
        max_error = std::max(max_error, st.piece_max_error_px);
        max_triangles = std::max(max_triangles, st.piece_triangles);
        rope_min = std::min(rope_min, st.camera_rope_m);
        cable_min = std::min(cable_min, st.camera_cable_m);
        if (st.camera_rope_m <= 0.5 && st.camera_cable_m <= 0.5) close_ups.push_back(f);
        if (capture.count(f) != 0) {
            const std::string path = frame_png(args.out, static_cast<uint64_t>(f));
            if (auto s = platform::capture_png(ctx, path); !s) {
                std::fprintf(stderr, "tunnel: %s\n", s.message.c_str());
                return 1;
            }
            written.push_back(path);
        }
        ctx.end_frame();
    }
    nlohmann::json mean = nlohmann::json::object();
    nlohmann::json max = nlohmann::json::object();
    for (const engine::ecs::SystemStats& st : level.system_stats()) {
        mean[st.name] = std::isfinite(st.mean_ms) ? st.mean_ms : -1.0;
        max[st.name] = std::isfinite(st.max_ms) ? st.max_ms : -1.0;
    }
    const nlohmann::json doc = {{"frames", frames},
                                {"summary",
                                 {{"frames", args.frames},
                                  {"width", ctx.framebuffer_size().width},
                                  {"height", ctx.framebuffer_size().height},
                                  {"dt_s", args.dt_s},
                                  {"systems_mean_ms", mean},
                                  {"systems_max_ms", max},
                                  {"frame_ms_mean", args.frames > 0 ? frame_ms_sum / args.frames : 0.0},
                                  {"nodes_inserted", inserted},
                                  {"nodes_removed", removed},
                                  {"rope_max_turn_deg", max_turn},
                                  {"rope_penetration_m", max_penetration},
                                  {"rope_radius_min_m", rope_radius_min(level)},
                                  {"piece_max_error_px", max_error},
                                  {"piece_tolerance_px", level.options().subdivision_tolerance_px},
                                  {"piece_triangles_max", max_triangles},
                                  {"camera_rope_min_m", rope_min},
                                  {"camera_cable_min_m", cable_min},
                                  {"close_up_frames", close_ups},
                                  {"non_finite", non_finite},
                                  {"images", written},
                                  {"gl_renderer", ctx.gl_renderer()}}}};
    const std::string stats_path = (std::filesystem::path(args.out) / "stats.json").string();
    std::ofstream out(stats_path);
    out << doc.dump(1) << "\n";
    if (!out) {
        std::fprintf(stderr, "tunnel: %s: write failed\n", stats_path.c_str());
        return 1;
    }
    std::printf("tunnel: %d frames at %dx%d on %s\n", args.frames, ctx.framebuffer_size().width,
                ctx.framebuffer_size().height, ctx.gl_renderer().c_str());
    for (const engine::ecs::SystemStats& st : level.system_stats())
        std::printf("  %-16s mean %7.3f ms  max %7.3f ms\n", st.name.c_str(), st.mean_ms, st.max_ms);
    std::printf("  rope nodes inserted %d, removed %d\n", inserted, removed);
    std::printf(
        "  rope max turn %.2f deg, max penetration %.4f m (radius %.3f m), piece max error %.3f px "
        "(tolerance %.2f px), %zu close-up frames\n",
        max_turn, max_penetration, rope_radius_min(level), max_error,
        level.options().subdivision_tolerance_px, close_ups.size());
    for (const std::string& p : written) std::printf("wrote %s\n", p.c_str());
    std::printf("wrote %s\n", stats_path.c_str());
    return non_finite == 0 ? 0 : 1;
}

int run_window(platform::Context& ctx, tunnel::Level& level, const Args& args) {
    auto ui = tunnel::DebugUi::create(ctx);
    std::printf(
        "tunnel: window %dx%d on %s, panel: %s\n"
        "  keys: Tab free/fly camera, WASD/arrows + right mouse drag (free camera), Q/E down/up, shift "
        "fast,\n"
        "        P pause bends, F1 wireframe, F12 screenshot (%s), Esc quit\n",
        ctx.framebuffer_size().width, ctx.framebuffer_size().height, ctx.gl_renderer().c_str(), ui->kind(),
        args.out.c_str());
    FreeCamera free_camera;
    auto last = std::chrono::steady_clock::now();
    double frame_ms = 0.0;
    int shots = 0;
    int frame_index = 0;
    while (!ctx.should_close()) {
        if (args.frames_given && frame_index >= args.frames) break;
        ctx.poll_events();
        const platform::Input& in = ctx.input();
        const bool keys = !ui->wants_keyboard();
        tunnel::LevelOptions& o = level.options();
        if (keys && in.pressed(platform::Key::escape)) ctx.request_close();
        if (keys && in.pressed(platform::Key::tab)) {
            o.camera_mode =
                o.camera_mode == tunnel::CameraMode::fly ? tunnel::CameraMode::free : tunnel::CameraMode::fly;
            if (o.camera_mode == tunnel::CameraMode::free) free_camera.take(level.camera());
        }
        if (keys && in.pressed(platform::Key::p)) o.animate_bends = !o.animate_bends;
        if (keys && in.pressed(platform::Key::f1)) o.wireframe = !o.wireframe;
        const auto now = std::chrono::steady_clock::now();
        const double dt = std::min(0.1, std::chrono::duration<double>(now - last).count());
        last = now;
        if (o.camera_mode == tunnel::CameraMode::free)
            free_camera.update(in, dt, !ui->wants_mouse(), keys, level.camera());

        const platform::Extent size = ctx.framebuffer_size();
        level.set_viewport(size.width, size.height);
        ctx.begin_frame();
        const auto start = std::chrono::steady_clock::now();
        level.frame(dt);
        frame_ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        tunnel::UiRequests requests;
        requests.screenshot = keys && in.pressed(platform::Key::f12);
        if (requests.screenshot) {  // the scene without the panel
            char name[64];
            std::snprintf(name, sizeof name, "screenshot_%03d.png", shots++);
            const std::string path = (std::filesystem::path(args.out) / name).string();
            if (auto s = platform::capture_png(ctx, path); !s) {
                std::fprintf(stderr, "tunnel: %s\n", s.message.c_str());
            } else {
                std::printf("wrote %s\n", path.c_str());
            }
            requests.screenshot = false;
        }
        ui->draw(level, frame_ms, requests);
        if (frame_index++ == args.screenshot_frame) requests.screenshot = true;
        if (requests.screenshot) {  // the panel's button: the frame with the panel
            char name[64];
            std::snprintf(name, sizeof name, "screenshot_%03d.png", shots++);
            const std::string path = (std::filesystem::path(args.out) / name).string();
            if (auto s = platform::capture_png(ctx, path); s) std::printf("wrote %s\n", path.c_str());
        }
        ctx.end_frame();
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Args args;
    CLI::App app{"tunnel: bent tunnel pieces with simulated and fixed cables (wire runtime demo level)"};
    app.add_flag("--headless", args.headless, "render off-screen (automatic when there is no display)");
    CLI::Option* frames =
        app.add_option("--frames", args.frames,
                       "frames to render (headless default 120; window: close after N frames)")
            ->check(CLI::PositiveNumber);
    app.add_option("--screenshot-frame", args.screenshot_frame,
                   "window: screenshot with the panel at frame K");
    app.add_option("--out", args.out,
                   "headless: folder of the PNGs and stats.json; window: screenshots (default out/tunnel)");
    app.add_option("--capture-every", args.capture_every, "headless: also capture every K-th frame")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--width", args.width, "framebuffer width (default 1280)")->check(CLI::PositiveNumber);
    app.add_option("--height", args.height, "framebuffer height (default 720)")->check(CLI::PositiveNumber);
    app.add_option("--dt", args.dt_s, "headless: fixed time step in seconds (default 1/30)")
        ->check(CLI::PositiveNumber);
    app.add_option("--pieces", args.pieces, "tunnel pieces of 4 m (default 16)")->check(CLI::Range(2, 256));
    app.add_option("--seed", args.seed, "seed of the bend animation (default 1)");
    app.add_option("--path", args.path,
                   "wire upload path: auto (default: nodes where the GL context has compute shaders, else cpu; "
                   "logged at start), nodes (nodes only: curve, LOD and rings in compute shaders), cpu (meshes "
                   "built on the CPU: the portable reference); gpu, retired, draws on nodes")
        ->check(CLI::IsMember({"auto", "cpu", "gpu", "nodes"}));
    app.add_option("--spline", args.spline, "catmull-rom, c2, automatic or linear")
        ->check(CLI::IsMember({"catmull-rom", "c2", "automatic", "linear"}));
    app.add_option("--lod-tolerance", args.lod_tolerance_px, "wire LOD screen error in pixels (default 0.5)")
        ->check(CLI::PositiveNumber);
    app.add_flag("--wireframe", args.wireframe, "draw wireframe");
    app.add_flag("--no-shadows", args.no_shadows, "the head lamp casts no shadows (default: it does: cables, ropes and "
                                                   "pieces into its map; pieces and wires receive)");
    app.add_option("--assets", args.assets,
                   "folder of the level's assets (default: " TUNNEL_ASSETS_FROM_EXE " relative to the executable)");
    CLI11_PARSE(app, argc, argv);
    args.frames_given = frames->count() > 0;
    std::string assets_error;
    const std::string asset_dir = find_assets(args, argv[0], assets_error);
    if (asset_dir.empty()) {
        std::fprintf(stderr, "tunnel: %s\n", assets_error.c_str());
        return 2;
    }

    platform::ContextDesc desc{
        .backend = args.headless ? platform::Backend::headless : platform::Backend::automatic,
        .width = args.width,
        .height = args.height,
        .title = "tunnel"};
    auto ctx = platform::create_context(desc);
    if (!ctx) {
        std::fprintf(stderr, "tunnel: %s\n", ctx.error().message.c_str());
        return 1;
    }
    auto level = tunnel::Level::create({.pieces = args.pieces, .seed = args.seed, .asset_dir = asset_dir});
    if (!level) {
        std::fprintf(stderr, "tunnel: %s\n", level.error().message.c_str());
        return 1;
    }
    tunnel::LevelOptions& o = level.value()->options();
    if (const std::string_view note = wire::retired_path_note(args.path); !note.empty())
        std::fprintf(stderr, "tunnel: %s\n", std::string(note).c_str());
    if (args.path != "auto") o.upload_path = *wire::parse_upload_path(args.path);
    o.spline = args.spline == "c2"          ? wire::SplineKind::c2
               : args.spline == "automatic" ? wire::SplineKind::automatic
               : args.spline == "linear"    ? wire::SplineKind::linear
                                            : wire::SplineKind::catmull_rom;
    o.lod_tolerance_px = args.lod_tolerance_px;
    o.wireframe = args.wireframe;
    o.shadows = !args.no_shadows;
    const platform::Extent size = ctx.value()->framebuffer_size();
    level.value()->set_viewport(size.width, size.height);
    if (ctx.value()->headless()) return run_headless(*ctx.value(), *level.value(), args);
    return run_window(*ctx.value(), *level.value(), args);
}
