// Test hooks into the curve stage's internal kernels (wire_testing, never installed): the AVX-512 record pass
// against the portable loop, the spread test's certificate against the exact test.
#pragma once

#include <cstddef>

namespace wire::detail {

/// Bezier records (12 doubles each, segment k's at out + 12k) of `count` segments from their start and end nodes
/// (3 doubles each, at p0 + 3k and p1 + 3k), node tangents per unit chord (Dx, Dy, Dz: the start node's at k, the
/// end node's at k + 1) and chord lengths len[k]: b1 = b0 + u0, b2 = b3 - u1 with u0 = (D[k] len[k]) / 3 and
/// u1 = (D[k + 1] len[k]) / 3. Returns whether every offset u is within +-offset_limit (false for NaN).
/// build_curve's record pass (src/spline/kernels.cpp): a hand-written AVX-512 version where the CPU has one and count >= 8;
/// `widest` false: the portable loop, the same bits (tests compare the two).
bool node_segment_records(std::size_t count, const double* p0, const double* p1, const double* Dx, const double* Dy,
                          const double* Dz, const double* len, double* out, double offset_limit, bool widest = true);

/// The automatic spline's spread test on count nodes (concentrated_turns' arrays, src/spline/tension.cpp: node i's incoming
/// chord length, previous curvature vector and previous edge at index i, its own at i + 1, the next curvature
/// vector at i + 2): flag[i] 1 where the spread is decided, and there lk[i] = |k|, sum[i] = |k| + |k~| and miss2[i]
/// = |k - k~|^2. `certified`: as build_curve runs it (the root-free certificate, the exact test only where it
/// fails); else the exact test on every node. Both must give the same flags and values (tests compare them).
/// Returns the number of nodes the certificate left to the exact test.
std::size_t spread_test(std::size_t count, const double* len, const double* kx, const double* ky, const double* kz,
                        const double* ax, const double* ay, const double* az, const double* ec, const double* eq,
                        double* lk, double* sum, double* miss2, double* flag, bool certified);

}  // namespace wire::detail
