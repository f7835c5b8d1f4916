// The span hierarchy's kernels (compute_lod_bounds), included by lod/span_kernels.cpp once per lane width: W is the
// wide lane type (L1, L2, L4 or L8 of simd/lanes.hpp); narrower lanes do the tail (L4 where WIRE_LOD_TAIL4 is
// defined, L2, L1). Not a header: no include guard, no namespace of its own.

// Runs run(i, L{}) over [0, n) in groups of L::width consecutive items, the widest lanes first: full groups, then
// one last group that ends at n and overlaps the one before (its items are computed again, bit for bit, and stored
// again: every kernel here writes each item's own outputs from its own inputs, and min / max accumulators do not
// mind an item twice). Where n is below a width, the next narrower lanes do the same. So a tail costs one more group,
// not one of each narrower width in sequence.
template <class Run>
__attribute__((always_inline)) inline void over_lanes(std::size_t n, Run&& run) {
    auto width = [&]<class L>(L) __attribute__((always_inline)) {
        if (n < L::width) return false;
        std::size_t i = 0;
        for (; i + L::width <= n; i += L::width) run(i, L{});
        if (i < n) run(n - L::width, L{});
        return true;
    };
    if (width(W{})) return;
#if defined(WIRE_LOD_TAIL4)
    if (width(L4{})) return;
#endif
#if defined(__SSE2__)
    if constexpr (W::width > 2)
        if (width(L2{})) return;
#endif
    width(L1{});
}

// Level 0 of the span hierarchy for one segment per lane: x, y, z of its four control points in; Wang's M, the
// box (lo, hi), the sphere (centre c, radius r) and the deviation out. A larger of two lengths is the root of the
// larger squared length (the root is monotone and correctly rounded: the same value, one root fewer). The hull's
// distance to the chord: both inner control points against one reciprocal of the chord's squared length (a foot
// parameter off by a rounding is still a point of the chord, so the distance can only come out larger: still a
// bound), skipped for groups whose every lane's hull is certified to exceed 3/4 of Wang's M (hull_certified()).
// Otherwise branch-free: a value a case does not need is computed and selected away.
template <class L>
struct Level0 {
    L wang, lo[3], hi[3], c[3], r, deviation, probe;
    Level0(const L (&x)[4], const L (&y)[4], const L (&z)[4]) {
        const L two = L::splat(2.0), zero = L::splat(0.0), one = L::splat(1.0), half = L::splat(0.5);
        const L m0x = (x[0] - two * x[1]) + x[2], m0y = (y[0] - two * y[1]) + y[2], m0z = (z[0] - two * z[1]) + z[2];
        const L m1x = (x[1] - two * x[2]) + x[3], m1y = (y[1] - two * y[2]) + y[3], m1z = (z[1] - two * z[2]) + z[3];
        const L m0 = (m0x * m0x + m0y * m0y) + m0z * m0z, m1 = (m1x * m1x + m1y * m1y) + m1z * m1z;
        const L mm = max_of(m0, m1);
        wang = sqrt_of(mm);
        probe = m0 + m1;  // NaN where a control point has a NaN coordinate (max_of above may skip it)
        const L* p[3] = {x, y, z};
        for (int k = 0; k < 3; ++k) {
            lo[k] = min_of(min_of(p[k][0], p[k][1]), min_of(p[k][2], p[k][3]));
            hi[k] = max_of(max_of(p[k][0], p[k][1]), max_of(p[k][2], p[k][3]));
        }
        const L abx = x[3] - x[0], aby = y[3] - y[0], abz = z[3] - z[0];
        const L p1x = x[1] - x[0], p1y = y[1] - y[0], p1z = z[1] - z[0];
        const L p2x = x[2] - x[0], p2y = y[2] - y[0], p2z = z[2] - z[0];
        const L len2 = (abx * abx + aby * aby) + abz * abz;
        const L dot1 = (p1x * abx + p1y * aby) + p1z * abz;
        const L w = L::splat(0.75) * wang;
        // d = min(hull, w) is w wherever hull >= w, which hull_certified() shows without the hull for the lanes
        // where b1 alone is provably far enough from the chord: on a hanging cable 9 groups of 10, which skip the
        // hull's division, root and ~40 operations (the kernel is bound by its arithmetic).
        if (hull_certified(p1x, p1y, p1z, dot1, len2, L::splat(9.0 / 16.0) * mm).bits() == (1u << L::width) - 1) {
            deviation = w;  // finite: w^2 <= ww (1 + 5.01u) <= 2^301 (hull_certified)
        } else {
            const L inv = select(zero < len2, one / len2, zero);
            const L dot2 = (p2x * abx + p2y * aby) + p2z * abz;
            // std::clamp(t, 0, 1) is std::min(std::max(t, 0), 1)
            const L t1 = min_of(max_of(dot1 * inv, zero), one), t2 = min_of(max_of(dot2 * inv, zero), one);
            const L v1x = p1x - t1 * abx, v1y = p1y - t1 * aby, v1z = p1z - t1 * abz;
            const L v2x = p2x - t2 * abx, v2y = p2y - t2 * aby, v2z = p2z - t2 * abz;
            const L hull = sqrt_of(max_of((v1x * v1x + v1y * v1y) + v1z * v1z, (v2x * v2x + v2y * v2y) + v2z * v2z));
            const L d = min_of(hull, w);
            // Not finite (NaN too): infinity.
            deviation = select(abs_of(d) <= L::splat(std::numeric_limits<double>::max()), d,
                               L::splat(std::numeric_limits<double>::infinity()));
        }
        for (int k = 0; k < 3; ++k) c[k] = half * (lo[k] + hi[k]);
        const L sx = hi[0] - lo[0], sy = hi[1] - lo[1], sz = hi[2] - lo[2];
        r = half * sqrt_of((sx * sx + sy * sy) + sz * sz) * L::splat(1.0 + 1e-12);
    }
    // Lanes where the hull's squared distance as computed above, h = max(|v1|^2, |v2|^2) (rounded), is at least
    // w^2 (w >= 0 a double): then sqrt(h) >= w exactly, so its rounding is >= w, and min_of(hull, w) is w (or an
    // equal hull: the same bits, neither is -0). p = b1 - b0 and a = b3 - b0 (doubles), dot and len2 their p.a and
    // |a|^2 rounded as the hull computes them, pp = |p|^2 rounded; u = 2^-53. ww = (9/16) mm rounded, mm the squared
    // length whose rounded root is Wang's M (w = 3/4 of that root, rounded): w^2 <= (9/16) mm (1 + u)^4 <= ww (1 + u)^4
    // / (1 - u) <= ww (1 + 5.01u) (no underflow: ww >= 2^-300 below). Taken from mm, not as w w, so the test does not
    // wait for M's square root: the group's branch resolves ~20 cycles earlier (level 0 -3% on swaying's curves).
    // 1. v1 = p - t a (t in [0, 1]), each component rounded twice (t a_k, then p_k minus it): |v1| >= |p - t a|
    //    (1 - u) - u |a| >= D (1 - u) - u |a|, D the distance of b1 to the chord's line, and |v1|^2 rounded >=
    //    (D - u |a|)^2 (1 - 5u). That is >= w^2 when D >= w (1 + 2.6u) + u |a|, which (x + y)^2 <= (1 + 2^-20) x^2 +
    //    (1 + 2^20) y^2 turns into: D^2 >= w^2 (1 + 2^-19) + 2^-85 |a|^2.
    // 2. D^2 |a|^2 = |p|^2 |a|^2 - (p.a)^2 (Lagrange). pp and len2 are within 3.01u of |p|^2 and |a|^2 (sums of
    //    squares), w^2 <= ww (1 + 5.01u), |dot - p.a| <= 3.01u |p| |a| (Cauchy-Schwarz), squared with the identity
    //    of step 1: step 1's condition holds when pp len2 (1 - 2^-49) >= dot^2 (1 + 2^-20) + len2 (ww (1 + 2^-17) +
    //    2^-84 len2).
    // 3. With len2 <= 2^60 ww the last term is at most 2^-24 len2 ww; divided by 1 + 2^-20: it holds when
    //    pp len2 (1 - 2^-19) >= dot^2 + len2 ww (1 + 2^-16).
    // 4. The test below has margins 2^-17 (for 2^-19) and 2^-15 (for 2^-16); its six roundings (all terms >= 0)
    //    move its left side by at most 2.01u and its right side by at most 3.01u relative, far inside the gaps.
    // Ranges: len2 in [2^-300, 2^60 ww], ww in [2^-300, 2^300], pp <= 2^300: no product overflows, and one that
    // passes has pp len2 >= 2^-600, so pp >= 2^-960: the absolute errors of underflow (< 2^-1074) vanish against the
    // margins. The lower bounds are tested on min_of(len2, ww), the upper ones on max_of(ww, pp) (one comparison each):
    // a NaN len2 or pp still fails (min_of(NaN, ww) is NaN; pp NaN makes lhs NaN), a NaN ww fails len2 <= 2^60 ww.
    // (LodLevel0.HullCertificateEqualsTheHull tests it near the boundary.)
    static auto hull_certified(L px, L py, L pz, L dot, L len2, L ww) {
        const L pp = (px * px + py * py) + pz * pz;
        const L lhs = (pp * len2) * L::splat(1.0 - 0x1p-17);
        const L rhs = dot * dot + (len2 * ww) * L::splat(1.0 + 0x1p-15);
        const auto ranges = ((L::splat(0x1p-300) <= min_of(len2, ww)) & (len2 <= ww * L::splat(0x1p60))) &
                            (max_of(ww, pp) <= L::splat(0x1p300));
        return (rhs <= lhs) & ranges;
    }
};

// A node of level l >= 1 from its two children (one pair per lane): chords A-M and M-B give the deviation
// max(d_left, d_right) + dist(M, A-B); the sphere is the smallest around the children's (merge of two spheres:
// one of them when it holds the other, else the one through both, its radius rounded up by a relative hair so
// rounding in the centre cannot leave a point out).
template <class L>
struct Merge {
    L c[3], r, deviation;
    Merge(const L (&a)[3], const L (&m)[3], const L (&b)[3], const L (&lc)[3], L lr, L ld, const L (&rc)[3], L rr,
          L rd)
        : deviation(chord_deviation(a, m, b, ld, rd)) {
        sphere(lc, lr, rc, rr, c, r);
    }
    // The two halves share nothing: span_merge_deviations() and span_merge_spheres() run them apart.
    static L chord_deviation(const L (&a)[3], const L (&m)[3], const L (&b)[3], L ld, L rd) {
        const L zero = L::splat(0.0), one = L::splat(1.0);
        // distance_to_chord(M, A, B)
        const L abx = b[0] - a[0], aby = b[1] - a[1], abz = b[2] - a[2];
        const L qx = m[0] - a[0], qy = m[1] - a[1], qz = m[2] - a[2];
        const L len2 = (abx * abx + aby * aby) + abz * abz;
        const L t = select(zero < len2, min_of(max_of(((qx * abx + qy * aby) + qz * abz) / len2, zero), one), zero);
        const L vx = m[0] - (a[0] + t * abx), vy = m[1] - (a[1] + t * aby), vz = m[2] - (a[2] + t * abz);
        return max_of(ld, rd) + sqrt_of((vx * vx + vy * vy) + vz * vz);
    }
    // merge_spheres(left, right)
    static void sphere(const L (&lc)[3], L lr, const L (&rc)[3], L rr, L (&c)[3], L& r) {
        const L dx = rc[0] - lc[0], dy = rc[1] - lc[1], dz = rc[2] - lc[2];
        const L dist = sqrt_of((dx * dx + dy * dy) + dz * dz);
        const L rad = L::splat(0.5) * ((dist + lr) + rr);
        const L s = (rad - lr) / dist;
        const auto take_left = dist + rr <= lr;
        const auto take_right = dist + lr <= rr;
        const L d[3] = {dx, dy, dz};
        for (int k = 0; k < 3; ++k) c[k] = select(take_left, lc[k], select(take_right, rc[k], lc[k] + d[k] * s));
        r = select(take_left, lr, select(take_right, rr, rad * L::splat(1.0 + 1e-12)));
    }
};

// The smallest and largest of a level's deviations (or of Wang's M), as std::min from +inf and std::max from 0 over
// them in sequence give them: the lanes' running min_of / max_of (a NaN skipped as the sequence skips it), then
// the lanes together. Exact in any order: the values are never -0 (square roots of sums of squares, and sums of
// those), so the one pair of equal values with two encodings cannot occur.
struct Range {
    W lo, hi;
    double slo = std::numeric_limits<double>::infinity(), shi = 0.0;
    // A constructor written here, not default member initializers: GCC compiles an implicit constructor outside
    // the `#pragma GCC target` region this file is included in, so without optimization (nothing inlined) it took
    // the wide lanes' values through the baseline ABI and left them garbage (Debug builds' LOD ranges). The rule
    // for every type in this file: a member of lane type is set by a written constructor or by the kernel itself.
    Range() : lo(W::splat(std::numeric_limits<double>::infinity())), hi(W::splat(0.0)) {}
    void add(W v) {
        lo = min_of(lo, v);
        hi = max_of(hi, v);
    }
    template <class L>
    void add_lanes(L v) {  // a narrower tail: lane by lane
        double t[L::width];
        v.store(t);
        for (std::size_t k = 0; k < L::width; ++k) {
            slo = min_of(slo, t[k]);
            shi = max_of(shi, t[k]);
        }
    }
    void finish(double& lo_out, double& hi_out) {
        double l[W::width], h[W::width];
        lo.store(l);
        hi.store(h);
        for (std::size_t k = 0; k < W::width; ++k) {
            slo = min_of(slo, l[k]);
            shi = max_of(shi, h[k]);
        }
        lo_out = slo;
        hi_out = shi;
    }
};

// Level 0: every segment's node (5 arrays: centre x, y, z, radius, deviation), Wang's M, box (6 arrays: lo, hi;
// skipped where `box` is null) and chord ends (6 arrays: b0, b3), W::width segments at a time, the rest one by one;
// range: the deviations' smallest and largest, the largest M, and a sum over the segments of their two squared
// second differences (finite where every coordinate is finite and the sum does not overflow; NaN where one is NaN).
inline void span_level0(const CubicBezier* seg, std::size_t n, double* node, double* wang, double* box,
                        double* ends, double* range) {
    static_assert(sizeof(CubicBezier) == 12 * sizeof(double));  // b0 .. b3, x y z each, no padding
    Range dev, m;
    W probe = W::splat(0.0);
    double probe_tail = 0.0;
    auto run = [&]<class L>(std::size_t i, L) __attribute__((always_inline)) {
        L x[4], y[4], z[4];
        L::points(&seg[i].b0.x, x, y, z);  // b0 x y z, b1 x y z, b2 ..., b3 ... of each lane's segment
        const Level0<L> q(x, y, z);
        q.wang.store(wang + i);
        if constexpr (std::is_same_v<L, W>) {
            dev.add(q.deviation);
            m.add(q.wang);
            probe = probe + q.probe;
        } else {
            dev.add_lanes(q.deviation);
            m.add_lanes(q.wang);
            double t[L::width];
            q.probe.store(t);
            for (std::size_t k = 0; k < L::width; ++k) probe_tail += t[k];
        }
        for (int k = 0; k < 3; ++k) q.c[k].store(node + k * n + i);
        if (box != nullptr)
            for (int k = 0; k < 3; ++k) {
                q.lo[k].store(box + k * n + i);
                q.hi[k].store(box + (3 + k) * n + i);
            }
        q.r.store(node + 3 * n + i);
        q.deviation.store(node + 4 * n + i);
        x[0].store(ends + i);
        y[0].store(ends + n + i);
        z[0].store(ends + 2 * n + i);
        x[3].store(ends + 3 * n + i);
        y[3].store(ends + 4 * n + i);
        z[3].store(ends + 5 * n + i);
    };
    over_lanes(n, run);
    dev.finish(range[0], range[1]);
    double unused = 0.0;
    m.finish(unused, range[2]);
    double p[W::width];
    probe.store(p);
    for (std::size_t k = 0; k < W::width; ++k) probe_tail += p[k];
    // Read only as finite or not (a NaN coordinate makes it NaN): the overlapping last group counts some segments
    // twice and the summation order depends on the lane width, so near DBL_MAX its finiteness may differ between
    // widths; that only turns update_lod_once's level stop off, whose result is the same either way.
    range[3] = probe_tail;
}

// Level l from level l - 1 (child: 5 arrays of cw nodes, e: their chord ends, 6 arrays of cw; parent: 5 arrays of
// w nodes, f: their chord ends): a parent's chord runs from its left child's first point to its right child's
// last. W::width parents at a time (their left children are the even nodes of 2 W::width children, their right
// ones the odd nodes), the rest one by one; an odd child count leaves the last child alone in its parent. range:
// the parents' smallest and largest deviation.
inline void span_merge_level(const double* child, const double* e, std::size_t cw, double* parent, double* f,
                             std::size_t w, double* range) {
    const std::size_t pairs = cw / 2;
    Range dev;
    auto run = [&]<class L>(std::size_t j, L) __attribute__((always_inline)) {
        const std::size_t at = 2 * j;
        const L a[3] = {L::evens(e + at), L::evens(e + cw + at), L::evens(e + 2 * cw + at)};
        const L m[3] = {L::odds(e + at), L::odds(e + cw + at), L::odds(e + 2 * cw + at)};
        const L b[3] = {L::odds(e + 3 * cw + at), L::odds(e + 4 * cw + at), L::odds(e + 5 * cw + at)};
        const L lc[3] = {L::evens(child + at), L::evens(child + cw + at), L::evens(child + 2 * cw + at)};
        const L rc[3] = {L::odds(child + at), L::odds(child + cw + at), L::odds(child + 2 * cw + at)};
        const Merge<L> q(a, m, b, lc, L::evens(child + 3 * cw + at), L::evens(child + 4 * cw + at), rc,
                         L::odds(child + 3 * cw + at), L::odds(child + 4 * cw + at));
        for (int k = 0; k < 3; ++k) {
            q.c[k].store(parent + k * w + j);
            a[k].store(f + k * w + j);
            b[k].store(f + (3 + k) * w + j);
        }
        q.r.store(parent + 3 * w + j);
        q.deviation.store(parent + 4 * w + j);
        if constexpr (std::is_same_v<L, W>) {
            dev.add(q.deviation);
        } else {
            dev.add_lanes(q.deviation);
        }
    };
    over_lanes(pairs, run);
    if (pairs < w) {
        const std::size_t l = cw - 1;
        for (int k = 0; k < 5; ++k) parent[k * w + pairs] = child[k * cw + l];
        for (int k = 0; k < 6; ++k) f[k * w + pairs] = e[k * cw + l];
        dev.add_lanes(L1{child[4 * cw + l]});
    }
    dev.finish(range[0], range[1]);
}

// span_merge_level() in two passes that together write the same: the deviations (with the chord ends and the
// range), then the spheres. compute_lod_bounds() with a stop test (update_lod_once()) runs the second only when
// the first's range does not stop the build: the stopping level's spheres are never read.
inline void span_merge_deviations(const double* child, const double* e, std::size_t cw, double* parent, double* f,
                                  std::size_t w, double* range) {
    const std::size_t pairs = cw / 2;
    Range dev;
    auto run = [&]<class L>(std::size_t j, L) __attribute__((always_inline)) {
        const std::size_t at = 2 * j;
        const L a[3] = {L::evens(e + at), L::evens(e + cw + at), L::evens(e + 2 * cw + at)};
        const L m[3] = {L::odds(e + at), L::odds(e + cw + at), L::odds(e + 2 * cw + at)};
        const L b[3] = {L::odds(e + 3 * cw + at), L::odds(e + 4 * cw + at), L::odds(e + 5 * cw + at)};
        const L d = Merge<L>::chord_deviation(a, m, b, L::evens(child + 4 * cw + at), L::odds(child + 4 * cw + at));
        for (int k = 0; k < 3; ++k) {
            a[k].store(f + k * w + j);
            b[k].store(f + (3 + k) * w + j);
        }
        d.store(parent + 4 * w + j);
        if constexpr (std::is_same_v<L, W>) {
            dev.add(d);
        } else {
            dev.add_lanes(d);
        }
    };
    over_lanes(pairs, run);
    if (pairs < w) {
        const std::size_t l = cw - 1;
        parent[4 * w + pairs] = child[4 * cw + l];
        for (int k = 0; k < 6; ++k) f[k * w + pairs] = e[k * cw + l];
        dev.add_lanes(L1{child[4 * cw + l]});
    }
    dev.finish(range[0], range[1]);
}
inline void span_merge_spheres(const double* child, std::size_t cw, double* parent, std::size_t w) {
    const std::size_t pairs = cw / 2;
    auto run = [&]<class L>(std::size_t j, L) __attribute__((always_inline)) {
        const std::size_t at = 2 * j;
        const L lc[3] = {L::evens(child + at), L::evens(child + cw + at), L::evens(child + 2 * cw + at)};
        const L rc[3] = {L::odds(child + at), L::odds(child + cw + at), L::odds(child + 2 * cw + at)};
        L c[3], r;
        Merge<L>::sphere(lc, L::evens(child + 3 * cw + at), rc, L::odds(child + 3 * cw + at), c, r);
        for (int k = 0; k < 3; ++k) c[k].store(parent + k * w + j);
        r.store(parent + 3 * w + j);
    };
    over_lanes(pairs, run);
    if (pairs < w) {
        const std::size_t l = cw - 1;
        for (int k = 0; k < 4; ++k) parent[k * w + pairs] = child[k * cw + l];
    }
}

// Bit k of an 8-bit mask to bit 0 of byte k: the low 7 bits by one multiplication (the shifted copies of the mask
// land 7 bits apart, so bit k reaches byte k alone), bit 7 by a shift.
inline uint64_t spread_bits(unsigned m) {
    return ((uint64_t{m & 0x7Fu} * 0x0002040810204081ull) & 0x0101010101010101ull) | (uint64_t{(m >> 7) & 1u} << 56);
}

// Every segment's hull depth (nearest control point depth, clamped to near), off-axis factor k and plane mask
// (bit i: all four control points farther than the radius outside plane i): hull_depth() and PlaneTest::outside()
// W::width segments at a time, the same arithmetic per lane (world -> view as ViewTransform computes it). Without
// the plane masks where `outside` is null (a caller that reads only the depths).
inline void hull_depth_kernel(const CubicBezier* seg, std::size_t n, const HullConstants& h, double* z_min,
                              double* k_out, unsigned char* outside) {
    auto group = [&]<bool Planes, class L>(std::size_t i, L) __attribute__((always_inline)) {
        L x[4], y[4], z[4];
        L::points(&seg[i].b0.x, x, y, z);
        const L near = L::splat(h.near), far = L::splat(h.far), tx = L::splat(h.tx), ty = L::splat(h.ty);
        const L neg_rx = L::splat(h.neg_rx), neg_ry = L::splat(h.neg_ry), neg_r = L::splat(h.neg_r);
        L zm = L::splat(std::numeric_limits<double>::infinity()), a = L::splat(0.0), b = L::splat(0.0);
        decltype(zm < zm) out[6];
        for (int c = 0; c < 4; ++c) {
            const L qx = ((L::splat(h.m[0]) * x[c] + L::splat(h.m[3]) * y[c]) + L::splat(h.m[6]) * z[c]) +
                         L::splat(h.t[0]);
            const L qy = ((L::splat(h.m[1]) * x[c] + L::splat(h.m[4]) * y[c]) + L::splat(h.m[7]) * z[c]) +
                         L::splat(h.t[1]);
            const L qz = neg_of(((L::splat(h.m[2]) * x[c] + L::splat(h.m[5]) * y[c]) + L::splat(h.m[8]) * z[c]) +
                                L::splat(h.t[2]));
            const L den = max_of(qz, near);
            zm = min_of(zm, qz);
            a = max_of(a, abs_of(qx) / den);
            b = max_of(b, abs_of(qy) / den);
            if constexpr (Planes) {
                const decltype(zm < zm) o[6] = {qx + qz * tx < neg_rx, qz * tx - qx < neg_rx, qy + qz * ty < neg_ry,
                                                qz * ty - qy < neg_ry, qz - near < neg_r,    far - qz < neg_r};
                for (int p = 0; p < 6; ++p) out[p] = c == 0 ? o[p] : out[p] & o[p];
            }
        }
        const auto in_front = near <= zm;
        a = select(in_front, min_of(a, tx), tx);
        b = select(in_front, min_of(b, ty), ty);
        max_of(zm, near).store(z_min + i);
        sqrt_of((L::splat(1.0) + a * a) + b * b).store(k_out + i);
        if constexpr (Planes) {
            // Transpose the six planes' lane masks into one byte per lane: byte k of `bytes` holds lane k's planes.
            uint64_t bytes = 0;
            for (int p = 0; p < 6; ++p) bytes |= spread_bits(out[p].bits()) << p;
            for (std::size_t lane = 0; lane < L::width; ++lane)
                outside[i + lane] = static_cast<unsigned char>(bytes >> (8 * lane));
        }
    };
    if (outside != nullptr) {
        over_lanes(n, [&]<class L>(std::size_t i, L) __attribute__((always_inline)) { group.template operator()<true>(i, L{}); });
    } else {
        over_lanes(n, [&]<class L>(std::size_t i, L) __attribute__((always_inline)) { group.template operator()<false>(i, L{}); });
    }
}

// Per segment: Wang's ring count at its hull depth (wang_ring_count()'s arithmetic on the cached M, as a double:
// an integer in [1, max_rings]) and whether max_rings clamped it (1 or 0), W::width segments at a time:
// eps = scale z_min / k, c = ceil(sqrt(3 M / (4 eps))), max_rings where eps is not positive or M not finite, else
// max(1, c) below max_rings and max_rings from there on (clamped unless c <= max_rings, so also for a NaN c).
inline void wang_counts(const double* z_min, const double* k, const double* m, std::size_t n, double scale,
                        double max_rings, double* raw_out, double* clamped_out) {
    auto run = [&]<class L>(std::size_t i, L) __attribute__((always_inline)) {
        const L zero = L::splat(0.0), one = L::splat(1.0), most = L::splat(max_rings), mi = L::load(m + i);
        const L eps = (L::splat(scale) * L::load(z_min + i)) / L::load(k + i);
        const L c = ceil_of(sqrt_of((L::splat(3.0) * mi) / (L::splat(4.0) * eps)));  // >= 0 or NaN: ceil_of exact
        const auto ok = (zero < eps) & (abs_of(mi) <= L::splat(std::numeric_limits<double>::max()));
        select(ok, select(c < most, max_of(c, one), most), most).store(raw_out + i);
        select(ok, select(c <= most, zero, one), zero).store(clamped_out + i);
    };
    over_lanes(n, run);
}

// SpanMerger::ratio() (without the loop limit, which the caller applies) of the w nodes of one level (`node`: its
// five arrays), W::width nodes at a time: deviation * c * k / max(z_lo, near) with z_lo the nearest depth of the
// node's sphere; where the wire's sphere is not inside the frustum, k is bounded over the node's own sphere
// (uncapped; the cap where the sphere reaches the near plane) and a node whose sphere, inflated by the tube
// radius, is outside a plane gets 0 (with coarse off-screen spans).
inline void span_ratios(const double* node, std::size_t w, const RatioConstants& h, double* out) {
    auto run = [&]<class L>(std::size_t j, L) __attribute__((always_inline)) {
        const L px = L::load(node + j), py = L::load(node + w + j), pz = L::load(node + 2 * w + j);
        const L r = L::load(node + 3 * w + j), dev = L::load(node + 4 * w + j);
        const L near = L::splat(h.near);
        const L z = neg_of(((L::splat(h.m[2]) * px + L::splat(h.m[5]) * py) + L::splat(h.m[8]) * pz) +
                           L::splat(h.t[2]));
        const L zr = z - r;
        if (h.inside) {
            ((dev * L::splat(h.c)) * L::splat(h.k) / max_of(zr, near)).store(out + j);
            return;
        }
        const L qx = ((L::splat(h.m[0]) * px + L::splat(h.m[3]) * py) + L::splat(h.m[6]) * pz) + L::splat(h.t[0]);
        const L qy = ((L::splat(h.m[1]) * px + L::splat(h.m[4]) * py) + L::splat(h.m[7]) * pz) + L::splat(h.t[1]);
        const L one = L::splat(1.0);
        const L a = (abs_of(qx) + r) / zr, b = (abs_of(qy) + r) / zr;
        const L k = select(near <= zr, sqrt_of((one + a * a) + b * b), L::splat(h.k_cap));
        L ratio = (dev * L::splat(h.c)) * k / max_of(zr, near);
        if (h.coarse_offscreen) {
            const L ri = r + L::splat(h.radius);
            const L neg_ri = neg_of(ri), tx = L::splat(h.tx), ty = L::splat(h.ty);
            const L rx = neg_ri * L::splat(h.sx), ry = neg_ri * L::splat(h.sy);
            const auto out_of_view = (((qx + z * tx < rx) | (z * tx - qx < rx)) | ((qy + z * ty < ry) | (z * ty - qy < ry))) |
                                     ((z - near < neg_ri) | (L::splat(h.far) - z < neg_ri));
            ratio = select(out_of_view, L::splat(0.0), ratio);
        }
        ratio.store(out + j);
    };
    over_lanes(w, run);
}

// The wire's box as curve_bounding_sphere() computes it, as 12 running minima and maxima (lo, hi): lane j of the
// 12 takes double j of every segment (b0.x b0.y b0.z b1.x ... b3.z), from +inf (-inf), in segment order, two
// accumulators for even and odd segments (two dependency chains), merged at the end. A coordinate's minimum over
// its 4 lanes is then the sequence's value (a NaN is skipped as the sequence skips it) unless it is a zero: the
// caller redoes a zero in order. 12 doubles are 6 L2 or 3 L4 vectors (L4 also serves the 8-lane build).
inline void wire_box(const CubicBezier* seg, std::size_t n, double* lo, double* hi) {
#if defined(WIRE_LOD_TAIL4)
    using B = L4;
#else
    using B = W;
#endif
    static_assert(12 % B::width == 0);
    constexpr std::size_t v = 12 / B::width;
    const double* p = &seg[0].b0.x;
    B lo0[v], hi0[v], lo1[v], hi1[v];
    for (std::size_t k = 0; k < v; ++k) {
        lo0[k] = lo1[k] = B::splat(std::numeric_limits<double>::infinity());
        hi0[k] = hi1[k] = B::splat(-std::numeric_limits<double>::infinity());
    }
    std::size_t i = 0;
    for (; i + 2 <= n; i += 2)
        for (std::size_t k = 0; k < v; ++k) {
            const B a = B::load(p + 12 * i + k * B::width), b = B::load(p + 12 * (i + 1) + k * B::width);
            lo0[k] = min_of(lo0[k], a);
            hi0[k] = max_of(hi0[k], a);
            lo1[k] = min_of(lo1[k], b);
            hi1[k] = max_of(hi1[k], b);
        }
    if (i < n)
        for (std::size_t k = 0; k < v; ++k) {
            const B a = B::load(p + 12 * i + k * B::width);
            lo0[k] = min_of(lo0[k], a);
            hi0[k] = max_of(hi0[k], a);
        }
    for (std::size_t k = 0; k < v; ++k) {
        min_of(lo0[k], lo1[k]).store(lo + k * B::width);
        max_of(hi0[k], hi1[k]).store(hi + k * B::width);
    }
}
