// Ring records: centres, frames, radius, stretch-aware texture u, fold detection.
#include "wire/rings.hpp"

#include "wire/detail/segment_soa.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES, WIRE_SELECT_KERNEL

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace wire {
namespace {

// 3-point Gauss-Legendre on [0,1]: nodes (1 + x_k)/2, weights w_k/2. Exact for polynomials of degree <= 5; on
// the speed |B'(t)| of a smooth cubic over 1/8 of a segment the relative error is ~1e-10 (tests bound it at 1e-7
// for 4 rings per segment on a 72-degree-per-segment helix).
constexpr int kGlPoints = 3;
constexpr double kGlX[kGlPoints] = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr double kGlW[kGlPoints] = {0.2777777777777778, 0.4444444444444444, 0.2777777777777778};

/// Fritsch-Carlson-limited slope (per unit t) at node k from its neighbours' radii.
double node_slope(const Curve& curve, std::size_t k) {
    const std::size_t n = curve.radius_m.size();
    const bool closed = curve.closed;
    const bool has_left = closed || k > 0;
    const bool has_right = closed || k + 1 < n;
    const double rk = curve.radius_m[k];
    const double dl = has_left ? rk - curve.radius_m[k == 0 ? n - 1 : k - 1] : 0.0;
    const double dr = has_right ? curve.radius_m[k + 1 == n ? 0 : k + 1] - rk : 0.0;
    if (!has_left) return dr;
    if (!has_right) return dl;
    if (dl * dr <= 0.0) return 0.0;  // local extremum: flat, so no overshoot
    const double m = 0.5 * (dl + dr);
    const double lim = 3.0 * std::min(std::abs(dl), std::abs(dr));
    return std::clamp(m, -lim, lim);
}

/// Per-segment constants, computed once per segment rather than per evaluation: power-basis derivatives,
/// radius polynomial (power basis in t), texture scale.
struct SegmentCoeffs {
    glm::dvec3 p0, p1, p2, p3;  // B(t) = p0 + t (p1 + t (p2 + t p3))
    glm::dvec3 d0, d1, d2;      // B'(t) = d0 + t (d1 + t d2)
    glm::dvec3 e0, e1;          // B''(t) = e0 + t e1
    double r0, r1, r2, r3;      // R(t) = r0 + t (r1 + t (r2 + t r3))
    double u_scale = 0.0;       // 1 / (2 pi stretch) (radius varying along the segment)
    double u_per_m = 0.0;       // 1 / (2 pi stretch r0) (radius constant along the segment: r1 = r2 = r3 = 0)
    bool constant_radius = false;
    double tiny_bound;          // >= tiny_speed() (1-norms instead of lengths): a faster speed is not tiny
    // `slope` is node `slope_node`'s radius slope (the end node of the last loaded segment).
    std::size_t slope_node = static_cast<std::size_t>(-1);
    double slope = 0.0;

    SegmentCoeffs() = default;
    SegmentCoeffs(const Curve& curve, uint32_t seg) { load(curve, seg); }
    void load(const Curve& curve, uint32_t seg) {
        load_geometry(curve.segments[seg]);
        load_radius(curve, seg);
    }
    /// The radius polynomial and texture scale as load() computes them (SegmentTables keeps them per segment).
    void load_radius(double c0, double c1, double c2, double c3, double scale, double per_m, bool constant) {
        r0 = c0;
        r1 = c1;
        r2 = c2;
        r3 = c3;
        u_scale = scale;
        u_per_m = per_m;
        constant_radius = constant;
    }
    void load_geometry(const CubicBezier& c) {
        p0 = c.b0;
        p1 = 3.0 * (c.b1 - c.b0);
        p2 = 3.0 * (c.b2 - 2.0 * c.b1 + c.b0);
        p3 = c.b3 - 3.0 * c.b2 + 3.0 * c.b1 - c.b0;
        d0 = p1;
        d1 = 2.0 * p2;
        d2 = 3.0 * p3;
        e0 = d1;
        e1 = 2.0 * d2;
        const auto norm1 = [](const glm::dvec3& v) { return std::abs(v.x) + std::abs(v.y) + std::abs(v.z); };
        tiny_bound = 1e-9 * (norm1(d0) + norm1(d1) + norm1(d2));
    }
    void load_radius(const Curve& curve, uint32_t seg) {
        load_polynomial(curve, seg);
        double stretch = seg < curve.stretch.size() ? curve.stretch[seg] : 1.0;
        if (!(stretch > 0.0) || !std::isfinite(stretch)) {
            stretch = 1.0;
        }
        // One radius along the whole segment (no per-node radii, the common case): u is length / (2 pi R stretch),
        // so the quadrature needs no division per point (and this one division per segment).
        constant_radius = r1 == 0.0 && r2 == 0.0 && r3 == 0.0;
        if (constant_radius) {
            u_per_m = 1.0 / (2.0 * std::numbers::pi * stretch * std::max(r0, 1e-30));
            u_scale = 0.0;
        } else {
            u_per_m = 0.0;
            u_scale = 1.0 / (2.0 * std::numbers::pi * stretch);
        }
    }
    /// load_radius()'s radius polynomial r0 .. r3 alone.
    void load_polynomial(const Curve& curve, uint32_t seg) {
        const std::size_t n = curve.radius_m.size();
        if (n == 0) {
            r0 = 1.0;
            r1 = r2 = r3 = 0.0;
        } else {
            const std::size_t a = std::min<std::size_t>(seg, n - 1);
            const std::size_t b = curve.closed ? (a + 1 == n ? 0 : a + 1) : std::min(a + 1, n - 1);
            const double ra = curve.radius_m[a], rb = curve.radius_m[b];
            // Consecutive segments share a node: its slope is computed once.
            const double ma = a == slope_node ? slope : node_slope(curve, a);
            const double mb = node_slope(curve, b);
            slope_node = b;
            slope = mb;
            // Hermite basis expanded: R = ra + ma t + (-3ra - 2ma + 3rb - mb) t^2 + (2ra + ma - 2rb + mb) t^3.
            r0 = ra;
            r1 = ma;
            r2 = -3.0 * ra - 2.0 * ma + 3.0 * rb - mb;
            r3 = 2.0 * ra + ma - 2.0 * rb + mb;
        }
    }
    [[nodiscard]] glm::dvec3 position(double t) const { return p0 + t * (p1 + t * (p2 + t * p3)); }
    [[nodiscard]] glm::dvec3 derivative(double t) const { return d0 + t * (d1 + t * d2); }
    [[nodiscard]] glm::dvec3 second_derivative(double t) const { return e0 + t * e1; }
    [[nodiscard]] double radius(double t) const { return r0 + t * (r1 + t * (r2 + t * r3)); }
    /// |B'| below this counts as vanishing (rounding noise of the control points); three roots, so only
    /// computed when a speed is below tiny_bound.
    [[nodiscard]] double tiny_speed() const { return 1e-9 * (glm::length(d0) + glm::length(d1) + glm::length(d2)); }
};

struct Interval {
    double length_m;
    double u;  // integral of |B'| / (2 pi R stretch) dt
};

/// Length and texture advance over one segment from ta to tb (Gauss-Legendre).
Interval integrate(const SegmentCoeffs& c, double ta, double tb) {
    Interval out{0.0, 0.0};
    const double h = tb - ta;
    if (!(h > 0.0)) {
        return out;
    }
    if (c.constant_radius) {
        for (int k = 0; k < kGlPoints; ++k) out.length_m += (h * kGlW[k]) * glm::length(c.derivative(ta + h * kGlX[k]));
        out.u = out.length_m * c.u_per_m;
        return out;
    }
    for (int k = 0; k < kGlPoints; ++k) {
        const double t = ta + h * kGlX[k];
        const double speed = glm::length(c.derivative(t));
        const double w = h * kGlW[k];
        out.length_m += w * speed;
        out.u += w * speed / std::max(c.radius(t), 1e-30);
    }
    out.u *= c.u_scale;
    return out;
}

/// |B'| at the three Gauss points of whole segment k of n laid out by detail::transpose_segments(), with
/// SegmentCoeffs::load's derivative coefficients and integrate()'s points (ta = 0, h = 1), the same operations.
/// Always inlined: GCC inlines nothing else into a kernel compiled with other options (WIRE_SELECT_KERNEL).
[[gnu::always_inline]] inline void whole_segment_speeds(const double* __restrict b, std::size_t n, std::size_t k,
                                                        double (&speed)[kGlPoints]) {
    double d0[3], d1[3], d2[3];
    for (int a = 0; a < 3; ++a) {
        const double p0 = b[a * n + k], p1 = b[(3 + a) * n + k], p2 = b[(6 + a) * n + k], p3 = b[(9 + a) * n + k];
        d0[a] = 3.0 * (p1 - p0);
        d1[a] = 2.0 * (3.0 * (p2 - 2.0 * p1 + p0));
        d2[a] = 3.0 * (p3 - 3.0 * p2 + 3.0 * p1 - p0);
    }
    for (int q = 0; q < kGlPoints; ++q) {
        const double t = 0.0 + 1.0 * kGlX[q];
        const double x = d0[0] + t * (d1[0] + t * d2[0]);
        const double y = d0[1] + t * (d1[1] + t * d2[1]);
        const double z = d0[2] + t * (d1[2] + t * d2[2]);
        speed[q] = std::sqrt(x * x + y * y + z * z);
    }
}

/// Segment k's length (gauss_whole_segments()'s) and u = length u_per_m (integrate()'s constant-radius case).
[[gnu::always_inline]] inline void whole_length(const double* __restrict b, std::size_t n, std::size_t k,
                                               const double* __restrict u_per_m, double* __restrict length_m,
                                               double* __restrict u) {
    double speed[kGlPoints];
    whole_segment_speeds(b, n, k, speed);
    double len = 0.0;
    for (int q = 0; q < kGlPoints; ++q) len += (1.0 * kGlW[q]) * speed[q];  // integrate()'s h w_q, h = 1
    length_m[k] = len;
    u[k] = len * u_per_m[k];
}

/// whole_length() of n segments (a wire of one radius). No select, so no WIRE_SELECT_KERNEL: that attribute keeps
/// the loop from some of its -O3 treatment (15% slower on AVX-512).
WIRE_VECTOR_CLONES void gauss_whole_lengths(const double* __restrict b, std::size_t n,
                                            const double* __restrict u_per_m, double* __restrict length_m,
                                            double* __restrict u) {
    for (std::size_t k = 0; k < n; ++k) whole_length(b, n, k, u_per_m, length_m, u);
}

/// gauss_whole_lengths() and detail::boundary_tangents() in one pass over the segments (a wire of one radius whose
/// intervals cross segment boundaries: the common moving wire): the same operations.
WIRE_VECTOR_CLONES void gauss_whole_lengths_and_tangents(const double* __restrict b, std::size_t n,
                                                         const double* __restrict u_per_m, double* __restrict length_m,
                                                         double* __restrict u, double* __restrict tangent) {
    for (std::size_t k = 0; k < n; ++k) {
        whole_length(b, n, k, u_per_m, length_m, u);
        detail::boundary_tangent(b, n, k, tangent, tangent + n, tangent + 2 * n, tangent + 3 * n);
    }
}

/// SegmentCoeffs::load_radius()'s u_per_m for n segments of radius r_safe (> 0) from their stretch: 1 / (2 pi stretch
/// r_safe), the same operations, in lanes. Returns whether every stretch is positive and finite (the common case);
/// if not, the caller recomputes with load_radius()'s replacement for the others (one pass for test and values: the
/// test was a pass and a call of its own).
WIRE_VECTOR_CLONES bool plain_u_per_m(const float* __restrict stretch, std::size_t n, double r_safe,
                                      double* __restrict u_per_m) {
    // Integer or-reductions vectorize, bool and-reductions do not. A float is positive and finite as a double
    // exactly when it is as a float.
    unsigned bad = 0;
    for (std::size_t k = 0; k < n; ++k) {
        const float st = stretch[k];
        bad |= ((st > 0.0f) & (st <= std::numeric_limits<float>::max())) ? 0u : 1u;
        u_per_m[k] = 1.0 / (2.0 * std::numbers::pi * static_cast<double>(st) * r_safe);
    }
    return bad == 0;
}

/// Whether v[1 .. n - 1] all equal v[0] (false where one of them is NaN); without an early exit, so in lanes.
WIRE_VECTOR_CLONES bool all_equal(const float* __restrict v, std::size_t n) {
    unsigned differ = 0;  // an integer or-reduction vectorizes, a bool and-reduction does not
    for (std::size_t k = 1; k < n; ++k) differ |= v[k] == v[0] ? 0u : 1u;
    return differ == 0;
}

/// integrate(SegmentCoeffs(curve, k), 0.0, 1.0) for the n segments laid out by detail::transpose_segments(): the
/// same operations in the same order. constant[k] != 0: a constant-radius segment, u = length u_per_m[k]; else u
/// integrates speed / radius (the segment's radius polynomial r0 + t (r1 + t (r2 + t r3))), times u_scale[k].
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL void gauss_whole_segments(const double* __restrict b, std::size_t n,
                                             const double* __restrict constant, const double* __restrict u_per_m, const double* __restrict u_scale,
                                             const double* __restrict r0, const double* __restrict r1,
                                             const double* __restrict r2, const double* __restrict r3,
                                             double* __restrict length_m, double* __restrict u) {
    for (std::size_t k = 0; k < n; ++k) {
        double speeds[kGlPoints];
        whole_segment_speeds(b, n, k, speeds);
        double len = 0.0, u_varying = 0.0;
        for (int q = 0; q < kGlPoints; ++q) {
            const double t = 0.0 + 1.0 * kGlX[q];  // integrate()'s ta + h x_q with ta = 0, h = 1
            const double w = 1.0 * kGlW[q];
            const double speed = speeds[q];
            len += w * speed;
            const double radius = r0[k] + t * (r1[k] + t * (r2[k] + t * r3[k]));
            u_varying += w * speed / (radius < 1e-30 ? 1e-30 : radius);  // std::max(radius, 1e-30)
        }
        length_m[k] = len;
        u[k] = constant[k] != 0.0 ? len * u_per_m[k] : u_varying * u_scale[k];
    }
}

/// What build_rings computes at every ring, for `count` rings whose segments' control points are laid out by
/// detail::gather_segments() in b and whose radius polynomials are in r (4 arrays: r0 .. r3): SegmentCoeffs'
/// load_geometry(), position(), derivative(), second_derivative() and radius() at t[i], the same operations in the
/// same order, in lanes. Out: the centre minus the origin o (b0 at t = 0, b3 at t = 1), B'(t) times the reciprocal
/// of its length, the radius, fold (1: radius >= curvature radius, see build_rings) and slow (1: |B'| not above
/// SegmentCoeffs::tiny_bound: the caller decides the tangent as build_rings does there).
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL void ring_samples(
    const double* __restrict b, std::size_t count, const double* __restrict t, const double* __restrict r, double ox,
    double oy, double oz, double* __restrict cx, double* __restrict cy, double* __restrict cz, double* __restrict tx,
    double* __restrict ty, double* __restrict tz, double* __restrict radius_out, double* __restrict fold,
    double* __restrict slow) {
    for (std::size_t i = 0; i < count; ++i) {
        const double ti = t[i];
        double c[3], d[3], e[3], norm0 = 0.0, norm1 = 0.0, norm2 = 0.0;
        for (int a = 0; a < 3; ++a) {
            const double b0 = b[a * count + i], b1 = b[(3 + a) * count + i];
            const double b2 = b[(6 + a) * count + i], b3 = b[(9 + a) * count + i];
            const double p1 = 3.0 * (b1 - b0);
            const double p2 = 3.0 * (b2 - 2.0 * b1 + b0);
            const double p3 = b3 - 3.0 * b2 + 3.0 * b1 - b0;
            const double d0 = p1, d1 = 2.0 * p2, d2 = 3.0 * p3;
            const double position = b0 + ti * (p1 + ti * (p2 + ti * p3));
            c[a] = ti == 0.0 ? b0 : (ti == 1.0 ? b3 : position);
            d[a] = d0 + ti * (d1 + ti * d2);
            e[a] = d1 + ti * (2.0 * d2);
            // norm1() of d0, d1, d2: |x| + |y| + |z| (0 + |x| is |x|, bit for bit). std::fabs, not std::abs: a
            // C++ function, not inlined into this kernel (WIRE_SELECT_KERNEL), where the C library's builtin is.
            norm0 += std::fabs(d0);
            norm1 += std::fabs(d1);
            norm2 += std::fabs(d2);
        }
        cx[i] = c[0] - ox;
        cy[i] = c[1] - oy;
        cz[i] = c[2] - oz;
        const double tiny_bound = 1e-9 * (norm0 + norm1 + norm2);
        const double speed2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const double speed = std::sqrt(speed2);
        const double inv = 1.0 / speed;
        tx[i] = d[0] * inv;
        ty[i] = d[1] * inv;
        tz[i] = d[2] * inv;
        const double radius = r[i] + ti * (r[count + i] + ti * (r[2 * count + i] + ti * r[3 * count + i]));
        radius_out[i] = radius;
        const double bx = d[1] * e[2] - e[1] * d[2];  // glm::cross(d, e)
        const double by = d[2] * e[0] - e[2] * d[0];
        const double bz = d[0] * e[1] - e[0] * d[1];
        const double bend2 = bx * bx + by * by + bz * bz;
        fold[i] = (radius * radius * bend2 >= speed2 * speed2 * speed2 && bend2 > 0.0) ? 1.0 : 0.0;
        slow[i] = speed > tiny_bound ? 0.0 : 1.0;
    }
}

/// One radius on every node (or none).
bool uniform_radius(const Curve& curve) { return all_equal(curve.radius_m.data(), curve.radius_m.size()); }

/// n rounded up to whole vectors of 8 lanes (AVX-512 doubles).
std::size_t whole_vectors(std::size_t n) { return (n + 7) / 8 * 8; }

/// Fills entries n .. stride - 1 of `arrays` arrays of `stride` with each array's entry n - 1 (n > 0).
void pad(double* a, std::size_t arrays, std::size_t n, std::size_t stride) {
    for (std::size_t j = 0; j < arrays && n != 0; ++j) {
        std::fill(a + j * stride + n, a + (j + 1) * stride, a[j * stride + n - 1]);
    }
}

/// Per-segment tables of a wire, from one structure-of-arrays copy of its segments, in passes the compiler
/// vectorizes: integrate(SegmentCoeffs(curve, k), 0.0, 1.0) of every segment k bit for bit (a wire whose LOD puts
/// fewer rings than nodes crosses most segments whole: this is their arc length and u), and, when asked, the unit
/// tangent at every segment's start (the frames carry the normal through the boundaries an interval crosses).
/// Every array has `stride` entries per quantity: segment_count() rounded up to whole vectors of 8 lanes, the rest
/// copies of the last segment's, so the kernels run no remainder loop (their results there are never read).
struct SegmentTables {
    std::vector<double> soa;       // detail::transpose_segments(), 12 arrays
    std::vector<double> length_m;  // per segment
    std::vector<double> u;         // per segment
    std::vector<double> tangent;   // 4 arrays: FrameInput::boundary_tangent
    std::vector<double> radius;    // 7 arrays: constant, u_per_m, u_scale, r0, r1, r2, r3
    std::vector<double> ring_data;         // build_rings' per-ring scratch
    std::vector<uint32_t> ring_segment;    // build_rings' per-ring segment index
    std::size_t stride = 0;
    void build(const Curve& curve, bool with_tangents) {
        const std::size_t n = curve.segment_count();
        const std::size_t sn = whole_vectors(n);
        stride = sn;
        soa.resize(12 * sn);
        length_m.resize(sn);
        u.resize(sn);
        radius.resize(7 * sn);
        tangent.resize(with_tangents ? 4 * sn : 0);
        detail::transpose_segments(curve.segments.data(), n, soa.data(), sn);
        pad(soa.data(), 12, n, sn);
        double* const constant = radius.data();
        double* const u_per_m = constant + sn;
        double* const u_scale = u_per_m + sn;
        double* const r0 = u_scale + sn;
        double* const r1 = r0 + sn;
        double* const r2 = r1 + sn;
        double* const r3 = r2 + sn;
        uniform = uniform_radius(curve);
        if (uniform) {
            // One radius (or none): every segment is constant-radius (both node slopes 0, so r1 = r2 = r3 = 0
            // exactly); SegmentCoeffs::load's u_per_m without its per-segment slope work, and only it is kept.
            uniform_r = curve.radius_m.empty() ? 1.0 : static_cast<double>(curve.radius_m[0]);
            const double r_safe = std::max(uniform_r, 1e-30);
            const std::size_t n_stretch = std::min(curve.stretch.size(), n);
            // Every stretch given, positive and finite: the common case, in lanes.
            const bool plain = n_stretch == n && plain_u_per_m(curve.stretch.data(), n, r_safe, u_per_m);
            if (!plain) {
                for (std::size_t k = 0; k < n; ++k) {
                    double stretch = k < n_stretch ? static_cast<double>(curve.stretch[k]) : 1.0;
                    stretch = (stretch > 0.0 && stretch <= std::numeric_limits<double>::max()) ? stretch : 1.0;
                    u_per_m[k] = 1.0 / (2.0 * std::numbers::pi * stretch * r_safe);
                }
            }
        } else {
            // SegmentCoeffs::load's radius polynomial and texture scale, segment by segment (the node slopes are
            // branchy: this loop stays scalar; the quadrature is the vector part).
            SegmentCoeffs c(curve, 0);
            for (std::size_t k = 0; k < n; ++k) {
                if (k != 0) c.load(curve, static_cast<uint32_t>(k));
                constant[k] = c.constant_radius ? 1.0 : 0.0;
                u_per_m[k] = c.u_per_m;
                u_scale[k] = c.u_scale;
                r0[k] = c.r0;
                r1[k] = c.r1;
                r2[k] = c.r2;
                r3[k] = c.r3;
            }
        }
        // Padded for the kernels below: of one radius, only u_per_m is written and read.
        if (uniform) {
            pad(u_per_m, 1, n, sn);
        } else {
            pad(radius.data(), 7, n, sn);
        }
        if (uniform && with_tangents) {
            gauss_whole_lengths_and_tangents(soa.data(), sn, u_per_m, length_m.data(), u.data(), tangent.data());
            return;
        }
        if (uniform) {
            gauss_whole_lengths(soa.data(), sn, u_per_m, length_m.data(), u.data());
        } else {
            gauss_whole_segments(soa.data(), sn, constant, u_per_m, u_scale, r0, r1, r2, r3, length_m.data(), u.data());
        }
        if (with_tangents) {
            detail::boundary_tangents(soa.data(), sn, tangent.data(), tangent.data() + sn, tangent.data() + 2 * sn,
                                      tangent.data() + 3 * sn);
        }
    }
    bool uniform = false;     // uniform_radius(): only u_per_m is kept
    double uniform_r = 0.0;   // its radius
    /// Whether length_m and u equal integrate(SegmentCoeffs(curve, k), 0.0, 1.0) for every segment k bit for bit: not
    /// for a uniform infinite radius (load()'s node slopes are then NaN: not a constant-radius segment).
    [[nodiscard]] bool exact() const { return !uniform || std::isfinite(uniform_r); }
    /// The radius polynomials (load_radius()'s r0 .. r3) of segments index[0 .. count - 1] into r, 4 arrays of count.
    void radius_of(const uint32_t* index, std::size_t count, double* r) const {
        const std::size_t n = stride;
        if (uniform) {
            std::fill(r, r + count, uniform_r);
            std::fill(r + count, r + 4 * count, 0.0);
            return;
        }
        for (std::size_t i = 0; i < count; ++i) {
            for (std::size_t a = 0; a < 4; ++a) r[a * count + i] = radius[(3 + a) * n + index[i]];
        }
    }
    /// Segment k's radius polynomial and texture scale into c, as SegmentCoeffs::load() computes them.
    void load_radius(std::size_t k, SegmentCoeffs& c) const {
        const std::size_t n = stride;
        const double* r = radius.data();
        if (uniform) {
            c.load_radius(uniform_r, 0.0, 0.0, 0.0, 0.0, r[n + k], true);
        } else {
            c.load_radius(r[3 * n + k], r[4 * n + k], r[5 * n + k], r[6 * n + k], r[2 * n + k], r[n + k], r[k] != 0.0);
        }
    }
};

}  // namespace

double radius_at(const Curve& curve, uint32_t segment, double t) {
    return SegmentCoeffs(curve, segment).radius(t);
}

void build_rings(const Curve& curve, std::span<const RingParam> params, const RingSettings& settings, RingSet& out) {
    const std::size_t n = params.size();
    out.closed = curve.closed;
    out.params.assign(params.begin(), params.end());
    out.rings.resize(n);
    out.frames.resize(n);
    out.centre_m.resize(n);
    out.tangent_scratch.resize(n);
    const std::size_t extra = curve.closed && n > 0 ? 1 : 0;
    out.arc_length_m.resize(n + extra);
    out.u.resize(n + extra);
    out.fold_count = 0;
    out.first_fold_ring = 0;
    out.length_m = 0.0;
    if (n == 0) {
        out.frame_stats = FrameStats{};
        return;
    }

    out.origin_m = position(curve.segments[params[0].segment], params[0].t);
    // Whole segments (crossed ones, and a ring at t = 0 whose next ring is on a later segment): from one table.
    thread_local SegmentTables tables;  // grows once per thread, then reused
    // Boundary tangents only where some interval crosses a segment boundary (LOD below node resolution; the closed
    // wire's wrap step computes its own).
    bool crossing = false;
    for (std::size_t i = 1; i < n && !crossing; ++i) {
        crossing = params[i].segment + (params[i].t > 0.0 ? 1u : 0u) > params[i - 1].segment + 1u;
    }
    tables.build(curve, crossing);
    // The segment a partial interval or a slow tangent of ring `ring` is evaluated on, loaded when first needed
    // (rarely): for the leading rings on ring 0's segment by load() itself, for the others with the table's radius
    // polynomial (no node slopes again): the coefficients each ring had when every ring loaded its segment.
    std::size_t lead = 1;
    while (lead < n && params[lead].segment == params[0].segment) ++lead;
    SegmentCoeffs seg;
    uint32_t seg_index = params[0].segment;
    int loaded = -1;  // 0: load() of ring 0's segment, 1: the table's for seg_index
    auto use_segment = [&](std::size_t ring) {
        const uint32_t i = params[ring].segment;
        if (ring < lead) {
            if (loaded != 0) seg.load(curve, i);
            loaded = 0;
        } else if (loaded != 1 || i != seg_index) {
            seg.load_geometry(curve.segments[i]);
            tables.load_radius(i, seg);
            loaded = 1;
        }
        seg_index = i;
    };
    const std::vector<double>& whole_length_m = tables.length_m;
    const std::vector<double>& whole_u = tables.u;
    // Centre, tangent, radius and fold test of every ring in lanes (ring_samples), from the rings' segments
    // gathered into structure-of-arrays scratch with their radius polynomials.
    std::vector<double>& ring_data = tables.ring_data;
    std::vector<uint32_t>& ring_segment = tables.ring_segment;
    const std::size_t rn = whole_vectors(n);  // whole vectors, the rest copies of the last ring (see SegmentTables)
    ring_segment.resize(rn);
    ring_data.resize(26 * rn);
    double* const ring_b = ring_data.data();      // 12 arrays: the rings' segments, gather_segments()
    double* const ring_t = ring_b + 12 * rn;      // t
    double* const ring_r = ring_t + rn;           // 4 arrays: radius polynomial r0 .. r3
    double* const sample = ring_r + 4 * rn;       // 9 arrays: ring_samples()'s output
    for (std::size_t i = 0; i < rn; ++i) {
        const RingParam& p = params[std::min(i, n - 1)];
        ring_segment[i] = p.segment;
        ring_t[i] = p.t;
    }
    tables.radius_of(ring_segment.data(), rn, ring_r);
    detail::gather_segments(curve.segments.data(), ring_segment.data(), rn, ring_b);
    // The rings on ring 0's segment use load()'s radius polynomial, as use_segment() gives it to them (the table's
    // is the same unless a radius is not finite).
    SegmentCoeffs first;
    first.load_polynomial(curve, params[0].segment);
    for (std::size_t i = 0; i < lead; ++i) {
        ring_r[i] = first.r0;
        ring_r[rn + i] = first.r1;
        ring_r[2 * rn + i] = first.r2;
        ring_r[3 * rn + i] = first.r3;
    }
    ring_samples(ring_b, rn, ring_t, ring_r, out.origin_m.x, out.origin_m.y, out.origin_m.z, sample, sample + rn,
                 sample + 2 * rn, sample + 3 * rn, sample + 4 * rn, sample + 5 * rn, sample + 6 * rn, sample + 7 * rn,
                 sample + 8 * rn);
    double s = 0.0;
    double u = settings.u_start;
    for (std::size_t i = 0; i < n; ++i) {
        const RingParam p = params[i];
        out.centre_m[i] = glm::dvec3(sample[i], sample[rn + i], sample[2 * rn + i]);
        if (sample[8 * rn + i] == 0.0) {
            out.tangent_scratch[i] = glm::dvec3(sample[3 * rn + i], sample[4 * rn + i], sample[5 * rn + i]);
        } else {  // not surely above the noise: SegmentCoeffs::tiny_speed() decides (rare)
            use_segment(i);
            const glm::dvec3 d1 = seg.derivative(p.t);
            const double speed = std::sqrt(glm::dot(d1, d1));
            // vanishing derivative: the one-sided limits of unit_tangent()
            out.tangent_scratch[i] = speed > seg.tiny_speed() ? d1 * (1.0 / speed)
                                                              : unit_tangent(curve.segments[p.segment], p.t);
        }
        // Fold: the inner side of the tube crosses itself where the radius reaches the curvature radius
        // |B'|^3 / |B' x B''| (ring_samples compares them squared, without a root).
        if (sample[7 * rn + i] != 0.0) {
            if (out.fold_count++ == 0) {
                out.first_fold_ring = static_cast<uint32_t>(i);
            }
        }
        Ring& ring = out.rings[i];
        ring.radius_m = static_cast<float>(sample[6 * rn + i]);
        ring.segment = p.segment;

        // Arc length and u of the interval to the next ring: the rest of this segment, every segment the interval
        // crosses (LOD below the node resolution gives segments no ring of their own), and the next ring's part of
        // its segment; for a closed wire the last interval returns to ring 0.
        if (i == 0) {
            out.arc_length_m[0] = 0.0;
            out.u[0] = u;
        }
        if (i + 1 < n || extra) {
            const bool wrap = i + 1 == n;
            const RingParam b = wrap ? params[0] : params[i + 1];
            const double tb = (!wrap && b.segment == p.segment) ? b.t : 1.0;
            Interval iv{whole_length_m[p.segment], whole_u[p.segment]};
            if (p.t != 0.0 || tb != 1.0) {
                use_segment(i);
                iv = integrate(seg, p.t, tb);
            }
            if (wrap || b.segment != p.segment) {
                const std::size_t end = wrap ? curve.segment_count() : b.segment;
                for (std::size_t k = p.segment + 1; k < end; ++k) {  // crossed segments, whole
                    iv.length_m += whole_length_m[k];
                    iv.u += whole_u[k];
                }
            }
            if (!wrap && b.segment != p.segment && b.t > 0.0) {  // custom params: the next segment's part too
                // At t = 1 (an open wire's last ring, on a segment without a ring of its own): the whole segment,
                // from the table.
                const Interval ib = b.t == 1.0 && tables.exact()
                                        ? Interval{whole_length_m[b.segment], whole_u[b.segment]}
                                        : integrate(SegmentCoeffs(curve, b.segment), 0.0, b.t);
                iv.length_m += ib.length_m;
                iv.u += ib.u;
            }
            s += iv.length_m;
            u += iv.u;
            out.arc_length_m[i + 1] = s;
            out.u[i + 1] = u;
        }
    }
    out.length_m = s;

    const FrameInput in{&curve,           params,         out.origin_m, out.centre_m, out.tangent_scratch,
                        out.arc_length_m, tables.tangent, tables.soa};
    out.frame_stats = compute_frames(in, settings.frames, out.frames);

    for (std::size_t i = 0; i < n; ++i) {
        Ring& r = out.rings[i];
        r.centre_m = glm::vec3(out.centre_m[i]);
        r.normal = glm::vec3(out.frames[i].r);
        r.binormal = glm::vec3(out.frames[i].s);
        r.u = static_cast<float>(out.u[i]);
    }
}

}  // namespace wire
