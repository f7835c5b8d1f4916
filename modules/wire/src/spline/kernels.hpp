// Internal: the curve stage's hand-written vector kernels: the tangent system's rows, segment tangents and the
// Bezier records with their range test (instruction-set clones chosen at load time, bit-identical).
#pragma once

#include <cstddef>

namespace wire::curve_stage {

// Interior rows of the tangent system (node j: incoming chord at index j, outgoing at j + 1; diagonal 2 + w_j).
void rows_kernel(std::size_t rows, const double* w, const double* ex, const double* ey, const double* ez,
                 const double* len, double* a, double* b, double* c, double* rx, double* ry, double* rz);

// Segment tangents from node tangents per unit chord (D: node k's at k, k + 1's at k + 1) and chord lengths.
void tangents_kernel(std::size_t segs, const double* D, const double* len, double* t0, double* t1);

// Bezier segments k = 0 .. count-1 (12 doubles each, out at 12k) from node coordinates p0 (3 per node, segment
// k's start at 3k), p1 (its end at 3k) and the segment tangents: inner control points B1 = P0 + t0/3 and
// B2 = P1 - t1/3, written straight into the records (one pass: the control points are not stored apart first).
// Returns whether every inner control point is within +-limit (write_record's test).
bool segments_kernel(std::size_t count, const double* p0, const double* p1, const double* t0x, const double* t0y,
                     const double* t0z, const double* t1x, const double* t1y, const double* t1z, double* out,
                     double limit);

// The same records from node tangents per unit chord (D: segment k's start node at k, its end node at k + 1) and
// the chord lengths: t0 = D[k] len[k], t1 = D[k + 1] len[k] (tangents_kernel's values) taken straight into the
// control points, with no pass through segment tangents (the spline kinds whose tangents are a node's).
// Returns whether every offset t/3 of a control point from its end point is within +-offset_limit (false for NaN),
// a sufficient test for the control points' range that the caller derives from the positions' (checked on entry).
// node_segments_kernel's records and test, by the AVX-512 version where the CPU has it (`widest`; false: the loop).
bool node_segments(std::size_t count, const double* p0, const double* p1, const double* Dx, const double* Dy,
                   const double* Dz, const double* len, double* out, double offset_limit, bool widest = true);

}  // namespace wire::curve_stage
