// How a wire moved between two states of its nodes: the best-fit rotation of its nodes matched by id, weighted
// toward the start, so the first frame (and with it the texture) moves with the wire instead of lagging it.
//
// Why: projecting last state's first normal onto the new normal plane is the smallest rotation that takes the old
// first tangent to the new one. Under a rigid motion that is not the motion: a rotation about any axis not
// perpendicular to the first tangent also turns the wire about that tangent, which the projection leaves out, so
// the texture slides around a swinging cable (2-3 degrees a frame) and a pose that returns shows another angle.
// The rotation that carries the nodes onto their new positions (weighted least squares, Horn 1987: the top
// eigenvector of a symmetric 4x4 matrix) is exact for a rigid motion whatever the path, and for a non-rigid one it
// is the mean rotation of the wire near its start: the weights fall with the distance s along the wire
// from node 0 (as (1 + s / 4l)^-4, which falls like it without an exp), and the reach l starts at two elements and grows 4x until the nodes within it fix the rotation (a
// straight start borrows the bend further along), so the first frame follows the wire where it sits. The reach is
// chosen once, from the shape the rings were built on (motion_reference), so a fit is one 4x4 eigenproblem.
//
// Where that reason stops holding: the nodes of a wire determine its rotation about the line through them only
// through their spread off that line. When the fit cannot tell rotations about that line apart (the gap between
// the two largest eigenvalues is below 1e-3 of the largest: a wire within a few percent of straight, where 1e-7
// relative noise of float physics would turn into up to 1e-4 rad of twist jitter), the carried normal blends
// smoothly into the projection (fully projection below 1e-4): a straight wire's twist about itself is not in its
// nodes, and the projection is the twist-free choice. Fewer than three nodes matched by id (ids replaced wholesale,
// a wire without ids whose node count changed) also falls back to the projection.
#pragma once

#include "wire/frames.hpp"
#include "wire/nodes.hpp"

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstdint>

namespace wire {

/// A state's nodes to fit the next state's motion against: the first nodes, then ever sparser ones to the end
/// (at most kCapacity), with their ids and their distance along the wire. Fixed size, no allocation (kept per wire).
struct MotionReference {
    static constexpr uint32_t kCapacity = 10;  // 64 nodes: 0, 1, 2, 3, 5, 8, 12, 18, 27 and 63
    std::array<glm::dvec3, kCapacity> position{};  ///< world metres
    std::array<uint32_t, kCapacity> id{};           ///< node ids (the node index when the wire has no ids)
    std::array<float, kCapacity> weight{};          ///< (1 + s / (4 reach))^-4, s the polyline length from node 0
    /// How well these nodes fix a rotation: 2 e2 / e1^2 of their weighted covariance (e1, e2 its first two invariants;
    /// to first order Horn's eigenvalue gap over the top eigenvalue for a rigid motion; 0 for collinear nodes).
    float determinacy = 0.0f;
    uint32_t count = 0;                             ///< 0: no reference (nothing to carry from)
    uint32_t node_count = 0;                        ///< nodes in the state (matching by index needs the same count)
    bool by_index = false;                          ///< the state had no ids: nodes are matched by index
};

/// The reference of `nodes` (positions finite; any count, 0 gives an empty reference): motion_samples, then
/// weigh_reference.
[[nodiscard]] MotionReference motion_reference(const WireNodes& nodes);

/// The reference's nodes alone (positions, ids, counts), weights and determinacy left 0: a copy of 10 nodes, for a
/// caller that fits only now and then (the nodes path, whose GPU fits the common case).
[[nodiscard]] MotionReference motion_samples(const WireNodes& nodes);
/// The weights and determinacy of a reference made by motion_samples (they depend on its nodes only).
void weigh_reference(MotionReference& reference);

/// Whether the nodes of `to` at the reference's node indices carry the reference's ids (or, without ids, whether
/// `to` has as many nodes): then matching by index is fit_motion's match by id.
[[nodiscard]] bool samples_match(const MotionReference& from, const WireNodes& to);

/// The rotation fitted from `from` to the matching nodes of `to`, and how well the nodes determine it.
struct MotionFit {
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  ///< unit: world directions of the old state -> the new state
    uint32_t matched = 0;      ///< reference nodes found in `to`
    /// 1: the nodes pin the rotation down (use it); 0: they do not (use the projection); between: blend.
    double confidence = 0.0;
};
[[nodiscard]] MotionFit fit_motion(const MotionReference& from, const WireNodes& to);

/// The rotation that carries last state's first normal into the new state: the fitted rotation's axis and
/// `confidence` times its angle (all of it when the fit is sure, identity when it is not: the frame stage then
/// projects the plain previous normal). Unit, w >= 0. The nodes path sends its vector part to the GPU.
[[nodiscard]] glm::dquat carried_rotation(const MotionFit& fit);

/// Last state's first normal carried into the new state: carried_rotation(fit) applied to it. Not yet orthogonal
/// to the new first tangent: pass it as FrameSettings::previous_normal.
[[nodiscard]] glm::dvec3 carry_normal(const MotionFit& fit, const glm::dvec3& previous_normal);

/// The frame settings of a wire's next ring build, the one place both drivers of the stages (the ECS systems and
/// WirePipeline) take them from: `method`, and, when the wire's rings were built before, ring 0's normal of that
/// build (`last_first`, built from the nodes `built_from`) carried by the wire's motion to `nodes`.
[[nodiscard]] FrameSettings carried_frames(FrameMethod method, const Frame* last_first, const MotionReference& built_from,
                                           const WireNodes& nodes);

}  // namespace wire
