// The automatic spline's tension (DESIGN §4.1, modules/wire/DESIGN.md "Automatic spline"): the turning pattern's
// spread test (a root-free certificate, the exact test where it fails) and the per-node weights it gives.
#include "spline/tension.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES, WIRE_SELECT_KERNEL
#include "spline/scratch.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace wire::curve_stage {

namespace {

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) * (1.0 / (e1 - e0)), 0.0, 1.0);  // constant edges: one product
    return t * t * (3.0 - 2.0 * t);
}

// Largest per-node tension w (added to the C2 row's diagonal 2): the tangent at a fully tensed node shrinks to
// ~3/(2+W) of the C2 one, a rounding of ~3e-5 of the element at a concentrated corner (the bending length
// sqrt(EI/T) ~ h/(2 sqrt(W)) = h/350), yet never 0, so the curve stays G1.
constexpr double kMaxNodeTension = 3e4;
// Turning-pattern thresholds: a node's curvature vector is "unsupported" by its neighbours when
// d = |k - k~| / (|k| + |k~|) exceeds kSpreadHi (1 = nothing in common: a corner between straight runs, an
// alternating zig-zag); smooth sag, drums and helices with >= 5 nodes per turn stay below kSpreadLo.
constexpr double kSpreadLo = 0.55, kSpreadHi = 0.85;
// ... and the node must carry at least its share of the turning (c = |k| / (|k| + |k~|)): a straight node next
// to a corner (c = 0) is not tensed (it stays on its line anyway; tensing it would only add rings).
constexpr double kShareLo = 0.3, kShareHi = 0.45;
// A node that stays straight while a neighbour turns (share below kStraightHi, fully at 0) ends a load-free
// span: a moderate tension there (w up to kStraightTension) damps the C2 spline's ringing into the straight run
// (wrapped-cable family: mean deviation 0.74x -> 0.61x chordal Catmull-Rom's, worst case 1.06x -> 1.03x). A
// larger band (up to share 0.3) tenses nodes whose element is partly curved and loses on the worst case (1.6x).
constexpr double kStraightLo = 0.0, kStraightHi = 0.1;
constexpr double kStraightTension = 30.0;

constexpr double kReversal = -1.0 + 1e-12;

// Per node i (incoming chord at index i, outgoing at i + 1): curvature vector k_i and chord-bisector tangent t_i.
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL
void curvature_kernel(std::size_t n, const double* __restrict ex, const double* __restrict ey,
                      const double* __restrict ez, const double* __restrict len, double* __restrict kx,
                      double* __restrict ky, double* __restrict kz, double* __restrict tx, double* __restrict ty,
                      double* __restrict tz) {
    for (std::size_t i = 0; i < n; ++i) {
        const double s = 2.0 / (len[i] + len[i + 1]);
        kx[i] = (ex[i + 1] - ex[i]) * s;
        ky[i] = (ey[i + 1] - ey[i]) * s;
        kz[i] = (ez[i + 1] - ez[i]) * s;
        const double bx = ex[i] + ex[i + 1], by = ey[i] + ey[i + 1], bz = ez[i] + ez[i + 1];
        const double lb = std::sqrt(bx * bx + by * by + bz * bz);
        const double inv = 1.0 / lb;
        const bool ok = lb > 1e-12;  // else the chords reverse: the outgoing one
        tx[i] = ok ? bx * inv : ex[i + 1];
        ty[i] = ok ? by * inv : ey[i + 1];
        tz[i] = ok ? bz * inv : ez[i + 1];
    }
}

// Per edge j (tangents t_j, t_j+1): the rotation's axis, cosine and 1 / (1 + cos) (0 at a reversal).
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL
void edge_kernel(std::size_t n, const double* __restrict tx, const double* __restrict ty, const double* __restrict tz,
                 double* __restrict ax, double* __restrict ay, double* __restrict az, double* __restrict ec,
                 double* __restrict eq) {
    for (std::size_t j = 0; j < n; ++j) {
        const double c = tx[j] * tx[j + 1] + ty[j] * ty[j + 1] + tz[j] * tz[j + 1];
        ax[j] = ty[j] * tz[j + 1] - ty[j + 1] * tz[j];
        ay[j] = tz[j] * tx[j + 1] - tz[j + 1] * tx[j];
        az[j] = tx[j] * ty[j + 1] - tx[j + 1] * ty[j];
        const double q = 1.0 / (1.0 + c);
        ec[j] = c;
        eq[j] = c <= kReversal ? 0.0 : q;
    }
}

// The spread test's threshold without square roots: with a = |k|^2 and b = |k~|^2 as computed, the exact test
// leaves a node undecided when miss2 <= (kSpreadLo sum)^2 (both sides rounded), sum = sqrt(a) + sqrt(b) rounded.
// kSpreadBound s2 >= miss2, s2 = a + b + 2 min(a, b) rounded, implies it (u = 2^-53, every value >= 0):
// 1. sqrt(a), sqrt(b) and their sum are each rounded once: sum >= (sqrt a + sqrt b)(1 - u)^2, and
//    (sqrt a + sqrt b)^2 = a + b + 2 sqrt(ab) >= a + b + 2 min(a, b) =: S, so sum^2 >= S (1 - u)^4.
// 2. The threshold (kSpreadLo sum)^2 rounds twice more: it is >= kSpreadLo^2 S (1 - u)^7 (kSpreadLo the double).
// 3. s2 <= S (1 + u)^2 (2 min(a, b) is exact), the bound's product <= kSpreadBound S (1 + u)^3; kSpreadBound =
//    0.3024 < 0.3025 (1 - 2^-12) <= kSpreadLo^2 (1 - u)^7 / (1 + u)^3: so bound >= miss2 gives threshold >= miss2.
// Ranges: s2 in [2^-900, 2^1000] keeps every value above normal numbers' range floor (sum >= 2^-451, the threshold
// >= 2^-903: no underflow's absolute error) and finite (sum <= 2^501). A NaN fails a comparison. Nodes outside
// the certificate (a node that may turn without support, or out of range) take the exact test with the roots.
// (WireCurveFamilies.SpreadCertificateEqualsTheExactTest tests it near the boundary.)
constexpr double kSpreadBound = 0.3024;
static_assert(kSpreadBound < 0.3025 * (1.0 - 0x1p-12) && 0.3025 <= kSpreadLo * kSpreadLo,
              "kSpreadBound must stay below kSpreadLo^2 by more than the roundings of the proof");

}  // namespace


// Per node (arrays offset so that node i's incoming chord length, previous node's curvature and previous edge are
// at index i, its own at i + 1, the next node's curvature at i + 2): the turn its neighbours predict, the spread's
// ingredients |k|^2, |k~|^2 and |k - k~|^2, and flag 1 where the spread may have to be decided (0: the neighbours
// predict this turn, d <= kSpreadLo, shown on squares without a root by kSpreadBound; the flagged nodes, about one
// a wire on a swaying cable, take the exact test in concentrated_turns). Returns the number of flagged nodes.
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL
std::size_t spread_kernel(std::size_t count, const double* __restrict len, const double* __restrict kx,
                          const double* __restrict ky, const double* __restrict kz, const double* __restrict ax,
                          const double* __restrict ay, const double* __restrict az, const double* __restrict ec,
                          const double* __restrict eq, double* __restrict lk2v, double* __restrict lp2v,
                          double* __restrict miss2v, double* __restrict flag) {
    std::size_t flagged = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const double hin = len[i], hout = len[i + 1];
        // Forwards along the previous edge (index i) from node i-1 (index i of k).
        double fx, fy, fz;
        {
            const double a_x = ax[i], a_y = ay[i], a_z = az[i], c = ec[i], q = eq[i];
            const double vx = kx[i], vy = ky[i], vz = kz[i];
            const double cx = a_y * vz - vy * a_z, cy = a_z * vx - vz * a_x, cz = a_x * vy - vx * a_y;
            const double dq = (a_x * vx + a_y * vy + a_z * vz) * q;
            const bool rev = c <= kReversal;
            fx = rev ? -vx : vx * c + cx + a_x * dq;
            fy = rev ? -vy : vy * c + cy + a_y * dq;
            fz = rev ? -vz : vz * c + cz + a_z * dq;
        }
        // Backwards along node i's own edge (index i + 1) from node i+1 (index i + 2 of k).
        double bx, by, bz;
        {
            const double a_x = ax[i + 1], a_y = ay[i + 1], a_z = az[i + 1], c = ec[i + 1], q = eq[i + 1];
            const double vx = kx[i + 2], vy = ky[i + 2], vz = kz[i + 2];
            const double cx = a_y * vz - vy * a_z, cy = a_z * vx - vz * a_x, cz = a_x * vy - vx * a_y;
            const double dq = (a_x * vx + a_y * vy + a_z * vz) * q;
            const bool rev = c <= kReversal;
            bx = rev ? -vx : vx * c - cx + a_x * dq;
            by = rev ? -vy : vy * c - cy + a_y * dq;
            bz = rev ? -vz : vz * c - cz + a_z * dq;
        }
        const double s = 1.0 / (hin + hout);
        const double px = (hout * fx + hin * bx) * s, py = (hout * fy + hin * by) * s, pz = (hout * fz + hin * bz) * s;
        const double vx = kx[i + 1], vy = ky[i + 1], vz = kz[i + 1];
        const double lk2 = vx * vx + vy * vy + vz * vz, lp2 = px * px + py * py + pz * pz;
        const double mx = vx - px, my = vy - py, mz = vz - pz;
        const double miss2 = mx * mx + my * my + mz * mz;
        lk2v[i] = lk2;
        lp2v[i] = lp2;
        miss2v[i] = miss2;
        const double s2 = (lk2 + lp2) + 2.0 * (lk2 < lp2 ? lk2 : lp2);
        const bool predicted = (s2 >= 0x1p-900) & (s2 <= 0x1p1000) & (miss2 <= kSpreadBound * s2);
        flag[i] = predicted ? 0.0 : 1.0;
        flagged += predicted ? 0 : 1;
    }
    return flagged;
}

// The spread's exact test for a node: sum = |k| + |k~| > 0 and finite (lengths are >= 0 or NaN), and the miss
// beyond kSpreadLo of it. lk = |k| and sum are returned for the weights.
bool spread_decides(double lk2, double lp2, double miss2, double& lk, double& sum) {
    lk = std::sqrt(lk2);
    sum = lk + std::sqrt(lp2);
    return (sum > 0.0) & (sum <= DBL_MAX) & !(miss2 <= (kSpreadLo * sum) * (kSpreadLo * sum));
}

// The exact test for the nodes spread_kernel flagged (its outputs, count nodes), as concentrated_turns' weight loop
// applies it, for the tests (detail::spread_test): a flag stays 1 where the spread must be decided (lk2v, lp2v then
// hold |k| and |k| + |k~|), else becomes 0. Returns whether any stays 1.
bool decide_flagged(std::size_t count, double* lk2v, double* lp2v, const double* miss2v, double* flag) {
    bool any = false;
    for (std::size_t i = 0; i < count; ++i) {
        if (flag[i] == 0.0) continue;
        double lk, sum;
        const bool decide = spread_decides(lk2v[i], lp2v[i], miss2v[i], lk, sum);
        lk2v[i] = lk, lp2v[i] = sum, flag[i] = decide ? 1.0 : 0.0;
        any |= decide;
    }
    return any;
}

/// Per-node tension weights from the turning pattern (see the constants above): g in [0, 1] (concentrated
/// turn), straight in [0, 1] (end of a load-free span), and the diagonal addition w they give (0 where both are 0).
/// n curve nodes. Returns false when every weight is 0 (no node to decide, or none that gets a weight: most
/// wires), leaving the outputs untouched (not zero-filled); else every output is resized to n.
bool concentrated_turns(const Chords& ch, std::size_t n, bool closed, std::vector<double>& g,
                        std::vector<double>& straight, std::vector<double>& w) {
    if (n < 3) return false;
    thread_local Pool pool;
    pool.reset(3 * (n + 2) + 3 * (n + 1) + 5 * (n + 1) + 4 * n);
    // Curvature vectors k_i = (e_out - e_in) / (mean of the two elements): |k| ~ 2 sin(phi/2) / h. Node i's at
    // index i + 1; index 0 repeats the last node's, index n + 1 the first's (wrap-around ghosts).
    double* __restrict kx = pool.carve(n + 2);
    double* __restrict ky = pool.carve(n + 2);
    double* __restrict kz = pool.carve(n + 2);
    // Node tangents (chord bisectors), to carry a neighbour's curvature vector to node i by the rotation that
    // takes its tangent to node i's (on a circle this maps one curvature vector exactly onto the next). Index n
    // repeats node 0's.
    double* __restrict tx = pool.carve(n + 1);
    double* __restrict ty = pool.carve(n + 1);
    double* __restrict tz = pool.carve(n + 1);
    const double* __restrict ex = ch.ex.data();  // node i: incoming chord at i, outgoing at i + 1
    const double* __restrict ey = ch.ey.data();
    const double* __restrict ez = ch.ez.data();
    const double* __restrict len = ch.len.data();
    // Every node, branch-free (open wires' end values are replaced below).
    curvature_kernel(n, ex, ey, ez, len, kx + 1, ky + 1, kz + 1, tx, ty, tz);
    if (!closed) {  // constant extrapolation
        kx[1] = kx[2], ky[1] = ky[2], kz[1] = kz[2];
        kx[n] = kx[n - 1], ky[n] = ky[n - 1], kz[n] = kz[n - 1];
        tx[0] = tx[1], ty[0] = ty[1], tz[0] = tz[1];
        tx[n - 1] = tx[n - 2], ty[n - 1] = ty[n - 2], tz[n - 1] = tz[n - 2];
    }
    kx[0] = kx[n], ky[0] = ky[n], kz[0] = kz[n];
    kx[n + 1] = kx[1], ky[n + 1] = ky[1], kz[n + 1] = kz[1];
    tx[n] = tx[0], ty[n] = ty[0], tz[n] = tz[0];
    // Rodrigues rotation t[j] -> t[j+1] per edge j (axis sin, cos, 1 / (1 + cos)), once per edge, at index j + 1
    // (index 0 repeats the last edge): node j+1 carries k[j] forwards with it, node j carries k[j+1] backwards
    // with its inverse (axis negated, the same cosine).
    double* __restrict ax = pool.carve(n + 1);
    double* __restrict ay = pool.carve(n + 1);
    double* __restrict az = pool.carve(n + 1);
    double* __restrict ec = pool.carve(n + 1);
    double* __restrict eq = pool.carve(n + 1);
    edge_kernel(n, tx, ty, tz, ax + 1, ay + 1, az + 1, ec + 1, eq + 1);
    ax[0] = ax[n], ay[0] = ay[n], az[0] = az[n], ec[0] = ec[n], eq[0] = eq[n];
    // What the neighbours predict at node i: their curvature vectors, carried to node i's tangent (a reversal,
    // any perpendicular axis: the sign is what matters), interpolated linearly in arc length; the spread's
    // ingredients per node.
    double* __restrict lkv = pool.carve(n);  // |k|^2 from spread_kernel, |k| for the nodes to decide
    double* __restrict sumv = pool.carve(n);  // |k~|^2 from spread_kernel, |k| + |k~| for the nodes to decide
    double* __restrict miss2v = pool.carve(n);
    double* __restrict flag = pool.carve(n);
    const std::size_t first = closed ? 0 : 1, end = closed ? n : n - 1;
    std::size_t flagged = 0;  // > 0 when any node is flagged (the last block's overlap counts some twice)
    in_whole_blocks(end - first, [&](std::size_t o, std::size_t count) {
        const std::size_t f = first + o;
        flagged += spread_kernel(count, len + f, kx + f, ky + f, kz + f, ax + f, ay + f, az + f, ec + f, eq + f,
                                 lkv + f, sumv + f, miss2v + f, flag + f);
    });
    // The rare nodes whose turn the neighbours may not predict (the common case, d <= kSpreadLo: g = 0 and
    // straight = 0), and not straight here and around: none in many wires (one vector test). The flagged ones
    // take the exact test.
    if (flagged == 0) return false;
    static const double log_max = std::log1p(kMaxNodeTension), log_straight = std::log1p(kStraightTension);
    bool any = false;
    for (std::size_t i = first; i < end; ++i) {
        if (flag[i] == 0.0) continue;
        double lk, sum;
        if (!spread_decides(lkv[i], sumv[i], miss2v[i], lk, sum)) continue;  // within the certificate's margin
        const double miss2 = miss2v[i];
        const double hin = len[i], hout = len[i + 1];
        const double inv_sum = 1.0 / sum;
        const double d = std::sqrt(miss2) * inv_sum;
        // Turning below ~1e-6 rad is rounding noise of collinear nodes (and invisible): nothing to decide.
        const double turn = 0.5 * sum * (hin + hout);
        const double unshared = smoothstep(kSpreadLo, kSpreadHi, d) * smoothstep(1e-8, 1e-6, turn);
        // Smoothsteps are +0 .. 1 (or NaN): an unshared turn of 0 gives g = straight = w = +0, the fill's values,
        // so the outputs are filled only at the first node that gets a weight (many wires' flagged nodes are
        // straight ones, turn < 1e-8, and none does).
        if (unshared == 0.0) continue;
        if (!any) g.assign(n, 0.0), straight.assign(n, 0.0), w.assign(n, 0.0);
        any = true;
        const double share = lk * inv_sum;
        g[i] = unshared * smoothstep(kShareLo, kShareHi, share);
        straight[i] = unshared * (1.0 - smoothstep(kStraightLo, kStraightHi, share));
        // Log-uniform in g (an untensed weight adds 0: expm1(0) = 0 exactly, so the call is skipped).
        const double wc = g[i] != 0.0 ? std::expm1(g[i] * log_max) : 0.0;
        const double ws = straight[i] != 0.0 ? std::expm1(straight[i] * log_straight) : 0.0;
        w[i] = wc + ws;
    }
    return any;
}

}  // namespace wire::curve_stage
