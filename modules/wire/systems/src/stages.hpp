// Internal: what the wire systems' stages share (systems.cpp, curve_system.cpp, lod_rings_mesh.cpp,
// draw_list_system.cpp): the per-wire jobs, one wire's LOD, rings and mesh (the curve stage runs them too, fused),
// the per-thread work lists, the parallel loop and the components' small helpers.
#pragma once

#include "wire/systems/systems.hpp"

#include "wire/systems/api.hpp"
#include "wire/systems/components.hpp"
#include "wire/systems/view.hpp"

#include "wire/spline.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <tuple>
#include <utility>
#include <vector>

namespace wire::systems::detail {

using engine::ecs::Entity;
using engine::ecs::Registry;

constexpr uint32_t kDefaultMaxSides = 16;

template <class Fn>
inline void parallel_over(std::size_t n, Fn&& fn) {
    if (n == 0) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) fn(i);
    });
}

inline bool by_index(Entity a, Entity b) { return engine::ecs::to_index(a) < engine::ecs::to_index(b); }

/// Sorted in entity order and each handle once. The order is total (index, then version): a handle destroyed while
/// blending and the new wire that reuses its slot share an index, and sorting by index alone could leave the new
/// wire's two copies apart, around the stale handle, where std::unique cannot see them (the same wire then built by
/// two threads at once).
inline void sort_unique(std::vector<Entity>& v) {
    std::sort(v.begin(), v.end(), [](Entity a, Entity b) {
        const auto ia = engine::ecs::to_index(a), ib = engine::ecs::to_index(b);
        return ia != ib ? ia < ib : engine::ecs::to_version(a) < engine::ecs::to_version(b);
    });
    v.erase(std::unique(v.begin(), v.end()), v.end());
}

inline SplineSettings spline_of(const Style& style) {
    SplineSettings s = style.spline;
    s.closed = style.closed;
    s.radius_m = style.radius_m > 0.0f ? style.radius_m : kDefaultWireRadius_m;
    return s;
}

struct CurveJob {
    Entity entity;
    const Nodes* nodes;
    const Style* style;
    WireCurve* curve;
    Status status;
    bool changed = false;
    bool restored = false;  // a released curve rebuilt because the nodes are invalid
    bool kept_released = false;  // a released curve rebuilt in the thread's buffer only (still outside the view)
    // Fused stages (WireContext::fused_stages): the wire's later components, and what ran right after its curve.
    WireLodState* lod = nullptr;
    WireRings* rings = nullptr;
    WireMesh* mesh = nullptr;
    unsigned char fused = 0;        // 1: lod updated, 2: rings built, 4: mesh built
    unsigned char lod_outcome = 0;  // lod_one's
};

struct LodJob {
    const Style* style;
    WireCurve* curve;  // the LOD stage keeps or releases the wire's LodBounds and curve (see WireCurve)
    WireLodState* lod;
};

struct RingJob {
    const WireCurve* curve;
    const WireLodState* lod;
    WireRings* rings;
};

struct MeshJob {
    const WireRings* rings;
    const WireLodState* lod;
    const Style* style;
    WireMesh* mesh;
    // The mesh buffers as they were when the job was queued: the job before prefetches them (reading them from
    // the vectors then would race with the thread that resizes them).
    const TubeVertex* vertices;
    std::size_t vertex_count;
    const uint32_t* indices;
    std::size_t index_count;
};

inline bool caps_of(const Style& style) { return style.caps && !style.closed; }

/// A per-thread list of T (tag K tells two lists of one type apart), emptied, its capacity kept.
template <class T, int K>
std::vector<T>& reused() {
    thread_local std::vector<T> v;
    v.clear();
    return v;
}

/// The LOD's bounds of the wire's curve, with the curve stage's sphere when it is of this curve.
inline void bounds_of(const WireCurve& c, LodBounds& out) {
    if (c.bounds_generation == c.generation) {
        compute_lod_bounds(c.curve, out, c.bounds);
    } else {
        compute_lod_bounds(c.curve, out);
    }
}

/// Starts fetching the cache lines of [data, data + bytes) (for writing when `write`): values unchanged, and a
/// prefetch of memory another thread has since released or reallocated is harmless.
template <bool write>
inline void prefetch_lines(const void* data, std::size_t bytes) {
    const char* const first = static_cast<const char*>(data);
    for (std::size_t at = 0; at < bytes; at += 64) __builtin_prefetch(first + at, write ? 1 : 0);
}

/// What a wire keeps of build_rings' output (see WireRings): the float records (swapped, so no copy and no
/// allocation once both buffers are large enough), ring 0's frame, scalars.
inline void keep_rings(RingSet& built, WireRings& r) {
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

/// Frees a vector's buffer (`v = {}` would only empty it: that is the initializer-list assignment).
template <class T>
inline void release(std::vector<T>& v) { std::vector<T>().swap(v); }

/// Releases a culled moving wire's curve (see WireCurve): its next change rebuilds it anyway.
inline void release_curve(WireCurve& c) {
    release(c.curve.segments);
    release(c.curve.source_node);
    release(c.curve.radius_m);
    release(c.curve.stretch);
    release(c.lod_bounds.data);
    c.lod_bounds_generation = 0;
    c.released = true;
}

/// to = from. The optional per-node arrays are usually empty on both sides: they are assigned only when either
/// has entries (a vector assignment is a call even for two empty vectors, 11 a wire a frame otherwise).
inline void copy_nodes(WireNodes& to, const WireNodes& from) {
    to.positions = from.positions;
    for_each_node_array([&](const char*, auto member) {
        if (!(to.*member).empty() || !(from.*member).empty()) to.*member = from.*member;
    });
}

/// Rebuilds a released curve from the last valid nodes with the settings it was built with. It was built by
/// build_curve from the same nodes and settings (the fast path), which is deterministic: the same curve, bit for
/// bit. False (still released) if that fails, which cannot happen for nodes that built once.
inline bool restore_curve(WireCurve& c, const SplineSettings& spline) {
    if (!build_curve(c.previous_nodes, spline, c.curve).ok()) return false;
    c.released = false;
    ++c.builds;
    return true;
}

inline void release_rings(WireRings& r) {
    release(r.params);
    release(r.rings.rings);  // ring 0's frame stays: it seeds the next build's first normal
    release(r.packed);
}

template <class T>
inline std::size_t bytes_of(const std::vector<T>& v) { return v.capacity() * sizeof(T); }

inline std::size_t bytes_of(const Curve& c) {
    return bytes_of(c.segments) + bytes_of(c.source_node) + bytes_of(c.radius_m) + bytes_of(c.stretch);
}

inline std::size_t bytes_of(const WireNodes& n) {
    std::size_t bytes = bytes_of(n.positions);
    for_each_node_array([&](const char*, auto member) { bytes += bytes_of(n.*member); });
    return bytes;
}

inline std::size_t bytes_of(const RingSet& r) {
    return bytes_of(r.params) + bytes_of(r.rings) + bytes_of(r.frames) + bytes_of(r.centre_m) +
           bytes_of(r.arc_length_m) + bytes_of(r.u) + bytes_of(r.tangent_scratch);
}

/// The camera as the LOD sees it: `view_generation` moves on when the view or the LOD settings changed (called
/// by the curve stage, for the stages it runs on, and by the lod stage; the second call changes nothing unless the
/// camera was moved in between).
inline void refresh_view(WireContext& ctx) {
    const LodView view = lod_view(ctx.camera, ctx.viewport_width_px, ctx.viewport_height_px);
    if (!ctx.has_view || !(view == ctx.view) || ctx.lod != ctx.seen_lod) {
        ctx.view = view;
        ctx.seen_lod = ctx.lod;
        ctx.has_view = true;
        ++ctx.view_generation;
    }
}

/// One wire's LOD update for `view` (the lod stage's work on one wire, also run right after a changed curve).
/// Returns 1 when it released the wire's curve (culled while moving), 2 when it restored a released one, else 0.
inline unsigned char lod_one(LodJob& job, const LodView& view, const LodSettings& base, uint64_t view_generation) {
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

/// One wire's rings for its current curve and counts (the rings stage's work on one wire); `gpu`: also packed.
inline void rings_one(RingJob& job, bool gpu) {
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
    if (gpu) {  // the renderer's form, here on the worker threads: the render thread only copies
        const std::vector<Ring>& built = r.rings.rings;
        r.packed.resize(built.size());
        pack_rings(built, r.packed.data());
        r.radius_varies = std::any_of(built.begin(), built.end(),
                                      [&](const Ring& g) { return g.radius_m != built.front().radius_m; });
    } else if (!r.packed.empty()) {
        release(r.packed);
    }
    ++r.generation;
    r.seen_curve = job.curve->generation;
    r.seen_lod = job.lod->generation;
}

/// One wire's mesh from its rings (the mesh stage's work on one wire).
inline void mesh_one(MeshJob& job) {
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
