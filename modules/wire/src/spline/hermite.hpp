// Internal: the Hermite tangents of the curve stage (spline/hermite.cpp): the per-segment tangent arrays, the node
// tangents, and the nu-spline tangent system's setup and finish around its solve.
#pragma once

#include "spline/merge.hpp"
#include "spline/scratch.hpp"
#include "spline/tridiagonal.hpp"

#include <cstddef>
#include <vector>

namespace wire::curve_stage {

// Per-segment Hermite tangents (per unit of the segment parameter u): t0 at the start, t1 at the end; structure
// of arrays, the six arrays one after the other in one buffer (checked in one pass).
struct Tangents {
    std::vector<double> buf;
    double *t0x = nullptr, *t0y = nullptr, *t0z = nullptr, *t1x = nullptr, *t1y = nullptr, *t1z = nullptr;
    void resize(std::size_t segs) {
        buf.resize(6 * segs);
        t0x = buf.data(), t0y = t0x + segs, t0z = t0y + segs, t1x = t0z + segs, t1y = t1x + segs, t1z = t1y + segs;
    }
    void set0(std::size_t k, const dvec3& v) { t0x[k] = v.x, t0y[k] = v.y, t0z[k] = v.z; }
    void set1(std::size_t k, const dvec3& v) { t1x[k] = v.x, t1y[k] = v.y, t1z[k] = v.z; }
    void scale0(std::size_t k, double s) { t0x[k] = t0x[k] * s, t0y[k] = t0y[k] * s, t0z[k] = t0z[k] * s; }
    void scale1(std::size_t k, double s) { t1x[k] = t1x[k] * s, t1y[k] = t1y[k] * s, t1z[k] = t1z[k] * s; }
};

// n zeros (per thread; grown when needed, never written): the weights of a wire with no tensed node.
const double* zeros(std::size_t n);

// Node tangents per unit chord, node i's at i and index n repeating node 0's (x, y, z arrays, per-thread memory
// valid until the next solve).
struct NodeTangents {
    const double *x = nullptr, *y = nullptr, *z = nullptr;
};

// Segment tangents from node tangents (for the kinds that then scale them per node).
void segment_tangents(const NodeTangents& D, const Chords& ch, Tangents& tg);

/// The nu-spline (Nielson 1974) with chordal knots: C1, and at node i the jump of the second derivative is
/// proportional to the tangent (tension w_i, from concentrated_turns; g and gs its weights). Rows as the C2
/// spline's (w = 0: c2) with w_i added to the diagonal; open ends not-a-knot, blending to free ends (zero
/// curvature) as the neighbouring node gets tensed.
/// The setup: everything but the solve of an open wire's interior rows (ts.pending), which solve() or
/// thomas_pair() does before finish_tangents(). `pool` holds the system until then.
void start_tangents(const Chords& ch, std::size_t n, bool closed, const double* g, const double* gs, const double* w,
                    Pool& pool, TangentSolve& ts);

// The end nodes from the solved interior (an open wire's), and index n; the node tangents.
NodeTangents finish_tangents(const TangentSolve& ts);

}  // namespace wire::curve_stage
