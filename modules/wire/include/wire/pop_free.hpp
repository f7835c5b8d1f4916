// The pop-free blend (of multiresolution node events): a small per-wire object that turns successive node states (with stable ids) into
// the curve to render, blending the change when nodes appear or vanish.
//
// The pop-free blend. Let P be the exact curve of the previous state and T the exact curve (build_curve) of the current
// one. When the ids change, P is mapped onto T's parameterisation: nodes present in both are matched exactly;
// an open wire's two ends always correspond (so a replaced end node, an end re-created by the physics under a
// new id, is covered); a closed loop is cut at a common node (the seam node is a node like any other). Between
// two consecutive matched nodes, a node only in P (removed) is placed on T at its closest point and a node only
// in T (inserted) on P at its closest point; if those disagree on the order, the stretch is cut at arc-length
// fractions instead. Both curves are subdivided at all these points (de Casteljau, exact), so the event's
// offset D = P - T is one cubic per sub-piece, continuous along the wire, and zero wherever P and T agree.
// The curve drawn is
//     rendered = T + sum over running events e of (1 - w(k_e / N_e)) * D_e,     w(s) = 3s^2 - 2s^3,
// k_e the frames since event e, N_e its length in frames. A later event carries the earlier offsets over onto
// the new parameterisation (exactly, by sub-division) and folds them into its own: its D is what the curve
// drawn at its switch frame holds off T (the running offsets at that frame's weights, plus P - T), so at most
// one event runs and its length is set by everything still to be blended. (Issue 31: events on their own
// clocks added their speeds; three running at their 1 mm bound moved an end-dense cable 2.0-2.4 mm a frame.)
// Properties, for the target at rest:
//   * no step: at an event's frame w = 0, so the switch shows the previous curve exactly; w is C1 with w' = 0
//     at both ends, and when an event ends its offset is exactly 0, so the end and the dropping of the ghost
//     junctions (sub-pieces of T that rejoin) change nothing;
//   * per-frame point travel <= max over the frame of |w(k/N) - w((k-1)/N)| * max_t |D(t)| <= 1.5 max|D| / N;
//     the curve itself moves less where D runs along it (below);
//   * lag: |rendered - T| <= (1 - w) max|D|; at the switch it is the instant pop itself (P drawn exactly);
//   * settles: after N frames the event's offset is gone; with no event running the curve drawn is T, bit for
//     bit (to far better than 1e-6 m).
// How far a frame moves the drawn curve (not its points): between junctions D pairs points by parameter, and
// where the two curves' parameter speeds differ (a node inserted or removed changes its neighbours' tangent
// lengths: centripetal and uniform Catmull-Rom across unequal elements, auto, end-dense spacing) D runs mostly
// along the curve: on end-dense centripetal cables max|D| was up to 20x the distance between the curves, and
// 99% of it along the tangent. A point sliding along the curve does not move the curve. The drawn piece at
// weight k is T + k D = (1 - k) T + k Q (Q = T + D), whose tangent lies between T's and Q's, so one frame moves
// it by at most 1.5 / N * max(|D x t_T| + |D| |t_Q - t_T|) to first order, plus 1.125 / N^2 * max(|D|^2 kappa)
// for the slide along a bend (kappa: the curvature bound of the pieces in between); an open wire's end moving
// along its tangent counts in full (the wire lengthens). Sampled (65 points a piece) with a 10% margin;
// last_frame_bound_m() is the smaller of this bound and 1.5 max|D| / N.
// Length of an event: the shortest N >= blend_s / frame_s (0.25 s: 15 frames at 60 Hz) whose frame bound is
// at most max_step_m (1 mm) and at most 0.15 of how far the drawn curve is from T at the switch (sampled both
// ways at the pieces, a lower bound of that distance, so a slide with little motion across is not blended
// faster than that small change allows: uniform's drawn curve cuts bends while it slides), and at most
// max_blend_s (4 s). For a change without slide the bound is 1.5 max|D| / N: each frame then moves the curve
// by at most 1/10 of the pop at 15 frames. A change of size P cannot move by at most s per frame in fewer
// than 1.5 P / s frames (smoothstep's peak speed is 1.5x its mean), so "<= 1 mm a frame" and "done in bounded
// time" meet only up to a size: with the defaults 1 mm a frame holds up to a motion of 16 cm, and a larger
// change takes 4 s at 1/160 of it a frame. A wire held more than 4 s away from its physics is no longer a
// smoothing.
// Events overlap: the running one is folded into the new one, so the per-frame bound holds for the frame, not
// per event: the switch frame moves as the folded event would have (<= its bound), later frames by at most the
// folded event's frame bound (<= max_step_m up to 16 cm). Events arriving faster than one blend restart it;
// the curve then settles at most max_blend_s after the last event.
// Where this stops holding: the sampled bounds are estimates between samples (the 10% margin covers the
// families in tests/modules/wire/pop_free_family_test.cpp, whose every frame is checked against the bound);
// points slide along the wire, so the rings placed by parameter move along it by up to 1.5 max|D| / N a
// frame (the surface stays within the LOD tolerance; a texture seam slides with them); uniform Catmull-Rom's
// slides still make its blends long (docs/issue31_popfree.md has the figures).
// Not blended (the new curve is shown at once, counted in unblended()): a node count change when
// WireNodes::ids is empty (nodes are then named by index), or a change between open and closed.
// A duplicate id in one state is an error (Status naming the node and the id); the previous curve stays.
// Cost per state: O(n) plus O(pieces * running events) while blending; at an event, projections of the
// changed nodes onto the stretch between their matched neighbours.
#pragma once

#include "wire/curve.hpp"
#include "wire/nodes.hpp"
#include "wire/status.hpp"

#include <cstdint>
#include <vector>

namespace wire {

struct PopFreeSettings {
    SplineSettings spline{};
    bool enabled = true;           ///< false: render each state's exact curve (the "no blend" baseline)
    double blend_s = 0.25;         ///< shortest blend, seconds (<= 0 or not finite: 0.25 s)
    double frame_s = 1.0 / 60.0;   ///< time one update() stands for, seconds (<= 0 or not finite: 1/60 s)
    double max_step_m = 1e-3;      ///< per-frame jump bound that lengthens a large event (<= 0 or not finite: 1 mm)
    double max_blend_s = 4.0;      ///< longest blend, seconds (<= 0 or not finite: 4 s; at least blend_s)
};

/// The pop metric (same as curve_jump_m in bezier.hpp): the symmetric Hausdorff distance between the dense
/// samples of two consecutive rendered curves, metres.
[[nodiscard]] double rendered_jump_m(const Curve& before, const Curve& after, int per_segment = 64);

/// Ok, or "node j: id X is used twice (also node i)" for the first repeated id of `nodes` (empty ids: ok).
[[nodiscard]] Status check_unique_ids(const WireNodes& nodes);

class PopFreeCurve {
public:
    explicit PopFreeCurve(const PopFreeSettings& settings = {});

    /// Takes the next state (one frame, frame_s seconds after the previous one). On success `rendered` is the
    /// curve to draw this frame (its nodes: the current nodes plus the junctions of pieces still morphing;
    /// `source_node` of a junction is the current node before it). On failure (build_curve's Status, or a
    /// duplicate id) `rendered` is left as the previous frame's curve and the state is unchanged.
    [[nodiscard]] Status update(const WireNodes& nodes, Curve& rendered);

    void reset();
    [[nodiscard]] const Curve& target() const { return target_; }  ///< the exact curve of the last state
    [[nodiscard]] bool blending() const { return !events_.empty(); }
    [[nodiscard]] std::size_t active_blends() const { return events_.size(); }  ///< events still morphing
    /// Length in frames of the newest event's blend (0 before any); the event has settled that many
    /// frames after the frame that showed it.
    [[nodiscard]] int last_blend_frames() const { return last_frames_; }
    /// The longest blend these settings allow, frames.
    [[nodiscard]] int max_blend_frames() const { return max_frames_; }
    /// max over the wire of |D| of the newest event, metres (its frames move the curve by at most
    /// 1.5 * that / last_blend_frames()).
    [[nodiscard]] double last_max_offset_m() const { return events_.empty() ? 0.0 : events_.back().max_d; }
    /// The newest event's bound on how far one of its frames moves the drawn curve, metres (<= max_step_m unless
    /// the event is too large for max_blend_s); see "Blend length" above.
    [[nodiscard]] double last_frame_bound_m() const { return events_.empty() ? 0.0 : events_.back().frame_bound_m; }
    /// Geomorphs started so far (an id change that moved nothing starts none).
    [[nodiscard]] std::size_t events_started() const { return started_; }
    /// States that changed topology but were shown without a blend (see above), and the code of the last.
    [[nodiscard]] std::size_t unremedied() const { return unremedied_; }
    [[nodiscard]] int last_unremedied_reason() const { return last_reason_; }

    struct Event {
        int elapsed = 0;     ///< frames since the event's switch frame
        int frames = 1;      ///< its length N
        double max_d = 0.0;  ///< max over the wire of |D|, metres
        double frame_bound_m = 0.0;  ///< how far one frame moves the drawn curve at most, metres
    };
    struct Piece {           ///< a part [u0, u1] of target segment `segment` carrying offsets
        uint32_t segment = 0;
        double u0 = 0.0, u1 = 1.0;
        std::vector<CubicBezier> offset;  ///< one per running event, in events_ order
    };

private:
    void remap(const Curve& T, const std::vector<uint32_t>& tid);
    void assemble(const Curve& T, Curve& out) const;

    PopFreeSettings settings_;
    int min_frames_ = 15, max_frames_ = 120;
    bool has_state_ = false;
    Curve target_;                      // exact curve of the last state
    std::vector<uint32_t> target_ids_;  // per target node
    Curve rendered_;                    // what was drawn last
    std::vector<Event> events_;
    std::vector<Piece> pieces_;         // sorted by (segment, u0); segments without pieces are drawn as T
    int last_frames_ = 0;
    std::size_t started_ = 0;
    std::size_t unremedied_ = 0;
    int last_reason_ = 0;
};

}  // namespace wire
