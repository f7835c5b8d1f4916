// Internal: what compute_frames (frames.cpp) shares with the parallel transport of the normal (frames_transport.cpp):
// the sample points, the double-reflection step's lane kernels, the Transporter and the pass-2 carry.
#pragma once

#include "wire/frames.hpp"

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace wire::detail {

/// The largest of three magnitudes (no NaN; equal values are equal), without a branch.
inline double max3(double a, double b, double c) {
    return std::max(std::max(a, b), c);
}

inline double max_abs(const glm::dvec3& v) {
    return max3(std::abs(v.x), std::abs(v.y), std::abs(v.z));
}

/// r made orthogonal to unit t and normalized; `fallback` (also made orthogonal) if r is (nearly) parallel to t.
glm::dvec3 orthonormalize(const glm::dvec3& r, const glm::dvec3& t);

struct Sample {
    glm::dvec3 x;  // position relative to the origin
    glm::dvec3 t;  // unit tangent
};

/// The double-reflection step from point q - 1 to point q (positions x, y, z relative to the rings' origin, unit
/// tangents tx, ty, tz) for q = 1 .. m - 1 (m - 1 a multiple of 8), as one matrix (column-major entries e00 .. e22:
/// e<column><row>), with the operations mirrors() and the step's matrix take, branch-free so the loop vectorizes.
/// special = 1 where mirrors() would not answer ok (repeated point with reversing tangent, vanishing or
/// ill-conditioned second mirror, a turn over 45 degrees) or the matrix is not a number: the guarded path takes
/// those steps. Out: blocks of 8 steps (see step_entries), 10 rows of 8 lanes each: e00, e01, e02, e10, ... e22,
/// special. In blocks the carry finds a step's 10 numbers at fixed distances from one pointer (from 10 arrays of
/// a wire-dependent stride it computed 10 addresses a step).
void step_matrices(const double* __restrict x, const double* __restrict y, const double* __restrict z,
                   const double* __restrict tx, const double* __restrict ty, const double* __restrict tz, std::size_t m,
                   double origin_noise, double* __restrict blocks);

/// Step q's 10 numbers in step_matrices()' blocks: entry k (e00, e01, ... e22, special) at [8 k].
inline const double* step_entries(const double* blocks, std::size_t q) {
    return blocks + 80 * ((q - 1) / 8) + (q - 1) % 8;
}

/// The frame points of `count` consecutive segment starts: position b0 - origin and boundary tangent (tx .. tz),
/// read from structure-of-arrays tables. Returns whether some tangent needs the caller's fix-up (its flag `ok` is
/// 0, or it is the zero vector): rare, so tested here, in lanes (integer or-reductions vectorize, bool ones do not).
bool segment_start_points(const double* __restrict b0x, const double* __restrict b0y, const double* __restrict b0z,
                          const double* __restrict tx, const double* __restrict ty, const double* __restrict tz,
                          const double* __restrict ok, double ox, double oy, double oz, std::size_t count,
                          double* __restrict px, double* __restrict py, double* __restrict pz, double* __restrict ptx,
                          double* __restrict pty, double* __restrict ptz);

/// The guarded step of the frames (every step of the rotation and projection baselines); in frames_transport.cpp.
class Transporter {
public:
    Transporter(const FrameInput& in, const FrameSettings& s, FrameStats& stats)
        : in_(in),
          method_(s.method),
          max_depth_(s.max_subdivision_depth ? s.max_subdivision_depth : 10),
          stats_(stats),
          origin_noise_(1e-13 * max_abs(in.origin_m)) {}

    /// Rounding noise of positions near a and b (a chord below it is a repeated point).
    [[nodiscard]] double noise(const Sample& a, const Sample& b) const {
        return origin_noise_ + 1e-13 * (max_abs(a.x) + max_abs(b.x));
    }

    /// Carries normal r0 at a (on segment seg at parameter ta) to b (at parameter tb of the same segment, or the
    /// next ring whose position equals that point).
    glm::dvec3 step(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb, const Sample& b);

private:
    glm::dvec3 reflect(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb, const Sample& b,
                       uint32_t depth);

    const FrameInput& in_;
    FrameMethod method_;
    uint32_t max_depth_;
    FrameStats& stats_;
    double origin_noise_;
};

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
void carry_normal(const CarryChain& c);

}  // namespace wire::detail
