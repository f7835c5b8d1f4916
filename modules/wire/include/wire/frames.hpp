// Rotation-minimizing frames along a wire by double reflection (Wang, Juttler, Zheng, Liu 2008), with the
// rotation and projection methods kept as baselines for comparison.
#pragma once

#include "wire/curve.hpp"
#include "wire/tessellate.hpp"

#include <cstdint>
#include <span>

namespace wire {

/// An orthonormal, right-handed frame at a ring: unit tangent t, normal r, binormal s = t x r (so t = r x s).
struct Frame {
    glm::dvec3 t{0.0, 0.0, 1.0};
    glm::dvec3 r{1.0, 0.0, 0.0};
    glm::dvec3 s{0.0, 1.0, 0.0};
};

enum class FrameMethod : uint8_t {
    double_reflection,  ///< fourth order with exact tangents; hairpin subdivision; the default
    rotation,           ///< baseline: rotate r by the angle between consecutive tangents (three.js, Blender); 2nd order
    projection,         ///< baseline: r -= (r.t) t, normalize; first order
};

/// Zero means default.
struct FrameSettings {
    FrameMethod method = FrameMethod::double_reflection;
    /// Temporal coherence: the first normal of this wire in the previous state (world direction). It is projected
    /// onto the plane normal to the new first tangent; if that is degenerate (|projection| < 1e-6) the frame is
    /// seeded from the world axis least aligned with the first tangent, as it is without a previous normal.
    bool has_previous_normal = false;
    glm::dvec3 previous_normal{};
    /// Hairpin guard: a reflection step whose second reflection is ill-conditioned (c2 < 0.1, i.e. the tangent
    /// turns the "wrong way" within one step) or whose tangent turns by more than 45 degrees is split at its
    /// parameter midpoint, recursively, at most this deep (the frame then stays accurate under coarse sampling).
    uint32_t max_subdivision_depth = 0;  ///< 0 -> 10 (at most 1024 sub-steps for one step)
    bool keep_holonomy = false;          ///< closed wires: true leaves the holonomy twist in (for measurement)
};

struct FrameStats {
    double holonomy_rad = 0.0;         ///< closed wires: signed angle (about t0) of the transported frame after one loop
    uint32_t subdivided_steps = 0;     ///< steps the hairpin guard split
    uint32_t degenerate_tangents = 0;  ///< rings with no tangent (on a one-point segment): took a neighbour's
    uint32_t fallback_steps = 0;       ///< steps that fell back to the rotation method (hairpin at max depth)
    bool seeded_from_previous = false; ///< first normal carried over from FrameSettings::previous_normal
};

/// The samples the frames are computed at. `centre_m[i]` is the curve position at params[i] minus origin_m (any
/// origin: a wire-local one keeps 1e6 m coordinates accurate); `tangent[i]` the unit tangent from unit_tangent().
/// `arc_length_m[i]` is the arc length from ring 0 to ring i and, for closed curves, one more entry with the
/// loop length: used only to spread the holonomy correction; if empty, chord lengths are used.
struct FrameInput {
    const Curve* curve = nullptr;
    std::span<const RingParam> params;
    glm::dvec3 origin_m{};
    std::span<const glm::dvec3> centre_m;
    std::span<const glm::dvec3> tangent;
    std::span<const double> arc_length_m;
    /// Optional: the unit tangent at t = 0 of every segment of `curve` as 4 arrays of equal length, at least
    /// segment_count() (x, y, z, and 1 where valid, 0 where the caller must take unit_tangent()'s limits), as
    /// build_rings computes them for the segment boundaries a ring interval crosses. Empty: compute_frames computes
    /// the ones it needs.
    std::span<const double> boundary_tangent;
    /// Optional, with boundary_tangent: `curve`'s segments as 12 arrays of boundary_tangent's length (b0.x, b0.y,
    /// b0.z, b1.x, ... b3.z; detail::transpose_segments()), as build_rings lays them out. With both, rings only at
    /// segment starts take their points from these tables.
    std::span<const double> segment_soa;
};

/// Unit tangent of segment `p.segment` at `p.t` from the analytic derivative. Where the derivative vanishes (a cusp,
/// a segment with coincident control points) the one-sided limit is used: the direction of B'' (of -B'' at t = 1),
/// then of B''', then the chord b3 - b0. Returns the zero vector if the segment is a single point (the caller then
/// uses a neighbouring tangent); `degenerate` reports whether the derivative vanished.
[[nodiscard]] glm::dvec3 unit_tangent(const CubicBezier& c, double t, bool* degenerate = nullptr);

/// Frames at every ring of `in` into `out` (out.size() == in.params.size()). Orthonormal to ~1e-14 in practice
/// (re-orthonormalized every 64 steps), promised to 1e-5. Closed curves: unless keep_holonomy, ring i is rotated
/// about its tangent by -wrap(holonomy) * s_i / L so the frame transported around the loop returns to ring 0's.
FrameStats compute_frames(const FrameInput& in, const FrameSettings& settings, std::span<Frame> out);

/// Axis-seeded first normal: the world axis least aligned with t, made orthogonal to t (unit). t must be unit.
[[nodiscard]] glm::dvec3 seed_normal(const glm::dvec3& t);

}  // namespace wire
