// The LOD, rings and mesh stages: each over the wires whose input changed, in parallel (one wire's work in
// one_wire.cpp: the curve stage runs it too for the wires it rebuilt).
#include "stages.hpp"

namespace wire::systems {

using namespace detail;

void lod_system(Registry& registry, WireContext& ctx) {
    refresh_view(ctx);
    if (ctx.path == UploadPath::gpu_nodes) {
        // The nodes path: the GPU chooses counts and sides. Here the cull by the sphere of the nodes (or of the
        // blended curve); a wire without a sphere (c2, automatic: unknown overshoot) is sent and culled there.
        auto& storage = registry.storage<WireLodState>();
        const auto& curves = registry.storage<WireCurve>();  // looked up here: the workers only read it
        // The other views' frusta (a square-pixel viewport of their aspect: the planes depend on it alone).
        ctx.other_lod_views.clear();
        for (const engine::scene::Camera& other : ctx.other_views) {
            ctx.other_lod_views.push_back(lod_view(other, 1000.0 * static_cast<double>(other.aspect), 1000.0));
        }
        const auto outside_all = [&](const BoundingSphere& sphere) {
            if (!sphere_outside_view(sphere, ctx.view)) return false;
            for (const LodView& v : ctx.other_lod_views) {
                if (!sphere_outside_view(sphere, v)) return false;
            }
            return true;
        };
        constexpr std::size_t kBlock = 256;  // each wire writes only its own state
        parallel_over((storage.size() + kBlock - 1) / kBlock, [&](std::size_t block) {
            for (std::size_t i = block * kBlock; i < std::min(storage.size(), (block + 1) * kBlock); ++i) {
                const WireCurve* curve = curves.try_get(storage.at(i));
                WireLodState& lod = storage.at_position(i);
                const bool visible = curve != nullptr && curve->generation > 0 &&
                                     (curve->bounds.radius_m < 0.0 || !outside_all(curve->bounds));
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
    parallel_over(jobs.size(), [&](std::size_t i) { rings_one(jobs[i]); });
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

}  // namespace wire::systems
