// One wire's LOD, rings and mesh (stages.hpp): the lod, rings and mesh stages run them over the wires whose
// input changed; the curve stage runs them right after a wire's new curve (WireContext::fused_stages).
#include "curve_state.hpp"
#include "stages.hpp"

namespace wire::systems::detail {

namespace {

/// What a wire keeps of build_rings' output (see WireRings): the float records (swapped, so no copy and no
/// allocation once both buffers are large enough), ring 0's frame, scalars.
void keep_rings(RingSet& built, WireRings& r) {
    RingSet& k = r.rings;
    std::swap(k.rings, built.rings);
    k.origin_m = built.origin_m;
    k.length_m = built.length_m;
    k.fold_count = built.fold_count;
    k.first_fold_ring = built.first_fold_ring;
    k.frame_stats = built.frame_stats;
    k.closed = built.closed;
    if (built.frames.empty()) {
        k.frames.clear();
    } else {
        k.frames.assign(1, built.frames.front());
    }
    r.u_close = built.closed && !built.u.empty() ? static_cast<float>(built.u.back()) : 0.0f;
}

}  // namespace

unsigned char lod_one(LodJob& job, const LodView& view, const LodSettings& base, uint64_t view_generation) {
    unsigned char outcome = 0;
    LodSettings settings = base;
    settings.max_sides = job.style->max_sides ? job.style->max_sides : kDefaultMaxSides;
    if (base.max_sides != 0) settings.max_sides = std::min(settings.max_sides, base.max_sides);
    WireLodState& s = *job.lod;
    WireCurve& c = *job.curve;
    // A released curve comes back when its sphere is not outside the view (the view turned to it).
    if (c.released && !sphere_outside_view(c.bounds, view) && restore_curve(c, c.spline)) {
        ++c.generation;
        outcome = 2;
    }
    const bool curve_changed = s.seen_curve != c.generation;  // since the last LOD update of this wire
    const bool kept_bounds = !curve_changed && c.lod_bounds_generation == c.generation;
    bool changed = false;
    if (kept_bounds) {
        // Same curve, new camera: update_lod starts with the sphere test itself; the kept bounds let
        // WireLod::Coherence answer the camera move.
        changed = update_lod(c.curve, view, settings, s.lod, c.lod_bounds);
    } else if (c.released || sphere_outside_view(c.bounds, view)) {
        // What update_lod gives a wire its sphere culls, without computing the LodBounds.
        changed = cull_lod(s.lod);
    } else if (curve_changed && c.bounds_generation == c.generation) {
        // Moving (or new): this frame's LOD is the only reader of the bounds (not kept, partly built).
        changed = update_lod_once(c.curve, c.bounds, view, settings, s.lod);
    } else if (curve_changed) {
        // Moving (or new): this frame's LOD is the only reader of the bounds; they are not kept.
        thread_local LodBounds scratch;  // a new version each compute: a Coherence made with it never matches
        scratch.transient = true;        // so none is made
        bounds_of(c, scratch);
        changed = update_lod(c.curve, view, settings, s.lod, scratch);
    } else {
        // Same curve as the last LOD update, new camera: keep the bounds for the next camera.
        bounds_of(c, c.lod_bounds);
        c.lod_bounds_generation = c.generation;
        changed = update_lod(c.curve, view, settings, s.lod, c.lod_bounds);
    }
    if ((curve_changed || !s.lod.visible) && c.lod_bounds.data.capacity() != 0) {
        // Bounds of an older curve, or of a culled wire (recomputed, in O(segments), when it is in view again).
        release(c.lod_bounds.data);
        c.lod_bounds_generation = 0;
    }
    if (changed) ++s.generation;
    ++s.updates;
    s.seen_curve = c.generation;
    s.seen_view = view_generation;
    if (!s.lod.visible) {
        // Culled: the counts are rebuilt from scratch when it comes back (hysteresis restarts either way).
        if (s.lod.counts.capacity() != 0) release(s.lod.counts);
        if (s.lod.required.capacity() != 0) release(s.lod.required);
        // Culled while moving: the next frame rebuilds the curve anyway (WireCurve).
        if (curve_changed && !c.released && c.pop_free_stale && !c.blending && !c.curve.segments.empty()) {
            release_curve(c);
            outcome = 1;
        }
    }
    return outcome;
}

void rings_one(RingJob& job) {
    WireRings& r = *job.rings;
    place_rings(job.curve->curve, job.lod->lod.counts, r.params);
    RingSettings settings;
    const WireNodes& nodes = job.curve->previous_nodes;  // the last valid nodes: what the curve shows
    settings.frames = carried_frames(FrameMethod::double_reflection,
                                     r.rings.frames.empty() ? nullptr : &r.rings.frames.front(), r.motion, nodes);
    thread_local RingSet scratch;  // the double per-ring arrays: per thread, not kept per wire
    // The float records are built straight into the wire's own buffer (lent to the scratch set for the build,
    // taken back in keep_rings): each wire's and the thread's buffers keep their capacity, so a frame
    // allocates only where a wire needs more rings than it ever had (a swap would pass buffers from wire
    // to wire and keep reallocating).
    std::swap(scratch.rings, r.rings.rings);
    build_rings(job.curve->curve, r.params, settings, scratch);
    r.frame_settings = settings.frames;
    r.motion = motion_reference(nodes);
    keep_rings(scratch, r);
    ++r.generation;
    r.seen_curve = job.curve->generation;
    r.seen_lod = job.lod->generation;
}

void mesh_one(MeshJob& job) {
    WireMesh& m = *job.mesh;
    m.sides = job.lod->lod.drawn_sides;
    m.caps = caps_of(*job.style);
    const RingSet& rs = job.rings->rings;
    const TubeSettings ts{.sides = m.sides, .caps = m.caps};
    // Strip or phone-wire line (drawn_sides 2 or 1): 2 vertices a ring (wire::write_strip); else the tube.
    const TubeCounts counts = m.sides <= 2 ? strip_counts(rs.rings.size(), rs.closed)
                                           : tube_counts(rs.rings.size(), rs.closed, ts);
    m.mesh.origin_m = rs.origin_m;
    m.mesh.vertices.resize(counts.vertices);
    m.mesh.indices.resize(counts.indices);
    if (m.sides <= 2) {
        write_strip(rs.rings, rs.closed, job.rings->u_close, m.mesh.vertices, m.mesh.indices);
    } else {
        write_tube(rs.rings, rs.closed, job.rings->u_close, ts, m.mesh.vertices, m.mesh.indices);
    }
    ++m.generation;
    m.seen_rings = job.rings->generation;
}

}  // namespace wire::systems::detail
