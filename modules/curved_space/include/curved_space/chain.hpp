// A chain of bend segments: per-segment matrices accumulated in double, the CPU reference transform of
// points and normals, and conservative bounds of a bent box (DESIGN §4.7).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "curved_space/bend.hpp"
#include "curved_space/status.hpp"

namespace curved_space {

/// Axis-aligned box in metres.
struct Aabb {
    glm::dvec3 min{0.0};
    glm::dvec3 max{0.0};
};

class Chain;

/// Checks every segment: length finite and > 0, angle and direction finite, |angle/length| at most 1e12 per metre, the
/// total length at most 1e12 m. The first problem found is
/// reported as e.g. "segment 3: length must be positive, got -1" or "segment 0: angle must be finite, got nan".
[[nodiscard]] Status validate(std::span<const Segment> segments);

/// Validates and builds the chain (matrices in double). On error `out` is left unchanged.
[[nodiscard]] Status make_chain(std::span<const Segment> segments, Chain& out,
                                const glm::dmat4& world_from_chain = glm::dmat4(1.0));

/// Segments laid one after the other along the unbent +z axis: segment i covers
/// z in [z_start(i), z_start(i) + length_i), z_start(0) = 0. Points with z < 0 continue straight along the
/// chain's start tangent, points with z >= total_length() straight along its end tangent. An empty chain is
/// the identity (times world_from_chain).
class Chain {
  public:
    Chain() = default;

    [[nodiscard]] std::size_t segment_count() const { return segments_.size(); }
    [[nodiscard]] const Segment& segment(std::size_t i) const { return segments_[i]; }
    [[nodiscard]] double total_length_m() const { return z_start_.back(); }
    /// Start of segment i on the unbent axis; i == segment_count() gives total_length_m().
    [[nodiscard]] double z_start_m(std::size_t i) const { return z_start_[i]; }
    /// M[i]: maps segment i's local frame (its start at the origin, unbent axis +z) to the world;
    /// i == segment_count() is the end frame. M[0] = world_from_chain,
    /// M[i+1] = M[i] Rz(g_i) T(d (a/2) sinc(a/2)^2, 0, d sinc(a)) Ry(a_i) Rz(-g_i).
    [[nodiscard]] const glm::dmat4& world_from_segment(std::size_t i) const { return world_from_segment_[i]; }
    /// M[i] Rz(g_i): the frame the bend of segment i is computed in (the end frame has g = 0).
    [[nodiscard]] const glm::dmat4& world_from_bend(std::size_t i) const { return world_from_bend_[i]; }
    /// Curvature angle/length of record i (0 for the end record).
    [[nodiscard]] double kappa_per_m(std::size_t i) const { return kappa_[i]; }

    /// The record a point at unbent height z uses: the last i in [0, segment_count()] with z_start(i) <= z
    /// (0 for z < 0). `straight` is true before and after the chain.
    struct Location {
        std::size_t record = 0;
        bool straight = false;
    };
    [[nodiscard]] Location locate(double z_m) const;

    /// The CPU reference: bends point p (unbent space, metres) and its normal n. Continuous (C1 along the
    /// centre line) across segment boundaries; exact identity for alpha = 0. Finite for finite input.
    [[nodiscard]] BentVertex transform(const glm::dvec3& p, const glm::dvec3& n) const;
    [[nodiscard]] glm::dvec3 transform_point(const glm::dvec3& p) const;

    /// A box that contains the bent image of every point of `box` (conservative). Exact for straight parts;
    /// curved parts are split into pieces (at most pi/16 rad, at most 1024 per segment), each bounded by its 8
    /// bent corners inflated by the arc sagitta; pieces are chosen so the slack is about 1e-3 of the
    /// cross-section diagonal plus the covered length.
    [[nodiscard]] Aabb bounds(const Aabb& box) const;

  private:
    friend Status make_chain(std::span<const Segment> segments, Chain& out, const glm::dmat4& world_from_chain);

    std::vector<Segment> segments_;
    std::vector<double> z_start_{0.0};  // segment_count() + 1 entries
    std::vector<double> kappa_{0.0};
    std::vector<double> cos_gamma_{1.0};
    std::vector<double> sin_gamma_{0.0};
    std::vector<glm::dmat4> world_from_segment_{glm::dmat4(1.0)};
    std::vector<glm::dmat4> world_from_bend_{glm::dmat4(1.0)};
};

/// Bends a vertex array in place: positions (xyz per vertex, float, relative to `origin_m`) and normals
/// (xyz per vertex, may be empty). Bent positions stay relative to `origin_m`. Returns the number of
/// vertices that fold (lie at or past a bend's centre of curvature).
std::size_t bend_vertices(const Chain& chain, std::span<float> positions, std::span<float> normals,
                          const glm::dvec3& origin_m = glm::dvec3(0.0));

}  // namespace curved_space
