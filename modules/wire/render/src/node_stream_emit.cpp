// The nodes path's part of the node stream (node_path.hpp): attaching it, and each frame the streamed wires' headers
// into the stream's region (the written ones) or onto the list of slots (the others), in parallel blocks.
#include "node_path.hpp"
#include "node_stream_state.hpp"
#include "gpu_wire_data.hpp"

#include <epoxy/gl.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <optional>

namespace wire::render {

namespace detail {

void attach_stream(NodePath& path, NodeStream& stream) {
    StreamState& s = stream.state();
    s.path = &path;
    path.attach(&s);
}
void detach_stream(NodeStream& stream, const Status& why) {
    StreamState& s = stream.state();
    if (s.path != nullptr) s.path->attach(nullptr);
    s.path = nullptr;
    s.unusable = why;
}
bool stream_active(NodeStream& stream) { return stream.state().active; }
void end_stream_frame(NodeStream& stream) {
    StreamState& s = stream.state();
    if (!s.active) return;
    s.buffer.end();
    s.active = false;
}

std::size_t NodePath::emit_stream(std::size_t materials, std::size_t& segments_visible, DrawStats& stats) {
    StreamState& s = *stream_;
    stream_wires_.clear();
    stream_bytes_ = 0;
    const uint32_t frame = s.active ? s.frame : 0;  // 0: nothing written this frame
    const auto wire_count = static_cast<uint32_t>(s.wires.size());
    // What a wire does this frame: 0 nothing, 1 its written nodes go to the GPU, 2 it is listed (drawn from its
    // state on the GPU), 3 skipped (its material is out of range).
    const auto role = [&](const StreamState::Wire& w, uint32_t) -> int {
        if (!w.live) return 0;
        if (w.material >= materials) return 3;
        if (w.written == frame && frame != 0) return 1;
        return w.built ? 2 : 0;
    };
    // (1) Serially, the few written wires that need a slot or another segment count (GL calls, the allocator).
    for (uint32_t i : s.pending) {
        StreamState::Wire& w = s.wires[i];
        if (role(w, i) != 1) continue;
        if (w.slot == UINT32_MAX) {
            const std::optional<uint32_t> slot = acquire_slot();
            if (!slot) {
                w.written = 0;
                ++stats.wires_skipped;
                continue;
            }
            w.slot = *slot;
            w.built = false;
        }
        const uint32_t segments = s.styles[i].closed ? w.count : w.count - 1;
        if (segments == w.segments) continue;
        free_segments(w.segment_first, w.segments);
        w.segments = 0;
        uint32_t first = 0;
        if (!allocate_segments(segments, first)) {
            w.built = false, w.written = 0;
            ++stats.wires_skipped;
            continue;
        }
        w.segment_first = first, w.segments = segments;
        clear_slot_state(w.slot, 16);  // the LOD starts afresh (SlotState::lod)
    }
    s.pending.clear();
    // (2) Per block of wires, in parallel: how many it sends and lists; then (3) each block writes its headers and
    // list entries at its offsets (prefix sums), so the order is the wires' whatever the threads.
    constexpr uint32_t kBlock = 4096;
    const uint32_t blocks = (wire_count + kBlock - 1) / kBlock;
    struct Block {
        std::size_t changed = 0, listed = 0, segments = 0, bytes = 0;
        uint32_t bad_material = UINT32_MAX;
        std::vector<uint8_t> used;
    };
    std::vector<Block> block(blocks);
    const auto over_blocks = [&](auto&& body) {
        if (wire_count >= 2 * kBlock) {
            tbb::parallel_for(uint32_t{0}, blocks, [&](uint32_t b) { body(b); });
        } else {
            for (uint32_t b = 0; b < blocks; ++b) body(b);
        }
    };
    over_blocks([&](uint32_t b) {
        Block& k = block[b];
        for (uint32_t i = b * kBlock; i < std::min(wire_count, (b + 1) * kBlock); ++i) {
            const int r = role(s.wires[i], i);
            k.changed += r == 1, k.listed += r == 2;
            if (r == 3 && k.bad_material == UINT32_MAX) k.bad_material = i;
        }
    });
    std::size_t changed = 0, listed = 0;
    std::vector<std::size_t> changed_at(blocks), listed_at(blocks);
    for (uint32_t b = 0; b < blocks; ++b) {
        changed_at[b] = changed, listed_at[b] = listed;
        changed += block[b].changed, listed += block[b].listed;
        if (block[b].bad_material != UINT32_MAX && stats.status.ok()) {
            const uint32_t i = block[b].bad_material;
            stats.status = Status::error("stream wire " + std::to_string(i) + ": material " +
                                         std::to_string(s.styles[i].material) + " is out of range (" +
                                         std::to_string(materials) + " materials): not drawn");
        }
    }
    const std::size_t visible_before = visible_slots_.size(), listed_before = listed_.size();
    visible_slots_.resize(visible_before + listed);
    listed_.resize(listed_before + listed);
    stream_wires_.resize(changed);
    auto* headers = s.active ? reinterpret_cast<GpuCurveHeader*>(s.region.data + s.header_at) : nullptr;
    over_blocks([&](uint32_t b) {
        Block& k = block[b];
        k.used.assign(materials, 0);
        std::size_t c = changed_at[b], l = listed_at[b];
        for (uint32_t i = b * kBlock; i < std::min(wire_count, (b + 1) * kBlock); ++i) {
            StreamState::Wire& w = s.wires[i];
            const int r = role(w, i);
            if (r == 0 || r == 3) continue;
            const StreamStyle& style = s.styles[i];
            const Dispatched d{NodeStream::wire_id(StreamWire{i}), w.slot, w.segment_first, w.segments};
            if (r == 1) {
                const uint32_t kind = style.kind == SplineKind::linear      ? kKindLinear
                                      : style.kind == SplineKind::c2        ? kKindC2
                                      : style.kind == SplineKind::automatic ? kKindAutomatic
                                                                            : kKindCatmullRom;
                const uint32_t sides = style.max_sides ? std::max<uint32_t>(style.max_sides, 3) : 16u;
                // The GPU fits the motion by index where the last upload had these nodes' count and neither merged.
                const bool fit = w.built && w.sent_count == w.count && w.sent_unmerged && w.unmerged;
                GpuCurveHeader h;
                h.node_first = w.node_first;
                h.node_count = w.count;
                h.segment_first = w.segment_first;
                h.flags = (style.closed ? kHeaderClosed : 0u) | (kind << kHeaderKindShift) |
                          (style.caps ? kHeaderCaps : 0u) | (fit ? kHeaderFitMotion : 0u) |
                          (std::min(sides, kHeaderSidesMask) << kHeaderSidesShift) |
                          (style.material << kHeaderMaterialShift);
                h.kb = {static_cast<float>(style.alpha), static_cast<float>(style.tension),
                        static_cast<float>(style.bias), static_cast<float>(style.continuity)};
                h.slot = w.slot;
                std::memcpy(h.origin_m, w.origin, sizeof h.origin_m);
                std::memcpy(headers + c, &h, sizeof h);  // mapped memory: written once, never read
                w.built = true;
                w.sent_count = w.count;
                w.sent_unmerged = w.unmerged;
                stream_wires_[c++] = d;
                k.bytes += sizeof(GpuCurveHeader) + std::size_t{w.count} * sizeof(glm::vec4);
            } else {
                visible_slots_[visible_before + l] = w.slot;
                listed_[listed_before + l] = d;
                ++l;
            }
            k.segments += w.segments;
            k.used[style.material] = 1;
        }
    });
    for (const Block& k : block) {
        segments_visible += k.segments;
        stream_bytes_ += k.bytes;
        for (std::size_t m = 0; m < k.used.size(); ++m) material_used_[m] |= k.used[m];
    }
    s.headers = changed;
    return changed;
}

NodePath::StreamLayout NodePath::stream_layout() const {
    const StreamState& s = *stream_;
    StreamLayout l;
    l.buffer = s.region.buffer;
    l.header_at = s.region.offset_bytes + s.header_at;
    l.header_bytes = std::max<std::size_t>(s.headers, 1) * sizeof(GpuCurveHeader);
    l.node_at = s.region.offset_bytes + s.node_at;
    l.node_bytes = std::max<std::size_t>(std::min(s.cursor.load(), s.node_capacity), 1) * sizeof(glm::vec4);
    return l;
}

std::size_t NodePath::stream_nodes() const { return std::min(stream_->cursor.load(), stream_->node_capacity); }
std::size_t NodePath::stream_wires() const { return stream_->wires.size(); }

void NodePath::unbuild_stream() {
    StreamState& s = *stream_;
    for (const Dispatched& d : stream_wires_) s.wires[static_cast<uint32_t>(d.wire_id)].built = false;
}

}  // namespace detail
}  // namespace wire::render

