// Building LodBounds: the curve's bounding sphere and the span hierarchy (chord deviations, spheres, Wang's M).
#include "wire/lod.hpp"

#include "lod/bounds.hpp"
#include "lod/span_kernels.hpp"
#include "simd/lanes.hpp"  // min_of, max_of

#include <glm/geometric.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace wire {

using namespace lod_stage;
using simd::max_of;
using simd::min_of;

namespace {

// Working memory of compute_lod_bounds (one per thread, grows once): the level-0 boxes and the chord end points of
// the nodes of two adjacent levels (structure of arrays).
struct BoundsScratch {
    std::vector<double> boxes;    // 6 n: lo x, y, z, hi x, y, z of every segment
    std::vector<double> ends[2];  // 6 arrays of a level's width: first point x, y, z, last point x, y, z
};
BoundsScratch& bounds_scratch() {
    thread_local BoundsScratch s;
    return s;
}

// std::min (std::max) of init and v[0..n) in sequence, which keeps the first of equal values: in four lanes,
// exact unless the result is a zero (the one value with two encodings, -0 and +0: then in sequence).
template <bool Max>
double ordered_extreme(const double* v, std::size_t n, double init) {
    auto pick = [](double acc, double x) { return Max ? max_of(acc, x) : min_of(acc, x); };
    double acc[4] = {init, init, init, init};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; ++k) acc[k] = pick(acc[k], v[i + k]);
    for (; i < n; ++i) acc[0] = pick(acc[0], v[i]);
    const double r = pick(pick(acc[0], acc[1]), pick(acc[2], acc[3]));
    if (r != 0.0) return r;
    double seq = init;
    for (i = 0; i < n; ++i) seq = pick(seq, v[i]);
    return seq;
}
double ordered_min(const double* v, std::size_t n) {
    return ordered_extreme<false>(v, n, std::numeric_limits<double>::infinity());
}
double ordered_max(const double* v, std::size_t n) {
    return ordered_extreme<true>(v, n, -std::numeric_limits<double>::infinity());
}

// std::max(0.0, r) over the radii in sequence (curve_bounding_sphere()'s radius): four lanes, in sequence when
// the result is a zero.
double largest_radius(const std::vector<float>& radii) {
    const std::size_t n = radii.size();
    double acc[4] = {0.0, 0.0, 0.0, 0.0};
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; ++k) acc[k] = max_of(acc[k], static_cast<double>(radii[i + k]));
    for (; i < n; ++i) acc[0] = max_of(acc[0], static_cast<double>(radii[i]));
    const double r = max_of(max_of(acc[0], acc[1]), max_of(acc[2], acc[3]));
    if (r != 0.0) return r;
    double seq = 0.0;
    for (const float x : radii) seq = std::max(seq, static_cast<double>(x));
    return seq;
}

}  // namespace

BoundingSphere curve_bounding_sphere(const Curve& curve) {
    // The box of all control points: std::min / std::max (glm::min / glm::max) over b0, b1, b2, b3 of every
    // segment in sequence from +inf (-inf), here as 12 lanes (wire_box), a zero redone in sequence; the radius
    // std::max(0.0, r) over the radii in sequence. compute_lod_bounds() gets the same sphere from its boxes.
    const std::size_t n = curve.segments.size();
    if (n == 0) return {};
    double lo12[12], hi12[12];
    span_kernels().box(curve.segments.data(), n, lo12, hi12);
    glm::dvec3 lo(0.0), hi(0.0);
    for (int c = 0; c < 3; ++c) {
        double l = min_of(min_of(lo12[c], lo12[c + 3]), min_of(lo12[c + 6], lo12[c + 9]));
        double h = max_of(max_of(hi12[c], hi12[c + 3]), max_of(hi12[c + 6], hi12[c + 9]));
        if (l == 0.0 || h == 0.0) {
            double sl = std::numeric_limits<double>::infinity(), sh = -std::numeric_limits<double>::infinity();
            for (const CubicBezier& s : curve.segments)
                for (const glm::dvec3* q : {&s.b0, &s.b1, &s.b2, &s.b3}) {
                    sl = min_of(sl, (*q)[c]);
                    sh = max_of(sh, (*q)[c]);
                }
            l = sl;
            h = sh;
        }
        lo[c] = l;
        hi[c] = h;
    }
    const double radius = largest_radius(curve.radius_m);
    const glm::dvec3 centre = 0.5 * (lo + hi);
    // Round the radius up by a relative hair so rounding in the centre cannot leave a corner outside.
    return {centre, (0.5 * glm::length(hi - lo)) * (1.0 + 1e-12) + radius, radius};
}

namespace lod_stage {

std::size_t compute_lod_bounds_impl(const Curve& curve, LodBounds& out, const BoundingSphere* known_sphere,
                                    const TopLevels* stop) {
    const std::size_t n = curve.segment_count();
    out.segments = n;
    out.sphere = BoundingSphere{};  // curve_bounding_sphere(curve), from the level-0 boxes below
    // largest_radius() of the same curve, as the given sphere keeps it (or again).
    out.radius_max_m = known_sphere != nullptr && known_sphere->tube_radius_m >= 0.0 ? known_sphere->tube_radius_m
                                                                                  : largest_radius(curve.radius_m);
    out.wang_m_max = 0.0;
    out.levels = 0;
    // Unique over all curves (a state made for other bounds never matches): each thread takes blocks of 2^16
    // versions from one counter, so threads do not contend for it on every wire.
    static std::atomic<uint64_t> version_blocks{0};
    thread_local uint64_t next_version = 0, block_end = 0;
    if (next_version == block_end) {
        const uint64_t block = version_blocks.fetch_add(1, std::memory_order_relaxed);
        next_version = (block << 16) + 1;  // never 0
        block_end = (block + 1) << 16;
    }
    out.version = next_version++;
    if (n == 0) {
        out.data.clear();
        return 0;
    }
    // Level widths and where each level starts (root first).
    uint32_t levels = 1;
    while (out.level_width(levels - 1) > 1) ++levels;
    out.levels = levels;
    std::size_t nodes = 0;
    for (std::size_t l = levels; l-- > 0;) {
        out.level_start[l] = static_cast<uint32_t>(nodes);
        nodes += out.level_width(l);
    }
    // Every entry is written below: a buffer of the right size (the same wire next frame, or a per-thread one for
    // wires of equal length) is not cleared first.
    if (out.data.size() != 2 * levels + 5 * nodes + n) out.data.assign(2 * levels + 5 * nodes + n, 0.0);
    double* wang = out.data.data() + 2 * levels + 5 * nodes;
    BoundsScratch& sc = bounds_scratch();
    if (sc.ends[0].size() < 6 * n) {
        sc.ends[0].resize(6 * n);
        sc.ends[1].resize(6 * n);
    }
    // The level-0 boxes only where the wire's box is not known already (as its sphere).
    if (known_sphere == nullptr && sc.boxes.size() < 6 * n) sc.boxes.resize(6 * n);
    const SpanKernels& kernels = span_kernels();
    // Level 0 with its deviation range (out.data[0], [1]) and the largest M (never -0: a root of a sum of squares).
    double range0[4];
    double* boxes = known_sphere == nullptr ? sc.boxes.data() : nullptr;
    kernels.level0(curve.segments.data(), n, out.level_data(0), wang, boxes, sc.ends[0].data(), range0);
    out.data[0] = range0[0];
    out.data[1] = range0[1];
    out.wang_m_max = range0[2];
    if (stop != nullptr && !std::isfinite(range0[3])) stop = nullptr;  // a coordinate NaN (or an overflow)
    if (known_sphere != nullptr) {
        out.sphere = *known_sphere;
    } else {
        // The wire's box.
        const double* b = sc.boxes.data();
        const glm::dvec3 lo(ordered_min(b, n), ordered_min(b + n, n), ordered_min(b + 2 * n, n));
        const glm::dvec3 hi(ordered_max(b + 3 * n, n), ordered_max(b + 4 * n, n), ordered_max(b + 5 * n, n));
        // curve_bounding_sphere(curve): the same box (the same minima and maxima), the same rounding.
        const double radius = out.radius_max_m;
        out.sphere = {0.5 * (lo + hi), (0.5 * glm::length(hi - lo)) * (1.0 + 1e-12) + radius, radius};
    }
    // Levels 1 and up, each from the one below, with their deviation ranges; the chord ends alternate between two
    // buffers.
    // With a stop test, a level's deviations come first: a level that stops the build needs no spheres.
    if (stop != nullptr && (out.level_deviation_min(0) * stop->c) * stop->k > stop->above) return 1;
    for (std::size_t level = 1; level < levels; ++level) {
        const double* child = out.level_data(level - 1);
        const std::size_t cw = out.level_width(level - 1), w = out.level_width(level);
        double* parent = out.level_data(level);
        const double* e = sc.ends[(level - 1) & 1].data();
        double* f = sc.ends[level & 1].data();
        if (stop == nullptr || level + 1 == levels) {  // the root: nothing above it to leave out
            kernels.merge_level(child, e, cw, parent, f, w, out.data.data() + 2 * level);
            continue;
        }
        kernels.merge_deviations(child, e, cw, parent, f, w, out.data.data() + 2 * level);
        if ((out.level_deviation_min(level) * stop->c) * stop->k > stop->above) return level + 1;
        kernels.merge_spheres(child, cw, parent, w);
    }
    return levels;
}

}  // namespace lod_stage

void compute_lod_bounds(const Curve& curve, LodBounds& out) { compute_lod_bounds_impl(curve, out, nullptr); }

void compute_lod_bounds(const Curve& curve, LodBounds& out, const BoundingSphere& sphere) {
    compute_lod_bounds_impl(curve, out, &sphere);
}

}  // namespace wire

namespace wire {

BoundingSphere node_bounding_sphere(const WireNodes& nodes, const SplineSettings& settings) {
    const bool local = settings.kind == SplineKind::linear || settings.kind == SplineKind::catmull_rom;
    const std::size_t n = nodes.size();
    if (!local || n == 0) return {};
    // K = max over nodes of |1 - tension| (1 + |bias|) (1 + |continuity|): the factor of t's bound (1 for linear,
    // whose t is the chord itself).
    double k = 1.0;
    if (settings.kind == SplineKind::catmull_rom) {
        const auto at = [](const auto& v, std::size_t i, double fallback) -> double {
            return v.empty() ? fallback : v[i];
        };
        const bool per_node = !nodes.kb_tension.empty() || !nodes.kb_bias.empty() || !nodes.kb_continuity.empty();
        for (std::size_t i = 0; i < (per_node ? n : 1); ++i) {
            const double t = at(nodes.kb_tension, i, settings.tension), b = at(nodes.kb_bias, i, settings.bias),
                         c = at(nodes.kb_continuity, i, settings.continuity);
            k = std::max(k, 2.0 * std::abs(1.0 - t) * (1.0 + std::abs(b)) * (1.0 + std::abs(c)));
        }
    }
    glm::dvec3 lo = nodes.positions[0], hi = nodes.positions[0];
    double chord = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        lo = glm::min(lo, nodes.positions[i]);
        hi = glm::max(hi, nodes.positions[i]);
        if (i + 1 < n) chord = std::max(chord, glm::length(nodes.positions[i + 1] - nodes.positions[i]));
    }
    if (settings.closed && n > 1) chord = std::max(chord, glm::length(nodes.positions[0] - nodes.positions[n - 1]));
    double radius = settings.radius_m > 0.0f ? settings.radius_m : kDefaultWireRadius_m;
    for (const float r : nodes.radius_m) radius = std::max(radius, static_cast<double>(r));
    BoundingSphere s;
    s.centre_m = 0.5 * (lo + hi);
    // Every control point within k/3 chord of its node (the node's box grown by that); a little more for rounding.
    const double grow = k * chord / 3.0 * (1.0 + 1e-9);
    s.tube_radius_m = radius;
    s.radius_m = 0.5 * glm::length(hi - lo) + std::sqrt(3.0) * grow + radius;
    return s;
}

}  // namespace wire
