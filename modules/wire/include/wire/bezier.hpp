// Small exact operations on the curve stage's cubic Bezier segments: sub-segments, arc length, sampling,
// closest points and the curve-to-curve distance used to measure pops.
#pragma once

#include "wire/curve.hpp"

#include <glm/vec3.hpp>

#include <vector>

namespace wire {

/// The piece of `c` for t in [t0, t1] as its own cubic (de Casteljau; exact up to rounding, so sub-segments
/// cut at shared parameters tile the original curve with no gap).
[[nodiscard]] CubicBezier sub_segment(const CubicBezier& c, double t0, double t1);

/// Arc length of one segment (16-point Gauss-Legendre per half; relative error < 1e-12 on smooth segments).
[[nodiscard]] double arc_length_m(const CubicBezier& c);
/// Total arc length of a curve, metres.
[[nodiscard]] double arc_length_m(const Curve& curve);

/// Dense samples: `per_segment` points per segment (t = i/per_segment), plus the curve's final point.
[[nodiscard]] std::vector<glm::dvec3> sample_curve(const Curve& curve, int per_segment);

/// Parameter t in [0,1] of the point of segment `c` nearest to p (dense scan + Newton polish).
[[nodiscard]] double closest_parameter(const CubicBezier& c, const glm::dvec3& p);

/// Distance from p to the polyline through `points` (brute force, O(points)).
[[nodiscard]] double distance_to_polyline(const glm::dvec3& p, const std::vector<glm::dvec3>& points);

/// The pop metric: the largest displacement between two rendered curves, as the symmetric Hausdorff distance
/// between their dense samples (`per_segment` samples per segment), each point measured against the other
/// curve's sample polyline. The polyline error is at most ~ h^2*k/8 for sample spacing h and curvature k
/// (64 samples on a 2 m segment bending 0.1 rad: < 2e-5 m). Metres. Cost O(N*M) in the sample counts.
[[nodiscard]] double curve_jump_m(const Curve& before, const Curve& after, int per_segment = 64);

}  // namespace wire
