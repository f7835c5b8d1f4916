// The LOD update: ring counts by screen-space error (Wang counts at the hull's nearest depth, or merged spans of
// the hierarchy walk), side counts from the projected radius, the per-segment passes, hysteresis, the coherence
// reuse of the last update.
#include "wire/lod.hpp"

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

namespace wire {

using namespace lod_stage;

namespace {

uint32_t wang_px(const CubicBezier& c, const HullDepth& h, const LodView& view, double tolerance_px,
                 uint32_t max_rings, bool* clamped) {
    const double eps_world = tolerance_px * h.z_min / (view.focal_px * h.k);
    const uint32_t n = wang_ring_count(c, eps_world, max_rings);
    if (clamped != nullptr && n >= max_rings) {
        // Clamped only if max_rings is really short of what the bound needs.
        const double m = std::max(glm::length(c.b0 - 2.0 * c.b1 + c.b2), glm::length(c.b1 - 2.0 * c.b2 + c.b3));
        *clamped = !(std::ceil(std::sqrt(3.0 * m / (4.0 * eps_world))) <= static_cast<double>(max_rings));
    }
    return n;
}

}  // namespace

uint32_t segment_ring_count_px(const CubicBezier& segment, const LodView& view, double tolerance_px,
                               uint32_t max_rings) {
    return wang_px(segment, hull_depth(ViewTransform(view).hull(segment), view), view, tolerance_or_default(tolerance_px),
                   max_rings ? max_rings : default_max_rings, nullptr);
}

uint32_t sides_for_radius(double radius_m, double z_m, double k, const LodView& view, double tolerance_px,
                          uint32_t max_sides) {
    max_sides = std::max<uint32_t>(max_sides ? max_sides : default_max_sides, 3);
    const double eps = tolerance_or_default(tolerance_px);
    const double r_px = radius_m * view.focal_px * k / std::max(z_m, view.near_m);
    if (!(r_px > 0.0)) return 3;
    const double x = eps / r_px;
    if (x >= 2.0) return 3;  // the whole tube is within eps of its centre line
    // Three sides, the usual answer, without the acos: n <= 3 iff acos(1 - x) >= pi / 3 iff x >= 1/2. Above
    // 1/2 by the relative margin below, 1 - x (exact: Sterbenz) is below 1/2 by 5e-10, so acos(1 - x) exceeds
    // pi / 3 by ~6e-10 relative, far more than the rounding of acos and of the quotient (a few 1e-16): the
    // formula's n is at most 3 there and the result 3. Nearer 1/2 the formula decides (tested on dense radii).
    if (x > 0.5 * (1.0 + 1e-9)) return 3;
    const double n = std::ceil(std::numbers::pi / std::acos(1.0 - x));
    if (!(n < static_cast<double>(max_sides))) return max_sides;
    return std::max<uint32_t>(3, static_cast<uint32_t>(n));
}

uint32_t hysteresis_count(uint32_t old_count, uint32_t raw_count, double band) {
    if (old_count == 0 || raw_count >= old_count || band < 0.0) return raw_count;
    if (static_cast<double>(old_count) <= static_cast<double>(raw_count) * (1.0 + band) + 1.0) return old_count;
    return std::min(old_count, raw_count + 1 + raw_count / 8);
}

namespace {

/// Tube, strip (2) or line (1) for a projected radius. Hysteresis: a thinner mode used last update is kept
/// until the radius exceeds its threshold by the band (like the counts), so a wire at the switch distance does
/// not alternate between two modes while the camera drifts.
uint32_t drawn_sides_for(double radius_px, uint32_t sides, uint32_t old_drawn, const LodSettings& settings,
                         double band) {
    const double strip = settings.strip_radius_px == 0.0 ? 2.0 : settings.strip_radius_px;
    const double line = settings.line_radius_px == 0.0 ? 0.5 : settings.line_radius_px;
    const double keep = 1.0 + std::max(band, 0.0);
    if (line > 0.0 && (radius_px < line || (old_drawn == 1 && radius_px < line * keep))) return 1;
    if (strip > 0.0 && (radius_px < strip || (old_drawn == 2 && radius_px < strip * keep))) return 2;
    return sides;
}

struct Limits {
    double eps;
    uint32_t max_rings, max_sides;
    double band;
    explicit Limits(const LodSettings& settings)
        : eps(tolerance_or_default(settings.tolerance_px)),
          max_rings(settings.max_rings_per_segment ? settings.max_rings_per_segment : default_max_rings),
          max_sides(std::max<uint32_t>(settings.max_sides ? settings.max_sides : default_max_sides, 3)),
          band(settings.hysteresis_band == 0.0 ? default_band : settings.hysteresis_band) {}
};

// Every segment's hull depth, off-axis factor and plane mask, into scratch(): z_min, k, outside.
// with_planes = false: the depths only (scratch().outside is left as it is).
void hull_depths(const Curve& curve, const LodView& view, double radius_m, bool with_planes = true) {
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
bool per_segment_required(const Curve& curve, const LodView& view, const LodSettings& settings,
                          const Limits& lim, const LodBounds& bounds, double radius, WireLod& lod,
                          double& wire_z, double& wire_k) {
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

bool same_settings(const WireLod::Coherence& c, const Limits& lim, const LodSettings& s) {
    return c.tolerance_px == lim.eps && c.band == lim.band && c.max_sides == lim.max_sides &&
           c.max_rings == lim.max_rings && c.coarse_offscreen == s.coarse_offscreen_segments &&
           c.keep_node_resolution == s.keep_node_resolution;
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
    if (!c.exact_sides &&
        sides_for_radius(bounds.radius_max_m, sb.z_lo_m, sb.k, view, lim.eps, lim.max_sides) != 3) {
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

// Wang's count of one segment from its hull depth, with the cached M (wang_ring_count() on it).
uint32_t wang_cached(double m, double eps_world, const Limits& lim, uint32_t& clamped) {
    if (!(eps_world > 0.0) || !std::isfinite(m)) return lim.max_rings;
    const double c = std::ceil(std::sqrt(3.0 * m / (4.0 * eps_world)));
    const uint32_t raw = !(c < static_cast<double>(lim.max_rings)) ? lim.max_rings
                                                                     : std::max<uint32_t>(1, static_cast<uint32_t>(c));
    if (raw >= lim.max_rings && !(c <= static_cast<double>(lim.max_rings))) ++clamped;
    return raw;
}

enum class SegmentPass { done, culled, fallback };

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

// built_levels: the hierarchy levels of `bounds` that were built (all but for update_lod_once(), which leaves out
// levels an update of a wire inside the frustum cannot read: see TopLevels).
bool update_lod_impl(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                     const LodBounds& bounds, bool sphere_cull, bool use_bound,
                     std::size_t built_levels = std::numeric_limits<std::size_t>::max(),
                     const SphereScreenBound* known_sb = nullptr) {
    const std::size_t n = curve.segment_count();
    if (sphere_cull && sphere_outside_view(bounds.sphere, view)) return cull_lod(lod);
    if (n == 0) {
        return cull_lod(lod);
    }
    const Limits lim(settings);
    const double radius = bounds.radius_max_m;
    const bool merge = !settings.keep_node_resolution && bounds.segments == n && bounds.levels > 0;
    if (use_bound && reuse(curve, view, settings, lim, bounds, lod)) return false;
    lod.coherence.valid = false;

    Scratch& sc = scratch();
    sc.old_counts.assign(lod.counts.begin(), lod.counts.end());
    const bool restart = sc.old_counts.size() != n;
    if (restart) sc.old_counts.assign(n, 0);
    const std::span<const uint32_t> old(sc.old_counts);

    lod.clamped_segments = 0;
    lod.changed_counts = 0;
    lod.visible_segments = 0;
    lod.spans = 0;
    lod.bounded = false;

    // The per-wire bound (sphere of the whole wire), also the spans' off-axis factor (every span lies
    // inside).
    SphereScreenBound sb;
    if (bounds.sphere.radius_m >= 0.0) {
        sb = known_sb != nullptr ? *known_sb
                                 : sphere_screen_bound(bounds.sphere.centre_m, bounds.sphere.radius_m, view, lim.eps);
    } else {
        sb.k = edge_factors(view).corner;
    }
    SpanMerger merger(bounds, view, lim.eps, sb.inside, sb.k, curve.closed,
                      settings.coarse_offscreen_segments, lim.band < 0.0 ? 1.0 : 1.0 / (1.0 + lim.band), old);
    // The margin only serves a Coherence, which is kept for bounds that outlive this update and a wire inside.
    const bool keeps_coherence = use_bound && !bounds.transient && sb.inside;
    if (!keeps_coherence) merger.skip_margin();
    merger.set_depth_range(sb.z_lo_m, sb.z_hi_m, built_levels);
    // Every segment lies in a span of both kinds (the common case on screen): the walk below writes each span's
    // first entry over zeros (the zeroed walk), so nothing before it needs to fill the counts.
    const bool zeroed_walk = merge && merger.writes_every_segment();

    // A sphere inside the frustum whose conservative side count is 3 (so the exact one is too) is decided
    // here.
    bool decided = false, whole = false, conservative_sides = false;
    double wire_z = std::numeric_limits<double>::infinity();
    double wire_k = 1.0;
    if (use_bound && bounds.sphere.radius_m >= 0.0 && sb.inside) {
        const std::size_t root = merger.root_level();
        // A root not built has a ratio above 1 (TopLevels): not one interval.
        const double root_ratio = !merge                  ? 0.0
                                  : root < built_levels ? merger.ratio(root, 0)
                                                        : std::numeric_limits<double>::infinity();
        if (merge) merger.note(root_ratio);
        if (merge && root_ratio <= merger.counts_scale(root, 0)) {
            // The whole wire is one interval for the counts (hysteresis threshold), so for the tolerance too.
            lod.required.assign(n, 0);
            lod.required[0] = 1;
            lod.counts.assign(n, 0);
            lod.counts[0] = 1;
            lod.spans = n > 1 ? 1u : 0u;
            decided = true;
            whole = true;
        } else if (one_ring_per_segment(bounds, sb)) {
            if (!zeroed_walk) lod.required.assign(n, 1);  // one ring each (the zeroed walk writes them itself)
            decided = true;
        }
        if (decided) {
            lod.bounded = true;
            lod.visible_segments = static_cast<uint32_t>(n);  // the sphere is inside the frustum
            if (sides_for_radius(radius, sb.z_lo_m, sb.k, view, lim.eps, lim.max_sides) == 3) {
                wire_z = sb.z_lo_m;  // the conservative side count is the least: so is the exact one
                wire_k = sb.k;
                conservative_sides = true;
            } else {
                hull_depths(curve, view, radius, false);  // the exact side count needs the segments' depths
                const Scratch& d = scratch();
                for (std::size_t i = 0; i < n; ++i) {
                    wire_z = std::min(wire_z, d.z_min[i]);
                    wire_k = std::max(wire_k, d.k[i]);
                }
            }
        }
    }
    if (!decided && use_bound && bounds.sphere.radius_m >= 0.0 && !sb.inside && settings.coarse_offscreen_segments &&
        sides_for_radius(radius, sb.z_lo_m, sb.k, view, lim.eps, lim.max_sides) == 3) {
        const SegmentPass pass = per_segment_bounded(curve, view, lim, bounds, radius, lod, wire_z);
        if (pass == SegmentPass::culled) {
            return cull_lod(lod);
        }
        if (pass == SegmentPass::done) {
            decided = true;
            lod.bounded = true;
            wire_z = std::max(wire_z, sb.z_lo_m);
            wire_k = sb.k;  // with wire_z >= the sphere's z_lo: the side count is 3, as the exact one
        } else {
            lod.visible_segments = 0;
            lod.clamped_segments = 0;
        }
    }
    if (!decided && !per_segment_required(curve, view, settings, lim, bounds, radius, lod, wire_z, wire_k)) {
        return cull_lod(lod);
    }

    lod.visible = true;
    bool zeroed = false;
    uint32_t zeroed_changed = 0;
    if (!whole && zeroed_walk) {
        // The per-segment counts (and the hysteresis on them) are never read.
        lod.required.assign(n, 0);
        lod.counts.assign(n, 0);
        lod.spans = merger.apply_zeroed(lod.required, lod.counts, zeroed_changed);
        zeroed = true;
    } else if (!whole) {
        // Per-segment hysteresis on the Wang counts (all >= 1), then the spans over both.
        lod.counts.resize(n);
        const uint32_t* req = lod.required.data();
        uint32_t* cnt = lod.counts.data();
        for (std::size_t i = 0; i < n; ++i) {
            // Hysteresis keeps an old count, but never above the cap in force now (it may have been lowered).
            // hysteresis_count() is the new count unless the old one is larger: that test alone in the loop.
            const uint32_t o = old[i], r = req[i];
            cnt[i] = std::min(o > r ? hysteresis_count(o, r, lim.band) : r, lim.max_rings);
        }
        if (merge) lod.spans = merger.apply(lod.required, lod.counts);
    }
    bool changed = restart;
    if (zeroed) {
        lod.changed_counts += zeroed_changed;
    } else {
        uint32_t changed_counts = 0;  // a local sum (not the member): the loop vectorizes
        const uint32_t* cnt = lod.counts.data();
        for (std::size_t i = 0; i < n; ++i) changed_counts += cnt[i] != old[i] ? 1u : 0u;
        lod.changed_counts += changed_counts;
    }
    changed = changed || lod.changed_counts != 0;

    if (lod.visible_segments == 0) {
        // The wire's hull meets the frustum but no single segment's does (the wire wraps around the view):
        // draw it coarsely with the fewest sides; nothing of it is on screen.
        wire_z = std::numeric_limits<double>::infinity();
    }
    lod.z_min_m = std::isfinite(wire_z) ? wire_z : 0.0;
    // conservative_sides: the bound's call above, with these very arguments (the visible segments are all of
    // them), gave 3 (and so does the non-finite case).
    lod.required_sides = conservative_sides       ? 3u
                         : std::isfinite(wire_z) ? sides_for_radius(radius, wire_z, wire_k, view, lim.eps, lim.max_sides)
                                                 : 3u;
    // Clamped before the comparison: a lowered max_sides changes the sides, and the caller must hear of it.
    const uint32_t sides = std::min(
        restart ? lod.required_sides : hysteresis_count(lod.sides, lod.required_sides, lim.band), lim.max_sides);
    changed = changed || sides != lod.sides;
    lod.sides = sides;
    lod.radius_px = std::isfinite(wire_z) ? radius * view.focal_px * wire_k / std::max(wire_z, view.near_m) : 0.0;
    lod.drawn_sides = drawn_sides_for(lod.radius_px, lod.sides, lod.drawn_sides, settings, lim.band);
    if (keeps_coherence && lod.bounded && merger.margin() > 1.0) {
        WireLod::Coherence& c = lod.coherence;
        c.valid = true;
        c.bounds = &bounds;
        c.bounds_version = bounds.version;
        c.eye_m = view.eye_m;
        c.rotation = ViewTransform(view).rotation;
        c.z_lo_m = sb.z_lo_m;
        c.k = sb.k;
        c.whole = whole;
        c.exact_sides = !conservative_sides;
        c.wire_z_m = wire_z;
        c.wire_k = wire_k;
        c.margin = merger.margin();
        c.tolerance_px = lim.eps;
        c.band = lim.band;
        c.max_sides = lim.max_sides;
        c.max_rings = lim.max_rings;
        c.coarse_offscreen = settings.coarse_offscreen_segments;
        c.keep_node_resolution = settings.keep_node_resolution;
    }
    return changed;
}

}  // namespace

bool one_ring_per_segment(const LodBounds& bounds, const SphereScreenBound& b) {
    // Wang: ceil(sqrt(3M / (4 eps))) == 1 iff 3M <= 4 eps; the margin covers the rounding of eps_world
    // between the bound and the per-segment evaluation (which uses a larger eps_world anyway).
    return std::isfinite(bounds.wang_m_max) && 3.0 * bounds.wang_m_max <= 4.0 * b.eps_world_m * (1.0 - 1e-9);
}

bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const BoundingSphere* bounds) {
    thread_local LodBounds lb;
    if (bounds != nullptr) {
        compute_lod_bounds(curve, lb, *bounds);  // the caller's sphere, not the boxes' again
    } else {
        compute_lod_bounds(curve, lb);
    }
    return update_lod_impl(curve, view, settings, lod, lb, bounds != nullptr && bounds->radius_m >= 0.0,
                           false);
}

bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const LodBounds& bounds) {
    if (bounds.segments != curve.segment_count()) {
        return update_lod(curve, view, settings, lod, static_cast<const BoundingSphere*>(nullptr));
    }
    return update_lod_impl(curve, view, settings, lod, bounds, true, true);
}

bool update_lod_once(const Curve& curve, const BoundingSphere& sphere, const LodView& view,
                     const LodSettings& settings, WireLod& lod) {
    thread_local LodBounds bounds;
    bounds.transient = true;  // no Coherence: the next update has new bounds
    // The stop of TopLevels where its conditions hold: a merging wire whose sphere is inside the frustum, finite
    // and bounded coordinates (the sphere's box here, level 0's probe for NaN), a positive finite z_hi.
    const double eps = tolerance_or_default(settings.tolerance_px);
    const SphereScreenBound sb = sphere.radius_m >= 0.0 ? sphere_screen_bound(sphere.centre_m, sphere.radius_m, view, eps)
                                                        : SphereScreenBound{};
    const double zh = std::max(sb.z_hi_m, view.near_m);
    const double extent = (std::abs(sphere.centre_m.x) + std::abs(sphere.centre_m.y) + std::abs(sphere.centre_m.z)) +
                          sphere.radius_m;
    const double eye = (std::abs(view.eye_m.x) + std::abs(view.eye_m.y)) + std::abs(view.eye_m.z);
    const TopLevels stop{view.focal_px / eps, sb.k, zh + 1e-6 * ((zh + extent) + eye)};
    const bool may_stop = sb.inside && !settings.keep_node_resolution && extent <= 1e149 && eye <= 1e149 &&
                          zh > 0.0 && zh <= 1e149 && std::isfinite(stop.c * stop.k);
    const std::size_t built = compute_lod_bounds_impl(curve, bounds, &sphere, may_stop ? &stop : nullptr);
    return update_lod_impl(curve, view, settings, lod, bounds, false, true, built, &sb);
}

}  // namespace wire
