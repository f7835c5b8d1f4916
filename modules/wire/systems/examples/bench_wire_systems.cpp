// Informational benchmark of the wire systems: 1,000 hanging wires of 64 nodes seen by a moving camera at
// 1920x1080, both upload paths, 1 and 2 threads; CPU ms per frame per system, counts, and the vertex count of
// the adaptive LOD against a uniform tessellation with the same maximum screen error.
// Each system is called directly (in install() order) so that both wall and process CPU time can be taken per
// system: on a loaded machine wall time is inflated by other processes, CPU time is not (with 2 threads it is
// the sum over both). An application reads the same wall times from Schedule::stats().
// Usage: example_bench_wire_systems [frames=120] [wires=1000]
#include "wire/systems/api.hpp"
#include "wire/systems/systems.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <vector>

namespace {

using engine::ecs::Entity;

// A cable of `n` nodes hanging (catenary) between two posts 10 m apart.
wire::WireNodes hanging(int n, const glm::dvec3& left, double a, double phase) {
    wire::WireNodes w;
    for (int i = 0; i < n; ++i) {
        const double x = 10.0 * (static_cast<double>(i) / (n - 1) - 0.5);
        w.positions.push_back(left + glm::dvec3(x + 5.0, a * (std::cosh(x / a) - std::cosh(5.0 / a)),
                                                0.2 * std::sin(phase + 0.5 * x)));
    }
    return w;
}

struct Scene {
    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    wire::systems::WireContext ctx;
    std::vector<Entity> wires;
};

void build(Scene& s, int count, wire::UploadPath path) {
    s.ctx.path = path;
    s.ctx.viewport_width_px = 1920;
    s.ctx.viewport_height_px = 1080;
    s.ctx.camera.aspect = 16.0f / 9.0f;
    s.ctx.camera.far_m = 500.0f;
    wire::systems::install(s.schedule, s.ctx);
    for (int i = 0; i < count; ++i) {
        const int row = i % 20, col = i / 20;  // 20 high, count/20 deep
        s.wires.push_back(wire::systems::spawn_wire(
            s.registry, hanging(64, {-5.0, 0.6 * row, -1.5 * col}, 4.0 + 0.1 * (i % 13), 0.3 * i),
            {.radius_m = 0.015f, .material = static_cast<uint32_t>(i % 4)}));
    }
}

void place_camera(Scene& s, int frame) {
    // Flies slowly into the field of cables, swaying: every frame moves the camera.
    const float t = static_cast<float>(frame);
    s.ctx.camera.position = {3.0f * std::sin(0.02f * t), 5.0f + std::sin(0.03f * t), 8.0f - 0.15f * t};
    s.ctx.camera.target = s.ctx.camera.position + glm::vec3(0.4f * std::sin(0.01f * t), -0.15f, -1.0f);
}

double cpu_ms() {  // CPU time of the whole process (all threads): robust against other load on the machine
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}
double wall_ms() {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// One frame of the five systems in install() order, timed one by one (wall and CPU).
void run_frame(Scene& s, uint64_t& since, std::vector<double>& wall, std::vector<double>& cpu) {
    using namespace wire::systems;
    auto timed = [&](std::size_t i, auto&& fn) {
        const double w0 = wall_ms(), c0 = cpu_ms();
        fn();
        wall[i] += wall_ms() - w0;
        cpu[i] += cpu_ms() - c0;
    };
    timed(0, [&] { curve_system(s.registry, s.ctx, since); });
    since = s.registry.tick();
    timed(1, [&] { lod_system(s.registry, s.ctx); });
    timed(2, [&] { rings_system(s.registry, s.ctx); });
    timed(3, [&] { mesh_system(s.registry, s.ctx); });
    timed(4, [&] { draw_list_system(s.registry, s.ctx); });
}

struct Timing {
    std::vector<double> sum_ms, cpu_ms;
    double frame_ms = 0.0, frame_cpu_ms = 0.0;
    double first_frame_ms = 0.0;
    wire::systems::FrameStats last{};
    double mean_visible = 0, mean_rings = 0, mean_vertices = 0;
};

Timing run(int threads, wire::UploadPath path, int frames, int count, bool moving_nodes) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    Scene s;
    build(s, count, path);
    Timing t;
    t.sum_ms.assign(5, 0.0);
    t.cpu_ms.assign(5, 0.0);
    uint64_t since = 0;
    std::vector<double> wall(5), cpu(5);
    for (int f = 0; f < frames; ++f) {
        place_camera(s, f);
        if (moving_nodes && f > 0) {
            // Every wire swings a little (the physics moved all nodes).
            for (std::size_t i = 0; i < s.wires.size(); ++i) {
                wire::WireNodes& n = wire::systems::edit_nodes(s.registry, s.wires[i]);
                for (std::size_t k = 1; k + 1 < n.positions.size(); ++k) {
                    n.positions[k].z += 0.002 * std::sin(0.1 * f + 0.1 * static_cast<double>(k + i));
                }
            }
        }
        std::fill(wall.begin(), wall.end(), 0.0);
        std::fill(cpu.begin(), cpu.end(), 0.0);
        run_frame(s, since, wall, cpu);
        if (f == 0) {
            for (double v : wall) t.first_frame_ms += v;
            continue;
        }
        for (std::size_t i = 0; i < 5; ++i) {
            t.sum_ms[i] += wall[i];
            t.cpu_ms[i] += cpu[i];
            t.frame_ms += wall[i];
            t.frame_cpu_ms += cpu[i];
        }
        t.mean_visible += static_cast<double>(s.ctx.stats.visible_wires);
        t.mean_rings += static_cast<double>(s.ctx.stats.rings);
        t.mean_vertices += static_cast<double>(s.ctx.stats.vertices);
    }
    const double n = frames - 1;
    for (double& v : t.sum_ms) v /= n;
    for (double& v : t.cpu_ms) v /= n;
    t.frame_ms /= n;
    t.frame_cpu_ms /= n;
    t.mean_visible /= n;
    t.mean_rings /= n;
    t.mean_vertices /= n;
    t.last = s.ctx.stats;
    return t;
}

// Adaptive vs uniform at the same maximum screen error, at one camera frame.
void compare_uniform(int count, int frame) {
    Scene s;
    build(s, count, wire::UploadPath::gpu_rings);
    place_camera(s, frame);
    s.schedule.run(s.registry, 1.0 / 60.0);
    const wire::ScreenError adaptive = wire::systems::scene_screen_error(s.registry, s.ctx, 64);
    std::size_t adaptive_vertices = 0, adaptive_rings = 0;
    uint32_t max_sides = 3;
    double max_radial_px = 0.0;
    for (const wire::DrawItem& item : s.ctx.draw_list.items) {
        const Entity e{static_cast<uint32_t>(item.wire_id)};
        const auto& lod = s.registry.get<wire::systems::WireLodState>(e).lod;
        adaptive_rings += item.rings.size();
        adaptive_vertices += wire::tube_counts(item.rings.size(), item.closed, {.sides = item.sides, .caps = item.caps}).vertices;
        max_sides = std::max(max_sides, item.sides);
        if (lod.z_min_m > 0.0) {
            const double r_px = 0.015 * s.ctx.view.focal_px / lod.z_min_m;
            max_radial_px = std::max(max_radial_px, r_px * (1.0 - std::cos(std::numbers::pi / item.sides)));
        }
    }
    // Uniform: the same rings per segment on every visible wire, raised until the centre-line error is no worse.
    uint32_t k = 1;
    double uniform_error = 0.0;
    std::size_t uniform_rings = 0;
    for (; k <= 256; ++k) {
        uniform_error = 0.0;
        uniform_rings = 0;
        for (const wire::DrawItem& item : s.ctx.draw_list.items) {
            const Entity e{static_cast<uint32_t>(item.wire_id)};
            const wire::Curve& curve = s.registry.get<wire::systems::WireCurve>(e).curve;
            std::vector<uint32_t> counts(curve.segment_count(), k);
            std::vector<wire::RingParam> params;
            wire::place_rings(curve, counts, params);
            uniform_rings += params.size();
            uniform_error = std::max(uniform_error, wire::measure_screen_error(curve, params, s.ctx.view, 64).max_px);
            if (uniform_error > adaptive.max_px) break;
        }
        if (uniform_error <= adaptive.max_px) break;
    }
    // Uniform sides: one side count for all, enough for the nearest wire's radial error.
    const std::size_t uniform_vertices =
        uniform_rings * (max_sides + 1) + 2 * (max_sides + 1) * s.ctx.draw_list.items.size();
    std::printf("frame %d, %zu visible of %d wires: adaptive %zu rings, %zu vertices, max centre error %.3f px, "
                "radial %.3f px (sides 3..%u)\n",
                frame, s.ctx.draw_list.items.size(), count, adaptive_rings, adaptive_vertices, adaptive.max_px,
                max_radial_px, max_sides);
    std::printf("          uniform %u rings/segment, %u sides: %zu rings, %zu vertices, max centre error %.3f px  "
                "-> adaptive uses %.1f%% of the uniform vertices\n",
                k, max_sides, uniform_rings, uniform_vertices, uniform_error,
                100.0 * static_cast<double>(adaptive_vertices) / static_cast<double>(uniform_vertices));
}

}  // namespace

int main(int argc, char** argv) {
    const int frames = argc > 1 ? std::max(2, std::atoi(argv[1])) : 120;
    const int count = argc > 2 ? std::max(1, std::atoi(argv[2])) : 1000;
    std::printf("%d hanging wires x 64 nodes, 1920x1080, 60 deg, tolerance 0.5 px, %d frames of a moving camera "
                "(means exclude frame 0)\n",
                count, frames);
    for (bool moving : {false, true}) {
        for (wire::UploadPath path : {wire::UploadPath::cpu_mesh, wire::UploadPath::gpu_rings}) {
            for (int threads : {1, 2}) {
                const Timing t = run(threads, path, frames, count, moving);
                std::printf("%-9s %-13s %d thr: wall %6.2f ms, cpu %6.2f ms (first frame wall %.1f) | wall/cpu:",
                            path == wire::UploadPath::cpu_mesh ? "cpu_mesh" : "gpu_rings",
                            moving ? "nodes moving" : "nodes at rest", threads, t.frame_ms, t.frame_cpu_ms,
                            t.first_frame_ms);
                const char* names[] = {"curve", "lod", "rings", "mesh", "draw"};
                for (std::size_t i = 0; i < 5; ++i) std::printf(" %s %.2f/%.2f", names[i], t.sum_ms[i], t.cpu_ms[i]);
                std::printf(" | visible %.0f, rings %.0f, vertices %.0f\n", t.mean_visible, t.mean_rings,
                            t.mean_vertices);
            }
        }
    }
    for (int frame : {0, 60, 110}) compare_uniform(count, frame);
    return 0;
}
