// Internal: building the per-segment and per-node kernels (instruction-set clones, select kernels) and the
// structure-of-arrays copy of a curve's segments they read.
#pragma once

#include "wire/curve.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

/// On x86-64 with GCC: the function is compiled for AVX-512, AVX2 and the baseline (SSE2), and the loader picks the
/// widest one the CPU has (an ifunc: one indirect call per call). Only for loops written so the compiler vectorizes
/// them. Every clone gives the same results, bit for bit: wire_core is compiled with -ffp-contract=off (no fused
/// multiply-add changes a rounding) and these loops use only correctly rounded operations (+, -, *, /, sqrt, min,
/// max, comparisons). Elsewhere (Clang, sanitizers, other CPUs): one plain function.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(WIRE_NO_VECTOR_CLONES) && \
    !defined(__SANITIZE_ADDRESS__)
#define WIRE_HAS_VECTOR_CLONES 1  // also for hand-made versions chosen at load time (spline.cpp's all_within)
#define WIRE_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define WIRE_VECTOR_CLONES
#endif

/// A kernel whose `?:` selects should become vector blends: GCC if-converts them only without trapping math. No
/// value changes (every operation is still performed and rounded as written; NaN comparisons keep their meaning);
/// only whether an operation whose result is discarded may raise a floating-point exception flag, which nothing
/// here reads.
#if defined(__GNUC__) && !defined(__clang__)
#define WIRE_SELECT_KERNEL __attribute__((optimize("no-trapping-math")))
#else
#define WIRE_SELECT_KERNEL
#endif

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

/// Bezier records (12 doubles each, segment k's at out + 12k) of `count` segments from their start and end nodes
/// (3 doubles each, at p0 + 3k and p1 + 3k), node tangents per unit chord (Dx, Dy, Dz: the start node's at k, the
/// end node's at k + 1) and chord lengths len[k]: b1 = b0 + u0, b2 = b3 - u1 with u0 = (D[k] len[k]) / 3 and
/// u1 = (D[k + 1] len[k]) / 3. Returns whether every offset u is within +-offset_limit (false for NaN).
/// build_curve's record pass (spline.cpp): a hand-written AVX-512 version where the CPU has one and count >= 8;
/// `widest` false: the portable loop, the same bits (tests compare the two).
bool node_segment_records(std::size_t count, const double* p0, const double* p1, const double* Dx, const double* Dy,
                          const double* Dz, const double* len, double* out, double offset_limit, bool widest = true);

/// The automatic spline's spread test on count nodes (concentrated_turns' arrays, spline.cpp: node i's incoming
/// chord length, previous curvature vector and previous edge at index i, its own at i + 1, the next curvature
/// vector at i + 2): flag[i] 1 where the spread is decided, and there lk[i] = |k|, sum[i] = |k| + |k~| and miss2[i]
/// = |k - k~|^2. `certified`: as build_curve runs it (the root-free certificate, the exact test only where it
/// fails); else the exact test on every node. Both must give the same flags and values (tests compare them).
/// Returns the number of nodes the certificate left to the exact test.
std::size_t spread_test(std::size_t count, const double* len, const double* kx, const double* ky, const double* kz,
                        const double* ax, const double* ay, const double* az, const double* ec, const double* eq,
                        double* lk, double* sum, double* miss2, double* flag, bool certified);

/// boundary_tangents()' work for segment k (of n laid out by transpose_segments()). Always inlined: GCC inlines
/// nothing else into a kernel compiled for another instruction set (WIRE_VECTOR_CLONES), and build_rings' Gauss
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
