// The nodes path's frame on the CPU (node_path.hpp): the counts read back from the GPU, and the list's items
// sorted into what is sent (changed wires: header and nodes), what is listed (unchanged visible wires: a
// slot) and what is evicted (wires not drawn for a while).
#include "node_path.hpp"

#include "gpu_wire_data.hpp"

#include <algorithm>
#include <string>
#include <tuple>

namespace wire::render::detail {

void NodePath::read_counts(DrawStats& stats) {
    // The ring buffer's size: the counts the GPU reported kReadbackSlots frames ago, read only once the fence
    // after their copy has signalled (else the capacity stays: a late GPU delays growth, never feeds it
    // garbage), and kept within what one shader storage block may hold.
    if (GLsync& fence = readback_fence_[frame_ % kReadbackSlots]; fence != nullptr) {
        const GLenum waited = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 0);
        if (waited == GL_ALREADY_SIGNALED || waited == GL_CONDITION_SATISFIED) {
            const auto* seen =
                static_cast<const uint32_t*>(readback_map_) + kCounterBytes / 4 * (frame_ % kReadbackSlots);
            const std::size_t most = max_block_bytes_ / sizeof(PackedRing) * 2 / 3;
            if (seen[0] > ring_capacity_ * 3 / 4)
                ring_capacity_ = std::min(std::size_t{seen[0]} * 3 / 2, most);
            stats.wires_coarse = seen[1];
            stats.triangles = seen[3];
            glDeleteSync(fence);
            fence = nullptr;
        }
    }
}

NodePath::Gathered NodePath::gather(const DrawList& list, std::size_t materials, WireUpload& up,
                                    DrawStats& stats) {
    Gathered g;
    std::size_t& node_total = g.node_total;
    std::size_t& extra_total = g.extra_total;  // 8-byte units and vec4s in the region's node and extra arrays
    std::size_t& segments_visible = g.segments_visible;
    up.clear();
    node_pieces_.clear(), extra_pieces_.clear();
    visible_slots_.clear();
    dispatched_.clear(), listed_.clear(), changed_wires_.clear();
    material_used_.assign(materials, 0);
    for (std::size_t i = 0; i < list.items.size(); ++i) {
        const DrawItem& item = list.items[i];
        const bool has_curve = item.curve != nullptr && !item.curve->segments.empty();
        const bool packed = item.packed_nodes != nullptr && item.packed_nodes->node_count >= 2;
        if (!has_curve && !packed && (item.nodes == nullptr || item.nodes->size() < 2)) continue;
        // draw() sends longer items to long_wires.cpp: a guard for other callers.
        if (const std::size_t nodes = node_count(item); nodes > kNodesPathMaxNodes) {
            ++stats.wires_skipped;
            if (stats.status.ok())
                stats.status = Status::error("wire " + std::to_string(item.wire_id) + ": " +
                                             std::to_string(nodes) + " nodes; the nodes path draws at most " +
                                             std::to_string(kNodesPathMaxNodes) +
                                             " a wire: not drawn (draw it on cpu-mesh, or split it)");
            continue;
        }
        if (item.material >= materials) {
            // The other paths assert this; here the GPU would index past its buckets: skipped, said once.
            ++stats.wires_skipped;
            if (stats.status.ok())
                stats.status = Status::error("wire " + std::to_string(item.wire_id) + ": material " +
                                             std::to_string(item.material) +
                                             " is out of range (the nodes path draws materials below " +
                                             std::to_string(materials) + "): not drawn");
            continue;
        }
        Slot* known = i < item_slot_.size() ? item_slot_[i] : nullptr;
        bool fresh = false;
        auto it = slots_.end();
        if (known == nullptr) {
            std::tie(it, fresh) = slots_.try_emplace(item.wire_id);
            known = &it->second;
        }
        Slot& slot = *known;
        if (slot.last_frame == frame_) {
            // A second item with this wire_id: both would write one slot's curve and state. The first is
            // drawn.
            ++stats.wires_skipped;
            if (stats.status.ok())
                stats.status =
                    Status::error("wire " + std::to_string(item.wire_id) +
                                  ": listed twice in the draw list (ids must be unique): drawn once");
            continue;
        }
        if (fresh) {
            const std::optional<uint32_t> index = acquire_slot();
            if (!index) {
                slots_.erase(it);
                continue;
            }
            slot.index = *index;
        }
        slot.last_frame = frame_;
        const bool changed = i < changed_item_.size() && changed_item_[i] != 0;
        if (changed) {
            uint32_t segments = 0;
            const std::size_t nodes_before = up.nodes.size(), extras_before = up.extras.size();
            const std::size_t node_pieces_before = node_pieces_.size(),
                              extra_pieces_before = extra_pieces_.size();
            const std::size_t node_total_before = node_total, extra_total_before = extra_total;
            if (packed) {
                // Packed by the systems: the header here, the nodes copied straight from them into the
                // region.
                const PackedNodes& p = *item.packed_nodes;
                up.headers.push_back(packed_header(p, slot.segment_first, slot.index, item.material,
                                                   item.caps, {item.motion, item.fit_motion},
                                                   static_cast<uint32_t>(node_total),
                                                   static_cast<uint32_t>(extra_total)));
                node_pieces_.push_back({p.records.data(), 0, p.records.size(), node_total});
                node_total += p.records.size();
                if (!p.extras.empty()) {
                    extra_pieces_.push_back({p.extras.data(), 0, p.extras.size(), extra_total});
                    extra_total += p.extras.size();
                }
                segments = static_cast<uint32_t>(p.segment_count());
            } else {
                // Made here (a blended curve's segments; nodes not packed by the systems): into `up`, then
                // copied.
                if (has_curve) {
                    append_segments(*item.curve, slot.segment_first, slot.index, item.material, item.caps,
                                    {item.motion, false}, up);
                    segments = static_cast<uint32_t>(item.curve->segment_count());
                } else if (!append_wire(*item.nodes, item.spline, slot.segment_first, slot.index,
                                        item.material, item.caps, {item.motion, item.fit_motion}, up,
                                        segments)) {
                    ++stats.wires_skipped;  // the systems validate; a kind the GPU does not build is skipped
                                            // here
                    continue;
                }
                GpuCurveHeader& h = up.headers.back();
                h.node_first = static_cast<uint32_t>(node_total),
                h.extra_first = static_cast<uint32_t>(extra_total);
                node_pieces_.push_back({nullptr, nodes_before, up.nodes.size() - nodes_before, node_total});
                node_total += up.nodes.size() - nodes_before;
                extra_pieces_.push_back(
                    {nullptr, extras_before, up.extras.size() - extras_before, extra_total});
                extra_total += up.extras.size() - extras_before;
            }
            // The wire's most sides (the LOD's max_sides for it; its Style's).
            up.headers.back().flags |= std::min(std::max<uint32_t>(item.sides, 3u), kHeaderSidesMask)
                                       << kHeaderSidesShift;
            if (segments != slot.segments) {
                free_segments(slot.segment_first, slot.segments);
                uint32_t first = 0;
                if (!allocate_segments(segments, first)) {
                    up.headers.pop_back();
                    up.nodes.resize(nodes_before), up.extras.resize(extras_before);
                    node_pieces_.resize(node_pieces_before), extra_pieces_.resize(extra_pieces_before);
                    node_total = node_total_before, extra_total = extra_total_before;
                    slot.segments = 0, slot.built = false;
                    ++stats.wires_skipped;
                    continue;
                }
                slot.segment_first = first, slot.segments = segments;
                up.headers.back().segment_first = first;
                clear_slot_state(slot.index, 16);  // the LOD starts afresh
            }
            slot.generation = item.nodes_generation;
            slot.built = true;
            changed_wires_.push_back({item.wire_id, slot.index, slot.segment_first, slot.segments});
        }
        if (!slot.built) continue;
        // The ring pass takes the changed wires' slots from their headers: only the others are listed.
        if (!changed) {
            visible_slots_.push_back(slot.index);
            listed_.push_back({item.wire_id, slot.index, slot.segment_first, slot.segments});
        }
        segments_visible += slot.segments;
        material_used_[item.material] = 1;
    }
    // Wires not drawn for a while give their slot and segments back: looked for every 16th frame (a walk over
    // every resident wire; evicted up to 15 frames after retain_frames, which changes nothing that is drawn).
    for (auto it = frame_ % 16 == 0 ? slots_.begin() : slots_.end(); it != slots_.end();) {
        if (it->second.last_frame + retain_frames_ < frame_) {
            free_segments(it->second.segment_first, it->second.segments);
            free_slots_.push_back(it->second.index);
            it = slots_.erase(it);
            ++stats.wires_evicted;
        } else {
            ++it;
        }
    }
    return g;
}

}  // namespace wire::render::detail
