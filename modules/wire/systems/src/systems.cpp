// The wire systems: curve -> lod -> rings -> mesh -> draw list, each over a dense array of the wires that need
// work, in parallel with oneTBB; every wire writes only its own components.
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

namespace wire::systems {
namespace {

using engine::ecs::Entity;
using engine::ecs::Registry;

constexpr uint32_t kDefaultMaxSides = 16;

template <class Fn>
void parallel_over(std::size_t n, Fn&& fn) {
    if (n == 0) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) fn(i);
    });
}

bool by_index(Entity a, Entity b) { return engine::ecs::to_index(a) < engine::ecs::to_index(b); }

/// Sorted in entity order and each handle once. The order is total (index, then version): a handle destroyed while
/// blending and the new wire that reuses its slot share an index, and sorting by index alone could leave the new
/// wire's two copies apart, around the stale handle, where std::unique cannot see them (the same wire then built by
/// two threads at once).
void sort_unique(std::vector<Entity>& v) {
    std::sort(v.begin(), v.end(), [](Entity a, Entity b) {
        const auto ia = engine::ecs::to_index(a), ib = engine::ecs::to_index(b);
        return ia != ib ? ia < ib : engine::ecs::to_version(a) < engine::ecs::to_version(b);
    });
    v.erase(std::unique(v.begin(), v.end()), v.end());
}

SplineSettings spline_of(const Style& style) {
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

bool caps_of(const Style& style) { return style.caps && !style.closed; }

/// A per-thread list of T (tag K tells two lists of one type apart), emptied, its capacity kept.
template <class T, int K>
std::vector<T>& reused() {
    thread_local std::vector<T> v;
    v.clear();
    return v;
}

/// The LOD's bounds of the wire's curve, with the curve stage's sphere when it is of this curve.
void bounds_of(const WireCurve& c, LodBounds& out) {
    if (c.bounds_generation == c.generation) {
        compute_lod_bounds(c.curve, out, c.bounds);
    } else {
        compute_lod_bounds(c.curve, out);
    }
}

/// Starts fetching the cache lines of [data, data + bytes) (for writing when `write`): values unchanged, and a
/// prefetch of memory another thread has since released or reallocated is harmless.
template <bool write>
void prefetch_lines(const void* data, std::size_t bytes) {
    const char* const first = static_cast<const char*>(data);
    for (std::size_t at = 0; at < bytes; at += 64) __builtin_prefetch(first + at, write ? 1 : 0);
}

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

/// Frees a vector's buffer (`v = {}` would only empty it: that is the initializer-list assignment).
template <class T>
void release(std::vector<T>& v) { std::vector<T>().swap(v); }

/// Releases a culled moving wire's curve (see WireCurve): its next change rebuilds it anyway.
void release_curve(WireCurve& c) {
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
void copy_nodes(WireNodes& to, const WireNodes& from) {
    static_assert(sizeof(WireNodes) == 12 * sizeof(std::vector<double>), "copy_nodes: a WireNodes array added?");
    to.positions = from.positions;
    const auto copy = [](auto& t, const auto& f) {
        if (!t.empty() || !f.empty()) t = f;
    };
    copy(to.ids, from.ids), copy(to.stretch, from.stretch), copy(to.radius_m, from.radius_m);
    copy(to.theta_rad, from.theta_rad), copy(to.iz_m4, from.iz_m4), copy(to.length_m, from.length_m);
    copy(to.delta_length_m, from.delta_length_m), copy(to.area_m2, from.area_m2);
    copy(to.kb_tension, from.kb_tension), copy(to.kb_bias, from.kb_bias), copy(to.kb_continuity, from.kb_continuity);
}

/// Rebuilds a released curve from the last valid nodes with the settings it was built with. It was built by
/// build_curve from the same nodes and settings (the fast path), which is deterministic: the same curve, bit for
/// bit. False (still released) if that fails, which cannot happen for nodes that built once.
bool restore_curve(WireCurve& c, const SplineSettings& spline) {
    if (!build_curve(c.previous_nodes, spline, c.curve).ok()) return false;
    c.released = false;
    ++c.builds;
    return true;
}

void release_rings(WireRings& r) {
    release(r.params);
    release(r.rings.rings);  // ring 0's frame stays: it seeds the next build's first normal
    release(r.packed);
}

template <class T>
std::size_t bytes_of(const std::vector<T>& v) { return v.capacity() * sizeof(T); }

std::size_t bytes_of(const Curve& c) {
    return bytes_of(c.segments) + bytes_of(c.source_node) + bytes_of(c.radius_m) + bytes_of(c.stretch);
}

std::size_t bytes_of(const WireNodes& n) {
    return bytes_of(n.positions) + bytes_of(n.ids) + bytes_of(n.stretch) + bytes_of(n.radius_m) +
           bytes_of(n.theta_rad) + bytes_of(n.iz_m4) + bytes_of(n.length_m) + bytes_of(n.delta_length_m) +
           bytes_of(n.area_m2) + bytes_of(n.kb_tension) + bytes_of(n.kb_bias) + bytes_of(n.kb_continuity);
}

std::size_t bytes_of(const RingSet& r) {
    return bytes_of(r.params) + bytes_of(r.rings) + bytes_of(r.frames) + bytes_of(r.centre_m) +
           bytes_of(r.arc_length_m) + bytes_of(r.u) + bytes_of(r.tangent_scratch);
}

/// The camera as the LOD sees it: `view_generation` moves on when the view or the LOD settings changed (called
/// by the curve stage, for the stages it runs on, and by the lod stage; the second call changes nothing unless the
/// camera was moved in between).
void refresh_view(WireContext& ctx) {
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

/// One wire's rings for its current curve and counts (the rings stage's work on one wire); `gpu`: also packed.
void rings_one(RingJob& job, bool gpu) {
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

}  // namespace

void curve_system(Registry& registry, WireContext& ctx, uint64_t since) {
    ctx.stats = RunStats{};
    ctx.new_errors.clear();
    ctx.curve_changed.clear();

    // Work lists: per-thread buffers reused frame after frame (no allocation per frame once they are large
    // enough). A local reference is what the parallel lambdas capture: a thread_local named inside them would be
    // the worker thread's own.
    std::vector<Entity>& work = reused<Entity, 0>();
    for (const Entity e : registry.changed<Nodes>(since)) work.push_back(e);
    for (const Entity e : registry.changed<Style>(since)) work.push_back(e);
    for (const Entity e : ctx.blending) work.push_back(e);
    const bool nodes_path = ctx.path == UploadPath::gpu_nodes;
    if (ctx.has_seen_path && (ctx.seen_path == UploadPath::gpu_nodes) != nodes_path) {
        // To or from the nodes path: every wire again (one keeps packed nodes and no curve, the other a curve).
        auto& curves = registry.storage<WireCurve>();
        for (std::size_t i = 0; i < curves.size(); ++i) work.push_back(curves.at(i));
    }
    ctx.seen_path = ctx.path;
    ctx.has_seen_path = true;
    sort_unique(work);

    const bool fused = ctx.fused_stages;
    std::vector<CurveJob>& jobs = reused<CurveJob, 0>();
    jobs.reserve(work.size());
    for (const Entity e : work) {
        if (!registry.valid(e)) continue;  // destroyed while blending
        Nodes* nodes = registry.try_get<Nodes>(e);
        Style* style = registry.try_get<Style>(e);
        WireCurve* curve = registry.try_get<WireCurve>(e);
        if (nodes == nullptr || style == nullptr || curve == nullptr) continue;
        jobs.push_back(CurveJob{e, nodes, style, curve, Status::success()});
        if (fused) {
            jobs.back().lod = registry.try_get<WireLodState>(e);
            jobs.back().rings = registry.try_get<WireRings>(e);
            jobs.back().mesh = registry.try_get<WireMesh>(e);
        }
    }

    const bool pop_free = ctx.pop_free;
    // The view the LOD stage will see (unless the camera changes in between: the LOD stage then restores what
    // needs restoring). A released wire that moved and is still outside it stays released (below).
    refresh_view(ctx);
    const LodView& cull_view = ctx.view;
    const LodSettings lod_base = ctx.lod;
    const uint64_t view_generation = ctx.view_generation;
    const bool gpu = ctx.path == UploadPath::gpu_rings;
    // A wire whose curve changed goes on through lod, rings and mesh here, on this thread, while its curve is in
    // cache: exactly what the later stages would do for it (they then find it up to date and skip it).
    const auto go_on = [&](CurveJob& job) {
        if (!fused || !job.status.ok() || !job.changed || job.lod == nullptr) return;
        LodJob lod_job{job.style, job.curve, job.lod};
        job.lod_outcome = lod_one(lod_job, cull_view, lod_base, view_generation);
        job.fused |= 1;
        if (job.rings == nullptr || !job.lod->lod.visible) return;
        RingJob ring_job{job.curve, job.lod, job.rings};
        rings_one(ring_job, gpu);
        job.fused |= 2;
        if (gpu || job.mesh == nullptr) return;
        MeshJob mesh_job{job.rings, job.lod, job.style, job.mesh, nullptr, 0, nullptr, 0};
        mesh_one(mesh_job);
        job.fused |= 4;
    };
    // One wire's update in two steps around its build, so that up to four wires building their exact curves share
    // build_curves (their tridiagonal solves, a serial chain of divisions each, run side by side).
    struct Step {
        SplineSettings spline;           // the wire's settings now
        SplineSettings released_spline;  // what a released curve was built with
        bool exact = false;              // the exact curve is built (no pop-free blending)
    };
    const auto prepare = [&](CurveJob& job, Step& step) {
        WireCurve& c = *job.curve;
        step.spline = spline_of(*job.style);
        step.released_spline = c.spline;
        const SplineSettings& spline = step.spline;
        if (c.builds == 0 || spline != c.spline || c.pop_free_on != pop_free || c.blend_s != job.style->blend_s) {
            c.pop_free = PopFreeCurve(PopFreeSettings{.spline = spline, .enabled = pop_free, .blend_s = job.style->blend_s});
            c.spline = spline;
            c.pop_free_on = pop_free;
            c.blend_s = job.style->blend_s;
        }
        const WireNodes& nodes = *job.nodes;
        const WireNodes& prev = c.previous_nodes;
        const bool same_ids = c.generation > 0 && !c.blending && nodes.ids == prev.ids &&
                              (!nodes.ids.empty() || nodes.size() == prev.size());
        // The first valid state has nothing to blend from: the pop-free blend would show its exact curve too (and is
        // primed from previous_nodes if the next state changes ids, as after any fast-path frame).
        const bool first = c.generation == 0;
        // No node appeared or vanished and nothing blends: the exact curve is what the pop-free blend would show.
        step.exact = !pop_free || same_ids || first;
    };
    // After the build (exact: job.status is build_curve's, its curve in `scratch`, a per-thread buffer swapped
    // with the wire's curve, not one per wire).
    const auto finish = [&](CurveJob& job, const Step& step, Curve& scratch) {
        WireCurve& c = *job.curve;
        const SplineSettings& spline = step.spline;
        const WireNodes& nodes = *job.nodes;
        const WireNodes& prev = c.previous_nodes;
        bool stays_released = false;
        BoundingSphere sphere{};  // of the new curve, once computed (radius >= 0)
        if (step.exact) {
            if (job.status.ok() && nodes.ids != prev.ids) job.status = check_unique_ids(nodes);
            if (job.status.ok()) {
                if (c.curve.segments.capacity() == 0) {
                    // Released (culled while moving) or new. A released wire still outside the view stays
                    // released: the LOD stage culls it by its sphere, so the curve is never copied out of the
                    // thread's buffer (no allocation and free per culled moving wire per frame).
                    sphere = curve_bounding_sphere(scratch);
                    stays_released = c.released && !c.blending && sphere_outside_view(sphere, cull_view);
                    if (!stays_released) c.curve = scratch;  // one exact allocation, the thread keeps its buffer
                } else {
                    std::swap(c.curve, scratch);
                }
            }
            if (!c.pop_free_stale) {
                // Re-priming rebuilds the pop-free state from previous_nodes: release it until then.
                c.pop_free = PopFreeCurve(
                    PopFreeSettings{.spline = spline, .enabled = pop_free, .blend_s = job.style->blend_s});
                c.pop_free_stale = true;
            }
        } else {
            if (c.pop_free_stale) {
                // Re-prime the pop-free state with the last valid nodes (what is on screen now), then step.
                c.pop_free.reset();
                (void)c.pop_free.update(prev, scratch);
                c.pop_free_stale = false;
            }
            job.status = c.pop_free.update(nodes, c.curve);
        }
        ++c.builds;
        if (job.status.ok()) {
            ++c.generation;
            // The LOD's O(1) cull test; its LodBounds are the LOD stage's (WireCurve::lod_bounds).
            c.bounds = sphere.radius_m >= 0.0 ? sphere : curve_bounding_sphere(c.curve);
            c.bounds_generation = c.generation;
            job.changed = true;
            copy_nodes(c.previous_nodes, nodes);
            c.released = stays_released;
            job.kept_released = stays_released;
        } else {
            // The pop-free blend path may have put its last state back into `curve` (or restore_curve below rebuilds
            // it): `bounds` is not known to be its sphere.
            c.bounds_generation = 0;
        }
        if (!job.status.ok() && c.released) {
            // Invalid nodes: the wire keeps its last valid curve, which was released. The pop-free blend path has
            // already put it back (it shows its last state on failure); the fast path leaves it empty.
            if (!c.curve.segments.empty()) {
                c.released = false;
            } else if (restore_curve(c, step.released_spline)) {
                job.restored = true;
            }
        }
        c.blending = job.status.ok() && !c.pop_free_stale && c.pop_free.blending();
    };
    if (ctx.path == UploadPath::gpu_nodes) {
        // The nodes path: the GPU builds the curve from the nodes. Here only build_curve's checks, the sphere the
        // CPU culls with (from the nodes), and the pop-free blend, whose blended curve is drawn while it lasts.
        parallel_over(jobs.size(), [&](std::size_t i) {
            // Memory, not arithmetic, bounds this path: the components of the wire 4 ahead, then the arrays of
            // the wire 2 ahead (through its components, fetched 2 wires ago), come in while this one packs.
            if (i + 4 < jobs.size()) {
                prefetch_lines<false>(jobs[i + 4].nodes, sizeof(WireNodes));
                prefetch_lines<true>(&jobs[i + 4].curve->previous_nodes, sizeof(WireNodes));
                prefetch_lines<true>(&jobs[i + 4].curve->packed, sizeof(PackedNodes));
                prefetch_lines<true>(jobs[i + 4].curve, 64);
            }
            if (i + 2 < jobs.size()) {
                const WireCurve& ahead = *jobs[i + 2].curve;
                const WireNodes& nodes = *jobs[i + 2].nodes;
                prefetch_lines<false>(nodes.positions.data(), nodes.positions.size() * sizeof(glm::dvec3));
                prefetch_lines<true>(ahead.previous_nodes.positions.data(),
                                     ahead.previous_nodes.positions.size() * sizeof(glm::dvec3));
                prefetch_lines<true>(ahead.packed.nodes.data(), ahead.packed.nodes.size() * sizeof(glm::vec4));
            }
            CurveJob& job = jobs[i];
            Step step;
            prepare(job, step);
            WireCurve& c = *job.curve;
            const WireNodes& nodes = *job.nodes;
            const WireNodes& prev = c.previous_nodes;
            BoundingSphere sphere{};
            if (step.exact && !gpu_builds(step.spline.kind)) {
                // A kind the GPU does not build: the CPU builds the curve and the renderer gets its segments.
                thread_local Curve built;  // swapped in on success: a failure keeps the last valid curve
                job.status = build_curve(nodes, step.spline, built);
                if (job.status.ok() && nodes.ids != prev.ids) job.status = check_unique_ids(nodes);
                if (job.status.ok()) {
                    std::swap(c.curve, built);
                    sphere = curve_bounding_sphere(c.curve);
                }
                if (!c.pop_free_stale) {
                    c.pop_free = PopFreeCurve(
                        PopFreeSettings{.spline = step.spline, .enabled = pop_free, .blend_s = job.style->blend_s});
                    c.pop_free_stale = true;
                }
            } else if (step.exact) {
                // build_curve's checks and the GPU's packing in one pass (c.packed is kept on failure).
                if (nodes.ids != prev.ids) job.status = check_unique_ids(nodes);
                if (job.status.ok()) job.status = pack_nodes(nodes, step.spline, c.packed);
                if (job.status.ok()) {
                    release(c.curve.segments);  // not kept: the GPU builds it
                    sphere = packed_bounding_sphere(c.packed);
                }
                if (!c.pop_free_stale) {
                    c.pop_free = PopFreeCurve(
                        PopFreeSettings{.spline = step.spline, .enabled = pop_free, .blend_s = job.style->blend_s});
                    c.pop_free_stale = true;
                }
            } else {
                thread_local Curve scratch;
                if (c.pop_free_stale) {
                    c.pop_free.reset();
                    (void)c.pop_free.update(prev, scratch);
                    c.pop_free_stale = false;
                }
                job.status = c.pop_free.update(nodes, c.curve);
                if (job.status.ok()) sphere = curve_bounding_sphere(c.curve);
            }
            ++c.builds;
            if (job.status.ok()) {
                ++c.generation;
                c.bounds = sphere;
                c.bounds_generation = c.generation;
                job.changed = true;
                copy_nodes(c.previous_nodes, nodes);
                c.released = false;
            }
            c.blending = job.status.ok() && !c.pop_free_stale && c.pop_free.blending();
        });
    } else parallel_over((jobs.size() + 3) / 4, [&](std::size_t group) {
        thread_local Curve scratch[4];
        const std::size_t first = 4 * group, count = std::min<std::size_t>(4, jobs.size() - first);
        CurveJob* const job = &jobs[first];
        Step step[4];
        // The next group's components (read first thing there, out of the cache since the last frame): their
        // lines come in while this group builds. WireCurve's per-frame fields lie from lod_bounds.data (what the
        // LOD stage reads of a moving wire) to the end of previous_nodes.
        for (std::size_t k = first + 4; k < std::min(first + 8, jobs.size()); ++k) {
            const char* const c = reinterpret_cast<const char*>(&jobs[k].curve->lod_bounds.data);
            prefetch_lines<true>(c, static_cast<std::size_t>(
                                        reinterpret_cast<const char*>(&jobs[k].curve->previous_nodes + 1) - c));
            prefetch_lines<false>(jobs[k].nodes, sizeof(WireNodes));
            prefetch_lines<false>(jobs[k].style, 1);
        }
        CurveBuildJob builds[4];  // the exact curves, built together (their tridiagonal solves side by side)
        std::size_t built[4], exact = 0;
        for (std::size_t k = 0; k < count; ++k) {
            prepare(job[k], step[k]);
            if (!step[k].exact) continue;
            // The curve's records are written at the end of its build into this buffer, another wire's curve
            // before (swapped), out of the cache since the last frame: start fetching its lines now, while the
            // tangents are built, not one by one as the records are written (values unchanged).
            prefetch_lines<true>(scratch[k].segments.data(),
                                 std::min(scratch[k].segments.capacity(), job[k].nodes->size()) * sizeof(CubicBezier));
            builds[exact] = CurveBuildJob{job[k].nodes, &step[k].spline, &scratch[k], {}};
            built[exact++] = k;
        }
        build_curves(std::span(builds, exact));
        for (std::size_t e = 0; e < exact; ++e) job[built[e]].status = std::move(builds[e].status);
        for (std::size_t k = 0; k < count; ++k) finish(job[k], step[k], scratch[k]);
        for (std::size_t k = 0; k < count; ++k) go_on(job[k]);
    });

    // Serial, in entity order: errors (reported once per distinct message), work lists.
    ctx.blending.clear();
    for (CurveJob& job : jobs) {
        if (!job.status.ok()) {
            std::string message = describe_entity(job.entity) + ": " + job.status.message;
            const WireError* old = registry.try_get<WireError>(job.entity);
            if (old == nullptr || old->message != message) {
                registry.emplace_or_replace<WireError>(job.entity, message, job.status.index);
                ErrorReport report{job.entity, std::move(message)};
                if (ctx.on_error) ctx.on_error(report);
                ctx.new_errors.push_back(std::move(report));
            }
        } else if (registry.has<WireError>(job.entity)) {
            registry.remove<WireError>(job.entity);
        }
        if (job.changed) ctx.curve_changed.push_back(job.entity);
        if (job.curve->blending) ctx.blending.push_back(job.entity);
    }
    ctx.stats.curves_built = jobs.size();
    for (const CurveJob& job : jobs) {
        ctx.stats.curves_restored += job.restored ? 1u : 0u;
        ctx.stats.curves_released += job.kept_released ? 1u : 0u;
        ctx.stats.lod_updates += (job.fused & 1) ? 1u : 0u;
        ctx.stats.rings_built += (job.fused & 2) ? 1u : 0u;
        ctx.stats.meshes_built += (job.fused & 4) ? 1u : 0u;
        ctx.stats.curves_released += job.lod_outcome == 1 ? 1u : 0u;
        ctx.stats.curves_restored += job.lod_outcome == 2 ? 1u : 0u;
    }
    ctx.stats.wires = registry.storage<WireCurve>().size();
    ctx.stats.errors = registry.storage<WireError>().size();
}

void lod_system(Registry& registry, WireContext& ctx) {
    refresh_view(ctx);
    if (ctx.path == UploadPath::gpu_nodes) {
        // The nodes path: the GPU chooses counts and sides. Here the cull by the sphere of the nodes (or of the
        // blended curve); a wire without a sphere (c2, automatic: unknown overshoot) is sent and culled there.
        auto& storage = registry.storage<WireLodState>();
        const auto& curves = registry.storage<WireCurve>();  // looked up here: the workers only read it
        constexpr std::size_t kBlock = 256;  // each wire writes only its own state
        parallel_over((storage.size() + kBlock - 1) / kBlock, [&](std::size_t block) {
            for (std::size_t i = block * kBlock; i < std::min(storage.size(), (block + 1) * kBlock); ++i) {
                const WireCurve* curve = curves.try_get(storage.at(i));
                WireLodState& lod = storage.at_position(i);
                const bool visible = curve != nullptr && curve->generation > 0 &&
                                     (curve->bounds.radius_m < 0.0 || !sphere_outside_view(curve->bounds, ctx.view));
                if (visible != lod.lod.visible) ++lod.generation;
                lod.lod.visible = visible;
                lod.seen_curve = curve != nullptr ? curve->generation : 0;
                lod.seen_view = ctx.view_generation;
            }
        });
        ctx.lod_pass_generation = ctx.view_generation;
        return;
    }
    // The view moved on since the LOD last visited every wire (this frame's curve stage may have updated the
    // wires it rebuilt for the new view already: they are skipped below as up to date).
    const bool view_changed = ctx.lod_pass_generation != ctx.view_generation;
    ctx.lod_pass_generation = ctx.view_generation;

    std::vector<LodJob>& jobs = reused<LodJob, 0>();
    auto consider = [&](Entity e, const Style* style, WireCurve* curve, WireLodState* lod) {
        if (style == nullptr || curve == nullptr || lod == nullptr) return;
        if (lod->seen_curve == curve->generation && lod->seen_view == ctx.view_generation) return;
        jobs.push_back(LodJob{style, curve, lod});
        (void)e;
    };
    if (view_changed) {
        // Every wire: the camera moved. Dense order of the LOD storage (deterministic, thread-independent).
        auto& storage = registry.storage<WireLodState>();
        jobs.reserve(storage.size());
        for (std::size_t i = 0; i < storage.size(); ++i) {
            const Entity e = storage.at(i);
            consider(e, registry.try_get<Style>(e), registry.try_get<WireCurve>(e), &storage.at_position(i));
        }
    } else {
        // Same camera: only wires whose curve changed this frame.
        for (const Entity e : ctx.curve_changed) {
            if (!registry.valid(e)) continue;
            consider(e, registry.try_get<Style>(e), registry.try_get<WireCurve>(e), registry.try_get<WireLodState>(e));
        }
    }

    const uint64_t view_generation = ctx.view_generation;
    const LodSettings base = ctx.lod;
    std::vector<unsigned char>& outcome = reused<unsigned char, 0>();  // 1: curve released, 2: curve restored
    outcome.assign(jobs.size(), 0);
    parallel_over(jobs.size(), [&](std::size_t i) { outcome[i] = lod_one(jobs[i], ctx.view, base, view_generation); });
    ctx.stats.lod_updates += jobs.size();
    for (const unsigned char o : outcome) {
        ctx.stats.curves_released += o == 1 ? 1u : 0u;
        ctx.stats.curves_restored += o == 2 ? 1u : 0u;
    }
}

void rings_system(Registry& registry, WireContext& ctx) {
    if (ctx.path == UploadPath::gpu_nodes) return;  // on the GPU
    std::vector<RingJob>& jobs = reused<RingJob, 0>();
    auto& storage = registry.storage<WireRings>();
    for (std::size_t i = 0; i < storage.size(); ++i) {
        const Entity e = storage.at(i);
        const WireCurve* curve = registry.try_get<WireCurve>(e);
        const WireLodState* lod = registry.try_get<WireLodState>(e);
        if (curve == nullptr || lod == nullptr) continue;
        WireRings& rings = storage.at_position(i);
        if (!lod->lod.visible) {
            // Culled, and its curve changed since the rings were built: the next visible frame rebuilds them.
            if (rings.seen_curve != curve->generation && rings.rings.rings.capacity() != 0) release_rings(rings);
            continue;
        }
        // Counts computed for an older curve (cannot happen in install() order, but a caller may skip lod).
        if (lod->seen_curve != curve->generation) continue;
        if (rings.seen_curve == curve->generation && rings.seen_lod == lod->generation && rings.generation != 0) continue;
        jobs.push_back(RingJob{curve, lod, &rings});
    }
    const bool gpu = ctx.path == UploadPath::gpu_rings;
    parallel_over(jobs.size(), [&](std::size_t i) { rings_one(jobs[i], gpu); });
    ctx.stats.rings_built += jobs.size();
}

void mesh_system(Registry& registry, WireContext& ctx) {
    if (ctx.path != UploadPath::cpu_mesh) return;
    std::vector<MeshJob>& jobs = reused<MeshJob, 0>();
    auto& storage = registry.storage<WireMesh>();
    for (std::size_t i = 0; i < storage.size(); ++i) {
        const Entity e = storage.at(i);
        const WireRings* rings = registry.try_get<WireRings>(e);
        const WireLodState* lod = registry.try_get<WireLodState>(e);
        const Style* style = registry.try_get<Style>(e);
        if (rings == nullptr || lod == nullptr || style == nullptr) continue;
        WireMesh& mesh = storage.at_position(i);
        if (!lod->lod.visible) {
            // Culled with rings older than its curve (or released): the next visible frame rebuilds the mesh.
            const WireCurve* curve = registry.try_get<WireCurve>(e);
            if (curve != nullptr && rings->seen_curve != curve->generation && mesh.mesh.vertices.capacity() != 0) {
                release(mesh.mesh.vertices);
                release(mesh.mesh.indices);
                mesh.seen_rings = 0;
            }
            continue;
        }
        if (rings->generation == 0) continue;
        if (mesh.seen_rings == rings->generation && mesh.sides == lod->lod.drawn_sides && mesh.caps == caps_of(*style)) continue;
        jobs.push_back(MeshJob{rings, lod, style, &mesh, mesh.mesh.vertices.data(), mesh.mesh.vertices.size(),
                               mesh.mesh.indices.data(), mesh.mesh.indices.size()});
    }
    parallel_over(jobs.size(), [&](std::size_t i) {
        if (i + 1 < jobs.size()) {
            // The next wire's rings (written by the ring stage) and mesh buffers (last written a frame ago) are out
            // of L1/L2 and each a separate block: start fetching them now, while this wire's mesh is written,
            // not line by line as the writers reach them.
            const MeshJob& next = jobs[i + 1];
            const std::vector<Ring>& rings = next.rings->rings.rings;  // read-only in this stage
            prefetch_lines<false>(rings.data(), rings.size() * sizeof(Ring));
            prefetch_lines<true>(next.vertices, next.vertex_count * sizeof(TubeVertex));
            prefetch_lines<true>(next.indices, next.index_count * sizeof(uint32_t));
        }
        mesh_one(jobs[i]);
    });
    ctx.stats.meshes_built += jobs.size();
}

void draw_list_system(Registry& registry, WireContext& ctx) {
    DrawList& list = ctx.draw_list;
    list.path = ctx.path;
    list.lod = ctx.lod;
    list.items.clear();

    std::vector<Entity>& visible = reused<Entity, 1>();
    auto& lods = registry.storage<WireLodState>();
    for (std::size_t i = 0; i < lods.size(); ++i) {
        if (lods.at_position(i).lod.visible) {
            visible.push_back(lods.at(i));
        } else {
            ++ctx.stats.culled_wires;
        }
    }
    std::sort(visible.begin(), visible.end(), by_index);  // entity order, whatever the storage order

    list.items.reserve(visible.size());
    if (ctx.path == UploadPath::gpu_nodes) {
        // Items built in parallel (each its own slot), then the ones without a curve dropped, in entity order.
        std::vector<DrawItem>& items = list.items;
        items.resize(visible.size());
        std::vector<unsigned char>& keep = reused<unsigned char, 1>();
        keep.assign(visible.size(), 0);
        constexpr std::size_t kBlock = 256;
        const auto& styles = registry.storage<Style>();  // looked up here: the workers only read them
        const auto& curves = registry.storage<WireCurve>();
        auto& rings = registry.storage<WireRings>();  // each item writes its own wire's motion reference
        parallel_over((visible.size() + kBlock - 1) / kBlock, [&](std::size_t block) {
          const std::size_t end = std::min(visible.size(), (block + 1) * kBlock);
          for (std::size_t v = block * kBlock; v < end; ++v) {
            // The components of the wire 4 ahead (out of the cache since the curve stage): fetched meanwhile.
            if (v + 4 < end) {
                const Entity ahead = visible[v + 4];
                if (const WireCurve* c = curves.try_get(ahead)) {
                    prefetch_lines<false>(c, 64);
                    prefetch_lines<false>(&c->previous_nodes, sizeof(WireNodes));
                    prefetch_lines<false>(&c->packed, sizeof(PackedNodes));
                }
                if (const WireRings* r = rings.try_get(ahead)) {
                    prefetch_lines<true>(&r->motion, sizeof(MotionReference) + sizeof(r->sent_curve));
                }
                if (const Style* s = styles.try_get(ahead)) prefetch_lines<false>(s, sizeof(Style));
            }
            const Entity e = visible[v];
            const Style* style = styles.try_get(e);
            const WireCurve* curve = curves.try_get(e);
            if (style == nullptr || curve == nullptr || curve->generation == 0) continue;
            DrawItem item;
            item.material = style->material;
            item.wire_id = engine::ecs::to_integral(e);
            // The last valid nodes (the current ones unless they are invalid), or the curve built on the CPU: the
            // blended one while a pop-free blend is live (or a kind the GPU does not build).
            const bool cpu_curve = !curve->pop_free_stale || !gpu_builds(style->spline.kind);
            if (cpu_curve && !curve->curve.segments.empty()) {
                item.curve = &curve->curve;
            } else {
                item.nodes = &curve->previous_nodes;
                if (curve->packed.nodes.size() >= 2) item.packed_nodes = &curve->packed;
            }
            item.spline = spline_of(*style);
            item.nodes_generation = curve->generation;
            WireRings* sent = rings.try_get(e);
            if (sent != nullptr && sent->sent_curve != curve->generation) {
                // New nodes for the renderer: how the wire moved since the last ones it got (rings_one's fit). The
                // GPU fits it where matching by index is matching by id (packed nodes, none merged, now and the
                // last time); here otherwise (an id event, merged nodes, a blended curve).
                const WireNodes& nodes = curve->previous_nodes;
                const bool unmerged = item.packed_nodes != nullptr && item.packed_nodes->nodes.size() == nodes.size();
                if (unmerged && sent->sent_unmerged && samples_match(sent->motion, nodes)) {
                    item.fit_motion = true;
                } else if (sent->motion.count != 0) {
                    MotionReference from = sent->motion;
                    weigh_reference(from);
                    const glm::dquat q = carried_rotation(fit_motion(from, nodes));
                    item.motion = glm::vec3(static_cast<float>(q.x), static_cast<float>(q.y), static_cast<float>(q.z));
                }
                sent->motion = motion_samples(nodes);
                sent->sent_unmerged = unmerged;
                sent->sent_curve = curve->generation;
            }
            item.sides = style->max_sides ? std::max<uint32_t>(style->max_sides, 3) : kDefaultMaxSides;
            item.closed = style->closed;
            item.caps = caps_of(*style);
            items[v] = item;
            keep[v] = 1;
          }
        });
        std::size_t kept = 0;
        for (std::size_t v = 0; v < items.size(); ++v)
            if (keep[v]) items[kept++] = items[v];
        items.resize(kept);
        ctx.stats.visible_wires = visible.size();
        ctx.stats.draw_items = list.items.size();
        return;
    }
    for (const Entity e : visible) {
        const WireRings* rings = registry.try_get<WireRings>(e);
        const WireLodState* lod = registry.try_get<WireLodState>(e);
        const Style* style = registry.try_get<Style>(e);
        const WireCurve* curve = registry.try_get<WireCurve>(e);
        if (rings == nullptr || lod == nullptr || style == nullptr || curve == nullptr) continue;
        if (rings->generation == 0 || rings->seen_curve != curve->generation || rings->seen_lod != lod->generation) {
            continue;  // not rebuilt for this frame's counts (a caller skipped the rings system)
        }
        const RingSet& rs = rings->rings;
        DrawItem item;
        item.origin_m = rs.origin_m;
        item.material = style->material;
        item.wire_id = engine::ecs::to_integral(e);
        item.rings = rs.rings;
        if (ctx.path == UploadPath::gpu_rings && rings->packed.size() == rs.rings.size()) {
            item.packed = rings->packed;
            item.radius_varies = rings->radius_varies;  // computed with `packed`
        }
        item.rings_generation = rings->generation;
        // Tube sides (>= 3), or 2 for a camera-facing strip, 1 for a phone-wire line.
        item.sides = lod->lod.drawn_sides <= 2 && lod->lod.drawn_sides >= 1 ? lod->lod.drawn_sides
                                                                            : std::max<uint32_t>(lod->lod.sides, 3);
        item.closed = rs.closed;
        item.caps = caps_of(*style);
        item.u_close = rings->u_close;
        if (ctx.path == UploadPath::cpu_mesh) {
            const WireMesh* mesh = registry.try_get<WireMesh>(e);
            if (mesh == nullptr || mesh->seen_rings != rings->generation) continue;
            item.vertices = mesh->mesh.vertices;
            item.indices = mesh->mesh.indices;
            ctx.stats.vertices += mesh->mesh.vertices.size();
            ctx.stats.indices += mesh->mesh.indices.size();
        } else {
            const TubeCounts counts = item.sides <= 2 ? strip_counts(rs.rings.size(), rs.closed)
                                                      : tube_counts(rs.rings.size(), rs.closed, TubeSettings{.sides = item.sides, .caps = item.caps});
            ctx.stats.vertices += counts.vertices;
            ctx.stats.indices += counts.indices;
        }
        ctx.stats.rings += rs.rings.size();
        list.items.push_back(item);
    }
    ctx.stats.visible_wires = visible.size();
    ctx.stats.draw_items = list.items.size();
}

void install(engine::ecs::Schedule& schedule, WireContext& context) {
    WireContext* ctx = &context;
    schedule.add(kCurveSystem, [ctx](Registry& r, const engine::ecs::FrameContext& f) {
        curve_system(r, *ctx, f.last_run_tick);
    });
    schedule.add(kLodSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { lod_system(r, *ctx); });
    schedule.add(kRingsSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { rings_system(r, *ctx); });
    schedule.add(kMeshSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { mesh_system(r, *ctx); });
    schedule.add(kDrawListSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { draw_list_system(r, *ctx); });
}

bool wire_ring_set(Registry& registry, Entity wire, RingSet& out) {
    const WireCurve* curve = registry.try_get<WireCurve>(wire);
    const WireRings* rings = registry.try_get<WireRings>(wire);
    if (curve == nullptr || rings == nullptr || rings->generation == 0 || rings->seen_curve != curve->generation ||
        rings->rings.rings.size() != rings->params.size()) {
        return false;
    }
    build_rings(curve->curve, rings->params, RingSettings{.frames = rings->frame_settings}, out);
    return true;
}

namespace {

/// Adds one wire's memory to `m` (see WireMemory).
void add_wire_memory(Registry& registry, Entity e, const WireCurve& c, WireMemory& m) {
    std::size_t curve =
        sizeof(WireCurve) + bytes_of(c.curve) + bytes_of(c.previous_nodes) + bytes_of(c.lod_bounds.data);
    if (!c.pop_free_stale) {  // live pop-free state: target and rendered curves, one id per node of each
        const Curve& t = c.pop_free.target();
        curve += 2 * (bytes_of(t) + t.node_count() * sizeof(uint32_t));
    }
    std::size_t lod = 0, rings = 0, mesh = 0;
    bool visible = false;
    if (const WireLodState* l = registry.try_get<WireLodState>(e)) {
        lod = sizeof(WireLodState) + bytes_of(l->lod.counts) + bytes_of(l->lod.required);
        visible = l->lod.visible;
    }
    if (const WireRings* r = registry.try_get<WireRings>(e)) {
        rings = sizeof(WireRings) + bytes_of(r->params) + bytes_of(r->rings) + bytes_of(r->packed);
    }
    if (const WireMesh* w = registry.try_get<WireMesh>(e)) {
        mesh = sizeof(WireMesh) + bytes_of(w->mesh.vertices) + bytes_of(w->mesh.indices);
    }
    if (const Nodes* n = registry.try_get<Nodes>(e)) m.nodes_bytes += bytes_of(static_cast<const WireNodes&>(*n));
    m.curve_bytes += curve;
    m.lod_bytes += lod;
    m.rings_bytes += rings;
    m.mesh_bytes += mesh;
    const std::size_t total = curve + lod + rings + mesh;
    if (visible) {
        ++m.visible_wires;
        m.visible_bytes += total;
    } else {
        ++m.culled_wires;
        m.culled_bytes += total;
    }
}

}  // namespace

WireMemory wire_memory(Registry& registry) {
    WireMemory m;
    auto& curves = registry.storage<WireCurve>();
    for (std::size_t i = 0; i < curves.size(); ++i) add_wire_memory(registry, curves.at(i), curves.at_position(i), m);
    return m;
}

WireMemory wire_memory(Registry& registry, Entity wire) {
    WireMemory m;
    if (const WireCurve* c = registry.try_get<WireCurve>(wire)) add_wire_memory(registry, wire, *c, m);
    return m;
}

ScreenError wire_screen_error(Registry& registry, const WireContext& ctx, Entity wire, int samples_per_segment) {
    const WireCurve* curve = registry.try_get<WireCurve>(wire);
    const WireRings* rings = registry.try_get<WireRings>(wire);
    const WireLodState* lod = registry.try_get<WireLodState>(wire);
    if (curve == nullptr || rings == nullptr || lod == nullptr || !lod->lod.visible || rings->params.empty()) return {};
    return measure_screen_error(curve->curve, rings->params, ctx.view, samples_per_segment);
}

ScreenError scene_screen_error(Registry& registry, const WireContext& ctx, int samples_per_segment) {
    ScreenError worst;
    std::size_t samples = 0;
    for (const DrawItem& item : ctx.draw_list.items) {
        const Entity e{static_cast<uint32_t>(item.wire_id)};
        const ScreenError s = wire_screen_error(registry, ctx, e, samples_per_segment);
        samples += s.samples;
        if (s.max_px > worst.max_px) worst = s;
    }
    worst.samples = samples;
    return worst;
}

}  // namespace wire::systems
