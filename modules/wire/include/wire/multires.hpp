// Pop-free multiresolution: a small per-wire object that turns successive node states (with stable ids) into
// the curve to render, geomorphing the segments around nodes that appear or vanish.
//
// Remedy (open wires): each state's exact curve T is built with build_curve. The previous state's target and
// the new one share "common" node ids; between two consecutive common nodes A, B lies a span. A span whose
// interior ids changed (a node inserted or removed), its `support` neighbours (whose tangents changed with it:
// 1 for the local splines, 3 for c2, 0 for linear) and any blend they touch start a geomorph:
//   * the span is rendered in the UNION topology: old-only nodes (removed) stay as ghost nodes, new-only nodes
//     (inserted) are cut into the old curve at their closest point. Old and new chains are both subdivided
//     (de Casteljau, exact) at all union points, so each side is represented exactly;
//   * per sub-segment, the control-point offset D = old - new is frozen (0 at the anchors A, B, which are never
//     mid-morph, so neighbouring spans stay joined), and the rendered control points are new(now) + keep * D;
//   * keep falls linearly from 1 to 0 at a constant rate: frame 0 renders the old curve exactly (no pop at the
//     switch), the last frame renders T exactly. A constant rate (not a smoothstep) because a later event
//     restarts the morph from what is on screen: an ease-in restarted every few frames would stall.
// Consecutive affected spans form one run (one blend): inner common nodes that are still mid-morph become
// union points, so nothing snaps. Ghosts whose two pieces are again one cubic within max_step_m/10 are pruned
// when a run restarts.
// With the target at rest, the point at parameter t moves in one frame by rate * |D(t)| (D(t) the Bezier
// combination of the offsets, at most the largest control-point offset); every rendered point is that close
// to a point of the previous frame, which bounds the measured jump. rate = max_step_m / max_t |D(t)|, clamped
// to [1/max_blend_frames, 1/blend_frames], keeps every frame's jump under max_step_m unless the morph would
// take longer than max_blend_frames. |D(t)| includes sliding along the curve, so the bound is conservative.
// Not remedied (the new curve is shown at once): closed loops, a wire's end node replaced (nothing to anchor
// on beyond it), duplicate ids, ids that change order, and a node count change when WireNodes::ids is empty
// (nodes are then named by index). Cost per state: O(n) plus, per restarted run, O(run nodes^2) projections.
#pragma once

#include "wire/curve.hpp"
#include "wire/nodes.hpp"
#include "wire/status.hpp"

#include <cstdint>
#include <vector>

namespace wire {

struct MultiresSettings {
    SplineSettings spline{};
    bool geomorph = true;        ///< false: render each state's exact curve (the "no remedy" baseline)
    int blend_frames = 8;        ///< minimum frames of a geomorph (<= 0: 8)
    double max_step_m = 0.5e-3;  ///< per-frame displacement bound that lengthens a geomorph (<= 0: 0.5 mm)
    int max_blend_frames = 240;  ///< cap on a geomorph's length (<= 0: 240)
};

/// The pop metric (same as curve_jump_m in bezier.hpp): the symmetric Hausdorff distance between the dense
/// samples of two consecutive rendered curves, metres.
[[nodiscard]] double rendered_jump_m(const Curve& before, const Curve& after, int per_segment = 64);

class MultiresCurve {
public:
    explicit MultiresCurve(const MultiresSettings& settings = {});

    /// Takes the next state. On success `rendered` is the curve to draw this frame (its nodes: the union of
    /// current nodes and ghosts of removed ones while they morph away; `source_node` of a ghost is the current
    /// node before it). On failure (build_curve's Status) `rendered` is left as the previous frame's curve.
    [[nodiscard]] Status update(const WireNodes& nodes, Curve& rendered);

    void reset();
    [[nodiscard]] const Curve& target() const { return target_; }      ///< the exact curve of the last state
    [[nodiscard]] bool blending() const { return !blends_.empty(); }
    [[nodiscard]] std::size_t active_blends() const { return blends_.size(); }
    /// States that changed topology but were shown without a geomorph (closed loop, replaced end node,
    /// duplicate ids, ...), and the code of the last such case (for diagnostics).
    [[nodiscard]] std::size_t unremedied() const { return unremedied_; }
    [[nodiscard]] int last_unremedied_reason() const { return last_reason_; }

    struct Point {  // a union point inside a span, in the new chain's coordinates
        uint32_t segment;  // offset from the span's first segment
        double u;
        uint32_t id;
        bool ghost;  // an old-only node (removed) rather than a current node
    };
    struct Blend {
        uint32_t anchor_a = 0, anchor_b = 0;  // ids of the common nodes bounding the span
        double keep = 1.0;                    // share of the start offset still shown (1 -> 0)
        double rate = 0.125;                  // decrease of keep per frame
        std::vector<Point> points;            // interior union points, in order
        std::vector<CubicBezier> offset;      // per sub-segment D = old - new at the start
    };

private:
    MultiresSettings settings_;
    bool has_state_ = false;
    Curve target_;                     // exact curve of the last state
    std::vector<uint32_t> target_ids_; // per target node
    Curve rendered_;                   // what was drawn last
    std::vector<uint32_t> rendered_ids_;
    std::vector<Blend> blends_;
    std::size_t unremedied_ = 0;
    int last_reason_ = 0;
};

}  // namespace wire
