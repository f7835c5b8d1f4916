// The ring expansion's counts, cpu-mesh's bytes and the nodes path's slot model of the wire renderer (no GL).
#include "wire/render/upload_plan.hpp"

#include "wire/packed_nodes.hpp"

#include <algorithm>
#include <cmath>

namespace wire::render {
uint32_t band_count(const RingExpansion& e) {
    if (e.rings == 0) return 0;
    return e.rings - 1 + (e.closed ? 1u : 0u);
}

bool draws_anything(const RingExpansion& e) {
    if (e.rings == 0) return false;
    if (e.sides <= 2) return band_count(e) > 0;  // strips and lines have no caps
    return band_count(e) > 0 || (!e.closed && e.caps);
}

std::array<uint32_t, kChunkKinds> chunk_counts(const RingExpansion& e) {
    std::array<uint32_t, kChunkKinds> counts{};
    if (!draws_anything(e)) return counts;
    counts[0] = e.sides > 2 && !e.closed && e.caps ? 1u : 0u;
    const uint32_t bands = band_count(e);
    counts[1] = bands / kChunkBands;
    for (uint32_t kind = 2; kind < kChunkKinds; ++kind)
        counts[kind] = (bands & chunk_kind_bands(kind)) != 0 ? 1u : 0u;  // the remainder's binary digits
    return counts;
}

uint32_t chunk_count(const RingExpansion& e) {
    const std::array<uint32_t, kChunkKinds> counts = chunk_counts(e);
    uint32_t sum = 0;
    for (uint32_t c : counts) sum += c;
    return sum;
}

uint32_t expanded_vertices(const RingExpansion& e) {
    if (!draws_anything(e)) return 0;
    const uint32_t rows = e.rings + (e.closed ? 1u : 0u);
    if (e.sides <= 2) return rows * 2;  // wire::strip_counts
    const uint32_t caps = !e.closed && e.caps ? 2u : 0u;
    return (rows + caps) * (e.sides + 1);
}

uint32_t expanded_triangles(const RingExpansion& e) {
    if (!draws_anything(e)) return 0;
    if (e.sides <= 2) return band_count(e) * 2;
    const uint32_t caps = !e.closed && e.caps ? 2u : 0u;
    return (band_count(e) * 2 + caps) * e.sides;
}

bool has_geometry(const DrawItem& item) {
    return !item.vertices.empty() && !item.indices.empty();
}

std::size_t draw_commands(const DrawList& list) {
    // Keys of the runs the renderer draws: (blended, material).
    std::vector<uint64_t> keys;
    for (const DrawItem& item : list.items) {
        if (!has_geometry(item)) continue;
        keys.push_back((item.sides == 1 ? uint64_t{1} << 63 : 0u) | uint64_t{item.material});
    }
    std::sort(keys.begin(), keys.end());
    return static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

std::size_t streamed_upload_bytes(const DrawList& list) {
    std::size_t bytes = draw_commands(list) * kCommandBytes;
    for (const DrawItem& item : list.items) {
        if (!has_geometry(item)) continue;
        bytes += kDrawRecordBytes + item.vertices.size() * (sizeof(TubeVertex) + kVertexDrawIndexBytes) +
                 item.indices.size_bytes();
    }
    return bytes;
}

std::size_t plan_nodes_frame(const DrawList& list, NodesPlan& plan) {
    ++plan.frame;
    std::size_t bytes = 0, drawn = 0;
    plan.listed.clear();
    thread_local PackedNodes packed;
    for (const DrawItem& item : list.items) {
        const bool has_curve = item.curve != nullptr && !item.curve->segments.empty();
        const bool has_packed = item.packed_nodes != nullptr && item.packed_nodes->node_count >= 2;
        if (!has_curve && !has_packed && (item.nodes == nullptr || item.nodes->size() < 2)) continue;
        auto [it, fresh] = plan.sent.try_emplace(item.wire_id);
        NodesPlan::Sent& s = it->second;
        if (!fresh && s.last_frame == plan.frame) continue;  // listed twice: drawn once
        s.last_frame = plan.frame;
        if (!fresh && item.nodes_generation != 0 && s.generation == item.nodes_generation) {
            plan.listed.push_back(item.wire_id);
            ++drawn;
            continue;
        }
        std::size_t wire_bytes = 64;  // the header
        if (has_curve) {
            wire_bytes += 64 * item.curve->segment_count();
        } else if (has_packed) {
            wire_bytes += 8 * item.packed_nodes->records.size() + 16 * item.packed_nodes->extras.size();
        } else if (pack_nodes(*item.nodes, item.spline, packed).ok()) {
            wire_bytes += 8 * packed.records.size() + 16 * packed.extras.size();
        } else {
            plan.sent.erase(it);  // not drawn; sent again next frame
            continue;
        }
        s.generation = item.nodes_generation;
        bytes += wire_bytes;
        ++drawn;
    }
    if (plan.frame % 16 == 0) {
        std::erase_if(plan.sent,
                      [&](const auto& e) { return e.second.last_frame + plan.retain_frames < plan.frame; });
    }
    if (drawn == 0) return 0;  // nothing drawn: the renderer stops before the list
    // The kept list: resent when it changed or outgrew its buffer (grown as the renderer grows it).
    const std::size_t list_bytes = std::max<std::size_t>(4 * drawn, 4);
    if (plan.listed != plan.last_listed || plan.kept_bytes == 0 || list_bytes > plan.kept_bytes) {
        bytes += 4 * plan.listed.size();
        const std::size_t need = std::max<std::size_t>(list_bytes, 16);
        if (need > plan.kept_bytes) plan.kept_bytes = std::max(need, plan.kept_bytes + plan.kept_bytes / 2);
        plan.last_listed = plan.listed;
    }
    return bytes;
}

}  // namespace wire::render
