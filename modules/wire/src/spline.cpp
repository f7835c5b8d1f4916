// The curve stage: validation, coincident-node merging, analytic Hermite tangents per spline kind, Bezier form.
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace wire {
namespace {

using glm::dvec3;

std::string describe(double v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::string node_prefix(std::size_t i) { return "node " + std::to_string(i) + ": "; }

// Largest accepted |coordinate| (metres): the tube's float vertices (relative to ring 0) and squared chord
// lengths must stay finite; 1e12 m is far beyond any scene (DESIGN §5 asks for 1e6 m from the origin).
constexpr double kMaxCoordinate_m = 1e12;
// Smallest accepted tube radius (metres) and node stretch: texture u grows as arc length / (2 pi radius stretch)
// and is stored as float; with both >= 1e-6 it stays below ~1e32 for any curve within kMaxCoordinate_m (a
// denormal radius overflowed it to Inf: fuzz_geometry). The radius polynomial between nodes is monotone, so
// node radii bound it from below.
constexpr float kMinRadius_m = 1e-6f;
constexpr float kMinStretch = 1e-6f;

// The log-domain knot ratio's clamp, exp(-+300), for the pow-free alphas.
const double kMinKnotRatio = std::exp(-300.0);
const double kMaxKnotRatio = std::exp(300.0);

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) * (1.0 / (e1 - e0)), 0.0, 1.0);  // constant edges: one product
    return t * t * (3.0 - 2.0 * t);
}

template <class T>
bool size_ok(const std::vector<T>& v, std::size_t n) { return v.empty() || v.size() == n; }

Status check_sizes(const WireNodes& w) {
    const std::size_t n = w.positions.size();
    struct Named { const char* name; std::size_t size; bool ok; };
    const Named arrays[] = {
        {"ids", w.ids.size(), size_ok(w.ids, n)},
        {"stretch", w.stretch.size(), size_ok(w.stretch, n)},
        {"radius_m", w.radius_m.size(), size_ok(w.radius_m, n)},
        {"theta_rad", w.theta_rad.size(), size_ok(w.theta_rad, n)},
        {"iz_m4", w.iz_m4.size(), size_ok(w.iz_m4, n)},
        {"length_m", w.length_m.size(), size_ok(w.length_m, n)},
        {"delta_length_m", w.delta_length_m.size(), size_ok(w.delta_length_m, n)},
        {"area_m2", w.area_m2.size(), size_ok(w.area_m2, n)},
        {"kb_tension", w.kb_tension.size(), size_ok(w.kb_tension, n)},
        {"kb_bias", w.kb_bias.size(), size_ok(w.kb_bias, n)},
        {"kb_continuity", w.kb_continuity.size(), size_ok(w.kb_continuity, n)},
    };
    for (const Named& a : arrays) {
        if (!a.ok) {
            return Status::error(std::string(a.name) + " has " + std::to_string(a.size) + " entries for " +
                                 std::to_string(n) + " nodes (must be empty or one per node)");
        }
    }
    return Status::success();
}

Status check_settings(const SplineSettings& s) {
    const struct { const char* name; double v; } finite[] = {
        {"alpha", s.alpha}, {"tension", s.tension}, {"bias", s.bias}, {"continuity", s.continuity},
        {"radius_m", s.radius_m}, {"merge_epsilon_rel", s.merge_epsilon_rel}};
    for (const auto& f : finite) {
        if (!std::isfinite(f.v)) return Status::error(std::string("settings.") + f.name + " is " + describe(f.v));
    }
    if (s.radius_m < 0.0f) return Status::error("settings.radius_m is " + describe(s.radius_m) + " (must be > 0; 0 means 1 cm)");
    if (s.radius_m > 0.0f && s.radius_m < kMinRadius_m)
        return Status::error("settings.radius_m is " + describe(s.radius_m) + " (below the smallest supported radius, 1e-6 m)");
    if (s.merge_epsilon_rel < 0.0) return Status::error("settings.merge_epsilon_rel is " + describe(s.merge_epsilon_rel) + " (must be >= 0)");
    return Status::success();
}

Status check_nodes(const WireNodes& w, bool use_physics) {
    static const char* const kAxis[3] = {"x", "y", "z"};
    for (std::size_t i = 0; i < w.positions.size(); ++i) {
        for (int a = 0; a < 3; ++a) {
            const double v = w.positions[i][a];
            if (!std::isfinite(v)) return Status::error(node_prefix(i) + "position." + kAxis[a] + " is " + describe(v), static_cast<int>(i));
            if (std::abs(v) > kMaxCoordinate_m)
                return Status::error(node_prefix(i) + "position." + kAxis[a] + " is " + describe(v) +
                                         " (beyond the supported range of +-1e12 m)", static_cast<int>(i));
        }
        if (!w.stretch.empty() && !(w.stretch[i] >= kMinStretch && std::isfinite(w.stretch[i]))) {
            return Status::error(node_prefix(i) + "stretch is " + describe(w.stretch[i]) + " (must be finite and >= 1e-6)", static_cast<int>(i));
        }
        if (!w.radius_m.empty() && !(w.radius_m[i] >= 0.0f && std::isfinite(w.radius_m[i]))) {
            return Status::error(node_prefix(i) + "radius_m is " + describe(w.radius_m[i]) +
                                     " (must be finite and >= 0; 0 uses the wire's radius)", static_cast<int>(i));
        }
        if (!w.radius_m.empty() && w.radius_m[i] > 0.0f && w.radius_m[i] < kMinRadius_m) {
            return Status::error(node_prefix(i) + "radius_m is " + describe(w.radius_m[i]) +
                                     " (below the smallest supported radius, 1e-6 m)", static_cast<int>(i));
        }
        const struct { const char* name; const std::vector<float>& v; } kb[] = {
            {"kb_tension", w.kb_tension}, {"kb_bias", w.kb_bias}, {"kb_continuity", w.kb_continuity}};
        for (const auto& k : kb) {
            if (!k.v.empty() && !std::isfinite(k.v[i])) return Status::error(node_prefix(i) + k.name + " is " + describe(k.v[i]), static_cast<int>(i));
        }
        if (use_physics) {
            const struct { const char* name; double v; } ph[] = {
                {"theta_rad", w.theta_rad[i]}, {"iz_m4", w.iz_m4[i]}, {"length_m", w.length_m[i]},
                {"delta_length_m", w.delta_length_m[i]}, {"area_m2", w.area_m2[i]}};
            for (const auto& p : ph) {
                if (!std::isfinite(p.v)) return Status::error(node_prefix(i) + p.name + " is " + describe(p.v), static_cast<int>(i));
            }
            if (!(w.area_m2[i] > 0.0)) return Status::error(node_prefix(i) + "area_m2 is " + describe(w.area_m2[i]) + " (must be > 0)", static_cast<int>(i));
        }
    }
    return Status::success();
}

// Merged nodes: the first input node of each group is kept; `last` is the group's last input node, whose
// element is the one that leaves the group (its stretch belongs to the outgoing segment).
struct Merged {
    std::vector<dvec3> p;
    std::vector<uint32_t> first, last;
};

void merge_nodes(const WireNodes& w, const SplineSettings& s, Merged& m) {
    const std::size_t n = w.positions.size();
    dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
    for (const dvec3& p : w.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const double diag = n ? glm::length(hi - lo) : 0.0;
    const double max_abs = n ? std::max(glm::length(lo), glm::length(hi)) : 0.0;
    const double rel = s.merge_epsilon_rel > 0.0 ? s.merge_epsilon_rel : 1e-9;
    const double eps = std::max(rel * diag, 64.0 * DBL_EPSILON * max_abs);
    m.p.clear(), m.first.clear(), m.last.clear();
    for (std::size_t i = 0; i < n; ++i) {
        if (!m.p.empty() && glm::length(w.positions[i] - m.p.back()) <= eps) {
            m.last.back() = static_cast<uint32_t>(i);
            continue;
        }
        m.p.push_back(w.positions[i]);
        m.first.push_back(static_cast<uint32_t>(i));
        m.last.push_back(static_cast<uint32_t>(i));
    }
    if (s.closed && m.p.size() >= 2 && glm::length(m.p.back() - m.p.front()) <= eps) {
        m.p.pop_back(), m.first.pop_back(), m.last.pop_back();  // the loop's end coincides with its start
    }
}

// Tridiagonal solve (sub a, diagonal b, super c); callers pass diagonally dominant rows. Twisted ("burn at both
// ends") elimination: rows are eliminated from the top and from the bottom at once, meeting in the middle row, so
// the two serial chains of one division each per row run side by side (half the latency of Thomas' one chain).
template <class V>
void thomas(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c,
            std::vector<V>& r) {
    const std::size_t n = b.size();
    thread_local std::vector<double> f;  // top half: c'/pivot; bottom half: a'/pivot (reused, no allocation)
    f.resize(n);
    if (n < 4) {  // plain Thomas
        double inv = 1.0 / b[0];
        f[0] = c[0] * inv;
        r[0] = r[0] * inv;
        for (std::size_t i = 1; i < n; ++i) {
            inv = 1.0 / (b[i] - a[i] * f[i - 1]);
            f[i] = c[i] * inv;
            r[i] = (r[i] - a[i] * r[i - 1]) * inv;
        }
        for (std::size_t i = n - 1; i-- > 0;) r[i] = r[i] - f[i] * r[i + 1];
        return;
    }
    const std::size_t p = n / 2;  // the meeting row; top rows 0..p-1, bottom rows p+1..n-1
    auto top = [&](std::size_t i) {
        const double inv = 1.0 / (b[i] - a[i] * f[i - 1]);
        f[i] = c[i] * inv;
        r[i] = (r[i] - a[i] * r[i - 1]) * inv;
    };
    auto bottom = [&](std::size_t j) {
        const double inv = 1.0 / (b[j] - c[j] * f[j + 1]);
        f[j] = a[j] * inv;
        r[j] = (r[j] - c[j] * r[j + 1]) * inv;
    };
    double inv = 1.0 / b[0];
    f[0] = c[0] * inv;
    r[0] = r[0] * inv;
    inv = 1.0 / b[n - 1];
    f[n - 1] = a[n - 1] * inv;
    r[n - 1] = r[n - 1] * inv;
    std::size_t i = 1, j = n - 2;
    for (; i < p && j > p; ++i, --j) top(i), bottom(j);
    for (; i < p; ++i) top(i);
    for (; j > p; --j) bottom(j);
    // Row p with x[p-1] = r[p-1] - f[p-1] x[p] and x[p+1] = r[p+1] - f[p+1] x[p] substituted.
    r[p] = (r[p] - a[p] * r[p - 1] - c[p] * r[p + 1]) * (1.0 / (b[p] - a[p] * f[p - 1] - c[p] * f[p + 1]));
    for (i = p, j = p; i > 0 && j + 1 < n;) {
        --i, ++j;
        r[i] = r[i] - f[i] * r[i + 1];
        r[j] = r[j] - f[j] * r[j - 1];
    }
    while (i > 0) --i, r[i] = r[i] - f[i] * r[i + 1];
    while (j + 1 < n) ++j, r[j] = r[j] - f[j] * r[j - 1];
}

// Cyclic tridiagonal (corners a[0] at column n-1 and c[n-1] at column 0) by Sherman-Morrison, n >= 3.
void thomas_cyclic(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c,
                   std::vector<dvec3>& r) {
    const std::size_t n = b.size();
    const double alpha = c[n - 1], beta = a[0], gamma = -b[0];
    thread_local std::vector<double> bb;
    bb.assign(b.begin(), b.end());
    bb[0] = b[0] - gamma;
    bb[n - 1] = b[n - 1] - alpha * beta / gamma;
    thomas(a, bb, c, r);
    thread_local std::vector<double> z;
    z.assign(n, 0.0);
    z[0] = gamma, z[n - 1] = alpha;
    thomas(a, bb, c, z);
    const dvec3 fact = (r[0] + beta * r[n - 1] / gamma) / (1.0 + z[0] + beta * z[n - 1] / gamma);
    for (std::size_t i = 0; i < n; ++i) r[i] -= fact * z[i];
}

struct Chords {
    std::vector<dvec3> d;     // segment chords
    std::vector<double> len;  // their lengths (> merge epsilon)
    std::vector<dvec3> e;     // unit directions d / len (computed once; every kind that needs them reads these)
};

// Per-segment Hermite tangents (per unit of the segment parameter u): t0 at the start, t1 at the end.
struct Tangents {
    std::vector<dvec3> t0, t1;
};

// ---- automatic: the nu-spline under tension read from the nodes' turning pattern (DESIGN §4.1,
// modules/wire/DESIGN.md "Automatic spline").

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

/// Per-node tension weight g in [0, 1] from the turning pattern (see the constants above).
/// The result is per-thread storage, valid until the next call on the same thread.
const std::vector<double>& concentrated_turns(const Chords& ch, bool closed, std::vector<double>* straight = nullptr) {
    const std::size_t segs = ch.d.size();
    const std::size_t n = closed ? segs : segs + 1;
    thread_local std::vector<double> g;
    g.assign(n, 0.0);
    if (straight) straight->assign(n, 0.0);
    if (n < 3) return g;
    // Curvature vectors k_i = (e_out - e_in) / (mean of the two elements): |k| ~ 2 sin(phi/2) / h.
    thread_local std::vector<dvec3> k;
    k.assign(n, dvec3(0.0));
    auto interior = [&](std::size_t i) { return closed || (i > 0 && i + 1 < n); };
    // Index arithmetic without `%` (an integer division per use: it was most of this function's time).
    const auto seg_in = [segs](std::size_t i) { return i == 0 ? segs - 1 : i - 1; };
    const auto seg_out = [segs](std::size_t i) { return i == segs ? 0 : i; };
    for (std::size_t i = 0; i < n; ++i) {
        if (!interior(i)) continue;
        const std::size_t kin = seg_in(i), kout = seg_out(i);
        k[i] = (ch.e[kout] - ch.e[kin]) * (2.0 / (ch.len[kin] + ch.len[kout]));
    }
    // Node tangents (chord bisectors), to carry a neighbour's curvature vector to node i by the rotation that
    // takes its tangent to node i's (on a circle this maps one curvature vector exactly onto the next).
    thread_local std::vector<dvec3> t;
    t.assign(n, dvec3(0.0));
    for (std::size_t i = 0; i < n; ++i) {
        const bool in = closed || i > 0, out = closed || i + 1 < n;
        const dvec3 e_in = in ? ch.e[seg_in(i)] : dvec3(0.0);
        const dvec3 e_out = out ? ch.e[seg_out(i)] : dvec3(0.0);
        const dvec3 b = e_in + e_out;
        const double lb = glm::length(b);
        t[i] = lb > 1e-12 ? b * (1.0 / lb) : (out ? e_out : e_in);
    }
    if (!closed) k[0] = k[1], k[n - 1] = k[n - 2], t[0] = t[1], t[n - 1] = t[n - 2];  // constant extrapolation
    // Rodrigues rotation t[j] -> t[j+1] per edge j (axis sin, cos, 1 / (1 + cos)), once per edge: node j+1 carries
    // k[j] forwards with it, node j carries k[j+1] backwards with its inverse (axis negated, the same cosine).
    struct EdgeTurn {
        dvec3 axis;
        double c, q;
    };
    thread_local std::vector<EdgeTurn> edge;
    const std::size_t edges = closed ? n : n - 1;
    edge.resize(edges);
    for (std::size_t j = 0; j < edges; ++j) {
        const dvec3& ta = t[j];
        const dvec3& tb = t[j + 1 == n ? 0 : j + 1];
        const double c = glm::dot(ta, tb);
        edge[j] = EdgeTurn{glm::cross(ta, tb), c, c <= -1.0 + 1e-12 ? 0.0 : 1.0 / (1.0 + c)};
    }
    const auto carry = [&](const EdgeTurn& e, const dvec3& kv, double sense) {  // sense +1: forwards, -1: back
        if (e.c <= -1.0 + 1e-12) return -kv;  // reversal: any perpendicular axis; the sign is what matters
        return kv * e.c + sense * glm::cross(e.axis, kv) + e.axis * (glm::dot(e.axis, kv) * e.q);
    };
    for (std::size_t i = 0; i < n; ++i) {
        if (!interior(i)) continue;
        const std::size_t kin = seg_in(i), kout = seg_out(i);
        const double hin = ch.len[kin], hout = ch.len[kout];
        // What the neighbours predict at node i: their curvature vectors, carried to node i's tangent,
        // interpolated linearly in arc length.
        const dvec3 pred =
            (hout * carry(edge[i == 0 ? n - 1 : i - 1], k[i == 0 ? n - 1 : i - 1], 1.0) +
             hin * carry(edge[i], k[i + 1 == n ? 0 : i + 1], -1.0)) *
            (1.0 / (hin + hout));
        const double lk = glm::length(k[i]), lp = glm::length(pred), sum = lk + lp;
        if (!(sum > 0.0) || !std::isfinite(sum)) continue;  // straight here and around: nothing to decide
        // The neighbours predict this turn (d <= kSpreadLo: g = 0 and straight = 0, the common case), decided
        // on squares, without the root.
        const dvec3 miss = k[i] - pred;
        const double miss2 = glm::dot(miss, miss);
        if (miss2 <= (kSpreadLo * sum) * (kSpreadLo * sum)) continue;
        const double inv_sum = 1.0 / sum;
        const double d = std::sqrt(miss2) * inv_sum;
        // Turning below ~1e-6 rad is rounding noise of collinear nodes (and invisible): nothing to decide.
        const double turn = 0.5 * sum * (hin + hout);
        const double unshared = smoothstep(kSpreadLo, kSpreadHi, d) * smoothstep(1e-8, 1e-6, turn);
        const double share = lk * inv_sum;
        g[i] = unshared * smoothstep(kShareLo, kShareHi, share);
        if (straight) (*straight)[i] = unshared * (1.0 - smoothstep(kStraightLo, kStraightHi, share));
    }
    return g;
}

/// The nu-spline (Nielson 1974) with chordal knots: C1, and at node i the jump of the second derivative is
/// proportional to the tangent (tension). Rows as c2_tangents' with w_i added to the diagonal; open ends
/// not-a-knot, blending to free ends (zero curvature) as the neighbouring node gets tensed.
void automatic_tangents(const Chords& ch, bool closed, const std::vector<double>& g, const std::vector<double>& gs, Tangents& tg) {
    const std::size_t segs = ch.d.size();
    const std::size_t n = closed ? segs : segs + 1;
    // Working memory: per thread, reused (no allocation per call once large enough).
    const std::vector<dvec3>& s = ch.e;
    thread_local std::vector<double> w;
    w.resize(n);
    // Log-uniform in g; most nodes are untensed (g = 0: expm1(0) = 0 exactly, so the calls are skipped).
    static const double log_max = std::log1p(kMaxNodeTension), log_straight = std::log1p(kStraightTension);
    for (std::size_t i = 0; i < n; ++i) {
        const double wc = g[i] != 0.0 ? std::expm1(g[i] * log_max) : 0.0;
        const double ws = gs[i] != 0.0 ? std::expm1(gs[i] * log_straight) : 0.0;
        w[i] = wc + ws;
    }
    thread_local std::vector<dvec3> D;
    D.resize(n);
    if (closed) {
        thread_local std::vector<double> a, b, c;
        a.assign(n, 0.0), b.assign(n, 0.0), c.assign(n, 0.0);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t kin = i == 0 ? segs - 1 : i - 1, kout = i;
            const double hin = ch.len[kin], hout = ch.len[kout], sum = hin + hout;
            a[i] = hout / sum, c[i] = hin / sum, b[i] = 2.0 + w[i];
            D[i] = 3.0 * (a[i] * s[kin] + c[i] * s[kout]);
        }
        thomas_cyclic(a, b, c, D);
    } else if (n == 2) {
        D[0] = D[1] = s[0];
    } else {
        // End rows beta D0 + D1 = r: not-a-knot (beta = h1/(h0+h1)) blending to free (beta = 2, r = 3 s0).
        const double h0 = ch.len[0], h1 = ch.len[1], hL = ch.len[segs - 1], hP = ch.len[segs - 2];
        const dvec3 r0n = (s[0] * (h1 * (3.0 * h0 + 2.0 * h1)) + (h0 * h0) * s[1]) / ((h0 + h1) * (h0 + h1));
        const dvec3 rln = (s[segs - 1] * (hP * (3.0 * hL + 2.0 * hP)) + (hL * hL) * s[segs - 2]) / ((hP + hL) * (hP + hL));
        // The not-a-knot end makes the first (last) two segments one cubic, which overshoots when either
        // node it spans is tensed (its tangent nearly vanishes): then the end becomes free.
        const auto tensed = [&](std::size_t i) { return std::max(g[i], gs[i]); };
        const double g0 = std::max(tensed(1), n > 3 ? tensed(2) : 0.0), gl = std::max(tensed(n - 2), n > 3 ? tensed(n - 3) : 0.0);
        const double beta0 = (1.0 - g0) * h1 / (h0 + h1) + 2.0 * g0, betal = (1.0 - gl) * hP / (hP + hL) + 2.0 * gl;
        const dvec3 r0 = (1.0 - g0) * r0n + (3.0 * g0) * s[0], rl = (1.0 - gl) * rln + (3.0 * gl) * s[segs - 1];
        const std::size_t m = n - 2;
        thread_local std::vector<double> a, b, c;
        a.assign(m, 0.0), b.assign(m, 0.0), c.assign(m, 0.0);
        thread_local std::vector<dvec3> r;
        r.assign(m, dvec3(0.0));
        for (std::size_t j = 0; j < m; ++j) {
            const std::size_t i = j + 1;
            const double hin = ch.len[i - 1], hout = ch.len[i], sum = hin + hout;
            a[j] = hout / sum, c[j] = hin / sum, b[j] = 2.0 + w[i];
            r[j] = 3.0 * (a[j] * s[i - 1] + c[j] * s[i]);
        }
        if (m == 1) {
            // 3 nodes: not-a-knot at both ends is the interpolating parabola (one cubic through 3 points is
            // not determined: the elimination below would be singular); it blends with the tensed solution
            // with free ends as the middle node gets tensed.
            const double g1 = g[1];
            const dvec3 p0 = s[0] - h0 * (s[1] - s[0]) / (h0 + h1), p1 = (h1 * s[0] + h0 * s[1]) / (h0 + h1);
            const dvec3 p2 = s[1] + h1 * (s[1] - s[0]) / (h0 + h1);
            // Free ends: 2 D0 + D1 = 3 s0, 2 D2 + D1 = 3 s1, middle row a D0 + (2 + w) D1 + c D2 = r.
            const dvec3 t1 = (r[0] - 1.5 * (a[0] * s[0] + c[0] * s[1])) / (b[0] - 0.5 * (a[0] + c[0]));
            const dvec3 t0 = 0.5 * (3.0 * s[0] - t1), t2 = 0.5 * (3.0 * s[1] - t1);
            D[0] = (1.0 - g1) * p0 + g1 * t0;
            D[1] = (1.0 - g1) * p1 + g1 * t1;
            D[2] = (1.0 - g1) * p2 + g1 * t2;
        } else {
            // Eliminate D0 and D[n-1] (pivots stay >= 1: a/beta <= 1).
            r[0] -= (a[0] / beta0) * r0, b[0] -= a[0] / beta0, a[0] = 0.0;
            r[m - 1] -= (c[m - 1] / betal) * rl, b[m - 1] -= c[m - 1] / betal, c[m - 1] = 0.0;
            thomas(a, b, c, r);
            for (std::size_t j = 0; j < m; ++j) D[j + 1] = r[j];
            D[0] = (r0 - D[1]) / beta0;
            D[n - 1] = (rl - D[n - 2]) / betal;
        }
    }
    for (std::size_t k = 0; k < segs; ++k) {
        tg.t0[k] = D[k] * ch.len[k];
        tg.t1[k] = D[k + 1 == n ? 0 : k + 1] * ch.len[k];
    }
}

// C2 interpolating spline with chordal knots (not-a-knot ends; the parabola through 3 nodes): the automatic
// spline's solve with no node tensed (w = 0 everywhere, ends purely not-a-knot), so the two share one solver.
void c2_tangents(const Chords& ch, bool closed, Tangents& tg) {
    thread_local std::vector<double> untensed;
    untensed.assign(closed ? ch.d.size() : ch.d.size() + 1, 0.0);
    automatic_tangents(ch, closed, untensed, untensed, tg);
}

}  // namespace

double curvature_tension(double theta_rad, double iz_m4, double length_m, double delta_length_m, double area_m2) {
    const double den = area_m2 * delta_length_m * delta_length_m;
    if (!(den > 0.0) || !std::isfinite(den)) return 0.0;
    const double R = std::abs(theta_rad * iz_m4 * length_m) / den;
    if (!(R <= 100.0)) return 0.0;
    return 1.0 - std::tanh(R / 50.0);
}

// Empties `c` keeping its capacity: a Curve reused across frames does not allocate.
void clear_curve(Curve& c) {
    c.segments.clear(), c.source_node.clear(), c.radius_m.clear(), c.stretch.clear();
    c.closed = false;
}

Status build_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out) {
    clear_curve(out);
    if (Status st = check_settings(settings); !st) return st;
    if (Status st = check_sizes(nodes); !st) return st;
    const bool physics = settings.curvature_tension && !nodes.theta_rad.empty() && !nodes.iz_m4.empty() &&
                         !nodes.length_m.empty() && !nodes.delta_length_m.empty() && !nodes.area_m2.empty();
    if (Status st = check_nodes(nodes, physics); !st) return st;

    thread_local Merged m;  // working memory, reused: no allocation per call once it is large enough
    merge_nodes(nodes, settings, m);
    const std::size_t n = m.p.size();
    const bool closed = settings.closed;
    if (n < 2) {
        return Status::error("a wire needs at least 2 distinct nodes, got " + std::to_string(nodes.size()) +
                             " node(s) and " + std::to_string(n) + " after merging coincident ones");
    }
    if (closed && n < 3) {
        return Status::error("a closed loop needs at least 3 distinct nodes, got " + std::to_string(n) +
                             " after merging coincident ones");
    }
    const std::size_t segs = closed ? n : n - 1;

    thread_local Chords ch;
    ch.d.resize(segs), ch.len.resize(segs), ch.e.resize(segs);
    for (std::size_t k = 0; k < segs; ++k) {
        ch.d[k] = m.p[k + 1 == n ? 0 : k + 1] - m.p[k];  // differences of nearby doubles: exact, whatever the offset
        ch.len[k] = glm::length(ch.d[k]);
        ch.e[k] = ch.d[k] * (1.0 / ch.len[k]);
    }
    std::vector<float>& seg_stretch = out.stretch;  // built in place
    seg_stretch.assign(segs, 1.0f);
    if (!nodes.stretch.empty()) {
        for (std::size_t k = 0; k < segs; ++k) seg_stretch[k] = nodes.stretch[m.last[k]];
    }

    thread_local Tangents tg;
    tg.t0.resize(segs), tg.t1.resize(segs);
    const SplineKind kind = settings.kind;
    if (kind == SplineKind::linear) {
        for (std::size_t k = 0; k < segs; ++k) tg.t0[k] = tg.t1[k] = ch.d[k];
    } else if (kind == SplineKind::c2) {
        c2_tangents(ch, closed, tg);
    } else if (kind == SplineKind::automatic) {
        thread_local std::vector<double> gs;
        const std::vector<double>& g = concentrated_turns(ch, closed, &gs);
        automatic_tangents(ch, closed, g, gs, tg);
        // Tension (wire, node, curvature-driven) scales both tangents at a node, as for catmull_rom (G1 kept;
        // C2 only where it is 0).
        for (std::size_t j = 0; j < n; ++j) {
            const uint32_t src = m.first[j];
            const double t_user = nodes.kb_tension.empty() ? settings.tension : nodes.kb_tension[src];
            const double t_curv = physics ? curvature_tension(nodes.theta_rad[src], nodes.iz_m4[src], nodes.length_m[src],
                                                              nodes.delta_length_m[src], nodes.area_m2[src])
                                          : 0.0;
            const double keep = (1.0 - t_user) * (1.0 - t_curv);
            if (keep == 1.0) continue;
            if (closed || j + 1 < n) tg.t0[j == segs ? 0 : j] *= keep;
            if (closed || j > 0) tg.t1[j == 0 ? segs - 1 : j - 1] *= keep;
        }
    } else {
        const double alpha = settings.alpha;
        for (std::size_t j = 0; j < n; ++j) {
            const uint32_t src = m.first[j];
            const bool has_in = closed || j > 0, has_out = closed || j + 1 < n;
            const std::size_t kin = has_in ? (j == 0 ? segs - 1 : j - 1) : 0;
            const std::size_t kout = has_out ? (j == segs ? 0 : j) : segs - 1;
            // Open ends reflect the missing neighbour (P[-1] = 2P[0]-P[1]): the missing chord equals the other.
            const dvec3 din = has_in ? ch.d[kin] : ch.d[kout];
            const dvec3 dout = has_out ? ch.d[kout] : ch.d[kin];
            const double lin = has_in ? ch.len[kin] : ch.len[kout];
            const double lout = has_out ? ch.len[kout] : ch.len[kin];

            const double t_user = nodes.kb_tension.empty() ? settings.tension : nodes.kb_tension[src];
            const double b = nodes.kb_bias.empty() ? settings.bias : nodes.kb_bias[src];
            const double c = nodes.kb_continuity.empty() ? settings.continuity : nodes.kb_continuity[src];
            double t_curv = 0.0;
            if (physics) {
                t_curv = curvature_tension(nodes.theta_rad[src], nodes.iz_m4[src], nodes.length_m[src],
                                           nodes.delta_length_m[src], nodes.area_m2[src]);
            }
            const double t = 1.0 - (1.0 - t_user) * (1.0 - t_curv);
            const double keep = 1.0 - t;

            // Only the knot ratio matters; computed in the log domain so extreme alpha or spacing cannot give 0/0.
            // alpha 1 and 0.5 (chordal, centripetal): the ratio itself and its square root, no log/exp; the
            // same clamp as the log domain's (both lengths are > 0 and finite, so the ratio is never 0/0).
            double rho;
            if (alpha == 1.0 || alpha == 0.5) {
                rho = lout / lin;
                if (alpha == 0.5) rho = std::sqrt(rho);
                rho = std::clamp(rho, kMinKnotRatio, kMaxKnotRatio);
            } else {
                const double lr = alpha == 0.0 ? 0.0 : std::clamp(alpha * (std::log(lout) - std::log(lin)), -300.0, 300.0);
                rho = std::exp(lr);
            }
            const double w = rho / (1.0 + rho), iw = 1.0 / (1.0 + rho);  // w + iw = 1
            const dvec3 start = keep * (((1.0 + b) * (1.0 + c) * rho * w) * din + ((1.0 - b) * (1.0 - c) * iw) * dout);
            const dvec3 end = keep * (((1.0 + b) * (1.0 - c) * w) * din + ((1.0 - b) * (1.0 + c) * iw / rho) * dout);
            if (has_out) tg.t0[kout] = start;
            if (has_in) tg.t1[kin] = end;
        }
    }

    out.closed = closed;
    out.segments.reserve(segs);  // appended, not resized: no zero-fill of what is written next
    for (std::size_t k = 0; k < segs; ++k) {
        const dvec3& p0 = m.p[k];
        const dvec3& p1 = m.p[k + 1 == n ? 0 : k + 1];
        const CubicBezier& bz =
            out.segments.emplace_back(CubicBezier{p0, p0 + tg.t0[k] * (1.0 / 3.0), p1 - tg.t1[k] * (1.0 / 3.0), p1});
        // Finite is not enough: a control point past the coordinate range (an extreme alpha) overflows the
        // tube's float vertices downstream.
        constexpr double kMaxControl_m = 10.0 * kMaxCoordinate_m;
        const auto in_range = [](const dvec3& b) {
            return std::abs(b.x) <= kMaxControl_m && std::abs(b.y) <= kMaxControl_m && std::abs(b.z) <= kMaxControl_m;
        };
        const bool finite = in_range(bz.b1) && in_range(bz.b2);  // false for NaN too
        if (!finite) {
            const uint32_t src = m.first[k];
            clear_curve(out);
            return Status::error(node_prefix(src) + "tangent overflowed (alpha " + describe(settings.alpha) +
                                     " is too extreme for this node spacing)", static_cast<int>(src));
        }
    }
    out.source_node = m.first;
    out.radius_m.resize(n);
    const float wire_radius = settings.radius_m > 0.0f ? settings.radius_m : 0.01f;
    for (std::size_t j = 0; j < n; ++j) {
        const float r = nodes.radius_m.empty() ? 0.0f : nodes.radius_m[m.first[j]];
        out.radius_m[j] = r > 0.0f ? r : wire_radius;
    }
    return Status::success();
}

}  // namespace wire
