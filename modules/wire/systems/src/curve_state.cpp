// WireCurve's transitions (curve_state.hpp).
#include "curve_state.hpp"

#include "stages.hpp"

namespace wire::systems::detail {

CurveStep begin_update(WireCurve& c, const WireNodes& nodes, const SplineSettings& spline, float blend_s,
                       bool pop_free) {
    CurveStep step;
    step.pop_free = PopFreeSettings{.spline = spline, .enabled = pop_free, .blend_s = blend_s};
    step.released_spline = c.spline;
    if (c.builds == 0 || spline != c.spline || c.pop_free_on != pop_free || c.blend_s != blend_s) {
        c.pop_free = PopFreeCurve(step.pop_free);
        c.spline = spline;
        c.pop_free_on = pop_free;
        c.blend_s = blend_s;
    }
    const WireNodes& prev = c.previous_nodes;
    const bool same_ids = c.generation > 0 && !c.blending && nodes.ids == prev.ids &&
                          (!nodes.ids.empty() || nodes.size() == prev.size());
    // The first valid state has nothing to blend from: the pop-free blend would show its exact curve too (and is
    // primed from previous_nodes if the next state changes ids, as after any fast-path frame).
    step.exact = !pop_free || same_ids || c.generation == 0;
    return step;
}

void stale_blend(WireCurve& c, const CurveStep& step) {
    if (c.pop_free_stale) return;
    c.pop_free = PopFreeCurve(step.pop_free);  // re-priming rebuilds it from previous_nodes: released until then
    c.pop_free_stale = true;
}

Status step_blend(WireCurve& c, const WireNodes& nodes, Curve& scratch) {
    if (c.pop_free_stale) {
        c.pop_free.reset();
        (void)c.pop_free.update(c.previous_nodes, scratch);
        c.pop_free_stale = false;
    }
    return c.pop_free.update(nodes, c.curve);
}

void commit(WireCurve& c, const WireNodes& nodes, const BoundingSphere& sphere, bool released) {
    ++c.generation;
    c.bounds = sphere;
    c.bounds_generation = c.generation;
    copy_nodes(c.previous_nodes, nodes);
    c.released = released;
}

bool keep_last_curve(WireCurve& c, const CurveStep& step) {
    c.bounds_generation = 0;
    if (!c.released) return false;
    if (!c.curve.segments.empty()) {
        c.released = false;
        return false;
    }
    return restore_curve(c, step.released_spline);
}

void end_update(WireCurve& c, bool ok) {
    ++c.builds;
    c.blending = ok && !c.pop_free_stale && c.pop_free.blending();
}

void release_curve(WireCurve& c) {
    release(c.curve.segments);
    release(c.curve.source_node);
    release(c.curve.radius_m);
    release(c.curve.stretch);
    release(c.lod_bounds.data);
    c.lod_bounds_generation = 0;
    c.released = true;
}

bool restore_curve(WireCurve& c, const SplineSettings& spline) {
    if (!build_curve(c.previous_nodes, spline, c.curve).ok()) return false;
    c.released = false;
    ++c.builds;
    return true;
}

}  // namespace wire::systems::detail
