// Parallel transport of a normal along the curve: the seed normal and unit tangent, the double-reflection step with
// hairpin subdivision, its lane kernels (step matrices, segment-start points), the pass-2 carry of compute_frames;
// the rotation and projection baselines.
#include "frames_internal.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace wire {

using detail::max_abs;

glm::dvec3 seed_normal(const glm::dvec3& t) {
    const glm::dvec3 a = glm::abs(t);
    glm::dvec3 e{0.0};
    if (a.x <= a.y && a.x <= a.z) {
        e.x = 1.0;
    } else if (a.y <= a.z) {
        e.y = 1.0;
    } else {
        e.z = 1.0;
    }
    return glm::normalize(e - glm::dot(e, t) * t);
}

glm::dvec3 unit_tangent(const CubicBezier& c, double t, bool* degenerate) {
    const double extent = std::max({max_abs(c.b1 - c.b0), max_abs(c.b2 - c.b0), max_abs(c.b3 - c.b0)});
    // Derivatives below this are rounding noise of the control-point differences (or exactly zero).
    const double tiny = 1e-10 * extent + 1e-15 * max_abs(c.b0) + 1e-300;
    const glm::dvec3 d1 = derivative(c, t);
    const double l1 = glm::length(d1);
    if (l1 > tiny) {
        if (degenerate) *degenerate = false;
        return d1 / l1;
    }
    if (degenerate) *degenerate = true;
    // One-sided limits: B'(t + h) ~ h B''(t); at t = 1 only the left side exists, B'(1 - h) ~ -h B''(1).
    const double side = t >= 1.0 ? -1.0 : 1.0;
    const glm::dvec3 d2 = side * second_derivative(c, t);
    const double l2 = glm::length(d2);
    if (l2 > tiny) {
        return d2 / l2;
    }
    const glm::dvec3 d3 = 6.0 * (c.b3 - 3.0 * c.b2 + 3.0 * c.b1 - c.b0);  // B'(t+h) ~ h^2/2 B'''
    const double l3 = glm::length(d3);
    if (l3 > tiny) {
        return d3 / l3;
    }
    const glm::dvec3 chord = c.b3 - c.b0;
    const double lc = glm::length(chord);
    if (lc > tiny) {
        return chord / lc;
    }
    return glm::dvec3(0.0);
}

namespace detail {
namespace {

/// Steps whose tangent turns by more than 45 degrees are split (see Transporter::reflect).
constexpr double kSplitCos = 0.70710678118654752;

/// Minimal rotation taking unit t0 to unit t1, applied to r0 (the rotation method). Antiparallel tangents: the
/// rotation by pi about r0's direction (keeps r, flips the binormal), the minimum the geometry allows.
glm::dvec3 rotate_minimal(const glm::dvec3& t0, const glm::dvec3& t1, const glm::dvec3& r0) {
    const double c = glm::dot(t0, t1);
    if (c < -1.0 + 1e-12) {
        return orthonormalize(r0, t1);
    }
    const glm::dvec3 v = glm::cross(t0, t1);  // axis * sin(angle)
    // Rodrigues with cos = c, axis*sin = v: R r = c r + v x r + v (v.r) / (1 + c).
    return c * r0 + glm::cross(v, r0) + v * (glm::dot(v, r0) / (1.0 + c));
}

enum class Mirrors : uint8_t { ok, split, degenerate };

/// The two mirrors of the double-reflection step a -> b: each reflection is r - f (v.r) v with f = 2 / |v|^2 (no
/// normalization, so no square root). `split` (mirrors valid) when the hairpin guard wants the step subdivided;
/// `degenerate` (invalid) when the tangent reverses at a repeated point or the second mirror vanishes.
struct MirrorPair {
    glm::dvec3 v1{}, v2{};
    double f1 = 0.0, f2 = 0.0;
};

Mirrors mirrors(const Sample& a, const Sample& b, double noise, MirrorPair& m) {
    glm::dvec3 v1 = b.x - a.x;
    double c1 = glm::dot(v1, v1);
    // Below the rounding noise of the positions the chord has no direction: a repeated point. The reflection
    // about the plane normal to t0 + t1 takes t0 to -t1 and the second one (about t1) to t1, as needed.
    if (c1 <= noise * noise * 64.0) {
        v1 = a.t + b.t;
        c1 = glm::dot(v1, v1);
        if (c1 < 1e-20) {
            return Mirrors::degenerate;
        }
    }
    const double f1 = 2.0 / c1;
    const glm::dvec3 tl = a.t - (f1 * glm::dot(v1, a.t)) * v1;  // t0 reflected
    const glm::dvec3 v2 = b.t - tl;
    const double c2 = glm::dot(v2, v2);
    if (c2 < 1e-20) {
        return Mirrors::degenerate;
    }
    m = MirrorPair{v1, v2, f1, 2.0 / c2};
    // Hairpin guard. c2 ~ 0: the tangent turns "the wrong way" within the step (a loop), the second mirror is
    // ill-conditioned. A turn of more than 45 degrees in one step (a hairpin under coarse sampling): the
    // method's error grows with the turn per step. Either way the step is split at its parameter midpoint; at a
    // cusp only the half containing it keeps splitting, so the cost is O(depth), not O(2^depth).
    return (c2 < 0.1 || glm::dot(a.t, b.t) < kSplitCos) ? Mirrors::split : Mirrors::ok;
}

glm::dvec3 reflect_pair(const MirrorPair& m, glm::dvec3 r) {
    r -= (m.f1 * glm::dot(m.v1, r)) * m.v1;
    r -= (m.f2 * glm::dot(m.v2, r)) * m.v2;
    return r;
}

}  // namespace

/// r made orthogonal to unit t and normalized; `fallback` (also made orthogonal) if r is (nearly) parallel to t.
glm::dvec3 orthonormalize(const glm::dvec3& r, const glm::dvec3& t) {
    glm::dvec3 p = r - glm::dot(r, t) * t;
    const double len2 = glm::dot(p, p);
    if (len2 > 1e-20) {
        return p * (1.0 / std::sqrt(len2));
    }
    return seed_normal(t);
}

/// The double-reflection step from point q - 1 to point q (positions x, y, z relative to the rings' origin, unit
/// tangents tx, ty, tz) for q = 1 .. m - 1 (m - 1 a multiple of 8), as one matrix (column-major entries e00 .. e22:
/// e<column><row>), with the operations mirrors() and the step's matrix take, branch-free so the loop vectorizes.
/// special = 1 where mirrors() would not answer ok (repeated point with reversing tangent, vanishing or
/// ill-conditioned second mirror, a turn over 45 degrees) or the matrix is not a number: the guarded path takes
/// those steps. Out: blocks of 8 steps (see step_entries), 10 rows of 8 lanes each: e00, e01, e02, e10, ... e22,
/// special. In blocks the carry finds a step's 10 numbers at fixed distances from one pointer (from 10 arrays of
/// a wire-dependent stride it computed 10 addresses a step).
WIRE_VECTOR_CLONES void step_matrices(const double* __restrict x, const double* __restrict y,
                                      const double* __restrict z, const double* __restrict tx,
                                      const double* __restrict ty, const double* __restrict tz, std::size_t m,
                                      double origin_noise, double* __restrict blocks) {
    for (std::size_t block = 0; block < (m - 1) / 8; ++block) {
        double* __restrict const e00 = blocks + 80 * block;
        double* __restrict const e01 = e00 + 8;
        double* __restrict const e02 = e00 + 16;
        double* __restrict const e10 = e00 + 24;
        double* __restrict const e11 = e00 + 32;
        double* __restrict const e12 = e00 + 40;
        double* __restrict const e20 = e00 + 48;
        double* __restrict const e21 = e00 + 56;
        double* __restrict const e22 = e00 + 64;
        double* __restrict const special = e00 + 72;
        for (std::size_t lane = 0; lane < 8; ++lane) {
            const std::size_t q = 1 + 8 * block + lane;
            const double ax = x[q - 1], ay = y[q - 1], az = z[q - 1];
            const double bx = x[q], by = y[q], bz = z[q];
            const double atx = tx[q - 1], aty = ty[q - 1], atz = tz[q - 1];
            const double btx = tx[q], bty = ty[q], btz = tz[q];
            // Transporter::noise()
            const double noise = origin_noise + 1e-13 * (max3(std::abs(ax), std::abs(ay), std::abs(az)) +
                                                         max3(std::abs(bx), std::abs(by), std::abs(bz)));
            double v1x = bx - ax, v1y = by - ay, v1z = bz - az;
            double c1 = v1x * v1x + v1y * v1y + v1z * v1z;
            const bool repeated = c1 <= noise * noise * 64.0;
            const double sx = atx + btx, sy = aty + bty, sz = atz + btz;
            const double cs = sx * sx + sy * sy + sz * sz;
            v1x = repeated ? sx : v1x;
            v1y = repeated ? sy : v1y;
            v1z = repeated ? sz : v1z;
            c1 = repeated ? cs : c1;
            const double f1 = 2.0 / c1;
            const double d1 = f1 * (v1x * atx + v1y * aty + v1z * atz);
            const double v2x = btx - (atx - d1 * v1x), v2y = bty - (aty - d1 * v1y), v2z = btz - (atz - d1 * v1z);
            const double c2 = v2x * v2x + v2y * v2y + v2z * v2z;
            const double f2 = 2.0 / c2;
            const double k = f1 * (v2x * v1x + v2y * v1y + v2z * v1z);
            // Column c: e_c - f1 v1 v1_c - f2 v2 (v2_c - k v1_c), k = f1 (v2.v1).
            const double g1x = f1 * v1x, g2x = f2 * (v2x - k * v1x);
            const double g1y = f1 * v1y, g2y = f2 * (v2y - k * v1y);
            const double g1z = f1 * v1z, g2z = f2 * (v2z - k * v1z);
            const double m00 = 1.0 - (v1x * g1x + v2x * g2x);
            e00[lane] = m00;
            e01[lane] = 0.0 - (v1y * g1x + v2y * g2x);
            e02[lane] = 0.0 - (v1z * g1x + v2z * g2x);
            e10[lane] = 0.0 - (v1x * g1y + v2x * g2y);
            e11[lane] = 1.0 - (v1y * g1y + v2y * g2y);
            e12[lane] = 0.0 - (v1z * g1y + v2z * g2y);
            e20[lane] = 0.0 - (v1x * g1z + v2x * g2z);
            e21[lane] = 0.0 - (v1y * g1z + v2y * g2z);
            e22[lane] = 1.0 - (v1z * g1z + v2z * g2z);
            const bool not_ok = (repeated & (cs < 1e-20)) | (c2 < 1e-20) | (c2 < 0.1) |
                                ((atx * btx + aty * bty + atz * btz) < kSplitCos) | (m00 != m00);
            special[lane] = not_ok ? 1.0 : 0.0;
        }
    }
}

/// The frame points of `count` consecutive segment starts: position b0 - origin and boundary tangent (tx .. tz),
/// read from structure-of-arrays tables. Returns whether some tangent needs the caller's fix-up (its flag `ok` is
/// 0, or it is the zero vector): rare, so tested here, in lanes (integer or-reductions vectorize, bool ones do not).
WIRE_VECTOR_CLONES bool segment_start_points(const double* __restrict b0x, const double* __restrict b0y,
                                             const double* __restrict b0z, const double* __restrict tx,
                                             const double* __restrict ty, const double* __restrict tz,
                                             const double* __restrict ok, double ox, double oy, double oz,
                                             std::size_t count, double* __restrict px, double* __restrict py,
                                             double* __restrict pz, double* __restrict ptx, double* __restrict pty,
                                             double* __restrict ptz) {
    unsigned unfit = 0;
    for (std::size_t j = 0; j < count; ++j) {
        px[j] = b0x[j] - ox;
        py[j] = b0y[j] - oy;
        pz[j] = b0z[j] - oz;
        ptx[j] = tx[j];
        pty[j] = ty[j];
        ptz[j] = tz[j];
        const bool flag_off = !(ok[j] != 0.0);
        const bool zero = (tx[j] == 0.0) & (ty[j] == 0.0) & (tz[j] == 0.0);
        unfit |= (flag_off | zero) ? 1u : 0u;
    }
    return unfit != 0;
}

/// Carries normal r0 at a (on segment seg at parameter ta) to b (at parameter tb of the same segment, or the
/// next ring whose position equals that point).
glm::dvec3 Transporter::step(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb,
                             const Sample& b) {
    switch (method_) {
        case FrameMethod::rotation:
            return orthonormalize(rotate_minimal(a.t, b.t, r0), b.t);
        case FrameMethod::projection:
            return orthonormalize(r0, b.t);
        case FrameMethod::double_reflection:
            break;
    }
    return reflect(seg, ta, a, r0, tb, b, 0);
}

glm::dvec3 Transporter::reflect(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb,
                                const Sample& b, uint32_t depth) {
    MirrorPair mp;
    const Mirrors m = mirrors(a, b, noise(a, b), mp);
    if (m != Mirrors::ok && depth < max_depth_ && in_.curve != nullptr && tb > ta) {
        if (depth == 0) {
            ++stats_.subdivided_steps;
        }
        const CubicBezier& c = in_.curve->segments[seg];
        const double tm = 0.5 * (ta + tb);
        Sample mid{position(c, tm) - in_.origin_m, unit_tangent(c, tm)};
        if (mid.t == glm::dvec3(0.0)) {
            mid.t = a.t;
        }
        const glm::dvec3 rm = reflect(seg, ta, a, r0, tm, mid, depth + 1);
        return reflect(seg, tm, mid, rm, tb, b, depth + 1);
    }
    if (m == Mirrors::degenerate) {  // tangent reverses at a point: the minimal rotation
        ++stats_.fallback_steps;
        return orthonormalize(rotate_minimal(a.t, b.t, r0), b.t);
    }
    // Each reflection preserves length and the pair preserves handedness; re-project against rounding drift.
    return orthonormalize(reflect_pair(mp, r0), b.t);
}

/// Pass 2. A function of its own: inlined into compute_frames, its loop ran out of registers and reloaded its
/// pointers from the stack every step.
void carry_normal(const CarryChain& c) {
    double x = c.r0.x, y = c.r0.y, z = c.r0.z;
    for (std::size_t q = 1; q < c.m; ++q) c.step(q, x, y, z);
}

}  // namespace detail
}  // namespace wire
