// Random families of node events for measuring the pop-free blend (pop_free.hpp): cables that the physics
// refines and coarsens, open (hanging catenaries) and closed (loops), with fixed seeds. Used by the pop-free blend
// tests (which assert on every frame) and by `wiretool bench` (which reports the distributions).
#pragma once

#include "wire/pop_free.hpp"
#include "wire/nodes.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace wire {

struct PopFreeFamilySettings {
    SplineSettings spline{};       ///< kind and knots; `closed` is set per cable
    PopFreeSettings blend{};   ///< pop-free blend settings (its `spline` is replaced by the cable's)
    int cables = 40;               ///< random cables; even ones open, odd ones closed
    int events_per_cable = 13;     ///< node events per cable (insert on the curve, remove, replace an end)
    int max_gap_frames = 40;       ///< frames between events, uniform in [0, max_gap_frames] (0: same frame)
    uint64_t seed = 1;
    int samples_per_segment = 8;   ///< sample points per segment of the distance metric (exact foot points)
    double jump_bound_m = 2e-3;    ///< the per-frame jump aim (issue 17: 2 mm on a 20-40 m cable)
    /// Which cables: 0 both (even open, odd closed), 1 open only, 2 closed only.
    int shapes = 0;
    /// Node spacing of the open cables: -1 drawn per cable (uniform, end-dense or jittered), 0 uniform,
    /// 1 end-dense (1 - cos: elements 10-40x shorter at the ends than in the middle), 2 jittered.
    int open_spacing = -1;
};

/// One event (a state whose ids differ from the previous one's) and what the pop-free blend did with it.
struct PopFreeEvent {
    enum Type : int { insert = 0, remove = 1, replace_end = 2, seam = 3 };
    int type = insert;
    bool closed = false;
    int cable = 0;
    double length_m = 0.0;    ///< the cable's length
    double pop_m = 0.0;       ///< instant pop: distance between the exact curves before and after
    double offset_m = 0.0;    ///< max|D|: the largest distance a point travels over the blend
    double frame_bound_m = 0.0;  ///< the event's bound on one frame's motion of the drawn curve
    int frames = 0;           ///< the blend's length (0: nothing to morph)
    double jump_m = 0.0;      ///< largest per-frame jump of the drawn curve while the event ran
    double lag_m = 0.0;       ///< largest distance between the drawn and the exact curve while it ran
    double jump_ratio = 0.0;  ///< largest jump / (sum of the instant pops of the events running then)
    double lag_ratio = 0.0;   ///< largest lag / (the same sum)
    bool overlapped = false;  ///< another event ran during this one
};

struct PopFreeFamilyResult {
    std::vector<PopFreeEvent> events;
    std::size_t frames = 0;             ///< frames drawn
    double max_jump_m = 0.0;            ///< over every frame while no "large" event runs (below)
    /// A change too large for jump_bound_m within the longest blend: its frame bound
    /// (PopFreeCurve::last_frame_bound_m) above jump_bound_m even at N_max frames. Such events still keep the
    /// 1/5 ratio, the lag and the settling; their frames move by up to their frame bound.
    double large_offset_m = 0.0;  ///< max|D| above which the frame bound 1.5 max|D| / N_max alone exceeds jump_bound_m
    std::size_t large_events = 0;
    double max_jump_over_design = 0.0;  ///< largest jump / (sum over running events of their frame bound; an event
                                        ///< folded into a later one counts up to that one's switch frame), large or not
    double max_jump_large_m = 0.0;      ///< largest jump in frames where a large event runs
    double max_jump_ratio = 0.0;        ///< per frame: jump / sum of the running events' pops (jump > 1e-9 m)
    double max_lag_ratio = 0.0;         ///< per frame: lag / the same sum (lag > 1e-9 m)
    double max_settled_gap_m = 0.0;     ///< per frame with no event running: drawn vs exact curve
    int max_frames = 0;                 ///< longest blend
    std::size_t unremedied = 0;         ///< events shown without a blend (must be 0)
    std::size_t state_mismatch = 0;     ///< frames where PopFreeCurve::blending() disagreed with the events
    std::string worst_jump, worst_lag;  ///< where the largest ratios occurred (cable, frame, event type)
    std::string error;                  ///< non-empty if a state failed (a generator bug)
};

/// Runs the family: per cable, the events with their gaps, then frames until every blend ended. Every frame
/// measures the jump (drawn curve against the previous frame's) and the lag (drawn against the exact curve of
/// the same nodes) as symmetric Hausdorff distances: sample points of one curve, exact foot points (Newton)
/// on the other. Deterministic for a given seed.
[[nodiscard]] PopFreeFamilyResult run_pop_free_family(const PopFreeFamilySettings& settings);

/// Exact symmetric distance between two curves: samples_per_segment points per segment of each, each measured
/// to its foot point on the other curve (pruned search, Newton polish). Metres.
[[nodiscard]] double curve_distance_m(const Curve& a, const Curve& b, int samples_per_segment = 8);

}  // namespace wire
