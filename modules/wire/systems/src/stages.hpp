// Internal: what the wire systems' stages share (systems.cpp, curve_system.cpp, lod_rings_mesh.cpp,
// draw_list_system.cpp): the per-wire jobs, one wire's LOD, rings and mesh (one_wire.cpp; the curve stage runs
// them too, fused), the per-thread work lists, the parallel loop and the components' small helpers.
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

/// Frees a vector's buffer (`v = {}` would only empty it: that is the initializer-list assignment).
template <class T>
inline void release(std::vector<T>& v) { std::vector<T>().swap(v); }

/// to = from. The optional per-node arrays are usually empty on both sides: they are assigned only when either
/// has entries (a vector assignment is a call even for two empty vectors, 11 a wire a frame otherwise).
inline void copy_nodes(WireNodes& to, const WireNodes& from) {
    to.positions = from.positions;
    for_each_node_array([&](const char*, auto member) {
        if (!(to.*member).empty() || !(from.*member).empty()) to.*member = from.*member;
    });
}

inline void release_rings(WireRings& r) {
    release(r.params);
    release(r.rings.rings);  // ring 0's frame stays: it seeds the next build's first normal
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
unsigned char lod_one(LodJob& job, const LodView& view, const LodSettings& base, uint64_t view_generation);
/// One wire's rings for its current curve and counts (the rings stage's work on one wire).
void rings_one(RingJob& job);
/// One wire's mesh from its rings (the mesh stage's work on one wire).
void mesh_one(MeshJob& job);

}  // namespace wire::systems::detail
