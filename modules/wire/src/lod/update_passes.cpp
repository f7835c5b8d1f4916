// The LOD update's passes before the hierarchy walk: the coherence test (reuse of the last update's state), every
// segment's hull depth, and the per-segment passes that give the required Wang counts, visibility and depth.
#include "lod/update_passes.hpp"

#include "lod/bounds.hpp"
#include "lod/cull.hpp"
#include "lod/span_kernels.hpp"
#include "lod/span_walk.hpp"
#include "lod/view.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

namespace wire::lod_stage {
namespace {

bool same_settings(const WireLod::Coherence& c, const Limits& lim, const LodSettings& s) {
    return c.tolerance_px == lim.eps && c.band == lim.band && c.max_sides == lim.max_sides &&
           c.max_rings == lim.max_rings && c.coarse_offscreen == s.coarse_offscreen_segments &&
           c.keep_node_resolution == s.keep_node_resolution;
}

// Wang's count of one segment from its hull depth, with the cached M (wang_ring_count() on it).
uint32_t wang_cached(double m, double eps_world, const Limits& lim, uint32_t& clamped) {
    if (!(eps_world > 0.0) || !std::isfinite(m)) return lim.max_rings;
    const double c = std::ceil(std::sqrt(3.0 * m / (4.0 * eps_world)));
    const uint32_t raw =
        !(c < static_cast<double>(lim.max_rings)) ? lim.max_rings : std::max<uint32_t>(1, static_cast<uint32_t>(c));
    if (raw >= lim.max_rings && !(c <= static_cast<double>(lim.max_rings))) ++clamped;
    return raw;
}

}  // namespace

// Every segment's hull depth, off-axis factor and plane mask, into scratch(): z_min, k, outside.
// with_planes = false: the depths only (scratch().outside is left as it is).
void hull_depths(const Curve& curve, const LodView& view, double radius_m, bool with_planes) {
    const std::size_t n = curve.segment_count();
    Scratch& sc = scratch();
    sc.z_min.resize(n);
    sc.k.resize(n);
    if (with_planes) sc.outside.resize(n);
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius_m);
    HullConstants h{};
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) h.m[3 * c + r] = tf.rotation[c][r];
    for (int r = 0; r < 3; ++r) h.t[r] = tf.translation[r];
    h.near = view.near_m;
    h.far = view.far_m;
    h.tx = view.tan_half_x;
    h.ty = view.tan_half_y;
    h.neg_rx = -planes.rx;
    h.neg_ry = -planes.ry;
    h.neg_r = -planes.r;
    span_kernels().hull_depths(curve.segments.data(), n, h, sc.z_min.data(), sc.k.data(),
                               with_planes ? sc.outside.data() : nullptr);
}

// Per-segment pass: required Wang counts (and visibility, depth) of every segment from the hull depths and the
// bounds' cached Wang's M. Returns false if the wire is culled by the hull test.
bool per_segment_required(const Curve& curve, const LodView& view, const LodSettings& settings, const Limits& lim,
                          const LodBounds& bounds, double radius, WireLod& lod, double& wire_z, double& wire_k) {
    const std::size_t n = curve.segment_count();
    hull_depths(curve, view, radius);
    Scratch& sc = scratch();
    const double* zmin = sc.z_min.data();
    const double* ks = sc.k.data();
    unsigned wire_outside = 63u;
    for (std::size_t i = 0; i < n; ++i) wire_outside &= sc.outside[i];
    if (wire_outside != 0) return false;

    lod.required.resize(n);
    wire_z = std::numeric_limits<double>::infinity();
    wire_k = 1.0;
    const double scale = lim.eps / view.focal_px;
    // Wang's M of every segment (cached in the bounds), then every segment's count and clamp flag in a lane kernel
    // (computed for all; used where the segment needs them).
    const double* mm = &bounds.data[bounds.data.size() - bounds.segments];  // wang_m(0 .. n): segments == n here
    sc.raw.resize(n);
    sc.clamped.resize(n);
    span_kernels().wang_counts(zmin, ks, mm, n, scale, static_cast<double>(lim.max_rings), sc.raw.data(),
                               sc.clamped.data());
    uint32_t visible = 0, clamped = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const bool seg_visible = sc.outside[i] == 0;
        uint32_t raw = 1;
        if (seg_visible || !settings.coarse_offscreen_segments) {
            raw = static_cast<uint32_t>(sc.raw[i]);  // an integer in [1, max_rings]
            clamped += sc.clamped[i] != 0.0 ? 1u : 0u;
            if (seg_visible) {
                ++visible;
                wire_z = std::min(wire_z, zmin[i]);
                wire_k = std::max(wire_k, ks[i]);
            }
        }
        lod.required[i] = raw;
    }
    lod.visible_segments += visible;
    lod.clamped_segments += clamped;
    return true;
}

// The coherence test (WireLod::Coherence): true if the state of the last update stands for this camera.
bool reuse(const Curve& curve, const LodView& view, const LodSettings& settings, const Limits& lim,
           const LodBounds& bounds, WireLod& lod) {
    const WireLod::Coherence& c = lod.coherence;
    if (!c.valid || c.bounds != &bounds || c.bounds_version != bounds.version || !lod.visible ||
        lod.counts.size() != curve.segment_count() || !same_settings(c, lim, settings)) {
        return false;
    }
    const SphereScreenBound sb = sphere_screen_bound(bounds.sphere.centre_m, bounds.sphere.radius_m, view, lim.eps);
    if (!sb.inside) return false;
    if (!c.exact_sides && sides_for_radius(bounds.radius_max_m, sb.z_lo_m, sb.k, view, lim.eps, lim.max_sides) != 3) {
        return false;
    }
    if (!c.whole && !one_ring_per_segment(bounds, sb)) return false;
    // Every point of the sphere moved by at most delta in view space: |R' - R| |p - e'| + |e' - e|.
    const ViewTransform tf(view);
    double rf = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const double d = tf.rotation[i][j] - c.rotation[i][j];
            rf += d * d;
        }
    const double delta = std::sqrt(rf) * (glm::length(bounds.sphere.centre_m - view.eye_m) + bounds.sphere.radius_m) +
                         glm::length(view.eye_m - c.eye_m);
    if (!(c.z_lo_m - delta > view.near_m)) return false;
    const double kr = sb.k / c.k;
    const double factor = std::max(kr * c.z_lo_m / (c.z_lo_m - delta), (c.z_lo_m + delta) / (c.z_lo_m * kr));
    if (!(factor * (1.0 + 1e-9) < c.margin)) return false;
    double z_min = sb.z_lo_m;
    if (c.exact_sides) {
        // The segments' nearest depth moved by at most delta, their off-axis factors as a = |x|/z allows:
        // sqrt(k^2 - 1) within (sqrt(k^2 - 1) -+ sqrt2 e) / (1 +- e), e = delta / z. The side count must not move.
        const double e = delta / c.wire_z_m;
        if (!(e < 0.5) || !(c.wire_z_m - delta > view.near_m)) return false;
        const double ka = std::sqrt(std::max(c.wire_k * c.wire_k - 1.0, 0.0));
        const double ka_hi = (ka + std::numbers::sqrt2 * e) / (1.0 - e);
        const double ka_lo = std::max(0.0, (ka - std::numbers::sqrt2 * e) / (1.0 + e));
        const double r = bounds.radius_max_m;
        const uint32_t most =
            sides_for_radius(r, c.wire_z_m - delta, std::sqrt(1.0 + ka_hi * ka_hi), view, lim.eps, lim.max_sides);
        const uint32_t least =
            sides_for_radius(r, c.wire_z_m + delta, std::sqrt(1.0 + ka_lo * ka_lo), view, lim.eps, lim.max_sides);
        if (most != lod.required_sides || least != lod.required_sides) return false;
        z_min = c.wire_z_m - delta;  // a lower bound of the segments' nearest depth
    }
    lod.z_min_m = z_min;
    lod.changed_counts = 0;
    ++lod.reused;
    return true;
}

// The per-segment pass of a wire partly out of view whose side count the wire's sphere already fixes at 3:
// each segment's sphere (LodBounds level 0) decides it when it lies inside the frustum (visible; one ring when
// the sphere's depth allows) or outside a plane (off screen, so is its hull); only the other segments take the
// hull test and hull depth. The same required counts and visibility as per_segment_required(); the depth kept
// is a lower bound. `fallback` when no segment was found visible (the hull test must then decide culling).
SegmentPass per_segment_bounded(const Curve& curve, const LodView& view, const Limits& lim, const LodBounds& b,
                                double radius, WireLod& lod, double& wire_z) {
    const std::size_t n = curve.segment_count();
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius);
    const double tx = view.tan_half_x, ty = view.tan_half_y;
    const double sx = edge_factors(view).sx, sy = edge_factors(view).sy;
    const double scale = lim.eps / view.focal_px;
    lod.required.resize(n);
    unsigned wire_outside = 63u;
    wire_z = std::numeric_limits<double>::infinity();
    uint32_t visible = 0, clamped = 0;
    const double* d0 = b.level_data(0);  // level 0: centre x, y, z and radius of each segment's sphere
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 q = tf(glm::dvec3(d0[i], d0[n + i], d0[2 * n + i]));
        const double r0 = d0[3 * n + i], ri = r0 + radius;
        const double l = q.x + q.z * tx, rt = q.z * tx - q.x, bt = q.y + q.z * ty, tp = q.z * ty - q.y;
        const double ne = q.z - view.near_m, fa = view.far_m - q.z;
        const double rx = ri * sx, ry = ri * sy;
        const unsigned outside = (l < -rx ? 1u : 0u) | (rt < -rx ? 2u : 0u) | (bt < -ry ? 4u : 0u) |
                                 (tp < -ry ? 8u : 0u) | (ne < -ri ? 16u : 0u) | (fa < -ri ? 32u : 0u);
        if (outside != 0) {  // every control point is outside these planes: the hull test says off screen too
            wire_outside &= outside;
            lod.required[i] = 1;
            continue;
        }
        const bool inside = l >= rx && rt >= rx && bt >= ry && tp >= ry && ne >= ri && fa >= ri;
        if (inside) {
            const double zl = q.z - r0;  // > near: the sphere is in front of the near plane
            const double a = std::min(tx, (std::abs(q.x) + r0) / zl), c = std::min(ty, (std::abs(q.y) + r0) / zl);
            const double k = std::sqrt(1.0 + a * a + c * c);
            wire_outside = 0;
            ++visible;
            if (3.0 * b.wang_m(i) <= 4.0 * (scale * zl / k) * (1.0 - 1e-9)) {
                lod.required[i] = 1;  // the hull's depth is larger and its k smaller: the exact count is 1 too
                wire_z = std::min(wire_z, zl);
                continue;
            }
            const HullDepth h = hull_depth(tf.hull(curve.segments[i]), view);
            lod.required[i] = wang_cached(b.wang_m(i), scale * h.z_min / h.k, lim, clamped);
            wire_z = std::min(wire_z, h.z_min);
            continue;
        }
        const ViewHull hull = tf.hull(curve.segments[i]);
        const unsigned o = planes.outside(hull);
        wire_outside &= o;
        if (o != 0) {
            lod.required[i] = 1;
            continue;
        }
        ++visible;
        const HullDepth h = hull_depth(hull, view);
        lod.required[i] = wang_cached(b.wang_m(i), scale * h.z_min / h.k, lim, clamped);
        wire_z = std::min(wire_z, h.z_min);
    }
    if (wire_outside != 0) return SegmentPass::culled;  // a superset of the hull test's planes: culled as well
    if (visible == 0) return SegmentPass::fallback;
    lod.visible_segments = visible;
    lod.clamped_segments = clamped;
    return SegmentPass::done;
}

}  // namespace wire::lod_stage
