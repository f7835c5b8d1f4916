// The draw-list stage: one DrawItem per visible wire, in entity order; on the nodes path the wire's nodes or
// blended curve and its motion since the renderer's last nodes.
#include "stages.hpp"

namespace wire::systems {

using namespace detail;

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
                if (curve->packed.node_count >= 2) item.packed_nodes = &curve->packed;
            }
            item.spline = spline_of(*style);
            item.nodes_generation = curve->generation;
            WireRings* sent = rings.try_get(e);
            if (sent != nullptr && sent->sent_curve != curve->generation) {
                // New nodes for the renderer: how the wire moved since the last ones it got (rings_one's fit). The
                // GPU fits it where matching by index is matching by id (packed nodes, none merged, now and the
                // last time); here otherwise (an id event, merged nodes, a blended curve).
                const WireNodes& nodes = curve->previous_nodes;
                const bool unmerged = item.packed_nodes != nullptr && item.packed_nodes->node_count == nodes.size();
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
        // Tube sides (>= 3), or 2 for a camera-facing strip, 1 for a phone-wire line.
        item.sides = lod->lod.drawn_sides <= 2 && lod->lod.drawn_sides >= 1 ? lod->lod.drawn_sides
                                                                            : std::max<uint32_t>(lod->lod.sides, 3);
        item.closed = rs.closed;
        item.caps = caps_of(*style);
        item.u_close = rings->u_close;
        const WireMesh* mesh = registry.try_get<WireMesh>(e);
        if (mesh == nullptr || mesh->seen_rings != rings->generation) continue;
        item.vertices = mesh->mesh.vertices;
        item.indices = mesh->mesh.indices;
        ctx.stats.vertices += mesh->mesh.vertices.size();
        ctx.stats.indices += mesh->mesh.indices.size();
        ctx.stats.rings += rs.rings.size();
        list.items.push_back(item);
    }
    ctx.stats.visible_wires = visible.size();
    ctx.stats.draw_items = list.items.size();
}

}  // namespace wire::systems
