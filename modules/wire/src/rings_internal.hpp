// Internal: what build_rings (rings.cpp) shares with the per-segment tables and lane kernels (rings_tables.cpp):
// the Gauss-Legendre rule, the per-segment coefficients, the tables and the per-ring samples kernel.
#pragma once

#include "wire/rings.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <vector>

namespace wire::detail {

// 3-point Gauss-Legendre on [0,1]: nodes (1 + x_k)/2, weights w_k/2. Exact for polynomials of degree <= 5; on
// the speed |B'(t)| of a smooth cubic over 1/8 of a segment the relative error is ~1e-10 (tests bound it at 1e-7
// for 4 rings per segment on a 72-degree-per-segment helix).
constexpr int kGlPoints = 3;
constexpr double kGlX[kGlPoints] = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr double kGlW[kGlPoints] = {0.2777777777777778, 0.4444444444444444, 0.2777777777777778};

/// Fritsch-Carlson-limited slope (per unit t) at node k from its neighbours' radii.
double node_slope(const Curve& curve, std::size_t k);

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
    double tiny_bound;  // >= tiny_speed() (1-norms instead of lengths): a faster speed is not tiny
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

/// What build_rings computes at every ring, for `count` rings whose segments' control points are laid out by
/// detail::gather_segments() in b and whose radius polynomials are in r (4 arrays: r0 .. r3): SegmentCoeffs'
/// load_geometry(), position(), derivative(), second_derivative() and radius() at t[i], the same operations in the
/// same order, in lanes. Out: the centre minus the origin o (b0 at t = 0, b3 at t = 1), B'(t) times the reciprocal
/// of its length, the radius, fold (1: radius >= curvature radius, see build_rings) and slow (1: |B'| not above
/// SegmentCoeffs::tiny_bound: the caller decides the tangent as build_rings does there).
void ring_samples(const double* __restrict b, std::size_t count, const double* __restrict t, const double* __restrict r,
                  double ox, double oy, double oz, double* __restrict cx, double* __restrict cy, double* __restrict cz,
                  double* __restrict tx, double* __restrict ty, double* __restrict tz, double* __restrict radius_out,
                  double* __restrict fold, double* __restrict slow);

/// n rounded up to whole vectors of 8 lanes (AVX-512 doubles).
inline std::size_t whole_vectors(std::size_t n) {
    return (n + 7) / 8 * 8;
}

/// Per-segment tables of a wire, from one structure-of-arrays copy of its segments, in passes the compiler
/// vectorizes: integrate(SegmentCoeffs(curve, k), 0.0, 1.0) of every segment k bit for bit (a wire whose LOD puts
/// fewer rings than nodes crosses most segments whole: this is their arc length and u), and, when asked, the unit
/// tangent at every segment's start (the frames carry the normal through the boundaries an interval crosses).
/// Every array has `stride` entries per quantity: segment_count() rounded up to whole vectors of 8 lanes, the rest
/// copies of the last segment's, so the kernels run no remainder loop (their results there are never read).
struct SegmentTables {
    std::vector<double> soa;             // detail::transpose_segments(), 12 arrays
    std::vector<double> length_m;        // per segment
    std::vector<double> u;               // per segment
    std::vector<double> tangent;         // 4 arrays: FrameInput::boundary_tangent
    std::vector<double> radius;          // 7 arrays: constant, u_per_m, u_scale, r0, r1, r2, r3
    std::vector<double> ring_data;       // build_rings' per-ring scratch
    std::vector<uint32_t> ring_segment;  // build_rings' per-ring segment index
    std::size_t stride = 0;
    void build(const Curve& curve, bool with_tangents);
    bool uniform = false;    // uniform_radius(): only u_per_m is kept
    double uniform_r = 0.0;  // its radius
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

}  // namespace wire::detail
