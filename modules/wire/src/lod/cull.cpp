// Culling: a wire's control hull or bounding sphere against the frustum (inflated by the tube radius), and the
// state a culled wire keeps.
#include "wire/lod.hpp"

#include "lod/cull.hpp"
#include "lod/view.hpp"

#include <glm/geometric.hpp>

#include <limits>

namespace wire {

namespace lod_stage {

void mark_culled(WireLod& lod, bool& changed) {
    changed = lod.visible || !lod.counts.empty();
    lod.visible = false;
    lod.counts.clear();
    lod.required.clear();
    lod.sides = 0;
    lod.required_sides = 0;
    lod.drawn_sides = 0;
    lod.radius_px = 0.0;
    lod.z_min_m = 0.0;
    lod.visible_segments = 0;
    lod.clamped_segments = 0;
    lod.changed_counts = 0;
    lod.spans = 0;
    lod.bounded = false;
    lod.coherence.valid = false;
}

}  // namespace lod_stage

using namespace lod_stage;

bool hull_visible(std::span<const CubicBezier> segments, double radius_m, const LodView& view) {
    if (segments.empty()) return false;
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius_m);
    unsigned all = 63u;
    for (const CubicBezier& c : segments) {
        all &= planes.outside(tf.hull(c));
        if (all == 0) return true;
    }
    return false;
}

bool sphere_outside_view(const BoundingSphere& sphere, const LodView& view) {
    if (!(sphere.radius_m >= 0.0)) return false;
    const ViewTransform tf(view);
    // The centre and the hull's control points each reach view space with a rounding error of a few ulps of
    // |point| + |eye|; far from the origin (5e11 m: ~1e-4 m) that exceeds the sphere's own slack and the
    // sphere could cull a wire the hull test keeps. Inflate the sphere by a bound of both errors.
    const double rounding =
        64.0 * std::numeric_limits<double>::epsilon() * (glm::length(sphere.centre_m) + glm::length(view.eye_m));
    return PlaneTest(view, sphere.radius_m + rounding).outside(tf(sphere.centre_m)) != 0;
}

bool cull_lod(WireLod& lod) {
    bool changed = false;
    mark_culled(lod, changed);
    return changed;
}

}  // namespace wire
