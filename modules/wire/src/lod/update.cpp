// The LOD update: ring counts by screen-space error (Wang counts at the hull's nearest depth, or merged spans of
// the hierarchy walk), side counts from the projected radius, hysteresis; the per-segment passes and the coherence
// reuse of the last update are in lod/update_passes.cpp.
#include "wire/lod.hpp"

#include "lod/bounds.hpp"
#include "lod/cull.hpp"
#include "lod/span_kernels.hpp"
#include "lod/span_walk.hpp"
#include "lod/update_passes.hpp"
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

uint32_t wang_px(const CubicBezier& c, const HullDepth& h, const LodView& view, double tolerance_px, uint32_t max_rings,
                 bool* clamped) {
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
    return wang_px(segment, hull_depth(ViewTransform(view).hull(segment), view), view,
                   tolerance_or_default(tolerance_px), max_rings ? max_rings : default_max_rings, nullptr);
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
uint32_t drawn_sides_for(double radius_px, uint32_t sides, uint32_t old_drawn, const Limits& lim) {
    const double strip = lim.strip_px, line = lim.line_px;
    const double keep = 1.0 + std::max(lim.band, 0.0);
    if (line > 0.0 && (radius_px < line || (old_drawn == 1 && radius_px < line * keep))) return 1;
    if (strip > 0.0 && (radius_px < strip || (old_drawn == 2 && radius_px < strip * keep))) return 2;
    return sides;
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
    SpanMerger merger(bounds, view, lim.eps, sb.inside, sb.k, curve.closed, settings.coarse_offscreen_segments,
                      lim.band < 0.0 ? 1.0 : 1.0 / (1.0 + lim.band), old);
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
        const double root_ratio = !merge                ? 0.0
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
    lod.required_sides = conservative_sides ? 3u
                         : std::isfinite(wire_z)
                             ? sides_for_radius(radius, wire_z, wire_k, view, lim.eps, lim.max_sides)
                             : 3u;
    // Clamped before the comparison: a lowered max_sides changes the sides, and the caller must hear of it.
    const uint32_t sides = std::min(
        restart ? lod.required_sides : hysteresis_count(lod.sides, lod.required_sides, lim.band), lim.max_sides);
    changed = changed || sides != lod.sides;
    lod.sides = sides;
    lod.radius_px = std::isfinite(wire_z) ? radius * view.focal_px * wire_k / std::max(wire_z, view.near_m) : 0.0;
    lod.drawn_sides = drawn_sides_for(lod.radius_px, lod.sides, lod.drawn_sides, lim);
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
    return update_lod_impl(curve, view, settings, lod, lb, bounds != nullptr && bounds->radius_m >= 0.0, false);
}

bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const LodBounds& bounds) {
    if (bounds.segments != curve.segment_count()) {
        return update_lod(curve, view, settings, lod, static_cast<const BoundingSphere*>(nullptr));
    }
    return update_lod_impl(curve, view, settings, lod, bounds, true, true);
}

bool update_lod_once(const Curve& curve, const BoundingSphere& sphere, const LodView& view, const LodSettings& settings,
                     WireLod& lod) {
    thread_local LodBounds bounds;
    bounds.transient = true;  // no Coherence: the next update has new bounds
    // The stop of TopLevels where its conditions hold: a merging wire whose sphere is inside the frustum, finite
    // and bounded coordinates (the sphere's box here, level 0's probe for NaN), a positive finite z_hi.
    const double eps = tolerance_or_default(settings.tolerance_px);
    const SphereScreenBound sb =
        sphere.radius_m >= 0.0 ? sphere_screen_bound(sphere.centre_m, sphere.radius_m, view, eps) : SphereScreenBound{};
    const double zh = std::max(sb.z_hi_m, view.near_m);
    const double extent =
        (std::abs(sphere.centre_m.x) + std::abs(sphere.centre_m.y) + std::abs(sphere.centre_m.z)) + sphere.radius_m;
    const double eye = (std::abs(view.eye_m.x) + std::abs(view.eye_m.y)) + std::abs(view.eye_m.z);
    const TopLevels stop{view.focal_px / eps, sb.k, zh + 1e-6 * ((zh + extent) + eye)};
    const bool may_stop = sb.inside && !settings.keep_node_resolution && extent <= 1e149 && eye <= 1e149 && zh > 0.0 &&
                          zh <= 1e149 && std::isfinite(stop.c * stop.k);
    const std::size_t built = compute_lod_bounds_impl(curve, bounds, &sphere, may_stop ? &stop : nullptr);
    return update_lod_impl(curve, view, settings, lod, bounds, false, true, built, &sb);
}

}  // namespace wire
