// The curve stage's Hermite tangents: node tangents to segment tangents, and the nu-spline (C2 with tension) tangent
// system's setup before its solve and its end nodes after it.
#include "spline/hermite.hpp"

#include "spline/kernels.hpp"
#include "spline/merge.hpp"
#include "spline/scratch.hpp"
#include "spline/tension.hpp"
#include "spline/tridiagonal.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace wire::curve_stage {

// n zeros (per thread; grown when needed, never written): the weights of a wire with no tensed node.
const double* zeros(std::size_t n) {
    thread_local std::vector<double> z;
    if (z.size() < n) z.resize(n);
    return z.data();
}

// Segment tangents from node tangents (for the kinds that then scale them per node).
void segment_tangents(const NodeTangents& D, const Chords& ch, Tangents& tg) {
    const double* const len = ch.len.data() + 1;  // segment k's length
    tangents_kernel(ch.segs, D.x, len, tg.t0x, tg.t1x);
    tangents_kernel(ch.segs, D.y, len, tg.t0y, tg.t1y);
    tangents_kernel(ch.segs, D.z, len, tg.t0z, tg.t1z);
}

/// The nu-spline (Nielson 1974) with chordal knots: C1, and at node i the jump of the second derivative is
/// proportional to the tangent (tension w_i, from concentrated_turns; g and gs its weights). Rows as the C2
/// spline's (w = 0: c2) with w_i added to the diagonal; open ends not-a-knot, blending to free ends (zero
/// curvature) as the neighbouring node gets tensed.
/// The setup: everything but the solve of an open wire's interior rows (ts.pending), which solve() or
/// thomas_pair() does before finish_tangents(). `pool` holds the system until then.
void start_tangents(const Chords& ch, std::size_t n, bool closed, const double* g, const double* gs, const double* w,
                    Pool& pool, TangentSolve& ts) {
    const std::size_t segs = ch.segs;
    const double* __restrict ex = ch.ex.data();  // node i: incoming chord at i, outgoing at i + 1
    const double* __restrict ey = ch.ey.data();
    const double* __restrict ez = ch.ez.data();
    const double* __restrict len = ch.len.data();
    // Working memory: the caller's, reused (no allocation per call once large enough). D (node tangents per
    // unit chord) has index n repeating node 0's.
    pool.reset(3 * (n + 1) + 4 * n);
    double* const D[3] = {pool.carve(n + 1), pool.carve(n + 1), pool.carve(n + 1)};
    double* __restrict a = pool.carve(n);
    double* __restrict b = pool.carve(n);
    double* __restrict c = pool.carve(n);
    ts = TangentSolve{{D[0], D[1], D[2]}, a, b, c, pool.carve(n), n, 0, false};
    // Rows i0 .. i0 + rows - 1 of the interior system, their right-hand sides in place in D.
    const auto fill_rows = [&](std::size_t i0, std::size_t rows) {
        in_whole_blocks(rows, [&](std::size_t o, std::size_t count) {
            const std::size_t j = i0 + o;
            rows_kernel(count, w + j, ex + j, ey + j, ez + j, len + j, a + o, b + o, c + o, D[0] + j, D[1] + j,
                        D[2] + j);
        });
    };
    const auto node = [&](std::size_t i) { return dvec3(D[0][i], D[1][i], D[2][i]); };
    const auto set_node = [&](std::size_t i, const dvec3& v) { D[0][i] = v.x, D[1][i] = v.y, D[2][i] = v.z; };
    if (closed) {
        fill_rows(0, n);
        thomas_cyclic(a, b, c, n, D);
    } else if (n == 2) {
        set_node(0, ch.e(0)), set_node(1, ch.e(0));
    } else {
        const auto s = [&](std::size_t k) { return ch.e(k); };
        // End rows beta D0 + D1 = r: not-a-knot (beta = h1/(h0+h1)) blending to free (beta = 2, r = 3 s0).
        const double h0 = ch.l(0), h1 = ch.l(1), hL = ch.l(segs - 1), hP = ch.l(segs - 2);
        const dvec3 r0n = (s(0) * (h1 * (3.0 * h0 + 2.0 * h1)) + (h0 * h0) * s(1)) / ((h0 + h1) * (h0 + h1));
        const dvec3 rln =
            (s(segs - 1) * (hP * (3.0 * hL + 2.0 * hP)) + (hL * hL) * s(segs - 2)) / ((hP + hL) * (hP + hL));
        // The not-a-knot end makes the first (last) two segments one cubic, which overshoots when either
        // node it spans is tensed (its tangent nearly vanishes): then the end becomes free.
        const auto tensed = [&](std::size_t i) { return std::max(g[i], gs[i]); };
        const double g0 = std::max(tensed(1), n > 3 ? tensed(2) : 0.0),
                     gl = std::max(tensed(n - 2), n > 3 ? tensed(n - 3) : 0.0);
        const double beta0 = (1.0 - g0) * h1 / (h0 + h1) + 2.0 * g0, betal = (1.0 - gl) * hP / (hP + hL) + 2.0 * gl;
        const dvec3 r0 = (1.0 - g0) * r0n + (3.0 * g0) * s(0), rl = (1.0 - gl) * rln + (3.0 * gl) * s(segs - 1);
        const std::size_t m = n - 2;
        fill_rows(1, m);  // row j is node j + 1's
        if (m == 1) {
            // 3 nodes: not-a-knot at both ends is the interpolating parabola (one cubic through 3 points is
            // not determined: the elimination below would be singular); it blends with the tensed solution
            // with free ends as the middle node gets tensed.
            const double g1 = g[1];
            const dvec3 p0 = s(0) - h0 * (s(1) - s(0)) / (h0 + h1), p1 = (h1 * s(0) + h0 * s(1)) / (h0 + h1);
            const dvec3 p2 = s(1) + h1 * (s(1) - s(0)) / (h0 + h1);
            // Free ends: 2 D0 + D1 = 3 s0, 2 D2 + D1 = 3 s1, middle row a D0 + (2 + w) D1 + c D2 = r.
            const dvec3 t1 = (node(1) - 1.5 * (a[0] * s(0) + c[0] * s(1))) / (b[0] - 0.5 * (a[0] + c[0]));
            const dvec3 t0 = 0.5 * (3.0 * s(0) - t1), t2 = 0.5 * (3.0 * s(1) - t1);
            set_node(0, (1.0 - g1) * p0 + g1 * t0);
            set_node(1, (1.0 - g1) * p1 + g1 * t1);
            set_node(2, (1.0 - g1) * p2 + g1 * t2);
        } else {
            // Eliminate D0 and D[n-1] (pivots stay >= 1: a/beta <= 1); the interior rows are solved next.
            set_node(1, node(1) - (a[0] / beta0) * r0), b[0] -= a[0] / beta0, a[0] = 0.0;
            set_node(m, node(m) - (c[m - 1] / betal) * rl), b[m - 1] -= c[m - 1] / betal, c[m - 1] = 0.0;
            ts.m = m, ts.pending = true;
            ts.r0 = r0, ts.rl = rl, ts.beta0 = beta0, ts.betal = betal;
        }
    }
}

// The end nodes from the solved interior (an open wire's), and index n; the node tangents.
NodeTangents finish_tangents(const TangentSolve& ts) {
    double* const* D = ts.D;
    const std::size_t n = ts.n;
    const auto node = [&](std::size_t i) { return dvec3(D[0][i], D[1][i], D[2][i]); };
    const auto set_node = [&](std::size_t i, const dvec3& v) { D[0][i] = v.x, D[1][i] = v.y, D[2][i] = v.z; };
    if (ts.pending) {
        set_node(0, (ts.r0 - node(1)) / ts.beta0);
        set_node(n - 1, (ts.rl - node(n - 2)) / ts.betal);
    }
    D[0][n] = D[0][0], D[1][n] = D[1][0], D[2][n] = D[2][0];
    return {D[0], D[1], D[2]};
}

}  // namespace wire::curve_stage
