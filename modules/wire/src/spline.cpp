// The curve stage: validation, coincident-node merging, analytic Hermite tangents per spline kind, Bezier form.
#include "wire/spline.hpp"

#include "wire/detail/segment_soa.hpp"  // WIRE_VECTOR_CLONES

#include <glm/geometric.hpp>

#include <algorithm>
#include <cassert>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <span>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(WIRE_HAS_VECTOR_CLONES)
#include <immintrin.h>  // node_segments_avx512
#endif

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
    // The common case in one branch-free test (every array empty or one per node); the messages below.
    const auto fits = [n](std::size_t size) { return (size == 0) | (size == n); };
    if (fits(w.ids.size()) & fits(w.stretch.size()) & fits(w.radius_m.size()) & fits(w.theta_rad.size()) &
        fits(w.iz_m4.size()) & fits(w.length_m.size()) & fits(w.delta_length_m.size()) & fits(w.area_m2.size()) &
        fits(w.kb_tension.size()) & fits(w.kb_bias.size()) & fits(w.kb_continuity.size())) {
        return Status::success();
    }
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

// Kernels: the vectorized loops, one function each, so that `__restrict` on their parameters tells the compiler
// the arrays do not overlap (it does not trust that of local pointers into one buffer). Kernels with selects are
// compiled without trapping math: GCC turns their `?:` into vector blends only then. That changes no value (every
// operation is still performed and rounded as written; NaN comparisons keep their meaning), only whether an
// operation whose result is discarded may raise a floating-point exception flag, which nothing here reads
// (WIRE_SELECT_KERNEL, wire/detail/segment_soa.hpp).
// Each kernel is also compiled for AVX-512 and AVX2 machines, picked at load time (WIRE_VECTOR_CLONES: 8 and 4
// lanes where baseline x86-64 has 2; 1.44 -> 1.12 ms for the stage on 1,000 moving 64-node wires); every clone's
// results are bit-identical to the baseline's (see the macro).

// all_within has a second version for AVX2 machines, chosen at load time like the kernels' clones (the compiler
// does not vectorize this reduction, and GCC's vector types split slowly on the SSE2 baseline); the same condition
// as WIRE_VECTOR_CLONES'.
#if defined(WIRE_HAS_VECTOR_CLONES)
#define WIRE_RANGE_VERSIONS 1
#define WIRE_RANGE_DEFAULT __attribute__((target("default")))
#else
#define WIRE_RANGE_DEFAULT
#endif

// True when |v[i]| <= limit for every i < count (false for NaN and Inf): an AND of vector comparisons, no branch
// per value.
WIRE_RANGE_DEFAULT
bool all_within(const double* v, std::size_t count, double limit) {
    std::size_t i = 0;
    bool all = true;
#if defined(__SSE2__)
    const __m128d lim = _mm_set1_pd(limit), sign = _mm_set1_pd(-0.0);
    __m128d ok = _mm_cmpeq_pd(lim, lim);  // all ones (limit is a number)
    for (; i + 2 <= count; i += 2) ok = _mm_and_pd(ok, _mm_cmple_pd(_mm_andnot_pd(sign, _mm_loadu_pd(v + i)), lim));
    all = _mm_movemask_pd(ok) == 3;
#endif
    for (; i < count; ++i) all &= std::abs(v[i]) <= limit;
    return all;
}

#if defined(WIRE_RANGE_VERSIONS)
__attribute__((target("avx2"))) bool all_within(const double* v, std::size_t count, double limit) {
    using v4d = double __attribute__((vector_size(32)));
    using v4i = long long __attribute__((vector_size(32)));
    const v4d hi = {limit, limit, limit, limit};
    const v4i magnitude = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};  // clears the sign bit: |x|
    v4i ok0 = {-1, -1, -1, -1}, ok1 = ok0;
    std::size_t i = 0;
    for (; i + 8 <= count; i += 8) {  // two independent chains
        v4i x0, x1;
        std::memcpy(&x0, v + i, sizeof x0);
        std::memcpy(&x1, v + i + 4, sizeof x1);
        ok0 &= reinterpret_cast<v4d>(x0 & magnitude) <= hi;
        ok1 &= reinterpret_cast<v4d>(x1 & magnitude) <= hi;
    }
    for (; i + 4 <= count; i += 4) {
        v4i x;
        std::memcpy(&x, v + i, sizeof x);
        ok0 &= reinterpret_cast<v4d>(x & magnitude) <= hi;
    }
    ok0 &= ok1;
    bool all = (ok0[0] & ok0[1] & ok0[2] & ok0[3]) != 0;
    for (; i < count; ++i) all &= std::abs(v[i]) <= limit;
    return all;
}

#endif

// True when v[i] > limit for every i < count (false for NaN).
bool all_above(const double* v, std::size_t count, double limit) {
    std::size_t i = 0;
    bool all = true;
#if defined(__SSE2__)
    const __m128d lim = _mm_set1_pd(limit);
    __m128d ok = _mm_cmpeq_pd(lim, lim);  // all ones (limit is a number)
    for (; i + 2 <= count; i += 2) ok = _mm_and_pd(ok, _mm_cmpgt_pd(_mm_loadu_pd(v + i), lim));
    all = _mm_movemask_pd(ok) == 3;
#endif
    for (; i < count; ++i) all &= v[i] > limit;
    return all;
}

Status check_nodes(const WireNodes& w, bool use_physics) {
    static const char* const kAxis[3] = {"x", "y", "z"};
    // Positions in one branch-free pass: every coordinate finite and in range (NaN and Inf fail the comparison).
    // When they pass, the per-node checks below skip them; a bad one is found there, with its message.
    static_assert(sizeof(glm::dvec3) == 3 * sizeof(double), "positions: 3 contiguous doubles a node");
    const bool positions_ok =
        !w.positions.empty() && all_within(&w.positions[0].x, 3 * w.positions.size(), kMaxCoordinate_m);
    if (positions_ok && w.stretch.empty() && w.radius_m.empty() && w.kb_tension.empty() && w.kb_bias.empty() &&
        w.kb_continuity.empty() && !use_physics) {
        return Status::success();
    }
    for (std::size_t i = 0; i < w.positions.size(); ++i) {
        for (int a = 0; a < 3 && !positions_ok; ++a) {
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

// The curve stage's per-node and per-segment passes work on structure-of-arrays scratch (x, y, z arrays, per
// thread, reused across calls) with branch-free bodies, so the compiler vectorizes them across nodes; the rare
// special nodes (a merge, a tensed node, a bad value) are flagged and handled by a scalar pass. Every value is
// computed by the same operations in the same order as the scalar form (vectorizing across independent nodes
// changes no rounding), so the output is bit-identical to it.

// Per-thread pool of double arrays: carve(k) hands out the next k doubles (valid until the next reset).
struct Pool {
    std::vector<double> buf;
    std::size_t used = 0;
    void reset(std::size_t total) {
        if (buf.size() < total) buf.resize(total);
        used = 0;
    }
    double* carve(std::size_t k) {
        assert(used + k <= buf.size() && "Pool::carve: more than reset() asked for");
        double* p = buf.data() + used;
        used += k;
        return p;
    }
};

// Merged nodes: the first input node of each group is kept; `last` is the group's last input node, whose
// element is the one that leaves the group (its stretch belongs to the outgoing segment).
struct Merged {
    std::vector<dvec3> p;
    std::vector<uint32_t> first, last;
    bool identity = false;  // first and last hold 0 .. size-1 (nothing merged): kept for the next wire of that size
};

// Segment chords, structure of arrays. Segment k is at index k + 1; index 0 repeats the last segment and index
// segs + 1 the first (wrap-around ghosts, so per-node passes read a node's incoming chord at i and outgoing at
// i + 1 without index arithmetic; on open wires the ghosts only feed end values that are overwritten).
struct Chords {
    std::vector<double> dx, dy, dz;  // chords
    std::vector<double> len;         // their lengths (> merge epsilon)
    std::vector<double> ex, ey, ez;  // unit directions d / len (computed once; every kind that needs them reads these)
    std::size_t segs = 0;
    dvec3 d(std::size_t k) const { return {dx[k + 1], dy[k + 1], dz[k + 1]}; }
    dvec3 e(std::size_t k) const { return {ex[k + 1], ey[k + 1], ez[k + 1]}; }
    double l(std::size_t k) const { return len[k + 1]; }
};

// Runs an element-wise kernel (element i's outputs from its own inputs only; outputs not read) on [0, count) in
// whole blocks of 8, the AVX-512 clone's vector: run(0, count rounded down to 8), then run(count - 8, 8), which
// rewrites up to 7 elements with the same values. A vector loop over the whole count would end in a 4-wide step
// and up to 3 scalar ones (a quarter of spread_kernel's time on 62 nodes); the second call is one 8-wide step.
template <class Run>
void in_whole_blocks(std::size_t count, Run&& run) {
    constexpr std::size_t kBlock = 8;
    const std::size_t head = count & ~(kBlock - 1);
    if (count < kBlock || head == count) return run(0, count);
    run(0, head);
    run(count - kBlock, kBlock);
}

// Chords k = 0 .. count-1 from node coordinates a (3 per node, node k at 3k) to b (node k + 1's at 3k).
WIRE_VECTOR_CLONES
void chords_kernel(std::size_t count, const double* __restrict a, const double* __restrict b, double* __restrict dx,
                   double* __restrict dy, double* __restrict dz, double* __restrict len, double* __restrict ex,
                   double* __restrict ey, double* __restrict ez) {
    for (std::size_t k = 0; k < count; ++k) {
        // Differences of nearby doubles: exact, whatever the offset. Length as glm::length: (x*x + y*y) + z*z.
        const double x = b[3 * k] - a[3 * k], y = b[3 * k + 1] - a[3 * k + 1], z = b[3 * k + 2] - a[3 * k + 2];
        const double l = std::sqrt(x * x + y * y + z * z);
        const double inv = 1.0 / l;
        dx[k] = x, dy[k] = y, dz[k] = z, len[k] = l;
        ex[k] = x * inv, ey[k] = y * inv, ez[k] = z * inv;
    }
}

// Chords of the nodes P[0..n) (n >= 2; closed: the closing chord P[0] - P[n-1] too), lengths and unit directions.
void fill_chords(const dvec3* P, std::size_t n, bool closed, Chords& ch) {
    const std::size_t segs = closed ? n : n - 1;
    ch.segs = segs;
    for (std::vector<double>* v : {&ch.dx, &ch.dy, &ch.dz, &ch.len, &ch.ex, &ch.ey, &ch.ez}) v->resize(segs + 2);
    const auto chords = [&](std::size_t k0, std::size_t count, const dvec3* a, const dvec3* b) {
        chords_kernel(count, &a->x, &b->x, ch.dx.data() + 1 + k0, ch.dy.data() + 1 + k0, ch.dz.data() + 1 + k0,
                      ch.len.data() + 1 + k0, ch.ex.data() + 1 + k0, ch.ey.data() + 1 + k0, ch.ez.data() + 1 + k0);
    };
    in_whole_blocks(n - 1, [&](std::size_t k0, std::size_t count) { chords(k0, count, P + k0, P + k0 + 1); });
    if (closed) chords(n - 1, 1, P + (n - 1), P);
    for (std::vector<double>* v : {&ch.dx, &ch.dy, &ch.dz, &ch.len, &ch.ex, &ch.ey, &ch.ez}) {
        (*v)[0] = (*v)[segs];
        (*v)[segs + 1] = (*v)[1];
    }
}

// Bounding box of n nodes (3 finite coordinates each, node i's at 3i) into lo and hi (3 each, HUGE_VAL and
// -HUGE_VAL on entry). Minima and maxima are exact in any order (only the sign of a zero could depend on it, and
// the merge reads the box only through lengths), so two nodes at a time.
WIRE_VECTOR_CLONES
void bbox_kernel(const double* p, std::size_t n, double* lo, double* hi) {
    std::size_t i = 0;
#if defined(__GNUC__)
    using v2d = double __attribute__((vector_size(16)));  // native on the SSE2 baseline too
    if (n >= 2) {
        // 6 doubles (2 nodes) a step: x y | z x | y z.
        v2d l[3], h[3];
        for (int a = 0; a < 3; ++a) std::memcpy(&l[a], p + 2 * a, sizeof(v2d)), h[a] = l[a];
        for (i = 2; i + 2 <= n; i += 2) {
            for (int a = 0; a < 3; ++a) {
                v2d x;
                std::memcpy(&x, p + 3 * i + 2 * a, sizeof x);
                l[a] = x < l[a] ? x : l[a];
                h[a] = x > h[a] ? x : h[a];
            }
        }
        for (int a = 0; a < 3; ++a) {
            for (int lane = 0; lane < 2; ++lane) {
                const int axis = (2 * a + lane) % 3;
                lo[axis] = std::min(lo[axis], l[a][lane]);
                hi[axis] = std::max(hi[axis], h[a][lane]);
            }
        }
    }
#endif
    for (; i < n; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            lo[axis] = std::min(lo[axis], p[3 * i + axis]);
            hi[axis] = std::max(hi[axis], p[3 * i + axis]);
        }
    }
}

// Coincident-node merging. Returns the curve's nodes: the input positions themselves when nothing merges (the
// common case: decided from the input's chords, which are then the curve's), else m.p. `ch` holds the chords of
// the returned nodes when there are at least 2 of them (3 closed).
const dvec3* merge_nodes(const WireNodes& w, const SplineSettings& s, Merged& m, Chords& ch, std::size_t& count) {
    const std::size_t n = w.positions.size();
    dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
    bbox_kernel(n ? &w.positions[0].x : nullptr, n, &lo.x, &hi.x);
    const double diag = n ? glm::length(hi - lo) : 0.0;
    const double max_abs = n ? std::max(glm::length(lo), glm::length(hi)) : 0.0;
    const double rel = s.merge_epsilon_rel > 0.0 ? s.merge_epsilon_rel : 1e-9;
    const double eps = std::max(rel * diag, 64.0 * DBL_EPSILON * max_abs);
    if (n >= 3) {
        // The chords of consecutive input nodes are the distances the merge tests (the closing one too: the
        // length of a negated difference is the same number); nothing merges when all exceed eps.
        fill_chords(w.positions.data(), n, s.closed, ch);
        if (all_above(ch.len.data() + 1, ch.segs, eps)) {
            // Already the identity of n nodes in the common case (the thread's build memory, reused by the
            // thread's wires, most of one size and merging nothing): not rewritten per wire then.
            if (!m.identity || m.first.size() != n) {
                m.first.resize(n), m.last.resize(n);
                for (std::size_t i = 0; i < n; ++i) m.first[i] = m.last[i] = static_cast<uint32_t>(i);
                m.identity = true;
            }
            count = n;
            return w.positions.data();
        }
    }
    m.p.clear(), m.first.clear(), m.last.clear();
    m.identity = false;
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
    count = m.p.size();
    if (count >= (s.closed ? 3u : 2u)) fill_chords(m.p.data(), count, s.closed, ch);
    return m.p.data();
}

// Tridiagonal solve (sub a, diagonal b, super c) of n rows for C right-hand sides r[0..C) (structure of arrays;
// each component gets exactly the operations the vector form gave it); callers pass diagonally dominant rows.
// Twisted ("burn at both ends") elimination: rows are eliminated from the top and from the bottom at once, meeting
// in the middle row, so the two serial chains of one division each per row run side by side (half the latency of
// Thomas' one chain). The chains' values are carried in registers (a store through r may not alias f or the
// other components, so nothing is reloaded on the critical path).
template <int C>
void thomas_kernel(const double* __restrict a, const double* __restrict b, const double* __restrict c, std::size_t n,
                   double* __restrict f, double* __restrict rx, double* __restrict ry, double* __restrict rz) {
    // One row step for every component: r[i] = (r[i] - m * prev) * inv, prev = r[i].
    const auto step = [&](std::size_t i, double m, double inv, double& px, double& py, double& pz) {
        px = (rx[i] - m * px) * inv, rx[i] = px;
        if constexpr (C == 3) {
            py = (ry[i] - m * py) * inv, ry[i] = py;
            pz = (rz[i] - m * pz) * inv, rz[i] = pz;
        }
    };
    const auto first = [&](std::size_t i, double inv, double& px, double& py, double& pz) {  // r[i] * inv
        px = rx[i] * inv, rx[i] = px;
        if constexpr (C == 3) {
            py = ry[i] * inv, ry[i] = py;
            pz = rz[i] * inv, rz[i] = pz;
        }
    };
    const auto back = [&](std::size_t i, double& px, double& py, double& pz) {
        px = rx[i] - f[i] * px, rx[i] = px;
        if constexpr (C == 3) {
            py = ry[i] - f[i] * py, ry[i] = py;
            pz = rz[i] - f[i] * pz, rz[i] = pz;
        }
    };
    double tx = 0.0, ty = 0.0, tz = 0.0;  // the top chain's last row
    double inv = 1.0 / b[0];
    double ft = c[0] * inv;
    f[0] = ft;
    first(0, inv, tx, ty, tz);
    if (n < 4) {  // plain Thomas
        for (std::size_t i = 1; i < n; ++i) {
            inv = 1.0 / (b[i] - a[i] * ft);
            ft = c[i] * inv;
            f[i] = ft;
            step(i, a[i], inv, tx, ty, tz);
        }
        for (std::size_t i = n - 1; i-- > 0;) back(i, tx, ty, tz);
        return;
    }
    const std::size_t p = n / 2;  // the meeting row; top rows 0..p-1, bottom rows p+1..n-1
    double bx = 0.0, by = 0.0, bz = 0.0;  // the bottom chain's last row
    inv = 1.0 / b[n - 1];
    double fb = a[n - 1] * inv;
    f[n - 1] = fb;
    first(n - 1, inv, bx, by, bz);
    const auto top = [&](std::size_t i) {
        const double it = 1.0 / (b[i] - a[i] * ft);
        ft = c[i] * it;
        f[i] = ft;
        step(i, a[i], it, tx, ty, tz);
    };
    const auto bottom = [&](std::size_t j) {
        const double ib = 1.0 / (b[j] - c[j] * fb);
        fb = a[j] * ib;
        f[j] = fb;
        step(j, c[j], ib, bx, by, bz);
    };
    std::size_t i = 1, j = n - 2;
    for (; i < p && j > p; ++i, --j) top(i), bottom(j);
    for (; i < p; ++i) top(i);
    for (; j > p; --j) bottom(j);
    // Row p with x[p-1] = r[p-1] - f[p-1] x[p] and x[p+1] = r[p+1] - f[p+1] x[p] substituted.
    inv = 1.0 / (b[p] - a[p] * ft - c[p] * fb);
    tx = (rx[p] - a[p] * tx - c[p] * bx) * inv, rx[p] = tx, bx = tx;
    if constexpr (C == 3) {
        ty = (ry[p] - a[p] * ty - c[p] * by) * inv, ry[p] = ty, by = ty;
        tz = (rz[p] - a[p] * tz - c[p] * bz) * inv, rz[p] = tz, bz = tz;
    }
    for (i = p, j = p; i > 0 && j + 1 < n;) {
        --i, ++j;
        back(i, tx, ty, tz);
        back(j, bx, by, bz);
    }
    while (i > 0) --i, back(i, tx, ty, tz);
    while (j + 1 < n) ++j, back(j, bx, by, bz);
}

template <int C>
void thomas(const double* a, const double* b, const double* c, std::size_t n, double* const* r) {
    thread_local std::vector<double> fv;  // top half: c'/pivot; bottom half: a'/pivot (reused, no allocation)
    fv.resize(n);
    thomas_kernel<C>(a, b, c, n, fv.data(), r[0], C == 3 ? r[1] : nullptr, C == 3 ? r[2] : nullptr);
}

// Cyclic tridiagonal (corners a[0] at column n-1 and c[n-1] at column 0) by Sherman-Morrison, n >= 3.
void thomas_cyclic(const double* a, const double* b, const double* c, std::size_t n, double* const* r) {
    const double alpha = c[n - 1], beta = a[0], gamma = -b[0];
    thread_local std::vector<double> bb;
    bb.assign(b, b + n);
    bb[0] = b[0] - gamma;
    bb[n - 1] = b[n - 1] - alpha * beta / gamma;
    thomas<3>(a, bb.data(), c, n, r);
    thread_local std::vector<double> z;
    z.assign(n, 0.0);
    z[0] = gamma, z[n - 1] = alpha;
    double* const zr[1] = {z.data()};
    thomas<1>(a, bb.data(), c, n, zr);
    const double den = 1.0 + z[0] + beta * z[n - 1] / gamma;
    for (int q = 0; q < 3; ++q) {
        const double fact = (r[q][0] + beta * r[q][n - 1] / gamma) / den;
        for (std::size_t i = 0; i < n; ++i) r[q][i] = r[q][i] - fact * z[i];
    }
}

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

// n zeros (per thread; grown when needed, never written): the weights of a wire with no tensed node.
const double* zeros(std::size_t n) {
    thread_local std::vector<double> z;
    if (z.size() < n) z.resize(n);
    return z.data();
}

// Interior rows of the tangent system (node j: incoming chord at index j, outgoing at j + 1; diagonal 2 + w_j).
WIRE_VECTOR_CLONES
void rows_kernel(std::size_t rows, const double* __restrict w, const double* __restrict ex, const double* __restrict ey,
                 const double* __restrict ez, const double* __restrict len, double* __restrict a, double* __restrict b,
                 double* __restrict c, double* __restrict rx, double* __restrict ry, double* __restrict rz) {
    for (std::size_t j = 0; j < rows; ++j) {
        const double hin = len[j], hout = len[j + 1], sum = hin + hout;
        const double aj = hout / sum, cj = hin / sum;
        a[j] = aj, c[j] = cj, b[j] = 2.0 + w[j];
        rx[j] = 3.0 * (aj * ex[j] + cj * ex[j + 1]);
        ry[j] = 3.0 * (aj * ey[j] + cj * ey[j + 1]);
        rz[j] = 3.0 * (aj * ez[j] + cj * ez[j + 1]);
    }
}

// Segment tangents from node tangents per unit chord (D: node k's at k, k + 1's at k + 1) and chord lengths.
WIRE_VECTOR_CLONES
void tangents_kernel(std::size_t segs, const double* __restrict D, const double* __restrict len, double* __restrict t0,
                     double* __restrict t1) {
    for (std::size_t k = 0; k < segs; ++k) {
        t0[k] = D[k] * len[k];
        t1[k] = D[k + 1] * len[k];
    }
}

// Writes one Bezier record at o (start point a, inner control points c0..c5, end point b) and returns whether
// every inner control point is within +-limit (false for NaN), tested on the values in the registers (a pass over
// the records just written would wait for the stores). Always inlined: GCC inlines nothing else into a kernel
// compiled with its own options (WIRE_SELECT_KERNEL); __builtin_fabs for the same reason (not std::abs).
[[gnu::always_inline]] inline bool within6(double c0, double c1, double c2, double c3, double c4, double c5,
                                           double limit) {
    return (__builtin_fabs(c0) <= limit) & (__builtin_fabs(c1) <= limit) & (__builtin_fabs(c2) <= limit) &
           (__builtin_fabs(c3) <= limit) & (__builtin_fabs(c4) <= limit) & (__builtin_fabs(c5) <= limit);
}
[[gnu::always_inline]] inline bool write_record(double* __restrict o, double ax, double ay, double az, double c0,
                                                double c1, double c2, double c3, double c4, double c5, double bx,
                                                double by, double bz, double limit) {
    o[0] = ax, o[1] = ay, o[2] = az, o[3] = c0, o[4] = c1, o[5] = c2;
    o[6] = c3, o[7] = c4, o[8] = c5, o[9] = bx, o[10] = by, o[11] = bz;
    return within6(c0, c1, c2, c3, c4, c5, limit);
}

// Bezier segments k = 0 .. count-1 (12 doubles each, out at 12k) from node coordinates p0 (3 per node, segment
// k's start at 3k), p1 (its end at 3k) and the segment tangents: inner control points B1 = P0 + t0/3 and
// B2 = P1 - t1/3, written straight into the records (one pass: the control points are not stored apart first).
// Returns whether every inner control point is within +-limit (write_record's test).
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL
bool segments_kernel(std::size_t count, const double* __restrict p0, const double* __restrict p1,
                     const double* __restrict t0x, const double* __restrict t0y, const double* __restrict t0z,
                     const double* __restrict t1x, const double* __restrict t1y, const double* __restrict t1z,
                     double* __restrict out, double limit) {
    double ok = 1.0;  // 0 once a value is out of range (a select, which vectorizes where a bool reduction does not)
    for (std::size_t k = 0; k < count; ++k) {
        double* o = out + 12 * k;
        const double ax = p0[3 * k], ay = p0[3 * k + 1], az = p0[3 * k + 2];
        const double bx = p1[3 * k], by = p1[3 * k + 1], bz = p1[3 * k + 2];
        const double c0 = ax + t0x[k] * (1.0 / 3.0), c1 = ay + t0y[k] * (1.0 / 3.0), c2 = az + t0z[k] * (1.0 / 3.0);
        const double c3 = bx - t1x[k] * (1.0 / 3.0), c4 = by - t1y[k] * (1.0 / 3.0), c5 = bz - t1z[k] * (1.0 / 3.0);
        ok = write_record(o, ax, ay, az, c0, c1, c2, c3, c4, c5, bx, by, bz, limit) ? ok : 0.0;
    }
    return ok == 1.0;
}

// The same records from node tangents per unit chord (D: segment k's start node at k, its end node at k + 1) and
// the chord lengths: t0 = D[k] len[k], t1 = D[k + 1] len[k] (tangents_kernel's values) taken straight into the
// control points, with no pass through segment tangents (the spline kinds whose tangents are a node's).
// Returns whether every offset t/3 of a control point from its end point is within +-offset_limit (false for NaN),
// a sufficient test for the control points' range that the caller derives from the positions' (checked on entry).
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL
bool node_segments_kernel(std::size_t count, const double* __restrict p0, const double* __restrict p1,
                          const double* __restrict Dx, const double* __restrict Dy, const double* __restrict Dz,
                          const double* __restrict len, double* __restrict out, double offset_limit) {
    double ok = 1.0;
    for (std::size_t k = 0; k < count; ++k) {
        double* o = out + 12 * k;
        const double ax = p0[3 * k], ay = p0[3 * k + 1], az = p0[3 * k + 2];
        const double bx = p1[3 * k], by = p1[3 * k + 1], bz = p1[3 * k + 2];
        const double h = len[k];
        const double u0 = (Dx[k] * h) * (1.0 / 3.0), u1 = (Dy[k] * h) * (1.0 / 3.0), u2 = (Dz[k] * h) * (1.0 / 3.0);
        const double u3 = (Dx[k + 1] * h) * (1.0 / 3.0), u4 = (Dy[k + 1] * h) * (1.0 / 3.0);
        const double u5 = (Dz[k + 1] * h) * (1.0 / 3.0);
        o[0] = ax, o[1] = ay, o[2] = az, o[3] = ax + u0, o[4] = ay + u1, o[5] = az + u2;
        o[6] = bx - u3, o[7] = by - u4, o[8] = bz - u5, o[9] = bx, o[10] = by, o[11] = bz;
        ok = within6(u0, u1, u2, u3, u4, u5, offset_limit) ? ok : 0.0;
    }
    return ok == 1.0;
}

#if defined(WIRE_HAS_VECTOR_CLONES)
// node_segments_kernel by hand for AVX-512 machines (count >= 8). The compiler's version of that loop scatters
// each 96-byte record with ~12 partial stores and as many shuffles. Here eight segments' offsets u = (D h) / 3
// are computed as the loop computes them and range-tested there, transposed once (8x8: one segment's per row),
// and each record is two stores, [a, a + u0, b.x - u1.x, b.y - u1.y] and [b.z - u1.z, b], by masked additions
// and subtractions of the row: the same operations on the same values as the loop (no fused multiply-add), so
// the records and the test are the loop's, bit for bit. The last block of eight overlaps the one before when
// count is not a multiple of 8 (those records are written twice, with the same values).
#pragma GCC diagnostic push
// GCC 12 warns about the intrinsics' own _mm512_undefined_pd() pass-through operands (a known false positive).
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
__attribute__((target("avx512f"))) bool node_segments_avx512(std::size_t count, const double* __restrict p0,
                                                             const double* __restrict p1, const double* __restrict Dx,
                                                             const double* __restrict Dy, const double* __restrict Dz,
                                                             const double* __restrict len, double* __restrict out,
                                                             double offset_limit) {
    const __m512d third = _mm512_set1_pd(1.0 / 3.0), lim = _mm512_set1_pd(offset_limit), zero = _mm512_setzero_pd();
    const __m512i low_index = _mm512_setr_epi64(0, 1, 2, 0, 1, 2, 8, 9);   // [a a b.x b.y] from a | b
    const __m512i high_index = _mm512_setr_epi64(2, 0, 1, 2, 2, 2, 2, 2);  // [b.z b ...] from b
    __mmask16 bad = 0;  // lanes of an offset not within +-offset_limit (or NaN)
    for (std::size_t k0 = 0;; k0 += 8) {
        const std::size_t k = std::min(k0, count - 8);
        const __m512d h = _mm512_loadu_pd(len + k);
#define WIRE_OFFSET(D) _mm512_mul_pd(_mm512_mul_pd(_mm512_loadu_pd(D), h), third)  // (D h) / 3, as the loop
        // Row s of the transpose, segment k + s's offsets: [u1.z, 0, 0, u0.x, u0.y, u0.z, u1.x, u1.y], each in
        // the lane of the record's first 8 doubles (u1.z: of its last 4) that it is added to or taken from.
        const __m512d v[8] = {WIRE_OFFSET(Dz + k + 1), zero, zero, WIRE_OFFSET(Dx + k), WIRE_OFFSET(Dy + k),
                              WIRE_OFFSET(Dz + k), WIRE_OFFSET(Dx + k + 1), WIRE_OFFSET(Dy + k + 1)};
#undef WIRE_OFFSET
        for (int q : {0, 3, 4, 5, 6, 7}) {
            bad = _mm512_kor(bad, _mm512_cmp_pd_mask(_mm512_abs_pd(v[q]), lim, _CMP_NLE_UQ));
        }
        __m512d t[8], w[8], row[8];
        for (int q = 0; q < 8; q += 2) t[q] = _mm512_unpacklo_pd(v[q], v[q + 1]), t[q + 1] = _mm512_unpackhi_pd(v[q], v[q + 1]);
        for (int q = 0; q < 8; q += 4) {
            w[q] = _mm512_shuffle_f64x2(t[q], t[q + 2], 0x88), w[q + 1] = _mm512_shuffle_f64x2(t[q + 1], t[q + 3], 0x88);
            w[q + 2] = _mm512_shuffle_f64x2(t[q], t[q + 2], 0xDD), w[q + 3] = _mm512_shuffle_f64x2(t[q + 1], t[q + 3], 0xDD);
        }
        for (int q = 0; q < 4; ++q) row[q] = _mm512_shuffle_f64x2(w[q], w[q + 4], 0x88), row[q + 4] = _mm512_shuffle_f64x2(w[q], w[q + 4], 0xDD);
        for (std::size_t s = 0; s < 8; ++s) {
            const std::size_t j = k + s;
            const __m512d a = _mm512_maskz_loadu_pd(0x07, p0 + 3 * j), b = _mm512_maskz_loadu_pd(0x07, p1 + 3 * j);
            __m512d lo = _mm512_permutex2var_pd(a, low_index, b);
            lo = _mm512_mask_add_pd(lo, 0x38, lo, row[s]);
            lo = _mm512_mask_sub_pd(lo, 0xC0, lo, row[s]);
            __m512d hi = _mm512_permutexvar_pd(high_index, b);
            hi = _mm512_mask_sub_pd(hi, 0x01, hi, row[s]);
            _mm512_storeu_pd(out + 12 * j, lo);
            _mm256_storeu_pd(out + 12 * j + 8, _mm512_castpd512_pd256(hi));
        }
        if (k0 + 8 >= count) break;
    }
    return bad == 0;
}
#pragma GCC diagnostic pop
#endif

#if defined(WIRE_HAS_VECTOR_CLONES)
// Whether the CPU (and the OS) run AVX-512 code: decided once, when the library is loaded (not on every call).
const bool kHasAvx512 = (__builtin_cpu_init(), __builtin_cpu_supports("avx512f"));
#endif

// node_segments_kernel's records and test, by the AVX-512 version where the CPU has it (`widest`; false: the loop).
bool node_segments(std::size_t count, const double* p0, const double* p1, const double* Dx, const double* Dy,
                   const double* Dz, const double* len, double* out, double offset_limit, bool widest = true) {
#if defined(WIRE_HAS_VECTOR_CLONES)
    if (widest && kHasAvx512 && count >= 8) return node_segments_avx512(count, p0, p1, Dx, Dy, Dz, len, out, offset_limit);
#endif
    (void)widest;
    return node_segments_kernel(count, p0, p1, Dx, Dy, Dz, len, out, offset_limit);
}

// Node tangents per unit chord, node i's at i and index n repeating node 0's (x, y, z arrays, per-thread memory
// valid until the next solve).
struct NodeTangents {
    const double *x = nullptr, *y = nullptr, *z = nullptr;
};

// Segment tangents from node tangents (for the kinds that then scale them per node).
void segment_tangents(const NodeTangents& D, const Chords& ch, Tangents& tg) {
    const double* const len = ch.len.data() + 1;  // segment k's length
    tangents_kernel(ch.segs, D.x, len, tg.t0x, tg.t1x);
    tangents_kernel(ch.segs, D.y, len, tg.t0y, tg.t1y);
    tangents_kernel(ch.segs, D.z, len, tg.t0z, tg.t1z);
}

// An automatic (or c2) spline's tangent system between its setup and its solution, so that the tridiagonal
// solves of two wires can run side by side (thomas_pair): the solve is a serial chain of divisions per wire, and
// two independent chains take the time of one.
struct TangentSolve {
    double* D[3] = {};        // node tangents per unit chord (n + 1 each; index n repeats node 0's)
    double *a = nullptr, *b = nullptr, *c = nullptr, *f = nullptr;  // interior rows (of nodes 1 .. m); f: factors
    std::size_t n = 0, m = 0;  // nodes; interior rows
    bool pending = false;      // the interior rows still to solve (an open wire of >= 4 nodes), then the ends
    dvec3 r0{}, rl{};          // the end rows' right-hand sides and diagonals (beta D0 + D1 = r0, ...)
    double beta0 = 0.0, betal = 0.0;
    double* r(int q) const { return D[q] + 1; }  // right-hand sides of the interior rows, solved in place
};

// Solves a pending system alone.
void solve(TangentSolve& ts) {
    thomas_kernel<3>(ts.a, ts.b, ts.c, ts.m, ts.f, ts.r(0), ts.r(1), ts.r(2));
}

// thomas_kernel<3> for two systems of the same size (>= 4 rows) at once: system s in lane s of two-double
// vectors (native on every x86-64), so every row gets exactly the operations thomas_kernel gives it (each lane
// is rounded as the scalar operation; the results are bit for bit its) and the two systems' division chains
// run side by side, in the registers (scalar code for two systems spilled its chain values).
void thomas_pair(TangentSolve& s0, TangentSolve& s1) {
    using v2 = double __attribute__((vector_size(16)));
    const std::size_t n = s0.m, p = n / 2;  // the meeting row, as thomas_kernel's
    assert(s1.m == n && n >= 4);
    const double *const a0 = s0.a, *const a1 = s1.a, *const b0 = s0.b, *const b1 = s1.b;
    const double *const c0 = s0.c, *const c1 = s1.c;
    double *const f0 = s0.f, *const f1 = s1.f;
    double* const r0[3] = {s0.r(0), s0.r(1), s0.r(2)};
    double* const r1[3] = {s1.r(0), s1.r(1), s1.r(2)};
    const auto a = [&](std::size_t i) { return v2{a0[i], a1[i]}; };
    const auto b = [&](std::size_t i) { return v2{b0[i], b1[i]}; };
    const auto c = [&](std::size_t i) { return v2{c0[i], c1[i]}; };
    const auto r = [&](int q, std::size_t i) { return v2{r0[q][i], r1[q][i]}; };
    const auto put_f = [&](std::size_t i, v2 v) { f0[i] = v[0], f1[i] = v[1]; };
    const auto put_r = [&](int q, std::size_t i, v2 v) { r0[q][i] = v[0], r1[q][i] = v[1]; };
    const v2 one = {1.0, 1.0};
    v2 t[3], u[3];  // the top and bottom chains' last rows
    v2 inv = one / b(0);
    v2 ft = c(0) * inv;
    put_f(0, ft);
    for (int q = 0; q < 3; ++q) t[q] = r(q, 0) * inv, put_r(q, 0, t[q]);
    inv = one / b(n - 1);
    v2 fb = a(n - 1) * inv;
    put_f(n - 1, fb);
    for (int q = 0; q < 3; ++q) u[q] = r(q, n - 1) * inv, put_r(q, n - 1, u[q]);
    const auto top = [&](std::size_t i) {
        const v2 ai = a(i), it = one / (b(i) - ai * ft);
        ft = c(i) * it;
        put_f(i, ft);
        for (int q = 0; q < 3; ++q) t[q] = (r(q, i) - ai * t[q]) * it, put_r(q, i, t[q]);
    };
    const auto bottom = [&](std::size_t j) {
        const v2 cj = c(j), ib = one / (b(j) - cj * fb);
        fb = a(j) * ib;
        put_f(j, fb);
        for (int q = 0; q < 3; ++q) u[q] = (r(q, j) - cj * u[q]) * ib, put_r(q, j, u[q]);
    };
    const auto back = [&](std::size_t i, v2* v) {
        const v2 fi = {f0[i], f1[i]};
        for (int q = 0; q < 3; ++q) v[q] = r(q, i) - fi * v[q], put_r(q, i, v[q]);
    };
    std::size_t i = 1, j = n - 2;
    for (; i < p && j > p; ++i, --j) top(i), bottom(j);
    for (; i < p; ++i) top(i);
    for (; j > p; --j) bottom(j);
    // Row p, as thomas_kernel's.
    inv = one / (b(p) - a(p) * ft - c(p) * fb);
    for (int q = 0; q < 3; ++q) t[q] = (r(q, p) - a(p) * t[q] - c(p) * u[q]) * inv, put_r(q, p, t[q]), u[q] = t[q];
    for (i = p, j = p; i > 0 && j + 1 < n;) {
        --i, ++j;
        back(i, t), back(j, u);
    }
    while (i > 0) --i, back(i, t);
    while (j + 1 < n) ++j, back(j, u);
}

// Four systems of the same size (>= 4 rows) at once: system s in lane s of four-double vectors, the rows of the
// four interleaved first (row i of system s at 4i + s) so that a row of all four is one load or store (two-double
// lanes read from separate arrays, as thomas_pair's, cost two instructions a load and three a store: that loop is
// bound by them, not by its division chain). Each lane gets exactly thomas_kernel's operations (the same twisted
// elimination, the same meeting row), so the results are bit for bit its. 4 lanes: ymm on AVX2 and AVX-512
// machines, two xmm halves on the SSE2 baseline.
#if defined(__GNUC__)
using v4d = double __attribute__((vector_size(32)));
using v4p = double __attribute__((vector_size(32), aligned(8), may_alias));  // four doubles at any double address

// dst[4i + s] = src_s[i], i < n (4x4 transposes of blocks of four rows).
WIRE_VECTOR_CLONES
void to_quad(std::size_t n, const double* s0, const double* s1, const double* s2, const double* s3, double* dst) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const v4d r0 = *reinterpret_cast<const v4p*>(s0 + i), r1 = *reinterpret_cast<const v4p*>(s1 + i);
        const v4d r2 = *reinterpret_cast<const v4p*>(s2 + i), r3 = *reinterpret_cast<const v4p*>(s3 + i);
        const v4d t0 = __builtin_shufflevector(r0, r1, 0, 4, 2, 6), t1 = __builtin_shufflevector(r0, r1, 1, 5, 3, 7);
        const v4d t2 = __builtin_shufflevector(r2, r3, 0, 4, 2, 6), t3 = __builtin_shufflevector(r2, r3, 1, 5, 3, 7);
        v4p* const o = reinterpret_cast<v4p*>(dst + 4 * i);
        o[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5), o[1] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
        o[2] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7), o[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
    }
    for (; i < n; ++i) dst[4 * i] = s0[i], dst[4 * i + 1] = s1[i], dst[4 * i + 2] = s2[i], dst[4 * i + 3] = s3[i];
}

// to_quad's inverse: d_s[i] = src[4i + s].
WIRE_VECTOR_CLONES
void from_quad(std::size_t n, const double* src, double* d0, double* d1, double* d2, double* d3) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const v4p* const r = reinterpret_cast<const v4p*>(src + 4 * i);
        const v4d r0 = r[0], r1 = r[1], r2 = r[2], r3 = r[3];
        const v4d t0 = __builtin_shufflevector(r0, r1, 0, 4, 2, 6), t1 = __builtin_shufflevector(r0, r1, 1, 5, 3, 7);
        const v4d t2 = __builtin_shufflevector(r2, r3, 0, 4, 2, 6), t3 = __builtin_shufflevector(r2, r3, 1, 5, 3, 7);
        *reinterpret_cast<v4p*>(d0 + i) = __builtin_shufflevector(t0, t2, 0, 1, 4, 5);
        *reinterpret_cast<v4p*>(d1 + i) = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
        *reinterpret_cast<v4p*>(d2 + i) = __builtin_shufflevector(t0, t2, 2, 3, 6, 7);
        *reinterpret_cast<v4p*>(d3 + i) = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
    }
    for (; i < n; ++i) d0[i] = src[4 * i], d1[i] = src[4 * i + 1], d2[i] = src[4 * i + 2], d3[i] = src[4 * i + 3];
}

// thomas_kernel<3> on four interleaved systems of n >= 4 rows (a, b, c, the right-hand sides r0..r2 solved in
// place, f the factors): thomas_pair's loop with four lanes.
WIRE_VECTOR_CLONES
void thomas_quad_kernel(std::size_t n, const double* __restrict a_, const double* __restrict b_,
                        const double* __restrict c_, double* __restrict f_, double* __restrict r0_,
                        double* __restrict r1_, double* __restrict r2_) {
    const v4p* const a = reinterpret_cast<const v4p*>(a_);
    const v4p* const b = reinterpret_cast<const v4p*>(b_);
    const v4p* const c = reinterpret_cast<const v4p*>(c_);
    v4p* const f = reinterpret_cast<v4p*>(f_);
    v4p* const r[3] = {reinterpret_cast<v4p*>(r0_), reinterpret_cast<v4p*>(r1_), reinterpret_cast<v4p*>(r2_)};
    const std::size_t p = n / 2;  // the meeting row, as thomas_kernel's
    const v4d one = {1.0, 1.0, 1.0, 1.0};
    v4d t[3], u[3];  // the top and bottom chains' last rows
    v4d inv = one / b[0];
    v4d ft = c[0] * inv;
    f[0] = ft;
    for (int q = 0; q < 3; ++q) t[q] = r[q][0] * inv, r[q][0] = t[q];
    inv = one / b[n - 1];
    v4d fb = a[n - 1] * inv;
    f[n - 1] = fb;
    for (int q = 0; q < 3; ++q) u[q] = r[q][n - 1] * inv, r[q][n - 1] = u[q];
    std::size_t i = 1, j = n - 2;
    // Row k of one chain (no lambdas: a target clone would not inline them): the top chain's row i is
    // WIRE_ROW(i, a, c, ft, t), the bottom chain's row j WIRE_ROW(j, c, a, fb, u) (its sub- and super-diagonals
    // swap roles). fv and v are the chain's factor and right-hand sides, carried from row to row.
#define WIRE_ROW(k, sub, super, fv, v)                                                                     \
    {                                                                                                      \
        const v4d sk = sub[k], ik = one / (b[k] - sk * fv);                                                \
        fv = super[k] * ik;                                                                                \
        f[k] = fv;                                                                                         \
        for (int q = 0; q < 3; ++q) v[q] = (r[q][k] - sk * v[q]) * ik, r[q][k] = v[q];                     \
    }
#define WIRE_BACK(i, v)                                                                                    \
    {                                                                                                      \
        const v4d fi = f[i];                                                                               \
        for (int q = 0; q < 3; ++q) v[q] = r[q][i] - fi * v[q], r[q][i] = v[q];                            \
    }
    for (; i < p && j > p; ++i, --j) {
        WIRE_ROW(i, a, c, ft, t)
        WIRE_ROW(j, c, a, fb, u)
    }
    for (; i < p; ++i) WIRE_ROW(i, a, c, ft, t)
    for (; j > p; --j) WIRE_ROW(j, c, a, fb, u)
    // Row p, as thomas_kernel's.
    inv = one / (b[p] - a[p] * ft - c[p] * fb);
    for (int q = 0; q < 3; ++q) t[q] = (r[q][p] - a[p] * t[q] - c[p] * u[q]) * inv, r[q][p] = t[q], u[q] = t[q];
    for (i = p, j = p; i > 0 && j + 1 < n;) {
        --i, ++j;
        WIRE_BACK(i, t)
        WIRE_BACK(j, u)
    }
    while (i > 0) {
        --i;
        WIRE_BACK(i, t)
    }
    while (j + 1 < n) {
        ++j;
        WIRE_BACK(j, u)
    }
#undef WIRE_ROW
#undef WIRE_BACK
}

// Solves four pending systems of the same size (>= 4 rows) side by side (see above).
void thomas_quad(TangentSolve* const s[4]) {
    const std::size_t n = s[0]->m;
    assert(s[1]->m == n && s[2]->m == n && s[3]->m == n && n >= 4);
    thread_local std::vector<double> buf;  // grows only: no allocation per call once large enough
    if (buf.size() < 7 * 4 * n) buf.resize(7 * 4 * n);
    double* const a = buf.data();
    double *const b = a + 4 * n, *const c = b + 4 * n, *const f = c + 4 * n, *const r = f + 4 * n;
    to_quad(n, s[0]->a, s[1]->a, s[2]->a, s[3]->a, a);
    to_quad(n, s[0]->b, s[1]->b, s[2]->b, s[3]->b, b);
    to_quad(n, s[0]->c, s[1]->c, s[2]->c, s[3]->c, c);
    for (int q = 0; q < 3; ++q) to_quad(n, s[0]->r(q), s[1]->r(q), s[2]->r(q), s[3]->r(q), r + 4 * n * q);
    thomas_quad_kernel(n, a, b, c, f, r, r + 4 * n, r + 8 * n);
    for (int q = 0; q < 3; ++q) from_quad(n, r + 4 * n * q, s[0]->r(q), s[1]->r(q), s[2]->r(q), s[3]->r(q));
}
#endif

/// The nu-spline (Nielson 1974) with chordal knots: C1, and at node i the jump of the second derivative is
/// proportional to the tangent (tension w_i, from concentrated_turns; g and gs its weights). Rows as the C2
/// spline's (w = 0: c2) with w_i added to the diagonal; open ends not-a-knot, blending to free ends (zero
/// curvature) as the neighbouring node gets tensed.
/// The setup: everything but the solve of an open wire's interior rows (ts.pending), which solve() or
/// thomas_pair() does before finish_tangents(). `pool` holds the system until then.
void start_tangents(const Chords& ch, std::size_t n, bool closed, const double* g, const double* gs,
                    const double* w, Pool& pool, TangentSolve& ts) {
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
        const dvec3 rln = (s(segs - 1) * (hP * (3.0 * hL + 2.0 * hP)) + (hL * hL) * s(segs - 2)) / ((hP + hL) * (hP + hL));
        // The not-a-knot end makes the first (last) two segments one cubic, which overshoots when either
        // node it spans is tensed (its tangent nearly vanishes): then the end becomes free.
        const auto tensed = [&](std::size_t i) { return std::max(g[i], gs[i]); };
        const double g0 = std::max(tensed(1), n > 3 ? tensed(2) : 0.0), gl = std::max(tensed(n - 2), n > 3 ? tensed(n - 3) : 0.0);
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

namespace {

// One wire's working memory in the curve stage (per thread, reused: no allocation per call once it is large
// enough), and what its build carries from begin_curve to end_curve.
struct CurveBuild {
    Merged m;
    Chords ch;
    Tangents tg;
    std::vector<double> g, gs, w;  // automatic: tension weights
    Pool pool;                     // c2, automatic: the tangent system
    TangentSolve ts;
    const dvec3* P = nullptr;      // the curve's nodes (merged)
    std::size_t n = 0, segs = 0;
    bool physics = false;          // the physics arrays drive a curvature tension
    bool solved = false;           // c2, automatic: node tangents in ts (once ts.pending is solved)
};

// Catmull-Rom / Kochanek-Bartels segment tangents into build.tg (see spline.hpp).
void catmull_rom_tangents(const WireNodes& nodes, const SplineSettings& settings, CurveBuild& build) {
    const Merged& m = build.m;
    const Chords& ch = build.ch;
    Tangents& tg = build.tg;
    const std::size_t n = build.n, segs = build.segs;
    const bool closed = settings.closed, physics = build.physics;
    const double alpha = settings.alpha;
    for (std::size_t j = 0; j < n; ++j) {
        const uint32_t src = m.first[j];
        const bool has_in = closed || j > 0, has_out = closed || j + 1 < n;
        const std::size_t kin = has_in ? (j == 0 ? segs - 1 : j - 1) : 0;
        const std::size_t kout = has_out ? (j == segs ? 0 : j) : segs - 1;
        // Open ends reflect the missing neighbour (P[-1] = 2P[0]-P[1]): the missing chord equals the other.
        const dvec3 din = has_in ? ch.d(kin) : ch.d(kout);
        const dvec3 dout = has_out ? ch.d(kout) : ch.d(kin);
        const double lin = has_in ? ch.l(kin) : ch.l(kout);
        const double lout = has_out ? ch.l(kout) : ch.l(kin);

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
        if (has_out) tg.set0(kout, start);
        if (has_in) tg.set1(kin, end);
    }
}

// build_curve without its clearing of `out` on entry, in two halves around the tridiagonal solve of c2 and
// automatic curves (b.ts.pending: solve() or thomas_pair() runs it in between). Every field of `out` is
// overwritten on success (the segments resized, not cleared first: a curve reused for the same wire is not
// zero-filled before it is written), and build_curve clears it on failure.
Status begin_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out, CurveBuild& b) {
    b.ts.pending = false, b.solved = false;
    if (Status st = check_settings(settings); !st) return st;
    if (Status st = check_sizes(nodes); !st) return st;
    const bool physics = settings.curvature_tension && !nodes.theta_rad.empty() && !nodes.iz_m4.empty() &&
                         !nodes.length_m.empty() && !nodes.delta_length_m.empty() && !nodes.area_m2.empty();
    if (Status st = check_nodes(nodes, physics); !st) return st;

    Merged& m = b.m;
    Chords& ch = b.ch;
    std::size_t n = 0;
    const dvec3* const P = merge_nodes(nodes, settings, m, ch, n);
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

    std::vector<float>& seg_stretch = out.stretch;  // built in place
    seg_stretch.assign(segs, 1.0f);
    if (!nodes.stretch.empty()) {
        for (std::size_t k = 0; k < segs; ++k) seg_stretch[k] = nodes.stretch[m.last[k]];
    }

    b.P = P, b.n = n, b.segs = segs, b.physics = physics;

    // Segment tangents (t0 at a segment's start, t1 at its end); c2 and automatic: node tangents, from the
    // tangent system set up here and solved before end_curve.
    Tangents& tg = b.tg;
    tg.resize(segs);
    const SplineKind kind = settings.kind;
    if (kind == SplineKind::linear) {
        for (std::size_t k = 0; k < segs; ++k) tg.set0(k, ch.d(k)), tg.set1(k, ch.d(k));
    } else if (kind == SplineKind::c2) {
        // C2 interpolating spline with chordal knots (not-a-knot ends; the parabola through 3 nodes): the
        // automatic spline's system with no node tensed (w = 0 everywhere, ends purely not-a-knot).
        const double* const untensed = zeros(n);
        start_tangents(ch, n, closed, untensed, untensed, untensed, b.pool, b.ts);
        b.solved = true;
    } else if (kind == SplineKind::automatic) {
        if (concentrated_turns(ch, n, closed, b.g, b.gs, b.w)) {
            start_tangents(ch, n, closed, b.g.data(), b.gs.data(), b.w.data(), b.pool, b.ts);
        } else {
            const double* const untensed = zeros(n);
            start_tangents(ch, n, closed, untensed, untensed, untensed, b.pool, b.ts);
        }
        b.solved = true;
    } else {
        catmull_rom_tangents(nodes, settings, b);
    }
    return Status::success();
}

Status end_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out, CurveBuild& b) {
    const Merged& m = b.m;
    const Chords& ch = b.ch;
    Tangents& tg = b.tg;
    const dvec3* const P = b.P;
    const std::size_t n = b.n, segs = b.segs;
    const bool closed = settings.closed, physics = b.physics;
    // The records are written from the node tangents (c2, and an automatic spline that no tension scales) or
    // from segment tangents.
    NodeTangents node_form{};
    if (b.solved) node_form = finish_tangents(b.ts);
    if (settings.kind == SplineKind::automatic) {
        // Tension (wire, node, curvature-driven) scales both tangents at a node, as for catmull_rom (G1 kept;
        // C2 only where it is 0). Nothing to scale with the wire's tension 0 and no per-node or physics input.
        if (!nodes.kb_tension.empty() || physics || settings.tension != 0.0) {
            segment_tangents(node_form, ch, tg);
            node_form = {};
            for (std::size_t j = 0; j < n; ++j) {
                const uint32_t src = m.first[j];
                const double t_user = nodes.kb_tension.empty() ? settings.tension : nodes.kb_tension[src];
                const double t_curv = physics ? curvature_tension(nodes.theta_rad[src], nodes.iz_m4[src], nodes.length_m[src],
                                                                  nodes.delta_length_m[src], nodes.area_m2[src])
                                              : 0.0;
                const double keep = (1.0 - t_user) * (1.0 - t_curv);
                if (keep == 1.0) continue;
                if (closed || j + 1 < n) tg.scale0(j == segs ? 0 : j, keep);
                if (closed || j > 0) tg.scale1(j == 0 ? segs - 1 : j - 1, keep);
            }
        }
    }


    // The Bezier records (inner control points B1 = P0 + t0/3, B2 = P1 - t1/3) and the range check of the inner
    // control points. Finite is not enough: a control point past the coordinate range (an extreme alpha)
    // overflows the tube's float vertices downstream.
    constexpr double kMaxControl_m = 10.0 * kMaxCoordinate_m;
    // The node-tangent records test the offsets t/3 instead (in their structure-of-arrays form, before they are
    // interleaved into records): the nodes are within +-kMaxCoordinate_m (check_nodes), so offsets within
    // +-kMaxOffset_m give control points within +-9e12 (rounding is monotonic and 9e12 is a double). Sufficient,
    // not necessary: when it fails, the exact test below decides (a control point just in range passes it).
    constexpr double kMaxOffset_m = kMaxControl_m - 2.0 * kMaxCoordinate_m;
    static_assert(sizeof(CubicBezier) == 12 * sizeof(double));
    out.segments.resize(segs);
    CubicBezier* const seg = out.segments.data();
    const auto segments = [&](std::size_t k0, std::size_t count, const dvec3* p0, const dvec3* p1) {
        if (node_form.x != nullptr) {
            return node_segments(count, &p0->x, &p1->x, node_form.x + k0, node_form.y + k0, node_form.z + k0,
                                 ch.len.data() + 1 + k0, &seg[k0].b0.x, kMaxOffset_m);
        }
        return segments_kernel(count, &p0->x, &p1->x, tg.t0x + k0, tg.t0y + k0, tg.t0z + k0, tg.t1x + k0,
                               tg.t1y + k0, tg.t1z + k0, &seg[k0].b0.x, kMaxControl_m);
    };
    bool in_range = segments(0, n - 1, P, P + 1);
    if (closed) in_range &= segments(n - 1, 1, P + (n - 1), P);
    if (!in_range) {
        for (std::size_t k = 0; k < segs; ++k) {
            if (all_within(&seg[k].b1.x, 6, kMaxControl_m)) continue;
            const uint32_t src = m.first[k];
            clear_curve(out);
            return Status::error(node_prefix(src) + "tangent overflowed (alpha " + describe(settings.alpha) +
                                     " is too extreme for this node spacing)", static_cast<int>(src));
        }
    }
    out.closed = closed;
    out.source_node = m.first;
    const float wire_radius = settings.radius_m > 0.0f ? settings.radius_m : 0.01f;
    if (nodes.radius_m.empty()) {
        out.radius_m.assign(n, wire_radius);
    } else {
        out.radius_m.resize(n);
        for (std::size_t j = 0; j < n; ++j) {
            const float r = nodes.radius_m[m.first[j]];
            out.radius_m[j] = r > 0.0f ? r : wire_radius;
        }
    }
    return Status::success();
}

// A thread's build memory: build_curve uses the first, build_curves (and build_curve_pair) one per wire (nothing
// calls build_curve between a group's begin_curve and end_curve), so a thread keeps at most two builds' worth for
// its largest wires and two more for wires of up to 1,024 nodes (build_curves' kGroupNodes).
CurveBuild& thread_build(std::size_t k) {
    thread_local CurveBuild b[4];
    return b[k];
}

}  // namespace

Status build_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out) {
    CurveBuild& b = thread_build(0);
    Status st = begin_curve(nodes, settings, out, b);
    if (st && b.ts.pending) solve(b.ts);
    if (st) st = end_curve(nodes, settings, out, b);
    if (!st) clear_curve(out);
    return st;
}

void build_curves(std::span<CurveBuildJob> jobs) {
    if (jobs.size() > 4) {  // four at a time, in order
        for (std::size_t first = 0; first < jobs.size(); first += 4) {
            build_curves(jobs.subspan(first, std::min<std::size_t>(4, jobs.size() - first)));
        }
        return;
    }
    const std::size_t count = jobs.size();
    // Two jobs writing one curve cannot be built side by side: what build_curve calls in order leave (the later
    // job's curve).
    for (std::size_t k = 1; k < count; ++k) {
        for (std::size_t l = 0; l < k; ++l) {
            if (jobs[k].out != jobs[l].out) continue;
            for (CurveBuildJob& job : jobs) job.status = build_curve(*job.nodes, *job.settings, *job.out);
            return;
        }
    }
    // Four builds in flight keep four builds' working memory per thread: only wires of up to kGroupNodes nodes
    // take the third and fourth (a group with a larger wire is built as two pairs, in the first two builds).
    constexpr std::size_t kGroupNodes = 1024;
    const auto large = [](const CurveBuildJob& j) { return j.nodes->size() > kGroupNodes; };
    if (count > 2 && std::any_of(jobs.begin(), jobs.begin() + count, large)) {
        build_curves(jobs.first(2));
        build_curves(jobs.subspan(2, count - 2));
        return;
    }
    CurveBuild* b[4] = {};
    for (std::size_t k = 0; k < count; ++k) {  // each build keeps its own memory until its end
        b[k] = &thread_build(k);
        jobs[k].status = begin_curve(*jobs[k].nodes, *jobs[k].settings, *jobs[k].out, *b[k]);
    }
    // The pending solves: four of one size side by side, else pairs of one size, else alone (the same results).
    const auto pending = [&](std::size_t k) { return jobs[k].status.ok && b[k]->ts.pending; };
    bool solved[4] = {};
#if defined(__GNUC__)
    if (count == 4 && pending(0) && pending(1) && pending(2) && pending(3) && b[0]->ts.m >= 4 &&
        b[1]->ts.m == b[0]->ts.m && b[2]->ts.m == b[0]->ts.m && b[3]->ts.m == b[0]->ts.m) {
        TangentSolve* const s[4] = {&b[0]->ts, &b[1]->ts, &b[2]->ts, &b[3]->ts};
        thomas_quad(s);
        solved[0] = solved[1] = solved[2] = solved[3] = true;
    }
#endif
    for (std::size_t k = 0; k < count; ++k) {
        if (!pending(k) || solved[k]) continue;
        solved[k] = true;
        std::size_t other = k + 1;
        while (other < count && !(pending(other) && !solved[other] && b[other]->ts.m == b[k]->ts.m)) ++other;
        if (other < count && b[k]->ts.m >= 4) {
            thomas_pair(b[k]->ts, b[other]->ts);
            solved[other] = true;
        } else {
            solve(b[k]->ts);
        }
    }
    for (std::size_t k = 0; k < count; ++k) {
        CurveBuildJob& job = jobs[k];
        if (job.status) job.status = end_curve(*job.nodes, *job.settings, *job.out, *b[k]);
        if (!job.status) clear_curve(*job.out);
    }
}

std::pair<Status, Status> build_curve_pair(const WireNodes& nodes0, const SplineSettings& settings0, Curve& out0,
                                           const WireNodes& nodes1, const SplineSettings& settings1, Curve& out1) {
    CurveBuildJob jobs[2] = {{&nodes0, &settings0, &out0, {}}, {&nodes1, &settings1, &out1, {}}};
    build_curves(jobs);
    return {std::move(jobs[0].status), std::move(jobs[1].status)};
}

namespace detail {

std::size_t spread_test(std::size_t count, const double* len, const double* kx, const double* ky, const double* kz,
                        const double* ax, const double* ay, const double* az, const double* ec, const double* eq,
                        double* lk, double* sum, double* miss2, double* flag, bool certified) {
    in_whole_blocks(count, [&](std::size_t o, std::size_t c) {  // as concentrated_turns runs it
        spread_kernel(c, len + o, kx + o, ky + o, kz + o, ax + o, ay + o, az + o, ec + o, eq + o, lk + o, sum + o,
                      miss2 + o, flag + o);
    });
    const std::size_t uncertain = static_cast<std::size_t>(std::count(flag, flag + count, 1.0));
    if (certified) {
        decide_flagged(count, lk, sum, miss2, flag);
        return uncertain;
    }
    for (std::size_t i = 0; i < count; ++i) {  // the exact test on every node, as before the certificate
        double l, s;
        flag[i] = spread_decides(lk[i], sum[i], miss2[i], l, s) ? 1.0 : 0.0;
        lk[i] = l, sum[i] = s;
    }
    return uncertain;
}

bool node_segment_records(std::size_t count, const double* p0, const double* p1, const double* Dx, const double* Dy,
                          const double* Dz, const double* len, double* out, double offset_limit, bool widest) {
    return node_segments(count, p0, p1, Dx, Dy, Dz, len, out, offset_limit, widest);
}

}  // namespace detail
}  // namespace wire
