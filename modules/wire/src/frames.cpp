// Rotation-minimizing frames by double reflection, hairpin subdivision, closed-loop holonomy removal; baselines.
#include "wire/frames.hpp"
#include "wire/detail/segment_soa.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES
#include "simd/transpose.hpp"

#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

namespace wire {
namespace {

/// Steps whose tangent turns by more than 45 degrees are split (see Transporter::reflect).
constexpr double kSplitCos = 0.70710678118654752;

/// The largest of three magnitudes (no NaN; equal values are equal), without a branch.
double max3(double a, double b, double c) { return std::max(std::max(a, b), c); }

double max_abs(const glm::dvec3& v) { return max3(std::abs(v.x), std::abs(v.y), std::abs(v.z)); }

/// r made orthogonal to unit t and normalized; `fallback` (also made orthogonal) if r is (nearly) parallel to t.
glm::dvec3 orthonormalize(const glm::dvec3& r, const glm::dvec3& t) {
    glm::dvec3 p = r - glm::dot(r, t) * t;
    const double len2 = glm::dot(p, p);
    if (len2 > 1e-20) {
        return p * (1.0 / std::sqrt(len2));
    }
    return seed_normal(t);
}

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

struct Sample {
    glm::dvec3 x;  // position relative to the origin
    glm::dvec3 t;  // unit tangent
};

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

/// The double-reflection step from point q - 1 to point q (positions x, y, z relative to the rings' origin, unit
/// tangents tx, ty, tz) for q = 1 .. m - 1 (m - 1 a multiple of 8), as one matrix (column-major entries e00 .. e22:
/// e<column><row>), with the operations mirrors() and the step's matrix take, branch-free so the loop vectorizes.
/// special = 1 where mirrors() would not answer ok (repeated point with reversing tangent, vanishing or
/// ill-conditioned second mirror, a turn over 45 degrees) or the matrix is not a number: the guarded path takes
/// those steps. Out: blocks of 8 steps (see step_entries), 10 rows of 8 lanes each: e00, e01, e02, e10, ... e22,
/// special. In blocks the carry finds a step's 10 numbers at fixed distances from one pointer (from 10 arrays of
/// a wire-dependent stride it computed 10 addresses a step).
WIRE_VECTOR_CLONES void step_matrices(const double* __restrict x, const double* __restrict y, const double* __restrict z,
                   const double* __restrict tx, const double* __restrict ty, const double* __restrict tz, std::size_t m,
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

/// Step q's 10 numbers in step_matrices()' blocks: entry k (e00, e01, ... e22, special) at [8 k].
inline const double* step_entries(const double* blocks, std::size_t q) {
    return blocks + 80 * ((q - 1) / 8) + (q - 1) % 8;
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

glm::dvec3 reflect_pair(const MirrorPair& m, glm::dvec3 r) {
    r -= (m.f1 * glm::dot(m.v1, r)) * m.v1;
    r -= (m.f2 * glm::dot(m.v2, r)) * m.v2;
    return r;
}

class Transporter {
public:
    Transporter(const FrameInput& in, const FrameSettings& s, FrameStats& stats)
        : in_(in), method_(s.method), max_depth_(s.max_subdivision_depth ? s.max_subdivision_depth : 10),
          stats_(stats), origin_noise_(1e-13 * max_abs(in.origin_m)) {}

    /// Rounding noise of positions near a and b (a chord below it is a repeated point).
    [[nodiscard]] double noise(const Sample& a, const Sample& b) const {
        return origin_noise_ + 1e-13 * (max_abs(a.x) + max_abs(b.x));
    }

    /// Carries normal r0 at a (on segment seg at parameter ta) to b (at parameter tb of the same segment, or the
    /// next ring whose position equals that point).
    glm::dvec3 step(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb, const Sample& b) {
        switch (method_) {
            case FrameMethod::rotation: return orthonormalize(rotate_minimal(a.t, b.t, r0), b.t);
            case FrameMethod::projection: return orthonormalize(r0, b.t);
            case FrameMethod::double_reflection: break;
        }
        return reflect(seg, ta, a, r0, tb, b, 0);
    }

private:
    glm::dvec3 reflect(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb, const Sample& b,
                       uint32_t depth) {
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

    const FrameInput& in_;
    FrameMethod method_;
    uint32_t max_depth_;
    FrameStats& stats_;
    double origin_noise_;
};

}  // namespace

namespace detail {

WIRE_VECTOR_CLONES void boundary_tangents(const double* __restrict b, std::size_t n, double* __restrict tx,
                                          double* __restrict ty, double* __restrict tz, double* __restrict ok) {
    for (std::size_t k = 0; k < n; ++k) boundary_tangent(b, n, k, tx, ty, tz, ok);
}

namespace {

/// transpose_segments() of the segments segment(0) .. segment(n - 1): four at a time by three 4x4 transposes.
template <class Segment>
[[gnu::always_inline]] inline void transpose_of(Segment segment, std::size_t n, std::size_t stride, double* out) {
    static_assert(sizeof(CubicBezier) == 12 * sizeof(double), "CubicBezier: 12 doubles, b0 to b3");
    using V = simd::v4d;  // 4 doubles (two SSE registers on the baseline)
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        const double* in[4] = {&segment(k).b0.x, &segment(k + 1).b0.x, &segment(k + 2).b0.x, &segment(k + 3).b0.x};
        for (std::size_t g = 0; g < 3; ++g) {  // doubles 4g .. 4g + 3 of each of the four segments
            V r[4];
            for (std::size_t s = 0; s < 4; ++s) std::memcpy(&r[s], in[s] + 4 * g, sizeof(V));
            V c[4];
            simd::transpose4x4(r, c);
            for (std::size_t j = 0; j < 4; ++j) std::memcpy(out + (4 * g + j) * stride + k, &c[j], sizeof(V));
        }
    }
    for (; k < n; ++k) {
        const double* in = &segment(k).b0.x;
        for (std::size_t j = 0; j < 12; ++j) out[j * stride + k] = in[j];
    }
}

}  // namespace

WIRE_VECTOR_CLONES void transpose_segments(const CubicBezier* segments, std::size_t n, double* out,
                                           std::size_t stride) {
    transpose_of([segments](std::size_t k) -> const CubicBezier& { return segments[k]; }, n, stride ? stride : n, out);
}

WIRE_VECTOR_CLONES void gather_segments(const CubicBezier* segments, const uint32_t* index, std::size_t n,
                                        double* out) {
    transpose_of([segments, index](std::size_t k) -> const CubicBezier& { return segments[index[k]]; }, n, n, out);
}

}  // namespace detail

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

namespace {

/// Pass 2 of one wire's double-reflection frames: the normal carried from point 0 (r0) through points 1 .. m - 1,
/// stored at every point (nx, ny, nz). Steps flagged special take the guarded path (Transporter).
struct CarryChain {
    std::size_t m = 0;
    glm::dvec3 r0{};
    const double* blocks = nullptr;  // step_matrices()' output
    const double *px = nullptr, *py = nullptr, *pz = nullptr, *ptx = nullptr, *pty = nullptr, *ptz = nullptr;
    // The segment and parameter a step from point q runs along: point_seg[q], point_ta[q]; without them (nullptr:
    // the points are segment starts) segment first_segment + q at t = 0, the one point past them at t = 1 of the last.
    const uint32_t* point_seg = nullptr;
    const double* point_ta = nullptr;
    double *nx = nullptr, *ny = nullptr, *nz = nullptr;
    Transporter* transport = nullptr;
    std::size_t first_segment = 0;
    std::size_t start_count = 0;

    [[nodiscard]] uint32_t segment_of(std::size_t q) const {
        if (point_seg != nullptr) return point_seg[q];
        return static_cast<uint32_t>(first_segment + std::min(q, start_count - 1));
    }
    [[nodiscard]] double t_of(std::size_t q) const {
        if (point_ta != nullptr) return point_ta[q];
        return q < start_count ? 0.0 : 1.0;
    }
    /// The guarded step into point q (rare: out of line).
    [[gnu::noinline]] glm::dvec3 guarded(std::size_t q, glm::dvec3 r) const {
        const Sample a{{px[q - 1], py[q - 1], pz[q - 1]}, {ptx[q - 1], pty[q - 1], ptz[q - 1]}};
        const Sample b{{px[q], py[q], pz[q]}, {ptx[q], pty[q], ptz[q]}};
        const double tb = segment_of(q) == segment_of(q - 1) ? t_of(q) : 1.0;
        return transport->step(segment_of(q - 1), t_of(q - 1), a, glm::normalize(r), tb, b);
    }
    /// The step into point q from normal (x, y, z) at point q - 1: one matrix-vector product (the serial part).
    /// Three scalars, not a glm::dvec3 by reference: that one GCC keeps in memory, in the latency chain.
    [[gnu::always_inline]] void step(std::size_t q, double& x, double& y, double& z) const {
        const double* e = step_entries(blocks, q);
        if (e[72] != 0.0) [[unlikely]] {
            const glm::dvec3 r = guarded(q, glm::dvec3(x, y, z));
            x = r.x;
            y = r.y;
            z = r.z;
        } else {
            const double rx = e[0] * x + e[24] * y + e[48] * z;
            const double ry = e[8] * x + e[32] * y + e[56] * z;
            const double rz = e[16] * x + e[40] * y + e[64] * z;
            x = rx;
            y = ry;
            z = rz;
            if ((q & 63) == 0) [[unlikely]] {  // reflections preserve length and plane; only rounding drifts, slowly
                const glm::dvec3 r = orthonormalize(glm::dvec3(x, y, z), glm::dvec3(ptx[q], pty[q], ptz[q]));
                x = r.x;
                y = r.y;
                z = r.z;
            }
        }
        nx[q] = x;
        ny[q] = y;
        nz[q] = z;
    }
};

/// Pass 2. A function of its own: inlined into compute_frames, its loop ran out of registers and reloaded its
/// pointers from the stack every step.
void carry_normal(const CarryChain& c) {
    double x = c.r0.x, y = c.r0.y, z = c.r0.z;
    for (std::size_t q = 1; q < c.m; ++q) c.step(q, x, y, z);
}

}  // namespace

FrameStats compute_frames(const FrameInput& in, const FrameSettings& settings, std::span<Frame> out) {
    FrameStats stats;
    const std::size_t n = in.params.size();
    assert(out.size() == n && in.centre_m.size() == n && in.tangent.size() == n && "compute_frames: sizes");
    if (n == 0) {
        return stats;
    }
    const bool closed = in.curve != nullptr && in.curve->closed;

    // Tangents: zero ones (a segment that is one point) take the previous ring's, the leading ones the first valid.
    std::size_t first_valid = n;
    for (std::size_t i = 0; i < n; ++i) {
        if (in.tangent[i] != glm::dvec3(0.0)) {
            first_valid = i;
            break;
        }
    }
    glm::dvec3 prev_t = first_valid < n ? in.tangent[first_valid] : glm::dvec3(0.0, 0.0, 1.0);
    for (std::size_t i = 0; i < n; ++i) {
        if (in.tangent[i] == glm::dvec3(0.0)) {
            ++stats.degenerate_tangents;
            out[i].t = prev_t;
        } else {
            out[i].t = in.tangent[i];
            prev_t = in.tangent[i];
        }
    }

    // First frame: carried over from the previous state when possible, else seeded from the least-aligned axis.
    const glm::dvec3 t0 = out[0].t;
    glm::dvec3 r0{};
    if (settings.has_previous_normal) {
        const glm::dvec3 p = settings.previous_normal - glm::dot(settings.previous_normal, t0) * t0;
        const double len = glm::length(p);
        if (len > 1e-6 && std::isfinite(len)) {
            r0 = p / len;
            stats.seeded_from_previous = true;
        }
    }
    if (!stats.seeded_from_previous) r0 = seed_normal(t0);
    out[0].r = r0;
    out[0].s = glm::cross(t0, r0);

    Transporter transport(in, settings, stats);
    // A step that crosses whole segments (LOD below the node resolution: an interval spanning several segments)
    // is carried through every segment boundary it crosses, so the frames equal those of one ring per segment at
    // the rings both have (no twist pop when spans merge or split). Boundaries pa.segment+1 .. end-1 lie between.
    const std::size_t n_seg = in.curve != nullptr ? in.curve->segment_count() : 0;
    auto boundary_end = [&](const RingParam& pb, bool wrap) -> std::size_t {
        return wrap ? n_seg : static_cast<std::size_t>(pb.segment) + (pb.t > 0.0 ? 1 : 0);
    };
    auto crosses = [&](const RingParam& pa, const RingParam& pb, bool wrap) {
        return n_seg != 0 && boundary_end(pb, wrap) > static_cast<std::size_t>(pa.segment) + 1;
    };
    auto carry = [&](const RingParam& pa, const Sample& a, glm::dvec3 r, const RingParam& pb, const Sample& b,
                     bool wrap) {
        const std::size_t end = boundary_end(pb, wrap);
        uint32_t seg = pa.segment;
        double ta = pa.t;
        Sample cur = a;
        for (std::size_t k = static_cast<std::size_t>(pa.segment) + 1; k < end; ++k) {
            const CubicBezier& c = in.curve->segments[k];
            Sample next{c.b0 - in.origin_m, unit_tangent(c, 0.0)};
            if (next.t == glm::dvec3(0.0)) next.t = cur.t;
            r = transport.step(seg, ta, cur, r, 1.0, next);
            seg = static_cast<uint32_t>(k);
            ta = 0.0;
            cur = next;
        }
        const double tb = !wrap && pb.segment == seg ? pb.t : 1.0;
        return transport.step(seg, ta, cur, r, tb, b);
    };
    auto general_step = [&](std::size_t i, const glm::dvec3& r_prev) {
        const RingParam& pa = in.params[i - 1];
        const RingParam& pb = in.params[i];
        const Sample a{in.centre_m[i - 1], out[i - 1].t};
        const Sample b{in.centre_m[i], out[i].t};
        if (crosses(pa, pb, false)) return carry(pa, a, r_prev, pb, b, false);
        const double tb = pb.segment == pa.segment ? pb.t : 1.0;
        return transport.step(pa.segment, pa.t, a, r_prev, tb, b);
    };
    if (settings.method == FrameMethod::double_reflection) {
        // The points the normal is carried through, in order: every ring and, between two rings, every segment
        // boundary the interval crosses (LOD below the node resolution), so a span's rings get the frames that one
        // ring per segment would give them (no twist pop when spans merge or split), and the boundaries take the
        // same independent-per-step path as rings. A boundary's tangent is computed as a ring's at t = 0 is.
        // Pass 1, independent per step: the product of the two reflections as one matrix (no square root: the
        // mirrors are not normalized), H2 H1 = I - f1 v1 v1^T - f2 v2 v2^T + f1 f2 (v2.v1) v2 v1^T; a flag marks a
        // step for the guarded path. Pass 2 then carries r by one matrix-vector product per step: the only serial
        // dependency, and a short one (no square root, no division), which is what bounds the speed. Reflections
        // keep |r| = 1 and r normal to t up to rounding, which is removed every 64 steps (drift stays ~1e-15); the
        // count runs over points, so a span's rings are re-projected exactly where the node-resolution rings are.
        // Pass 3 writes the rings' normals and binormals.
        const CubicBezier* const segs = in.curve != nullptr ? in.curve->segments.data() : nullptr;
        // The points, in structure-of-arrays scratch (grows once per thread, then reused): position, tangent, the
        // segment and parameter a step from the point runs along (segment starts: computed, see CarryChain), and
        // the point of every ring (the other points are crossed boundaries).
        // Rings only at segment starts (t = 0, at most one per segment; the last may be at t = 1: LOD at or below the
        // node resolution, the common moving wire) with build_rings' tables: the points are the segment starts
        // from ring 0's on, in order, so they are copied from the tables in lanes and the rings written over their
        // starts. Else (and without the tables) point by point.
        const std::size_t ss = in.segment_soa.size() / 12;  // the tables' stride
        bool starts = n_seg != 0 && in.segment_soa.size() == 12 * ss && ss >= n_seg &&
                      in.boundary_tangent.size() == 4 * ss && in.params[0].t == 0.0;
        for (std::size_t i = 1; i < n && starts; ++i) {
            const RingParam& pa = in.params[i - 1];
            const RingParam& pb = in.params[i];
            starts = pa.t == 0.0 && (pb.t == 0.0 ? pb.segment > pa.segment
                                                 : (i + 1 == n && pb.t == 1.0 && pb.segment >= pa.segment));
        }
        const std::size_t s0 = in.params[0].segment;
        const std::size_t count = in.params[n - 1].segment + 1 - s0;  // with `starts`: segment starts from ring 0's on
        std::size_t m = starts ? count + (in.params[n - 1].t == 1.0 ? 1 : 0) : n;
        std::size_t first_crossed = n_seg, last_crossed = 0;  // boundary range whose tangents are needed
        for (std::size_t i = 1; i < n && !starts; ++i) {
            const RingParam& pa = in.params[i - 1];
            const RingParam& pb = in.params[i];
            if (crosses(pa, pb, false)) {
                const std::size_t end = boundary_end(pb, false);
                m += end - (pa.segment + 1);
                first_crossed = std::min<std::size_t>(first_crossed, pa.segment + 1);
                last_crossed = std::max(last_crossed, end);
            }
        }
        thread_local std::vector<double> soa;
        thread_local std::vector<uint32_t> point_seg;
        thread_local std::vector<double> point_ta;
        thread_local std::vector<uint32_t> ring_point;  // the point of every ring
        const std::size_t nb = last_crossed > first_crossed ? last_crossed - first_crossed : 0;
        // The arrays have room for whole vectors of steps (8 lanes): step_matrices then runs no remainder loop
        // (the steps past the last point, between copies of it, are computed and never read).
        const std::size_t mp = 1 + (m - 1 + 7) / 8 * 8;
        soa.resize(19 * mp + 4 * nb);
        if (!starts) {  // segment starts: CarryChain knows their segments and parameters
            point_seg.resize(m);
            point_ta.resize(m);
        }
        ring_point.resize(n);
        double* const px = soa.data();
        double* const py = px + mp;
        double* const pz = py + mp;
        double* const ptx = pz + mp;
        double* const pty = ptx + mp;
        double* const ptz = pty + mp;
        double* const blocks = ptz + mp;  // step_matrices()' blocks: the step into j, and whether it is guarded
        double* const nx = blocks + 10 * mp;  // 3 arrays: the normal carried to point j
        double* const ny = nx + mp;
        double* const nz = ny + mp;
        // Boundary tangents of the crossed range (detail::boundary_tangents): build_rings's, for every segment, or
        // computed here; a vanishing derivative (flag 0) takes unit_tangent()'s one-sided limits below.
        double* const btan = nz + mp;  // 4 arrays: x, y, z, ok
        const double* bt = btan;
        std::size_t bt_stride = nb;
        if (nb != 0 && in.boundary_tangent.size() % 4 == 0 && in.boundary_tangent.size() >= 4 * n_seg) {
            bt = in.boundary_tangent.data() + first_crossed;
            bt_stride = in.boundary_tangent.size() / 4;
        } else if (nb != 0) {
            thread_local std::vector<double> transposed;
            transposed.resize(12 * nb);
            detail::transpose_segments(segs + first_crossed, nb, transposed.data());
            detail::boundary_tangents(transposed.data(), nb, btan, btan + nb, btan + 2 * nb, btan + 3 * nb);
        }
        std::size_t j = 0;
        auto put = [&](const glm::dvec3& x, const glm::dvec3& t, uint32_t seg, double ta, int64_t ring) {
            px[j] = x.x;
            py[j] = x.y;
            pz[j] = x.z;
            ptx[j] = t.x;
            pty[j] = t.y;
            ptz[j] = t.z;
            point_seg[j] = seg;
            point_ta[j] = ta;
            if (ring >= 0) ring_point[static_cast<std::size_t>(ring)] = static_cast<uint32_t>(j);
            ++j;
        };
        if (starts) {
            const double* const b = in.segment_soa.data() + s0;
            const double* const t = in.boundary_tangent.data() + s0;
            const double* const tok = t + 3 * ss;
            const bool unfit = segment_start_points(b, b + ss, b + 2 * ss, t, t + ss, t + 2 * ss, tok, in.origin_m.x,
                                                    in.origin_m.y, in.origin_m.z, count, px, py, pz, ptx, pty, ptz);
            // The rings over their starts (a ring's segment and t are its start's; the last ring may be at t = 1,
            // one point more).
            for (std::size_t i = 0; i < n; ++i) {
                const std::size_t q = i + 1 == n && in.params[i].t == 1.0 ? count : in.params[i].segment - s0;
                px[q] = in.centre_m[i].x;
                py[q] = in.centre_m[i].y;
                pz[q] = in.centre_m[i].z;
                ptx[q] = out[i].t.x;
                pty[q] = out[i].t.y;
                ptz[q] = out[i].t.z;
                ring_point[i] = static_cast<uint32_t>(q);
            }
            j = m;  // their segments and parameters: CarryChain::segment_of(), t_of()
            // A boundary tangent whose flag is 0 takes unit_tangent()'s limits, a zero one the previous point's (the
            // test reads the tables, not the point arrays just written in lanes). Rare: segment_start_points tells.
            std::size_t next_ring = 0;  // the first ring whose point is not before q (ring_point increases)
            for (std::size_t q = 1; q < count && unfit; ++q) {
                while (ring_point[next_ring] < q) ++next_ring;  // the last ring's point is at least count - 1
                const glm::dvec3 table_t(t[q], t[ss + q], t[2 * ss + q]);
                if ((tok[q] != 0.0 && table_t != glm::dvec3(0.0)) || ring_point[next_ring] == q) continue;
                glm::dvec3 tq = tok[q] != 0.0 ? table_t : unit_tangent(segs[s0 + q], 0.0);
                if (tq == glm::dvec3(0.0)) tq = glm::dvec3(ptx[q - 1], pty[q - 1], ptz[q - 1]);
                ptx[q] = tq.x;
                pty[q] = tq.y;
                ptz[q] = tq.z;
            }
        } else {
            put(in.centre_m[0], out[0].t, in.params[0].segment, in.params[0].t, 0);
            for (std::size_t i = 1; i < n; ++i) {
                const RingParam& pa = in.params[i - 1];
                const RingParam& pb = in.params[i];
                if (crosses(pa, pb, false)) {
                    glm::dvec3 cur_t = out[i - 1].t;
                    for (std::size_t k = static_cast<std::size_t>(pa.segment) + 1; k < boundary_end(pb, false); ++k) {
                        const CubicBezier& c = segs[k];
                        const std::size_t b = k - first_crossed;
                        glm::dvec3 t = bt[3 * bt_stride + b] != 0.0
                                           ? glm::dvec3(bt[b], bt[bt_stride + b], bt[2 * bt_stride + b])
                                           : unit_tangent(c, 0.0);
                        if (t == glm::dvec3(0.0)) t = cur_t;
                        put(c.b0 - in.origin_m, t, static_cast<uint32_t>(k), 0.0, -1);
                        cur_t = t;
                    }
                }
                put(in.centre_m[i], out[i].t, pb.segment, pb.t, static_cast<int64_t>(i));
            }
        }
        assert(j == m);
        // Pass 1: mirrors() and the step matrix of every step, branch-free (selects), vectorized; a step mirrors()
        // would not call ok is flagged for the guarded path.
        for (std::size_t q = m; q < mp; ++q) {
            px[q] = px[m - 1];
            py[q] = py[m - 1];
            pz[q] = pz[m - 1];
            ptx[q] = ptx[m - 1];
            pty[q] = pty[m - 1];
            ptz[q] = ptz[m - 1];
        }
        step_matrices(px, py, pz, ptx, pty, ptz, mp, 1e-13 * max_abs(in.origin_m), blocks);
        // Pass 2: carry r, one matrix-vector product per step (the serial part); guarded steps through Transporter.
        CarryChain chain{m, r0, blocks, px, py, pz, ptx, pty, ptz, nullptr, nullptr, nx, ny, nz, &transport, s0, count};
        if (!starts) {
            chain.point_seg = point_seg.data();
            chain.point_ta = point_ta.data();
        }
        carry_normal(chain);
        // Pass 3: the rings' normals and binormals (after the carry: a branch on whether a point is a ring, in the
        // carry loop, is mispredicted wherever LOD leaves segments without rings).
        for (std::size_t i = 1; i < n; ++i) {
            const std::size_t q = ring_point[i];
            Frame& f = out[i];
            f.r = glm::dvec3(nx[q], ny[q], nz[q]);
            f.s = glm::cross(f.t, f.r);
        }
    } else {
        for (std::size_t i = 1; i < n; ++i) {
            out[i].r = general_step(i, out[i - 1].r);
            out[i].s = glm::cross(out[i].t, out[i].r);
        }
    }

    if (closed && n >= 1) {
        // Transport once more, from the last ring back to ring 0 (t = 1 of the last segment), and measure the twist.
        const RingParam& pa = in.params[n - 1];
        const Sample a{in.centre_m[n - 1], out[n - 1].t};
        const Sample b{in.centre_m[0], out[0].t};
        const glm::dvec3 r_end = crosses(pa, in.params[0], true)
                                     ? carry(pa, a, out[n - 1].r, in.params[0], b, true)
                                     : transport.step(pa.segment, pa.t, a, out[n - 1].r, 1.0, b);
        const double delta = std::atan2(glm::dot(glm::cross(out[0].r, r_end), out[0].t), glm::dot(out[0].r, r_end));
        stats.holonomy_rad = delta;
        if (!settings.keep_holonomy && delta != 0.0) {
            // Arc length per ring; chord lengths if none were given.
            double total = 0.0;
            const bool have_s = in.arc_length_m.size() == n + 1;
            if (have_s) {
                total = in.arc_length_m[n];
            } else {
                for (std::size_t i = 0; i < n; ++i) {
                    total += glm::length(in.centre_m[(i + 1) % n] - in.centre_m[i]);
                }
            }
            double s = 0.0;
            for (std::size_t i = 1; i < n; ++i) {
                s = have_s ? in.arc_length_m[i] : s + glm::length(in.centre_m[i] - in.centre_m[i - 1]);
                const double angle = total > 0.0 ? -delta * s / total : 0.0;
                const double ca = std::cos(angle);
                const double sa = std::sin(angle);
                const glm::dvec3 r = ca * out[i].r + sa * out[i].s;  // rotation about t by angle
                out[i].s = ca * out[i].s - sa * out[i].r;
                out[i].r = r;
            }
        }
    }
    return stats;
}

}  // namespace wire
