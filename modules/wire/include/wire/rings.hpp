// Ring records along a wire: centre, rotation-minimizing frame, radius and texture u at every ring parameter.
#pragma once

#include "wire/curve.hpp"
#include "wire/frames.hpp"
#include "wire/tessellate.hpp"

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace wire {

/// One ring as the GPU path uploads it: 48 bytes, all 32-bit. The centre is a float offset from the wire's origin
/// (RingSet::origin_m, double), so a wire 1e6 m from the world origin keeps float precision relative to its own
/// extent (a 100 m wire: ~4 um). The tangent is normal x binormal. u is float: it resolves 1/2^23 of its value, so
/// a wire more than ~10^4 circumferences long starts to lose texture precision (the double u stays in RingSet).
struct Ring {
    glm::vec3 centre_m{};  ///< ring centre minus RingSet::origin_m (metres)
    float radius_m = 0.0f;
    glm::vec3 normal{};    ///< r: unit, orthogonal to the tangent
    float u = 0.0f;        ///< texture coordinate along the wire (see build_rings)
    glm::vec3 binormal{};  ///< s = t x r
    uint32_t segment = 0;  ///< curve segment the ring lies on (its t is RingSet::params[i].t)
};
static_assert(sizeof(Ring) == 48, "Ring is the 48-byte GPU ring record");

/// Zero means default.
struct RingSettings {
    FrameSettings frames{};  ///< method, carried-over first normal, hairpin depth
    double u_start = 0.0;    ///< texture u at ring 0
};

/// Everything the ring stage produces for one wire. Vectors are resized, so a RingSet reused across frames does not
/// allocate once its capacity suffices. All per-ring arrays have one entry per ring parameter, in order.
struct RingSet {
    glm::dvec3 origin_m{};              ///< world position Ring::centre_m and centre_m are relative to (ring 0's centre)
    std::vector<RingParam> params;      ///< copy of the ring parameters
    std::vector<Ring> rings;            ///< compact float records
    std::vector<Frame> frames;          ///< double frames (carry frames[0].r over to the next state)
    std::vector<glm::dvec3> centre_m;   ///< double centres relative to origin_m
    std::vector<double> arc_length_m;   ///< from ring 0; a closed wire has one more entry: the loop length
    std::vector<double> u;              ///< double texture u; a closed wire has one more entry: u where it closes
    double length_m = 0.0;              ///< arc length of the rendered part (open: ring 0 to last ring; closed: loop)
    uint32_t fold_count = 0;            ///< rings whose radius >= local curvature radius (inner side folds)
    uint32_t first_fold_ring = 0;       ///< index of the first such ring (valid if fold_count > 0)
    FrameStats frame_stats{};
    bool closed = false;
    std::vector<glm::dvec3> tangent_scratch;  ///< working memory
};

/// Tube radius at (segment, t): monotone cubic Hermite in t between the segment's two node radii, with
/// Fritsch-Carlson-limited slopes from the neighbouring nodes (C1 along the wire, never overshoots, so it stays
/// between the node radii and positive).
[[nodiscard]] double radius_at(const Curve& curve, uint32_t segment, double t);

/// Ring records for `params` (from place_rings) on `curve`, into `out`.
/// - Centres, tangents: analytic (position(), unit_tangent()). Frames: compute_frames() with settings.frames.
/// - Arc length between consecutive rings: 3-point Gauss-Legendre quadrature of |B'(t)| per ring interval (exact
///   for polynomial speed of degree <= 5; relative error ~1e-10 at 8 rings per segment of a smooth cubic, tested
///   below 1e-7 at 4 rings per segment of a coarse helix). Not chord length.
/// - u (thesis §3.3): u_i = u_{i-1} + integral ds / (2*pi*R(s)*stretch_segment), by the same quadrature; continuous
///   across segments and monotonic (strictly increasing where the curve has length).
/// - Fold: a ring with radius >= curvature radius |B'|^3 / |B' x B''| is counted (the mesh is still produced).
void build_rings(const Curve& curve, std::span<const RingParam> params, const RingSettings& settings, RingSet& out);

}  // namespace wire
