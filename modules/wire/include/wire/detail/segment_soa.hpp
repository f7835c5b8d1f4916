// Internal: the structure-of-arrays copy of a curve's segments that the per-segment kernels read (frames.cpp).
#pragma once

#include "wire/curve.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace wire::detail {

/// Segments' control points as 12 arrays of `n` (b0.x, b0.y, b0.z, b1.x, ... b3.z): the layout the per-segment
/// loops vectorize over (an array of 96-byte Bezier records is a gather the compiler does not vectorize). Four
/// segments at a time by three 4x4 transposes of their 12 doubles (in frames.cpp).
/// `stride` (>= n; 0: n) is the distance between the arrays.
void transpose_segments(const CubicBezier* segments, std::size_t n, double* out, std::size_t stride = 0);

/// transpose_segments() of segments[index[0]], .. segments[index[n - 1]] (a segment may appear more than once).
void gather_segments(const CubicBezier* segments, const uint32_t* index, std::size_t n, double* out);

/// Unit tangents at t = 0 of `n` segments given as transpose_segments() lays them out: B'(0) = 3 (b1 - b0) times
/// the reciprocal of its length, the operations build_rings uses for a ring at t = 0 (a crossed segment boundary
/// and a ring there carry the same tangent). ok[k] = 0 where that derivative is below the segment's rounding noise
/// (the caller takes unit_tangent()'s one-sided limits there). In frames.cpp.
void boundary_tangents(const double* soa, std::size_t n, double* tx, double* ty, double* tz, double* ok);

/// boundary_tangents()' work for segment k (of n laid out by transpose_segments()). Always inlined: GCC inlines
/// nothing else into a kernel compiled for another instruction set (WIRE_VECTOR_CLONES, src/simd/dispatch.hpp), and build_rings' Gauss
/// lengths kernel does this in the same pass over the segments.
[[gnu::always_inline]] inline void boundary_tangent(const double* __restrict b, std::size_t n, std::size_t k,
                                                    double* __restrict tx, double* __restrict ty,
                                                    double* __restrict tz, double* __restrict ok) {
    // The largest of three magnitudes (no NaN; equal values are equal), without a branch.
    const auto max3 = [](double p, double q, double r) { return std::max(std::max(p, q), r); };
    const double b0x = b[k], b0y = b[n + k], b0z = b[2 * n + k];
    const double b1x = b[3 * n + k], b1y = b[4 * n + k], b1z = b[5 * n + k];
    const double b2x = b[6 * n + k], b2y = b[7 * n + k], b2z = b[8 * n + k];
    const double b3x = b[9 * n + k], b3y = b[10 * n + k], b3z = b[11 * n + k];
    const double dx = 3.0 * (b1x - b0x), dy = 3.0 * (b1y - b0y), dz = 3.0 * (b1z - b0z);
    const double speed = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double extent = max3(max3(std::fabs(b1x - b0x), std::fabs(b1y - b0y), std::fabs(b1z - b0z)),
                               max3(std::fabs(b2x - b0x), std::fabs(b2y - b0y), std::fabs(b2z - b0z)),
                               max3(std::fabs(b3x - b0x), std::fabs(b3y - b0y), std::fabs(b3z - b0z)));
    const double inv = 1.0 / speed;
    tx[k] = dx * inv;
    ty[k] = dy * inv;
    tz[k] = dz * inv;
    const double tiny = 1e-10 * extent + 1e-15 * max3(std::fabs(b0x), std::fabs(b0y), std::fabs(b0z)) + 1e-300;
    ok[k] = speed > tiny ? 1.0 : 0.0;
}

}  // namespace wire::detail
