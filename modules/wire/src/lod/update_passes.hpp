// Internal: the LOD update's passes before the hierarchy walk (lod/update_passes.cpp), shared with the update itself
// (lod/update.cpp): the limits from the settings, the coherence test, the hull depths and the per-segment passes.
#pragma once

#include "wire/lod.hpp"

#include "lod/view.hpp"

#include <algorithm>
#include <cstdint>

namespace wire::lod_stage {

/// The settings' values an update reads (LodSettings::resolved), resolved once per update.
struct Limits {
    double eps;
    uint32_t max_rings, max_sides;
    double band, strip_px, line_px;
    explicit Limits(const LodSettings& settings) {
        const LodSettings r = settings.resolved();
        eps = r.tolerance_px, max_rings = r.max_rings_per_segment, max_sides = r.max_sides, band = r.hysteresis_band;
        strip_px = r.strip_radius_px, line_px = r.line_radius_px;
    }
};

// The coherence test (WireLod::Coherence): true if the state of the last update stands for this camera.
bool reuse(const Curve& curve, const LodView& view, const LodSettings& settings, const Limits& lim,
           const LodBounds& bounds, WireLod& lod);

// Every segment's hull depth, off-axis factor and plane mask, into scratch(): z_min, k, outside.
// with_planes = false: the depths only (scratch().outside is left as it is).
void hull_depths(const Curve& curve, const LodView& view, double radius_m, bool with_planes = true);

// Per-segment pass: required Wang counts (and visibility, depth) of every segment from the hull depths and the
// bounds' cached Wang's M. Returns false if the wire is culled by the hull test.
bool per_segment_required(const Curve& curve, const LodView& view, const LodSettings& settings, const Limits& lim,
                          const LodBounds& bounds, double radius, WireLod& lod, double& wire_z, double& wire_k);

enum class SegmentPass { done, culled, fallback };

// The per-segment pass of a wire partly out of view whose side count the wire's sphere already fixes at 3:
// each segment's sphere (LodBounds level 0) decides it when it lies inside the frustum (visible; one ring when
// the sphere's depth allows) or outside a plane (off screen, so is its hull); only the other segments take the
// hull test and hull depth. The same required counts and visibility as per_segment_required(); the depth kept
// is a lower bound. `fallback` when no segment was found visible (the hull test must then decide culling).
SegmentPass per_segment_bounded(const Curve& curve, const LodView& view, const Limits& lim, const LodBounds& b,
                                double radius, WireLod& lod, double& wire_z);

}  // namespace wire::lod_stage
