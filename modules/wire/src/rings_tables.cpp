// The rings' per-segment tables and lane kernels: Gauss-Legendre arc length and texture u of whole segments, the
// radius tables, and the per-ring samples (centre, tangent, radius, fold) build_rings reads.
#include "rings_internal.hpp"

#include "wire/detail/segment_soa.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES, WIRE_SELECT_KERNEL

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace wire::detail {
namespace {

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
WIRE_VECTOR_CLONES void gauss_whole_lengths(const double* __restrict b, std::size_t n, const double* __restrict u_per_m,
                                            double* __restrict length_m, double* __restrict u) {
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
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL void gauss_whole_segments(
    const double* __restrict b, std::size_t n, const double* __restrict constant, const double* __restrict u_per_m,
    const double* __restrict u_scale, const double* __restrict r0, const double* __restrict r1,
    const double* __restrict r2, const double* __restrict r3, double* __restrict length_m, double* __restrict u) {
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

/// One radius on every node (or none).
bool uniform_radius(const Curve& curve) {
    return all_equal(curve.radius_m.data(), curve.radius_m.size());
}

/// Fills entries n .. stride - 1 of `arrays` arrays of `stride` with each array's entry n - 1 (n > 0).
void pad(double* a, std::size_t arrays, std::size_t n, std::size_t stride) {
    for (std::size_t j = 0; j < arrays && n != 0; ++j) {
        std::fill(a + j * stride + n, a + (j + 1) * stride, a[j * stride + n - 1]);
    }
}

}  // namespace

/// What build_rings computes at every ring, for `count` rings whose segments' control points are laid out by
/// detail::gather_segments() in b and whose radius polynomials are in r (4 arrays: r0 .. r3): SegmentCoeffs'
/// load_geometry(), position(), derivative(), second_derivative() and radius() at t[i], the same operations in the
/// same order, in lanes. Out: the centre minus the origin o (b0 at t = 0, b3 at t = 1), B'(t) times the reciprocal
/// of its length, the radius, fold (1: radius >= curvature radius, see build_rings) and slow (1: |B'| not above
/// SegmentCoeffs::tiny_bound: the caller decides the tangent as build_rings does there).
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL void ring_samples(const double* __restrict b, std::size_t count,
                                                        const double* __restrict t, const double* __restrict r,
                                                        double ox, double oy, double oz, double* __restrict cx,
                                                        double* __restrict cy, double* __restrict cz,
                                                        double* __restrict tx, double* __restrict ty,
                                                        double* __restrict tz, double* __restrict radius_out,
                                                        double* __restrict fold, double* __restrict slow) {
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

void SegmentTables::build(const Curve& curve, bool with_tangents) {
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

}  // namespace wire::detail
