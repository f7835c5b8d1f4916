// `wiretool bench`, part 1: the wire systems (curve -> lod -> rings -> mesh -> draw_list) on a field of
// hanging wires seen by a moving camera: CPU time per frame and per system, counts, upload bytes, measured
// screen error, and a uniform tessellation with the same maximum screen error as the baseline. Writes
// bench.csv and bench.md.
#include "bench/common.hpp"
#include "wiretool/commands.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/gfx/gpu_timer.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <wire/io/wire_json.hpp>
#include <wire/lod.hpp>
#include <wire/testing/reference.hpp>
#include <wire/render/upload_plan.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/rings.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>
#include <wire/tessellate.hpp>
#include <wire/tube.hpp>

#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace wiretool::bench {
namespace {

using engine::ecs::Entity;

constexpr int kNodes = 64;
constexpr double kTolerancePx = 0.5;
constexpr float kRadiusM = 0.015f;
constexpr int kSystems = 5;
constexpr const char* kSystemNames[kSystems] = {"curve", "lod", "rings", "mesh", "draw_list"};

enum class SceneKind { standard, offscreen, swaying, far };

const char* scene_name(SceneKind k) {
    switch (k) {
        case SceneKind::standard:
            return "standard";
        case SceneKind::offscreen:
            return "offscreen";
        case SceneKind::swaying:
            return "swaying";
        case SceneKind::far:
            return "far";
    }
    return "?";
}

// Wire i of the field (20 rows high, count/20 deep): a catenary 10 m across, 3-8% longer than its chord,
// through 64 nodes at equal arc lengths.
wire::WireNodes hanging_wire(int i) {
    const int row = i % 20, col = i / 20;
    const glm::dvec3 p1(-5.0, 0.6 * row, -1.5 * col);
    const glm::dvec3 p2 = p1 + glm::dvec3(10.0, 0.3 * std::sin(0.7 * i), 0.2 * std::sin(0.3 * i));
    const double length_m = glm::length(p2 - p1) * (1.03 + 0.004 * (i % 13));
    wire::Catenary cable;
    (void)cable.solve(p1, p2, length_m);  // p1, p2 are never vertically aligned here
    std::vector<double> s(kNodes);
    for (int k = 0; k < kNodes; ++k) s[static_cast<std::size_t>(k)] = length_m * k / (kNodes - 1);
    wire::WireNodes n;
    n.positions = cable.points_at_arc_lengths(s);
    return n;
}

// `far`: a 2 km x 2 km landscape (rolling ground) with 10,000 cables of 64 nodes: power lines (three
// conductors per span, 120-260 m spans between 18-26 m towers, 2-4% slack) along 12 corridors of parallel lines
// (wrapped at the landscape's edges), and rigging (mast stays, crane and ship rigging, 12-45 m, sloped, 1-3%
// slack) in 60 clusters. Deterministic in i.
double ground_m(double x, double z) { return 12.0 * std::sin(x / 310.0) * std::cos(z / 270.0) + 6.0 * std::sin(z / 130.0); }

struct FarWire {
    wire::WireNodes nodes;
    float radius_m = 0.015f;
};

FarWire far_wire(int i) {
    constexpr int kPower = 6000;  // the rest are rigging
    glm::dvec3 p1, p2;
    double slack = 1.02;
    float radius = 0.015f;
    auto hash = [](int a, int b) {  // a fixed pseudo-random number in [0, 1)
        const double v = std::sin(12.9898 * a + 78.233 * b) * 43758.5453;
        return v - std::floor(v);
    };
    if (i < kPower) {
        const int route = i % 12, k = i / 12;  // k: 500 conductors per route
        const int span = k / 3, phase = k % 3;
        const double angle = 0.4 + 0.52 * route + 0.1 * hash(route, 1);
        const glm::dvec3 dir(std::cos(angle), 0.0, std::sin(angle));
        const glm::dvec3 side(-dir.z, 0.0, dir.x);
        const glm::dvec3 start(-900.0 + 150.0 * route, 0.0, -950.0 + 60.0 * route);
        const double s0 = 190.0 * span, s1 = s0 + 120.0 + 140.0 * hash(route, span);
        auto tower = [&](double s) {
            // A route longer than the landscape folds back as a parallel line 45 m to the side (a corridor).
            const double lap = std::floor(s / 2400.0);
            glm::dvec3 p = start + dir * std::fmod(s, 2400.0) + side * (3.5 * (phase - 1) + 45.0 * lap);
            p.x = std::fmod(p.x + 3000.0, 2000.0) - 1000.0;
            p.z = std::fmod(p.z + 3000.0, 2000.0) - 1000.0;
            p.y = ground_m(p.x, p.z) + 18.0 + 8.0 * hash(route, static_cast<int>(s));
            return p;
        };
        p1 = tower(s0);
        p2 = p1 + dir * (s1 - s0);
        p2.y = ground_m(p2.x, p2.z) + 18.0 + 8.0 * hash(route, span + 7);
        slack = 1.02 + 0.02 * hash(i, 3);
        radius = 0.015f;
    } else {
        const int j = i - kPower, cluster = j % 60, k = j / 60;
        const glm::dvec3 base(-950.0 + 1900.0 * hash(cluster, 11), 0.0, -950.0 + 1900.0 * hash(cluster, 13));
        const double mast = 15.0 + 30.0 * hash(cluster, 17);
        const double a = 6.2831853 * hash(cluster * 97 + k, 19);
        const double reach = 12.0 + 30.0 * hash(cluster * 89 + k, 23);
        p1 = base + glm::dvec3(0.0, ground_m(base.x, base.z) + mast * (0.5 + 0.5 * hash(k, 29)), 0.0);
        p2 = base + glm::dvec3(reach * std::cos(a), 0.0, reach * std::sin(a));
        p2.y = ground_m(p2.x, p2.z) + 1.0 + 6.0 * hash(k, 31);
        slack = 1.01 + 0.02 * hash(i, 37);
        radius = 0.008f + 0.012f * static_cast<float>(hash(i, 41));
    }
    const double length_m = glm::length(p2 - p1) * slack;
    wire::Catenary cable;
    (void)cable.solve(p1, p2, length_m);  // never vertically aligned: every cable has a horizontal run
    std::vector<double> s(kNodes);
    for (int k = 0; k < kNodes; ++k) s[static_cast<std::size_t>(k)] = length_m * k / (kNodes - 1);
    FarWire w;
    w.nodes.positions = cable.points_at_arc_lengths(s);
    w.radius_m = radius;
    return w;
}

// standard/swaying: flies slowly into the field, swaying, so every frame moves the camera. offscreen: the
// same motion sideways, 12 m in front of the field and looking away from it: every wire is behind the camera.
void place_camera(engine::scene::Camera& cam, SceneKind kind, int frame) {
    const float t = static_cast<float>(frame);
    if (kind == SceneKind::offscreen) {
        cam.position = {3.0f * std::sin(0.02f * t), 5.0f + std::sin(0.03f * t), 12.0f};
        cam.target = cam.position + glm::vec3(0.4f * std::sin(0.01f * t), -0.15f, 1.0f);
        return;
    }
    if (kind == SceneKind::far) {
        // Flying over the landscape 45 m up, along a gentle curve, looking ahead and a little down.
        const float x = -700.0f + 2.5f * t, z = -600.0f + 1.5f * t + 40.0f * std::sin(0.01f * t);
        cam.position = {x, static_cast<float>(ground_m(x, z)) + 45.0f, z};
        cam.target = cam.position + glm::vec3(0.8f + 0.1f * std::sin(0.02f * t), -0.12f, 0.6f);
        return;
    }
    cam.position = {3.0f * std::sin(0.02f * t), 5.0f + std::sin(0.03f * t), 8.0f - 0.15f * t};
    cam.target = cam.position + glm::vec3(0.4f * std::sin(0.01f * t), -0.15f, -1.0f);
}

// What one frame at a sampled frame keeps for the uniform baseline: the view and the visible wires' curves.
struct Sample {
    wire::LodView view;
    std::vector<wire::Curve> curves;
    double adaptive_error_px = 0.0;
    double adaptive_radial_px = 0.0;
    double max_radial_scale_px = 0.0;  // max over visible wires of R_px = radius * focal / z_min
    std::size_t adaptive_vertices = 0;
};

struct SceneRun {
    std::vector<std::array<double, kSystems>> system_cpu_ms;  // per measured frame
    std::vector<double> frame_cpu_ms, frame_wall_ms;
    std::vector<double> visible, rings, vertices, bytes;
    std::vector<double> retained_bytes;  // gpu-rings: what the retained path sends (upload_plan.hpp's model)
    std::vector<double> visible_segments;  // per frame: segments of the visible wires (uniform counts)
    std::vector<Sample> samples;
    double max_error_px = 0.0;
    wire::systems::WireMemory memory{};  // after the last frame
    double rss_kb = 0.0;                 // VmRSS of the process after the last frame (the scene still alive)
};

// A /proc/self/status field in kB (VmRSS, VmHWM), or 0 where there is none.
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

struct RunSpec {
    SceneKind kind = SceneKind::standard;
    wire::UploadPath path = wire::UploadPath::cpu_mesh;
    int threads = 1;
    int frames = 120;
    int wires = 1000;
    bool sample_errors = true;
    int error_samples = 3;  // frames at which the screen error is measured (spread over the run)
    /// Called after the systems of every frame, frame 0 included (untimed), e.g. to draw the DrawList with GL.
    std::function<void(const wire::systems::WireContext&, int frame)> after_frame;
    wire::SplineSettings spline{.kind = wire::SplineKind::automatic};  ///< the wires' Style::spline (--spline)
};

SceneRun run_scene(const RunSpec& spec) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(spec.threads));
    engine::ecs::Registry registry;
    wire::systems::WireContext ctx;
    ctx.path = spec.path;
    ctx.viewport_width_px = 1920;
    ctx.viewport_height_px = 1080;
    ctx.camera.aspect = 16.0f / 9.0f;
    ctx.camera.far_m = spec.kind == SceneKind::far ? 3000.0f : 500.0f;
    ctx.lod.tolerance_px = kTolerancePx;
    std::vector<Entity> wires;
    for (int i = 0; i < spec.wires; ++i) {
        if (spec.kind == SceneKind::far) {
            FarWire w = far_wire(i);
            wires.push_back(wire::systems::spawn_wire(registry, std::move(w.nodes),
                                                      {.radius_m = w.radius_m, .spline = spec.spline, .material = static_cast<uint32_t>(i % 4)}));
            continue;
        }
        wires.push_back(wire::systems::spawn_wire(
            registry, hanging_wire(i), {.radius_m = kRadiusM, .spline = spec.spline, .material = static_cast<uint32_t>(i % 4)}));
    }
    std::vector<int> sample_frames;
    for (int k = 0; k < spec.error_samples; ++k)
        sample_frames.push_back(1 + (spec.frames - 2) * k / std::max(1, spec.error_samples - 1));

    SceneRun out;
    wire::render::RingResidency residency;  // the retained path's bookkeeping, as the renderer keeps it
    uint64_t since = 0;
    for (int f = 0; f < spec.frames; ++f) {
        place_camera(ctx.camera, spec.kind, f);
        if (spec.kind == SceneKind::swaying && f > 0) {
            // The physics moved every node of every wire a little (ends stay on their posts).
            for (std::size_t i = 0; i < wires.size(); ++i) {
                wire::WireNodes& n = wire::systems::edit_nodes(registry, wires[i]);
                for (std::size_t k = 1; k + 1 < n.positions.size(); ++k)
                    n.positions[k].z += 0.002 * std::sin(0.1 * f + 0.1 * static_cast<double>(k + i));
            }
        }
        std::array<double, kSystems> cpu{};
        double wall = 0.0;
        auto timed = [&](int i, auto&& fn) {
            const double w0 = wall_ms(), c0 = cpu_ms();
            fn();
            cpu[static_cast<std::size_t>(i)] = cpu_ms() - c0;
            wall += wall_ms() - w0;
        };
        using namespace wire::systems;
        timed(0, [&] { curve_system(registry, ctx, since); });
        since = registry.tick();
        timed(1, [&] { lod_system(registry, ctx); });
        timed(2, [&] { rings_system(registry, ctx); });
        timed(3, [&] { mesh_system(registry, ctx); });
        timed(4, [&] { draw_list_system(registry, ctx); });
        const wire::render::RetainedFrame retained = spec.path == wire::UploadPath::gpu_rings
                                                         ? wire::render::plan_retained_frame(ctx.draw_list, residency)
                                                         : wire::render::RetainedFrame{};
        if (spec.after_frame) spec.after_frame(ctx, f);
        if (f == 0) continue;  // the first frame builds everything: a loading cost, not a frame cost

        out.system_cpu_ms.push_back(cpu);
        double total = 0.0;
        for (double v : cpu) total += v;
        out.frame_cpu_ms.push_back(total);
        out.frame_wall_ms.push_back(wall);
        out.visible.push_back(static_cast<double>(ctx.stats.visible_wires));
        out.rings.push_back(static_cast<double>(ctx.stats.rings));
        out.vertices.push_back(static_cast<double>(ctx.stats.vertices));
        out.bytes.push_back(static_cast<double>(upload_bytes(ctx.draw_list)));
        out.retained_bytes.push_back(static_cast<double>(retained.bytes));
        double segments = 0.0;
        for (const wire::DrawItem& item : ctx.draw_list.items)
            segments += static_cast<double>(
                registry.get<wire::systems::WireCurve>(Entity{static_cast<uint32_t>(item.wire_id)})
                    .curve.segment_count());
        out.visible_segments.push_back(segments);

        if (!spec.sample_errors ||
            std::find(sample_frames.begin(), sample_frames.end(), f) == sample_frames.end())
            continue;
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
        out.max_error_px = std::max(out.max_error_px, s.adaptive_error_px);
        out.samples.push_back(std::move(s));
    }
    out.memory = wire::systems::wire_memory(registry);
    out.rss_kb = proc_status_kb("VmRSS");
    return out;
}

// Uniform baseline: k rings per segment on every visible wire, the same side count everywhere.
struct Uniform {
    uint32_t rings_per_segment = 1;
    uint32_t sides = 3;
    double max_error_px = 0.0;
    double rebuild_cpu_ms = 0.0;  // median over samples: rings + mesh of every visible wire
};

// Max screen error of k rings per segment over every sample, stopping early once it exceeds `limit`.
double uniform_error_px(const std::vector<Sample>& samples, uint32_t k, double limit) {
    double worst = 0.0;
    std::vector<uint32_t> counts;
    std::vector<wire::RingParam> params;
    for (const Sample& s : samples) {
        for (const wire::Curve& c : s.curves) {
            counts.assign(c.segment_count(), k);
            wire::place_rings(c, counts, params);
            worst = std::max(worst, wire::measure_screen_error(c, params, s.view, 64).max_px);
            if (worst > limit) return worst;
        }
    }
    return worst;
}

Uniform search_uniform(const SceneRun& run) {
    Uniform u;
    double adaptive_radial = 0.0, radial_scale = 0.0;
    for (const Sample& s : run.samples) {
        adaptive_radial = std::max(adaptive_radial, s.adaptive_radial_px);
        radial_scale = std::max(radial_scale, s.max_radial_scale_px);
    }
    // Smallest k with error <= the adaptive run's. The error falls with k (as ~1/k^2), so: double k until it
    // passes, then bisect the last doubling. A failing k stops at its first wire over the limit (cheap); only
    // passing ones are measured in full, so the search measures few of them.
    const double limit = run.max_error_px;
    uint32_t hi = 1;
    double hi_error = uniform_error_px(run.samples, hi, limit);
    while (hi_error > limit && hi < 256) {
        hi = std::min(256u, 2 * hi);
        hi_error = uniform_error_px(run.samples, hi, limit);
    }
    uint32_t lo = hi / 2 + 1;  // hi / 2 failed (or hi == 1)
    while (lo < hi) {
        const uint32_t mid = (lo + hi) / 2;
        const double e = uniform_error_px(run.samples, mid, limit);
        if (e <= limit) {
            hi = mid;
            hi_error = e;
        } else {
            lo = mid + 1;
        }
    }
    u.rings_per_segment = hi;
    u.max_error_px = hi_error;
    // Smallest side count whose radial error on the nearest wire is no worse than the adaptive sides'.
    for (u.sides = 3; u.sides < 64; ++u.sides)
        if (radial_scale * (1.0 - std::cos(std::numbers::pi / u.sides)) <= adaptive_radial * (1.0 + 1e-12))
            break;

    // CPU cost of building that tessellation (rings + mesh) for the visible wires of each sample.
    std::vector<double> ms;
    std::vector<uint32_t> counts;
    std::vector<wire::RingParam> params;
    wire::RingSet rings;
    wire::TubeMesh mesh;
    for (const Sample& s : run.samples) {
        const double c0 = cpu_ms();
        for (const wire::Curve& c : s.curves) {
            counts.assign(c.segment_count(), u.rings_per_segment);
            wire::place_rings(c, counts, params);
            wire::build_rings(c, params, {}, rings);
            wire::build_tube(rings, {.sides = u.sides}, mesh);
        }
        ms.push_back(cpu_ms() - c0);
    }
    u.rebuild_cpu_ms = median(ms);
    return u;
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

std::vector<std::string> row(const std::string& scene, const std::string& method, const std::string& mode, int wires,
                             double visible, double rings, double vertices, double bytes, double cpu_ms_frame,
                             double error_px) {
    const double ns_per_vertex = vertices > 0 ? cpu_ms_frame * 1e6 / vertices : 0.0;
    return {scene,
            method,
            mode,
            num(kTolerancePx),
            std::to_string(wires),
            num(visible, 6),
            num(rings, 8),
            num(vertices, 9),
            num(bytes, 10),
            num(cpu_ms_frame),
            num(ns_per_vertex),
            num(error_px)};
}

// --gl: the real WireRenderer on a headless EGL context (Mesa llvmpipe), drawing every frame of `standard` on
// three paths (cpu-mesh and gpu-rings streamed by one renderer, gpu-rings retained by another): checks that the
// computed upload size equals FrameStats::bytes_uploaded, and measures per frame the draw() call's wall time
// (CPU: packing, memcpy, GL calls), the GPU time of the pass (GL_TIME_ELAPSED through engine::gfx::GpuTimer,
// read back a few frames later) and draw + glFinish wall time. The framebuffer is small: the bytes do not
// depend on it, and llvmpipe's fill rate would dominate otherwise.
struct GlPath {
    std::string name;
    std::size_t frames = 0, mismatches = 0;
    std::vector<double> renderer_bytes, computed_bytes, draw_ms, finish_ms, gpu_ms, systems_ms;
    engine::gfx::GpuTimer timer;
};

struct GlCheck {
    std::unique_ptr<engine::platform::Context> context;
    wire::render::WireRenderer streamed, retained;
    wire::render::RingResidency model;  // what the retained renderer should send
    GlPath paths[3];                    // cpu-mesh, gpu-rings, gpu-retained
    std::string error;

    bool init() {
        auto created = engine::platform::create_context(
            {.backend = engine::platform::Backend::headless, .width = 480, .height = 270, .quiet = true});
        if (!created) {
            error = created.error().message;
            return false;
        }
        context = std::move(created).value();
        for (bool keep : {false, true}) {
            auto r = wire::render::WireRenderer::create({.retain_rings = keep});
            if (!r) {
                error = r.error().message;
                return false;
            }
            wire::render::WireRenderer& renderer = keep ? retained : streamed;
            renderer = std::move(r).value();
            for (int i = 1; i < 4; ++i) renderer.add_material({.tint = {0.3f * i, 0.5f, 1.0f - 0.2f * i}});
        }
        const char* names[3] = {"cpu-mesh", "gpu-rings", "gpu-retained"};
        for (int i = 0; i < 3; ++i) {
            paths[i].name = names[i];
            paths[i].timer = engine::gfx::GpuTimer::create();
        }
        return true;
    }
    void draw_one(GlPath& path, wire::render::WireRenderer& renderer, const wire::systems::WireContext& ctx,
                  std::size_t computed, bool measured, const std::filesystem::path& png) {
        context->begin_frame();
        engine::gfx::clear({0.1f, 0.1f, 0.12f, 1.0f});
        const double t0 = wall_ms();
        path.timer.begin();
        const wire::render::FrameStats st = renderer.draw(ctx.draw_list, ctx.camera);
        path.timer.end();
        const double t1 = wall_ms();
        engine::gfx::finish_gpu();  // llvmpipe's threads finish the frame before the next path is timed
        const double t2 = wall_ms();
        context->end_frame();
        for (const auto& m : path.timer.poll()) path.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
        if (!measured) return;
        ++path.frames;
        path.mismatches += st.bytes_uploaded != computed;
        path.renderer_bytes.push_back(static_cast<double>(st.bytes_uploaded));
        path.computed_bytes.push_back(static_cast<double>(computed));
        path.draw_ms.push_back(t1 - t0);
        path.finish_ms.push_back(t2 - t0);
        if (!png.empty()) (void)engine::platform::capture_png(*context, png);
    }
    void draw(const wire::systems::WireContext& ctx, int frame, int frames, const std::filesystem::path& dir) {
        const bool measured = frame > 0;  // frame 0 uploads everything: loading, not a frame
        const bool last = frame + 1 == frames;
        if (ctx.draw_list.path == wire::UploadPath::cpu_mesh) {
            draw_one(paths[0], streamed, ctx, upload_bytes(ctx.draw_list), measured,
                     last ? dir / "bench_gl_cpu_mesh.png" : std::filesystem::path{});
            return;
        }
        draw_one(paths[1], streamed, ctx, upload_bytes(ctx.draw_list), measured,
                 last ? dir / "bench_gl_gpu_rings.png" : std::filesystem::path{});
        const std::size_t planned = wire::render::plan_retained_frame(ctx.draw_list, model).bytes;
        draw_one(paths[2], retained, ctx, planned, measured,
                 last ? dir / "bench_gl_gpu_retained.png" : std::filesystem::path{});
    }
    void finish() {
        for (GlPath& p : paths)
            for (const auto& m : p.timer.finish()) p.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
        for (GlPath& p : paths) std::erase_if(p.gpu_ms, [](double v) { return v < 0.0; });  // frame 0
    }
};

}  // namespace

int run_systems_bench(const Options& o) {
    // The wires' spline (--spline; default auto, the runtime's Style default), resolved as `wiretool mesh` does.
    wire::PipelineSettings resolved;
    wire::io::SettingsOverrides overrides;
    overrides.spline_type = o.spline;
    if (wire::Status st = wire::io::resolve_settings(wire::io::WireSpec{}, overrides, resolved); !st.ok) {
        std::fprintf(stderr, "wiretool bench: --spline: %s\n", st.message.c_str());
        return 2;
    }
    const wire::SplineSettings spline = resolved.spline;
    const int frames = o.quick ? 16 : 120;
    const int error_samples = o.quick ? 2 : 3;
    Table csv;
    csv.header = {"scene",          "method",           "mode",          "tolerance_px",
                  "wires",          "visible_wires",    "rings",         "vertices",
                  "bytes_uploaded", "cpu_ms_per_frame", "ns_per_vertex", "max_screen_error_px"};
    std::string notes;
    char buf[2048];
    double standard_cpu_ms = 0.0, offscreen_cpu_ms = -1.0;
    double bytes_cpu = 0.0, bytes_gpu = 0.0;
    double adaptive_vertices_at_samples = 0.0, uniform_vertices_at_samples = 0.0;
    double far_adaptive_vertices = 0.0, far_uniform_vertices = 0.0, far_cpu_ms = -1.0;
    std::array<double, kSystems> standard_systems{}, far_systems{};
    std::string thread_lines;
    GlCheck gl;
    std::string gl_note;
    std::string scene_bytes;  // per scene: gpu-rings streamed and retained bytes, cpu-mesh bytes, ratios
    std::string system_lines, memory_lines;  // per scene: per-system CPU table rows, memory table rows
    double scene_bytes_cpu = 0.0;
    double standard_systems_wall_cpu = 0.0, standard_systems_wall_gpu = 0.0;
    if (o.gl && !gl.init())
        gl_note = "- --gl: no headless GL context (" + gl.error + "); bytes are computed only.\n";
    const bool use_gl = o.gl && gl_note.empty();

    for (SceneKind kind : {SceneKind::standard, SceneKind::offscreen, SceneKind::swaying, SceneKind::far}) {
        const std::string name = scene_name(kind);
        if (!selected(o, name)) continue;
        const int wires = kind == SceneKind::far ? 10000 : 1000;
        const int scene_frames = kind == SceneKind::swaying && o.quick ? 8 : frames;
        SceneRun cpu_run, gpu_run;
        for (wire::UploadPath path : {wire::UploadPath::cpu_mesh, wire::UploadPath::gpu_rings}) {
            const bool cpu = path == wire::UploadPath::cpu_mesh;
            std::fprintf(stderr, "bench: %s %s, %d wires, %d frames, %d thread(s)\n", name.c_str(),
                         cpu ? "cpu-mesh" : "gpu-rings", wires, scene_frames, o.threads);
            RunSpec spec{.kind = kind,
                         .path = path,
                         .threads = o.threads,
                         .frames = scene_frames,
                         .wires = wires,
                         .sample_errors = true,
                         .error_samples = error_samples,
                         .after_frame = {},
                         .spline = spline};
            if (use_gl && kind == SceneKind::standard) {
                const std::filesystem::path dir = o.out_dir;
                spec.after_frame = [&gl, dir, scene_frames](const wire::systems::WireContext& c, int f) {
                    gl.draw(c, f, scene_frames, dir);
                };
            }
            SceneRun r = run_scene(spec);
            {
                const wire::systems::WireMemory& m = r.memory;
                auto per = [](std::size_t bytes, std::size_t n) { return n ? bytes / 1024.0 / n : 0.0; };
                std::snprintf(buf, sizeof buf, "| %s | %s | %zu | %.2f | %zu | %.2f | %.2f | %.2f | %.2f | %.1f |\n",
                              name.c_str(), cpu ? "cpu-mesh" : "gpu-rings", m.visible_wires,
                              per(m.visible_bytes, m.visible_wires), m.culled_wires, per(m.culled_bytes, m.culled_wires),
                              per(m.mesh_bytes, m.visible_wires), per(m.nodes_bytes, m.visible_wires + m.culled_wires),
                              (m.visible_bytes + m.culled_bytes) / 1048576.0, r.rss_kb / 1024.0);
                memory_lines += buf;
            }
            csv.add(row(name, o.spline, cpu ? "cpu-mesh" : "gpu-rings", wires, median(r.visible), median(r.rings),
                        median(r.vertices), median(r.bytes), median(r.frame_cpu_ms), r.max_error_px));
            if (!cpu) {
                // The same frames through the retained ring storage: only changed wires' rings are sent.
                csv.add(row(name, o.spline, "gpu-retained", wires, median(r.visible), median(r.rings), median(r.vertices),
                            median(r.retained_bytes), median(r.frame_cpu_ms), r.max_error_px));
                scene_bytes += "| " + name + " | " + num(median(r.bytes), 8) + " | " +
                               num(median(r.retained_bytes), 8) + " |";
            } else {
                scene_bytes_cpu = median(r.bytes);
            }
            if (kind == SceneKind::standard && use_gl) {
                (cpu ? standard_systems_wall_cpu : standard_systems_wall_gpu) = median(r.frame_wall_ms);
            }
            (cpu ? cpu_run : gpu_run) = std::move(r);
        }
        if (scene_bytes_cpu > 0.0) {
            std::snprintf(buf, sizeof buf, " %.8g | %.1fx | %.1fx |\n", scene_bytes_cpu,
                          scene_bytes_cpu / std::max(1.0, median(gpu_run.bytes)),
                          scene_bytes_cpu / std::max(1.0, median(gpu_run.retained_bytes)));
            scene_bytes += buf;
        } else {
            scene_bytes += " 0 | - | - |\n";
        }
        scene_bytes_cpu = 0.0;
        // Uniform baseline at the cpu-mesh run's sampled frames.
        const Uniform u = search_uniform(cpu_run);
        std::vector<double> u_rings, u_vertices, u_bytes, a_vertices;
        for (std::size_t f = 0; f < cpu_run.visible.size(); ++f) {
            const double n = cpu_run.visible[f];
            const double r =
                u.rings_per_segment * cpu_run.visible_segments[f] + n;     // open wires: one extra ring
            const double v = r * (u.sides + 1) + n * 2.0 * (u.sides + 1);  // sides + caps
            const double idx = r * 6.0 * u.sides;                          // (r - n) bands + n cap pairs
            u_rings.push_back(r);
            u_vertices.push_back(v);
            u_bytes.push_back(static_cast<double>(cpu_mesh_bytes(
                static_cast<std::size_t>(n), static_cast<std::size_t>(v), static_cast<std::size_t>(idx))));
        }
        const double curve_ms = system_medians(cpu_run)[0];
        {
            const std::array<double, kSystems> sys = system_medians(cpu_run);
            std::snprintf(buf, sizeof buf, "| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |\n", name.c_str(), sys[0],
                          sys[1], sys[2], sys[3], sys[4], median(cpu_run.frame_cpu_ms));
            system_lines += buf;
        }
        csv.add(row(name, o.spline, "uniform", wires, median(cpu_run.visible), median(u_rings), median(u_vertices),
                    median(u_bytes), curve_ms + u.rebuild_cpu_ms, u.max_error_px));
        std::snprintf(
            buf, sizeof buf,
            "- `%s` uniform baseline: %u rings per segment, %u sides (max centre-line error %.3f px "
            "against the adaptive run's %.3f px over %zu sampled frames).\n",
            name.c_str(), u.rings_per_segment, u.sides, u.max_error_px, cpu_run.max_error_px,
            cpu_run.samples.size());
        notes += buf;

        // Adaptive and uniform vertices at the same sampled frames (same visible wires).
        auto vertices_at_samples = [&](double& adaptive, double& uniform) {
            for (const Sample& s : cpu_run.samples) {
                adaptive += static_cast<double>(s.adaptive_vertices);
                for (const wire::Curve& c : s.curves) {
                    const std::size_t r = u.rings_per_segment * c.segment_count() + 1;
                    uniform += static_cast<double>(wire::tube_counts(r, false, {.sides = u.sides}).vertices);
                }
            }
        };
        if (kind == SceneKind::standard) {
            standard_cpu_ms = median(cpu_run.frame_cpu_ms);
            standard_systems = system_medians(cpu_run);
            bytes_cpu = median(cpu_run.bytes);
            bytes_gpu = median(gpu_run.bytes);
            vertices_at_samples(adaptive_vertices_at_samples, uniform_vertices_at_samples);
        }
        if (kind == SceneKind::far) {
            far_cpu_ms = median(cpu_run.frame_cpu_ms);
            far_systems = system_medians(cpu_run);
            vertices_at_samples(far_adaptive_vertices, far_uniform_vertices);
        }
        if (kind == SceneKind::offscreen) offscreen_cpu_ms = median(cpu_run.frame_cpu_ms);

        // 1 vs 2 threads (wall time: the point of threads is to finish sooner), on the cpu-mesh path. Both thread
        // counts get runs of their own, alternated (1, 2, 1, 2) and at least 40 frames each, so that a short
        // --quick scene or a moment of load on the machine does not decide the ratio; the median over the frames
        // of both runs of a thread count.
        if (kind != SceneKind::offscreen &&
            (!o.quick || kind == SceneKind::standard || kind == SceneKind::swaying)) {
            std::vector<double> walls[2];
            for (int round = 0; round < 2; ++round) {
                for (int t : {1, 2}) {
                    std::fprintf(stderr, "bench: %s cpu-mesh, %d thread(s) (thread scaling)\n", name.c_str(), t);
                    const SceneRun r = run_scene({.kind = kind,
                                                  .path = wire::UploadPath::cpu_mesh,
                                                  .threads = t,
                                                  .frames = std::max(scene_frames, 40),
                                                  .wires = wires,
                                                  .sample_errors = false,
                                                  .error_samples = 0,
                                                  .after_frame = {},
                                                  .spline = spline});
                    walls[t - 1].insert(walls[t - 1].end(), r.frame_wall_ms.begin(), r.frame_wall_ms.end());
                }
            }
            const double wall[2] = {median(walls[0]), median(walls[1])};
            std::snprintf(buf, sizeof buf, "| %s | %.3f | %.3f | %.2fx |\n", name.c_str(), wall[0], wall[1],
                          wall[1] > 0 ? wall[0] / wall[1] : 0.0);
            thread_lines += buf;
        }
    }

    if (!csv.write_csv(o.out_dir / "bench.csv")) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench.csv").c_str());
        return exit_failure;
    }

    std::string md = "# wiretool bench: wire systems\n\n";
    std::snprintf(
        buf, sizeof buf,
        "%d hanging wires of %d nodes (catenaries 10 m across; `far`: 10,000 cables over a 2 km landscape), "
        "1920x1080, 60 degree field of view, "
        "tolerance %.2f px, %d frames of a moving camera (medians exclude frame 0, which builds "
        "everything)%s; "
        "%d thread(s). `standard`: static nodes; `swaying`: every node moves every frame; `offscreen`: "
        "the same wires, all behind the camera; `far`: power lines (120-260 m spans) and rigging (12-45 m) over "
        "2 km x 2 km of rolling ground, a camera flying 45 m up. CPU time is process CPU time of the five systems "
        "(curve, lod, rings, mesh, draw_list) per frame. `bytes_uploaded` is computed exactly as "
        "WireRenderer::draw() would memcpy it from the frame's DrawList (no GL is run). `uniform`: a fixed "
        "ring count per segment and one side count, the smallest whose measured maximum screen error is "
        "no worse than the adaptive run's; its CPU time is the curve stage plus building its rings and "
        "mesh for every visible wire (what it costs whenever the wires move).\n\n",
        1000, kNodes, kTolerancePx, frames, o.quick ? " (--quick; `swaying` runs 8 frames)" : "", o.threads);
    md += buf;
    md += csv.markdown();
    md += "\n" + notes;
    if (standard_cpu_ms > 0.0) {
        md += "\n## Figures\n\n";
        md += "Per-system CPU ms per frame, `standard`, cpu-mesh (median):";
        for (int i = 0; i < kSystems; ++i) {
            std::snprintf(buf, sizeof buf, " %s %.3f;", kSystemNames[i],
                          standard_systems[static_cast<std::size_t>(i)]);
            md += buf;
        }
        md += "\n\n";
        if (adaptive_vertices_at_samples > 0.0) {
            std::snprintf(
                buf, sizeof buf,
                "- adaptive vs uniform at equal max screen error (`standard`, same sampled frames): "
                "%.0f vs %.0f vertices, %.1fx fewer (aim >= 5x)\n",
                adaptive_vertices_at_samples, uniform_vertices_at_samples,
                uniform_vertices_at_samples / adaptive_vertices_at_samples);
            md += buf;
        }
        if (standard_systems[1] > 0.0) {
            double total = 0.0;
            for (double v : standard_systems) total += v;
            std::snprintf(buf, sizeof buf, "- lod share of the five systems (`standard`, cpu-mesh): %.1f%% (aim <= 25%%)\n",
                          100.0 * standard_systems[1] / total);
            md += buf;
        }
        if (bytes_gpu > 0.0) {
            std::snprintf(buf, sizeof buf,
                          "- gpu-rings vs cpu-mesh bytes per frame: %.0f vs %.0f, %.1fx fewer (aim >= 6x)\n",
                          bytes_gpu, bytes_cpu, bytes_cpu / bytes_gpu);
            md += buf;
        }
        if (offscreen_cpu_ms >= 0.0) {
            std::snprintf(buf, sizeof buf,
                          "- offscreen vs standard CPU per frame: %.4f vs %.4f ms = %.2f%% (aim < 2%%)\n",
                          offscreen_cpu_ms, standard_cpu_ms, 100.0 * offscreen_cpu_ms / standard_cpu_ms);
            md += buf;
        }
    }
    if (!system_lines.empty()) {
        md += "\n## Per-system CPU ms per frame (cpu-mesh, median; " + std::to_string(o.threads) +
              " thread(s))\n\n| scene | curve | lod | rings | mesh | draw_list | frame |\n"
              "| --- | --- | --- | --- | --- | --- | --- |\n" + system_lines;
    }
    if (!memory_lines.empty()) {
        std::snprintf(buf, sizeof buf, "%.1f", proc_status_kb("VmHWM") / 1024.0);
        md += "\n## Memory the wire systems hold (after the last frame; wire::systems::wire_memory: capacity of "
              "their per-wire containers plus the components, KiB per wire; the mesh column is the cpu-mesh "
              "output, included in the visible figure; nodes are the game's input, not included)\n\n"
              "| scene | path | visible | KiB / visible wire | culled | KiB / culled wire | mesh KiB / visible | "
              "nodes KiB / wire | systems MiB | process RSS MiB |\n"
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n" + memory_lines +
              "\nProcess peak resident size (VmHWM) at the end of the bench: " + buf + " MiB.\n"
              "\nPer wire the systems keep the curve (double Bezier segments), the last valid nodes (they re-prime "
              "the pop-free state), the LOD state, the float ring records and, on cpu-mesh, the drawn mesh. A wire "
              "culled while it moves keeps none of curve, LOD counts, rings or mesh (the next frame rebuilds them; "
              "the curve comes back from the last valid nodes when the view turns to it); the LOD's span hierarchy "
              "(LodBounds) is kept only by wires whose curve did not change since their last LOD update (static "
              "wires: the coherence reuse). Aims (issue 18): <= 16 KB per visible and <= 4 KB per culled 64-node "
              "wire on `swaying`.\n";
    }
    if (!scene_bytes.empty()) {
        md += "\n## Bytes uploaded per frame (median)\n\n| scene | gpu-rings streamed | gpu-rings retained | "
              "cpu-mesh | cpu-mesh / streamed | cpu-mesh / retained |\n| --- | --- | --- | --- | --- | --- |\n" +
              scene_bytes + "\n(aims: retained >= 20x fewer than cpu-mesh on `standard`, >= 6x on `swaying`)\n";
    }
    if (far_cpu_ms >= 0.0) {
        md += "\nPer-system CPU ms per frame, `far` (10,000 cables), cpu-mesh (median):";
        for (int i = 0; i < kSystems; ++i) {
            std::snprintf(buf, sizeof buf, " %s %.3f;", kSystemNames[i], far_systems[static_cast<std::size_t>(i)]);
            md += buf;
        }
        md += "\n\n";
        if (far_adaptive_vertices > 0.0) {
            std::snprintf(buf, sizeof buf,
                          "- adaptive vs uniform at equal max screen error (`far`, same sampled frames): %.0f vs %.0f "
                          "vertices, %.1fx fewer (aim >= 10x)\n",
                          far_adaptive_vertices, far_uniform_vertices, far_uniform_vertices / far_adaptive_vertices);
            md += buf;
        }
    }
    if (use_gl) {
        gl.finish();
        md += "\n## --gl: WireRenderer on " + gl.context->gl_renderer() +
              ", `standard`, 480x270, every frame (medians over frames 1..N)\n\n"
              "| path | frames | bytes matched | bytes/frame (renderer) | systems wall ms | draw() wall ms | "
              "GPU ms (timer) | draw + glFinish wall ms | end to end ms (systems + draw + finish) |\n"
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
        for (const GlPath& p : gl.paths) {
            const double systems = &p == &gl.paths[0] ? standard_systems_wall_cpu : standard_systems_wall_gpu;
            std::snprintf(buf, sizeof buf, "| %s | %zu | %zu | %.0f | %.2f | %.2f | %.2f | %.2f | %.2f |\n",
                          p.name.c_str(), p.frames, p.frames - p.mismatches, median(p.renderer_bytes), systems,
                          median(p.draw_ms), median(p.gpu_ms), median(p.finish_ms), systems + median(p.finish_ms));
            md += buf;
        }
        md += "\nGPU ms: GL_TIME_ELAPSED around the wire pass, read back without stalling (engine::gfx::GpuTimer); "
              "systems wall ms: the five wire systems (the retained path runs the same systems as gpu-rings). "
              "bench_gl_*.png: the last frame of each path.\n";
    }
    md += gl_note;
    if (!thread_lines.empty()) {
        std::string load = "unknown";
        if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {  // other work on the machine skews wall times
            char text[128] = {};
            if (std::fgets(text, sizeof text, f)) load = std::string(text, std::strcspn(text, "\n"));
            std::fclose(f);
        }
        md +=
            "\n## 1 vs 2 threads (cpu-mesh, median wall ms per frame of the five systems over two runs of at least 40 "
            "frames each, alternated; /proc/loadavg at "
            "the "
            "end: " +
            load +
            ")\n\n"
            "| scene | 1 thread | 2 threads | speed-up |\n| --- | --- | --- | --- |\n" +
            thread_lines;
    }
    if (!write_text(o.out_dir / "bench.md", md)) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench.md").c_str());
        return exit_failure;
    }
    return exit_ok;
}

}  // namespace wiretool::bench
