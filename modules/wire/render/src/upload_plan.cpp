// Ring packing, draw counts and the residency bookkeeping of the wire renderer (no GL).
#include "wire/render/upload_plan.hpp"

#include "wire/packed_nodes.hpp"

#include <algorithm>
#include <cmath>

namespace wire::render {
uint32_t band_count(const DrawItem& item) {
    const auto rings = static_cast<uint32_t>(item.rings.size());
    if (rings == 0) return 0;
    return rings - 1 + (item.closed ? 1u : 0u);
}

bool has_geometry(const DrawItem& item, UploadPath path) {
    if (path == UploadPath::cpu_mesh) return !item.vertices.empty() && !item.indices.empty();
    if (item.rings.empty()) return false;
    if (item.sides <= 2) return band_count(item) > 0;  // strips and lines have no caps
    return band_count(item) > 0 || (!item.closed && item.caps);
}

std::array<uint32_t, kChunkKinds> chunk_counts(const DrawItem& item) {
    std::array<uint32_t, kChunkKinds> counts{};
    if (!has_geometry(item, UploadPath::gpu_rings)) return counts;
    counts[0] = item.sides > 2 && !item.closed && item.caps ? 1u : 0u;
    const uint32_t bands = band_count(item);
    counts[1] = bands / kChunkBands;
    for (uint32_t kind = 2; kind < kChunkKinds; ++kind)
        counts[kind] = (bands & chunk_kind_bands(kind)) != 0 ? 1u : 0u;  // the remainder's binary digits
    return counts;
}

uint32_t chunk_count(const DrawItem& item) {
    const std::array<uint32_t, kChunkKinds> counts = chunk_counts(item);
    uint32_t sum = 0;
    for (uint32_t c : counts) sum += c;
    return sum;
}

namespace {

std::size_t count_commands(std::span<const DrawItem> items, UploadPath path) {
    // Keys of the runs the renderer draws: (blended, material) on cpu-mesh, plus (side count, kind) on gpu-rings.
    std::vector<uint64_t> keys;
    for (const DrawItem& item : items) {
        if (!has_geometry(item, path)) continue;
        const uint64_t run = (item.sides == 1 ? uint64_t{1} << 63 : 0u) | (uint64_t{item.material} << 32);
        if (path == UploadPath::cpu_mesh) {
            keys.push_back(run);
            continue;
        }
        const std::array<uint32_t, kChunkKinds> counts = chunk_counts(item);
        for (uint32_t kind = 0; kind < kChunkKinds; ++kind)
            if (counts[kind] != 0) keys.push_back(run | (uint64_t{item.sides} << 8) | kind);
    }
    std::sort(keys.begin(), keys.end());
    return static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

}  // namespace

std::size_t draw_commands(const DrawList& list) {
    return count_commands(list.items, list.path);
}

uint32_t expanded_vertices(const DrawItem& item) {
    if (!has_geometry(item, UploadPath::gpu_rings)) return 0;
    const uint32_t rows = static_cast<uint32_t>(item.rings.size()) + (item.closed ? 1u : 0u);
    if (item.sides <= 2) return rows * 2;  // wire::strip_counts
    const uint32_t caps = !item.closed && item.caps ? 2u : 0u;
    return (rows + caps) * (item.sides + 1);
}

uint32_t expanded_triangles(const DrawItem& item) {
    if (!has_geometry(item, UploadPath::gpu_rings)) return 0;
    if (item.sides <= 2) return band_count(item) * 2;
    const uint32_t caps = !item.closed && item.caps ? 2u : 0u;
    return (band_count(item) * 2 + caps) * item.sides;
}

std::size_t streamed_upload_bytes(const DrawList& list) {
    std::size_t bytes = draw_commands(list) * kCommandBytes;
    for (const DrawItem& item : list.items) {
        if (!has_geometry(item, list.path)) continue;
        if (list.path == UploadPath::cpu_mesh) {
            bytes += kDrawRecordBytes + item.vertices.size() * (sizeof(TubeVertex) + kVertexDrawIndexBytes) +
                     item.indices.size_bytes();
        } else {
            bytes += kDrawRecordBytes + chunk_count(item) * kChunkRecordBytes + item.rings.size() * sizeof(PackedRing);
        }
    }
    return bytes;
}

RingResidency::Touch RingResidency::touch(const DrawItem& item) {
    Touch t;
    auto [it, inserted] = entries_.try_emplace(item.wire_id);
    Residency& e = it->second;
    const bool changed = !inserted && (item.rings_generation == 0 || e.generation != item.rings_generation);
    if (changed && e.changed_frame + 1 == frame_) {  // changed in two frames running: moving, stream it
        if (e.size_bytes > 0) t.replaced = e;
        t.stream = true;
    } else if (inserted || changed || e.streamed) {  // new, changed after a still frame, or settled
        if (!inserted && e.size_bytes > 0) t.replaced = e;
        t.upload = true;
    }
    if (t.stream || t.upload) {
        const uint64_t changed_frame = inserted || changed ? frame_ : e.changed_frame;
        e = Residency{};
        e.wire_id = item.wire_id;
        e.generation = item.rings_generation;
        e.rings = static_cast<uint32_t>(item.rings.size());
        e.changed_frame = changed_frame;
        e.streamed = t.stream;
    }
    e.last_frame = frame_;
    t.entry = &e;
    return t;
}

std::vector<Residency> RingResidency::evict() {
    std::vector<Residency> out;
    for (auto it = entries_.begin(); it != entries_.end();) {
        if (frame_ - it->second.last_frame > retain_frames_) {
            out.push_back(it->second);
            it = entries_.erase(it);
        } else {
            ++it;
        }
    }
    // Deterministic order for the caller (the map's order is not).
    std::sort(out.begin(), out.end(), [](const Residency& a, const Residency& b) { return a.wire_id < b.wire_id; });
    return out;
}

const Residency* RingResidency::find(uint64_t wire_id) const {
    const auto it = entries_.find(wire_id);
    return it == entries_.end() ? nullptr : &it->second;
}

RetainedFrame plan_retained_frame(const DrawList& list, RingResidency& residency) {
    RetainedFrame f;
    residency.begin_frame();
    f.bytes = count_commands(list.items, UploadPath::gpu_rings) * kCommandBytes;
    for (const DrawItem& item : list.items) {
        if (!has_geometry(item, UploadPath::gpu_rings)) continue;
        f.bytes += kDrawRecordBytes + chunk_count(item) * kChunkRecordBytes;
        const RingResidency::Touch t = residency.touch(item);
        if (t.upload || t.stream) {
            f.ring_bytes += item.rings.size() * sizeof(PackedRing);
            ++f.wires_uploaded;
        }
    }
    f.wires_evicted = residency.evict().size();
    f.bytes += f.ring_bytes;
    return f;
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
