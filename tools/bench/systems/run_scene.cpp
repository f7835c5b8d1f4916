// The wire systems bench's measuring loop (run_scene.hpp).
#include "bench/systems/run_scene.hpp"

#include "bench/common.hpp"
#include "bench/scenes/camera_paths.hpp"

#include <engine/ecs/registry.hpp>
#include <wire/render/upload_plan.hpp>
#include <wire/systems/systems.hpp>
#include <wire/tessellate.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <utility>

namespace wiretool::bench {
namespace {

using engine::ecs::Entity;

// The context every scene is seen through: spec's viewport (1920x1080 by default), the LOD at kTolerancePx.
void set_up_view(wire::systems::WireContext& ctx, const RunSpec& spec) {
    ctx.path = spec.path;
    ctx.viewport_width_px = spec.width_px;
    ctx.viewport_height_px = spec.height_px;
    ctx.camera.aspect = static_cast<float>(spec.width_px) / static_cast<float>(spec.height_px);
    if (!spec.thin_wires) ctx.lod.strip_radius_px = ctx.lod.line_radius_px = -1.0;
    ctx.fused_stages = spec.fused_stages;
    ctx.camera.far_m = spec.kind == SceneKind::far ? 3000.0f : 500.0f;
    ctx.lod.tolerance_px = kTolerancePx;
}

std::vector<Entity> spawn_scene_wires(engine::ecs::Registry& registry, const RunSpec& spec) {
    std::vector<Entity> wires;
    for (int i = 0; i < spec.wires; ++i) {
        if (spec.kind == SceneKind::far) {
            FarWire w = far_wire(i);
            wires.push_back(wire::systems::spawn_wire(
                registry, std::move(w.nodes),
                {.radius_m = w.radius_m, .spline = spec.spline, .material = static_cast<uint32_t>(i % 4)}));
            continue;
        }
        wires.push_back(wire::systems::spawn_wire(
            registry, hanging_wire(i),
            {.radius_m = kRadiusM, .spline = spec.spline, .material = static_cast<uint32_t>(i % 4)}));
    }
    return wires;
}

// The five systems in install() order, each timed (process CPU per system; wall summed over the frame).
struct FrameTimes {
    std::array<double, kSystems> cpu{};
    double wall = 0.0;
};

FrameTimes run_systems_timed(engine::ecs::Registry& registry, wire::systems::WireContext& ctx,
                             uint64_t& since) {
    FrameTimes t;
    auto timed = [&](int i, auto&& fn) {
        const double w0 = wall_ms(), c0 = cpu_ms();
        fn();
        t.cpu[static_cast<std::size_t>(i)] = cpu_ms() - c0;
        t.wall += wall_ms() - w0;
    };
    using namespace wire::systems;
    timed(0, [&] { curve_system(registry, ctx, since); });
    since = registry.tick();
    timed(1, [&] { lod_system(registry, ctx); });
    timed(2, [&] { rings_system(registry, ctx); });
    timed(3, [&] { mesh_system(registry, ctx); });
    timed(4, [&] { draw_list_system(registry, ctx); });
    return t;
}

// A measured frame's times, counts and upload bytes (`nodes_bytes`: plan_nodes_frame's, on the nodes path).
void record_frame(SceneRun& out, const FrameTimes& t, engine::ecs::Registry& registry,
                  const wire::systems::WireContext& ctx, std::size_t nodes_bytes) {
    out.system_cpu_ms.push_back(t.cpu);
    double total = 0.0;
    for (double v : t.cpu) total += v;
    out.frame_cpu_ms.push_back(total);
    out.frame_wall_ms.push_back(t.wall);
    out.visible.push_back(static_cast<double>(ctx.stats.visible_wires));
    out.rings.push_back(static_cast<double>(ctx.stats.rings));
    out.vertices.push_back(static_cast<double>(ctx.stats.vertices));
    out.bytes.push_back(static_cast<double>(
        ctx.draw_list.path == wire::UploadPath::gpu_nodes ? nodes_bytes : upload_bytes(ctx.draw_list)));
    double segments = 0.0;
    for (const wire::DrawItem& item : ctx.draw_list.items)
        segments += static_cast<double>(
            registry.get<wire::systems::WireCurve>(Entity{static_cast<uint32_t>(item.wire_id)})
                .curve.segment_count());
    out.visible_segments.push_back(segments);
}

// The screen error of the frame as drawn, and what the uniform baseline needs to match it.
Sample sample_errors(engine::ecs::Registry& registry, const wire::systems::WireContext& ctx) {
    Sample s;
    s.view = ctx.view;
    s.adaptive_error_px = wire::systems::scene_screen_error(registry, ctx, 64).max_px;
    s.adaptive_vertices = ctx.stats.vertices;
    for (const wire::DrawItem& item : ctx.draw_list.items) {
        const Entity e{static_cast<uint32_t>(item.wire_id)};
        s.curves.push_back(registry.get<wire::systems::WireCurve>(e).curve);
        const wire::WireLod& lod = registry.get<wire::systems::WireLodState>(e).lod;
        if (lod.z_min_m > 0.0) {
            const double radius = registry.get<wire::systems::Style>(e).radius_m;
            const double r_px = radius * ctx.view.focal_px / lod.z_min_m;
            s.max_radial_scale_px = std::max(s.max_radial_scale_px, r_px);
            // A strip's silhouette is the tube's (2R across, no polygon error); a phone-wire line's edge
            // lies 0.5 px - R from the true one (its coverage is the true width's).
            const double radial = item.sides == 2   ? 0.0
                                  : item.sides == 1 ? std::max(0.0, 0.5 - r_px)
                                                    : r_px * (1.0 - std::cos(std::numbers::pi / item.sides));
            s.adaptive_radial_px = std::max(s.adaptive_radial_px, radial);
        }
    }
    return s;
}

}  // namespace

SceneRun run_scene(const RunSpec& spec) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(spec.threads));
    engine::ecs::Registry registry;
    wire::systems::WireContext ctx;
    set_up_view(ctx, spec);
    const std::vector<Entity> wires = spawn_scene_wires(registry, spec);
    std::vector<int> sample_frames;
    for (int k = 0; k < spec.error_samples; ++k)
        sample_frames.push_back(1 + (spec.frames - 2) * k / std::max(1, spec.error_samples - 1));

    SceneRun out;
    wire::render::NodesPlan nodes_plan;  // the nodes path's slots, as the renderer keeps them
    uint64_t since = 0;
    for (int f = 0; f < spec.frames; ++f) {
        place_camera(ctx.camera, spec.kind, f);
        if (spec.kind == SceneKind::swaying && f > 0) {
            for (std::size_t i = 0; i < wires.size(); ++i)
                sway_nodes(wire::systems::edit_nodes(registry, wires[i]), i, f);
        }
        const FrameTimes times = run_systems_timed(registry, ctx, since);
        const std::size_t nodes_bytes = spec.path == wire::UploadPath::gpu_nodes
                                             ? wire::render::plan_nodes_frame(ctx.draw_list, nodes_plan)
                                             : 0;
        if (spec.after_frame) spec.after_frame(ctx, f);
        if (f == 0) continue;  // the first frame builds everything: a loading cost, not a frame cost

        record_frame(out, times, registry, ctx, nodes_bytes);
        if (!spec.sample_errors ||
            std::find(sample_frames.begin(), sample_frames.end(), f) == sample_frames.end())
            continue;
        Sample s = sample_errors(registry, ctx);
        out.max_error_px = std::max(out.max_error_px, s.adaptive_error_px);
        out.samples.push_back(std::move(s));
    }
    out.memory = wire::systems::wire_memory(registry);
    out.rss_kb = proc_status_kb("VmRSS");
    return out;
}

std::array<double, kSystems> system_medians(const SceneRun& r) {
    std::array<double, kSystems> m{};
    for (int i = 0; i < kSystems; ++i) {
        std::vector<double> v;
        for (const auto& f : r.system_cpu_ms) v.push_back(f[static_cast<std::size_t>(i)]);
        m[static_cast<std::size_t>(i)] = median(v);
    }
    return m;
}

double proc_status_kb(const char* field) {
    double kb = 0.0;
    if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
        char line[256];
        const std::size_t len = std::strlen(field);
        while (std::fgets(line, sizeof line, f))
            if (std::strncmp(line, field, len) == 0 && line[len] == ':') kb = std::atof(line + len + 1);
        std::fclose(f);
    }
    return kb;
}

}  // namespace wiretool::bench
