// Internal: WireCurve's state machine, owned by the curve stage. A wire's curve is in one of three states:
//   exact     the curve is build_curve's of the nodes (on the nodes path: the nodes packed, the GPU builds it);
//             the pop-free blend state is stale (released, re-primed from the last valid nodes when needed);
//   blending  the pop-free blend's curve, stepped each frame until it settles (no node appeared or vanished);
//   released  culled while moving: the curve freed, its sphere kept; rebuilt when in view or when needed.
// Every transition is one function here; the curve stage drives them, the LOD stage releases and restores a
// curve through them, nothing else writes these fields.
#pragma once

#include "wire/systems/components.hpp"

namespace wire::systems::detail {

/// One update of a wire's curve: its settings now and whether the exact curve is what it shows.
struct CurveStep {
    PopFreeSettings pop_free{};      ///< the wire's settings now
    SplineSettings released_spline;  ///< what a released curve was built with
    bool exact = false;              ///< no node appeared or vanished and nothing blends (or no blending at all)
};

/// Starts an update: new settings reset the blend state; the exact curve is shown when blending is off, nothing
/// blends and the node ids are unchanged, or this is the first valid state (nothing to blend from).
CurveStep begin_update(WireCurve& c, const WireNodes& nodes, const SplineSettings& spline, float blend_s,
                       bool pop_free);

/// exact: the blend state goes stale (released; re-primed from the last valid nodes when ids next change).
void stale_blend(WireCurve& c, const CurveStep& step);

/// blending: one step of the pop-free blend (primed first with the last valid nodes, what is on screen, if it
/// was stale), its curve written to c.curve. `scratch`: the priming's output buffer.
Status step_blend(WireCurve& c, const WireNodes& nodes, Curve& scratch);

/// A valid update: the curve moves on a generation with its sphere (the LOD's O(1) cull), the nodes become the
/// last valid ones, and the curve is released or not as `released` says.
void commit(WireCurve& c, const WireNodes& nodes, const BoundingSphere& sphere, bool released);

/// An invalid update: the wire keeps its last valid curve, whose sphere `bounds` is no longer known to be (a
/// failed blend step may rewrite the curve). A released curve comes back: the blend path has put its last state
/// back (it shows it on failure), else it is rebuilt (restore_curve). True when it was rebuilt.
bool keep_last_curve(WireCurve& c, const CurveStep& step);

/// Ends an update (valid or not): counts the build and whether a blend goes on next frame.
void end_update(WireCurve& c, bool ok);

/// released: frees a culled moving wire's curve (its next change rebuilds it anyway).
void release_curve(WireCurve& c);

/// Rebuilds a released curve from the last valid nodes with the settings it was built with. It was built by
/// build_curve from the same nodes and settings (the fast path), which is deterministic: the same curve, bit for
/// bit. False (still released) if that fails, which cannot happen for nodes that built once.
bool restore_curve(WireCurve& c, const SplineSettings& spline);

}  // namespace wire::systems::detail
