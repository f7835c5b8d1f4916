// The wire systems bench's uniform baseline (uniform_baseline.hpp).
#include "bench/systems/uniform_baseline.hpp"

#include "bench/common.hpp"

#include <wire/rings.hpp>
#include <wire/tessellate.hpp>
#include <wire/tube.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace wiretool::bench {
namespace {

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

}  // namespace

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

UniformCounts uniform_counts(const SceneRun& run, const Uniform& u) {
    UniformCounts out;
    for (std::size_t f = 0; f < run.visible.size(); ++f) {
        const double n = run.visible[f];
        const double r = u.rings_per_segment * run.visible_segments[f] + n;  // open wires: one extra ring
        const double v = r * (u.sides + 1) + n * 2.0 * (u.sides + 1);        // sides + caps
        const double idx = r * 6.0 * u.sides;                                // (r - n) bands + n cap pairs
        out.rings.push_back(r);
        out.vertices.push_back(v);
        out.bytes.push_back(static_cast<double>(cpu_mesh_bytes(
            static_cast<std::size_t>(n), static_cast<std::size_t>(v), static_cast<std::size_t>(idx))));
    }
    return out;
}

void add_vertices_at_samples(const SceneRun& run, const Uniform& u, double& adaptive, double& uniform) {
    for (const Sample& s : run.samples) {
        adaptive += static_cast<double>(s.adaptive_vertices);
        for (const wire::Curve& c : s.curves) {
            const std::size_t r = u.rings_per_segment * c.segment_count() + 1;
            uniform += static_cast<double>(wire::tube_counts(r, false, {.sides = u.sides}).vertices);
        }
    }
}

}  // namespace wiretool::bench
