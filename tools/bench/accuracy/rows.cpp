// The accuracy bench's rows (rows.hpp).
#include "bench/accuracy/rows.hpp"

#include "bench/accuracy/truth_error.hpp"
#include "bench/common.hpp"

#include <wire/lod.hpp>
#include <wire/packed_nodes.hpp>
#include <wire/pop_free.hpp>
#include <wire/rings.hpp>
#include <wire/spline.hpp>
#include <wire/tessellate.hpp>
#include <wire/tube.hpp>

#include <algorithm>
#include <cmath>
#include <functional>

namespace wiretool::bench {
namespace {

struct WireOutput {
    wire::Curve curve;
    wire::WireLod lod;
    std::vector<wire::RingParam> params;
    wire::RingSet rings;
    wire::TubeMesh mesh;
};

/// lod -> rings [-> mesh] for a built curve.
void tessellate(const wire::LodView& view, double tolerance_px, wire::FrameMethod frames, bool mesh,
                WireOutput& w) {
    w.lod = {};
    (void)wire::update_lod(w.curve, view, {.tolerance_px = tolerance_px, .hysteresis_band = -1.0}, w.lod);
    if (w.lod.counts.empty())
        w.lod.counts.assign(w.curve.segment_count(), 1u);  // culled: never in these scenes
    wire::place_rings(w.curve, w.lod.counts, w.params);
    wire::RingSettings rs;
    rs.frames.method = frames;
    wire::build_rings(w.curve, w.params, rs, w.rings);
    if (mesh) wire::build_tube(w.rings, {.sides = std::max(3u, w.lod.sides)}, w.mesh);
}

/// Median over 3 trials of the CPU time of one call of `fn`, microseconds (each trial repeats `fn` until it
/// has used at least `min_ms`).
double time_us(const std::function<void()>& fn, double min_ms) {
    std::vector<double> trials;
    for (int t = 0; t < 3; ++t) {
        int reps = 0;
        const double c0 = cpu_ms();
        double used = 0.0;
        do {
            fn();
            ++reps;
            used = cpu_ms() - c0;
        } while (used < min_ms);
        trials.push_back(1e3 * used / reps);
    }
    return median(trials);
}

}  // namespace

Row measure_row(const ReferenceScene& s, const Method& m, const wire::WireNodes& nodes, double tol,
                double min_ms) {
    Row r;
    r.scene = s.name;
    r.method = m.name;
    r.tolerance_px = tol;
    WireOutput w;
    if (!wire::build_curve(nodes, m.spline, w.curve)) {
        r.world_m = r.screen_px = NAN;
        return r;
    }
    tessellate(s.view, tol, m.frames, true, w);
    r.rings = w.params.size();
    r.sides = w.lod.sides;
    r.vertices = w.mesh.vertices.size();
    r.bytes_cpu = cpu_mesh_bytes(1, w.mesh.vertices.size(), w.mesh.indices.size());
    r.bytes_gpu = gpu_nodes_bytes(nodes, m.spline);
    r.world_m = world_error_m(s, w.curve, w.params);
    r.screen_px = wire::measure_screen_error(w.curve, w.params, s.view, 256).max_px;
    r.twist_deg = twist_error_deg(w.curve, w.params, w.rings);

    WireOutput t;
    r.us_cpu = time_us(
        [&] {
            (void)wire::build_curve(nodes, m.spline, t.curve);
            tessellate(s.view, tol, m.frames, true, t);
        },
        min_ms);
    wire::PackedNodes packed;
    r.us_gpu = time_us([&] { (void)wire::pack_nodes(nodes, m.spline, packed); }, min_ms);
    r.ns_per_vertex = r.vertices > 0 ? 1e3 * r.us_cpu / static_cast<double>(r.vertices) : 0.0;
    return r;
}

Row measure_churn_row(const ReferenceScene& s, const Method& m, const std::vector<wire::WireNodes>& states,
                      double tol) {
    Row r;
    r.scene = s.name;
    r.method = m.name;
    r.tolerance_px = tol;
    wire::PopFreeCurve multires({.spline = m.spline});
    WireOutput w;
    std::vector<double> us, us_nodes;
    std::size_t frames = 0;
    for (std::size_t f = 0; f < states.size(); ++f) {
        const double c0 = cpu_ms();
        if (!multires.update(states[f], w.curve)) continue;
        const double c1 = cpu_ms();
        tessellate(s.view, tol, m.frames, true, w);
        us.push_back(1e3 * (cpu_ms() - c0));
        // The nodes path runs the pop-free stage on the CPU too; a blending wire sends its curve's segments.
        us_nodes.push_back(1e3 * (c1 - c0));
        ++frames;
        r.rings = std::max(r.rings, w.params.size());
        r.sides = std::max<std::size_t>(r.sides, w.lod.sides);
        r.vertices = std::max(r.vertices, w.mesh.vertices.size());
        r.bytes_cpu = std::max(r.bytes_cpu, cpu_mesh_bytes(1, w.mesh.vertices.size(), w.mesh.indices.size()));
        // The nodes path: a blending wire's curve as 64-byte segments (plan_nodes_frame), else its nodes.
        r.bytes_gpu = std::max(r.bytes_gpu, multires.blending() ? 64 + 64 * w.curve.segment_count() + 4
                                                                : gpu_nodes_bytes(states[f], m.spline));
        if (f % 10 == 0 || f + 1 == states.size()) {
            r.world_m = std::max(r.world_m, world_error_m(s, w.curve, w.params));
            r.screen_px =
                std::max(r.screen_px, wire::measure_screen_error(w.curve, w.params, s.view, 128).max_px);
            r.twist_deg = std::max(r.twist_deg, twist_error_deg(w.curve, w.params, w.rings));
        }
    }
    r.us_cpu = median(us);
    r.us_gpu = median(us_nodes);
    r.ns_per_vertex = r.vertices > 0 ? 1e3 * r.us_cpu / static_cast<double>(r.vertices) : 0.0;
    (void)frames;
    return r;
}

}  // namespace wiretool::bench
