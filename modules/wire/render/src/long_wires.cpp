// Nodes-path items longer than kNodesPathMaxNodes (renderer_state.hpp's LongWire): one GPU invocation walks a
// whole wire, so these are drawn as cpu-mesh from a curve, LOD, rings and mesh built here, in the same draw() as
// the rest of the list, which goes on the nodes path.
#include "renderer_state.hpp"

#include "wire/lod.hpp"
#include "wire/spline.hpp"

#include <algorithm>
#include <string>

namespace wire::render {

DrawStats WireRenderer::State::draw_with_long_wires(const DrawList& list, const engine::scene::Camera& camera,
                                                    const DrawSettings& settings) {
    ++long_frame;
    DrawStats mesh_stats;
    DrawList meshes{.path = UploadPath::cpu_mesh, .items = {}, .lod = list.lod};
    DrawList rest{.path = UploadPath::gpu_nodes, .items = {}, .lod = list.lod};
    const View view = view_of(camera);
    const LodSettings resolved = list.lod.resolved();
    for (const DrawItem& item : list.items) {
        if (detail::node_count(item) <= kNodesPathMaxNodes) {
            rest.items.push_back(item);
            continue;
        }
        LongWire& w = long_wires[item.wire_id];
        w.last_frame = long_frame;
        if (!w.has_curve || item.nodes_generation == 0 || item.nodes_generation != w.generation) {
            Status built = Status::success();
            if (item.curve != nullptr && !item.curve->segments.empty()) {
                w.curve = *item.curve;
            } else if (item.nodes != nullptr) {
                built = build_curve(*item.nodes, item.spline, w.curve);
            } else {
                built = Status::error("only packed nodes, which the renderer cannot build a mesh from");
            }
            if (!built) {
                ++mesh_stats.wires_skipped;
                if (mesh_stats.status.ok())
                    mesh_stats.status = Status::error("wire " + std::to_string(item.wire_id) + " (" +
                                                      std::to_string(detail::node_count(item)) +
                                                      " nodes, drawn from a mesh): " + built.message);
                continue;
            }
            w.generation = item.nodes_generation;
            w.has_curve = true;
            w.has_mesh = false;
        }
        // The wire's most sides, as the nodes path takes them from DrawItem::sides.
        LodSettings lod = list.lod;
        if (item.sides != 0) lod.max_sides = std::max(3u, std::min(resolved.max_sides, item.sides));
        update_lod(w.curve, view.lod, lod, w.lod, static_cast<const BoundingSphere*>(nullptr));
        if (!w.lod.visible) continue;
        if (!w.has_mesh || w.lod.counts != w.mesh_counts || w.lod.drawn_sides != w.mesh_sides) {
            place_rings(w.curve, w.lod.counts, w.params);
            RingSettings rings;
            if (w.has_mesh && !w.rings.frames.empty()) {
                rings.frames.has_previous_normal = true;  // no twist between rebuilds
                rings.frames.previous_normal = w.rings.frames.front().r;
            }
            build_rings(w.curve, w.params, rings, w.rings);
            if (w.lod.drawn_sides <= 2) {
                build_strip(w.rings, w.mesh);
            } else {
                build_tube(w.rings, {.sides = w.lod.drawn_sides, .caps = item.caps}, w.mesh);
            }
            w.mesh_counts = w.lod.counts;
            w.mesh_sides = w.lod.drawn_sides;
            w.has_mesh = true;
        }
        DrawItem m;
        m.origin_m = w.mesh.origin_m;
        m.wire_id = item.wire_id;
        m.material = item.material;
        m.vertices = w.mesh.vertices;
        m.indices = w.mesh.indices;
        m.rings = w.rings.rings;
        m.sides = w.lod.drawn_sides;
        m.closed = w.rings.closed;
        m.caps = item.caps;
        m.u_close = w.rings.closed ? static_cast<float>(w.rings.u.back()) : 0.0f;
        meshes.items.push_back(m);
        long_drawn.emplace_back(item.wire_id, &w);
    }
    // Wires not drawn for as long as the nodes path keeps a slot are let go.
    const uint64_t keep = desc.retain_frames != 0 ? desc.retain_frames : 180;
    std::erase_if(long_wires, [&](const auto& entry) { return entry.second.last_frame + keep < long_frame; });
    if (!meshes.items.empty()) mesh_stats = draw_mesh(meshes, camera, settings, mesh_stats);
    DrawStats stats = draw_nodes(rest, camera, settings);
    stats.bytes_uploaded += mesh_stats.bytes_uploaded;
    stats.wires_skipped += mesh_stats.wires_skipped;
    stats.draw_items += mesh_stats.draw_items;
    stats.vertices += mesh_stats.vertices;
    stats.triangles += mesh_stats.triangles;
    stats.indirect_commands += mesh_stats.indirect_commands;
    stats.multi_draw_calls += mesh_stats.multi_draw_calls;
    stats.buffer_grew = stats.buffer_grew || mesh_stats.buffer_grew;
    stats.waited_for_gpu = stats.waited_for_gpu || mesh_stats.waited_for_gpu;
    if (stats.status.ok() && !mesh_stats.status.ok()) stats.status = failed(mesh_stats, mesh_stats.status).status;
    return stats;
}

}  // namespace wire::render
