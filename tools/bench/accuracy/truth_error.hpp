// The accuracy bench's error measures against a reference scene's exact curve: the drawn centre line's
// distance (world error) and the ring frames' twist against the rotation-minimizing frame.
#pragma once

#include "bench/scenes/reference_scenes.hpp"

#include <wire/bezier.hpp>
#include <wire/rings.hpp>
#include <wire/tessellate.hpp>

#include <vector>

namespace wiretool::bench {

/// Largest distance of the drawn centre polyline (ring centres, 4 points per ring interval) to the exact
/// curve; for the stretched run: largest distance off the line y = z = 0 over its first straight_segments
/// segments.
double world_error_m(const ReferenceScene& s, const wire::Curve& curve,
                     const std::vector<wire::RingParam>& params);

/// Largest angle (degrees) between each ring's normal and the rotation-minimizing frame of the same curve at
/// the same parameter, both seeded alike at ring 0. The reference is double reflection with 64 steps per ring
/// interval (fourth order: converged to ~1e-9 degrees), so this isolates the frame method from the spline.
double twist_error_deg(const wire::Curve& curve, const std::vector<wire::RingParam>& params,
                       const wire::RingSet& rings);

}  // namespace wiretool::bench
