// The curve stage: validated nodes -> the curve drawn (pop-free blended where nodes appear or vanish), its sphere;
// on the nodes path the nodes packed for the GPU instead (the GPU builds the curve).
#include "curve_state.hpp"
#include "stages.hpp"

namespace wire::systems {

using namespace detail;

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
        // To or from the nodes path: every wire again (one keeps packed nodes and no curve, the other a curve), and
        // the LOD for every wire (the nodes path computes no counts on the CPU): a wire whose nodes are bad keeps
        // its generation, and its curve comes back from its last valid nodes with counts to match.
        auto& curves = registry.storage<WireCurve>();
        for (std::size_t i = 0; i < curves.size(); ++i) work.push_back(curves.at(i));
        ++ctx.view_generation;
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
    // A wire whose curve changed goes on through lod, rings and mesh here, on this thread, while its curve is in
    // cache: exactly what the later stages would do for it (they then find it up to date and skip it).
    const auto go_on = [&](CurveJob& job) {
        if (!fused || !job.status.ok() || !job.changed || job.lod == nullptr) return;
        LodJob lod_job{job.style, job.curve, job.lod};
        job.lod_outcome = lod_one(lod_job, cull_view, lod_base, view_generation);
        job.fused |= 1;
        if (job.rings == nullptr || !job.lod->lod.visible) return;
        RingJob ring_job{job.curve, job.lod, job.rings};
        rings_one(ring_job);
        job.fused |= 2;
        if (job.mesh == nullptr) return;
        MeshJob mesh_job{job.rings, job.lod, job.style, job.mesh, nullptr, 0, nullptr, 0};
        mesh_one(mesh_job);
        job.fused |= 4;
    };
    // One wire's update in two steps around its build (prepare, finish), so that up to four wires building their
    // exact curves share build_curves (their tridiagonal solves, a serial chain of divisions each, side by side).
    const auto prepare = [&](CurveJob& job, CurveStep& step) {
        step = begin_update(*job.curve, *job.nodes, spline_of(*job.style), job.style->blend_s, pop_free);
    };
    // After the build (exact: job.status is build_curve's, its curve in `scratch`, a per-thread buffer swapped
    // with the wire's curve, not one per wire).
    const auto finish = [&](CurveJob& job, const CurveStep& step, Curve& scratch) {
        WireCurve& c = *job.curve;
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
            stale_blend(c, step);
        } else {
            job.status = step_blend(c, nodes, scratch);
        }
        if (job.status.ok()) {
            // The LOD's O(1) cull test; its LodBounds are the LOD stage's (WireCurve::lod_bounds).
            commit(c, nodes, sphere.radius_m >= 0.0 ? sphere : curve_bounding_sphere(c.curve), stays_released);
            job.changed = true;
            job.kept_released = stays_released;
        } else {
            job.restored = keep_last_curve(c, step);
        }
        end_update(c, job.status.ok());
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
                prefetch_lines<true>(ahead.packed.records.data(), ahead.packed.records.size() * sizeof(glm::uvec2));
            }
            CurveJob& job = jobs[i];
            CurveStep step;
            prepare(job, step);
            WireCurve& c = *job.curve;
            const WireNodes& nodes = *job.nodes;
            const WireNodes& prev = c.previous_nodes;
            BoundingSphere sphere{};
            if (step.exact && !gpu_builds(step.pop_free.spline.kind)) {
                // A kind the GPU does not build: the CPU builds the curve and the renderer gets its segments.
                thread_local Curve built;  // swapped in on success: a failure keeps the last valid curve
                job.status = build_curve(nodes, step.pop_free.spline, built);
                if (job.status.ok() && nodes.ids != prev.ids) job.status = check_unique_ids(nodes);
                if (job.status.ok()) {
                    std::swap(c.curve, built);
                    sphere = curve_bounding_sphere(c.curve);
                }
                stale_blend(c, step);
            } else if (step.exact) {
                // build_curve's checks and the GPU's packing in one pass (c.packed is kept on failure).
                if (nodes.ids != prev.ids) job.status = check_unique_ids(nodes);
                if (job.status.ok()) job.status = pack_nodes(nodes, step.pop_free.spline, c.packed);
                if (job.status.ok()) {
                    release(c.curve.segments);  // not kept: the GPU builds it
                    sphere = packed_bounding_sphere(c.packed);
                }
                stale_blend(c, step);
            } else {
                thread_local Curve scratch;
                job.status = step_blend(c, nodes, scratch);
                if (job.status.ok()) sphere = curve_bounding_sphere(c.curve);
            }
            if (job.status.ok()) {
                // Without its curve (the GPU builds it) the wire's curve is released, as a culled moving wire's:
                // back on cpu-mesh it comes back from the last valid nodes, also while the current ones are bad.
                commit(c, nodes, sphere, c.curve.segments.empty());
                job.changed = true;
            } else if (c.generation > 0) {
                // Bad nodes: the wire draws its last valid nodes, so `packed` holds them (it may hold none, or older
                // ones, when the wire comes from cpu-mesh), packed here on the worker thread, not on the render's.
                (void)pack_nodes(prev, step.pop_free.spline, c.packed);
            }
            end_update(c, job.status.ok());
        });
    } else parallel_over((jobs.size() + 3) / 4, [&](std::size_t group) {
        thread_local Curve scratch[4];
        const std::size_t first = 4 * group, count = std::min<std::size_t>(4, jobs.size() - first);
        CurveJob* const job = &jobs[first];
        CurveStep step[4];
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
            builds[exact] = CurveBuildJob{job[k].nodes, &step[k].pop_free.spline, &scratch[k], {}};
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

}  // namespace wire::systems
