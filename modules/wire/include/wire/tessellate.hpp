// Ring placement: how many rings each cubic segment of a wire gets, and the (segment, t) of every ring in order.
#pragma once

#include "wire/curve.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace wire {

/// Where one ring sits on the curve: segment index and Bezier parameter t in [0,1].
struct RingParam {
    uint32_t segment = 0;
    double t = 0.0;
};

/// How to choose the ring count per segment. Zero means default.
/// - tolerance_m > 0: adaptive (Wang's formula), each segment gets the fewest rings whose centre polyline stays
///   within tolerance_m of the cubic; clamped to [1, max_rings_per_segment].
/// - otherwise: rings_per_segment on every segment (default 8).
struct TessellateSettings {
    uint32_t rings_per_segment = 0;      ///< fixed count per segment; 0 -> 8
    double tolerance_m = 0.0;            ///< > 0 selects the adaptive count (metres)
    uint32_t max_rings_per_segment = 0;  ///< clamp for the adaptive count; 0 -> 256
};

/// Wang's formula for a cubic: N = ceil(sqrt(3*M / (4*eps))), M = max_i |B_i - 2B_{i+1} + B_{i+2}|.
/// Promise: sampling the segment at t = k/N, k = 0..N, the chord polyline is within eps (metres) of every point of
/// the cubic (|B''| <= 6M and the chord error over a parameter step h is h^2/8 * max|B''|). Clamped to [1, max].
/// Non-finite control points or eps <= 0 give max_rings.
[[nodiscard]] uint32_t wang_ring_count(const CubicBezier& c, double tolerance_m, uint32_t max_rings);

/// Ring count of every segment of `curve` per `settings`, written into `counts` (resized to segment_count()).
void segment_ring_counts(const Curve& curve, const TessellateSettings& settings, std::vector<uint32_t>& counts);

/// Ring parameters in order along the wire: segment i gets counts[i] rings at t = k/counts[i], k = 0..counts[i]-1;
/// a count of 0 gives segment i no ring (the interval from the previous ring crosses it: LOD below the node
/// resolution), except on segment 0, which always gets at least one; an open wire gets one more ring at t = 1 of
/// its last segment, a closed wire does not (its first ring closes the loop). `out` is resized; no allocation when its capacity suffices.
/// counts.size() must equal curve.segment_count().
void place_rings(const Curve& curve, std::span<const uint32_t> counts, std::vector<RingParam>& out);
/// The same placement for a wire known only by its counts (one a segment) and whether it is closed.
void place_rings(std::span<const uint32_t> counts, bool closed, std::vector<RingParam>& out);

/// Number of rings place_rings() produces for these counts.
[[nodiscard]] std::size_t ring_count(std::span<const uint32_t> counts, bool closed);

}  // namespace wire
