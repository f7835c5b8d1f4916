// The renderer's nodes path (see node_path.hpp).
#include "node_path.hpp"

#include "gpu_wire_data.hpp"
#include "shaders.hpp"

#include "wire/render/upload_plan.hpp"

#include <epoxy/gl.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <optional>
#include <cstring>
#include <string>
#include <tuple>

namespace wire::render::detail {
namespace {

namespace gfx = engine::gfx;

constexpr std::size_t kAlign = 256;  // >= GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT everywhere we know
constexpr uint32_t kReadbackSlots = 3;
// The ring pass's Counter: rings, wires that did not fit, reserve rings, triangles.
constexpr std::size_t kCounterBytes = 16;
constexpr std::size_t kJobBytes = 64, kSlotStateBytes = 32, kSegmentBytes = 64, kDrawBytes = 32;

std::size_t align_up(std::size_t v) { return (v + kAlign - 1) / kAlign * kAlign; }

void clear_range(const gfx::Buffer& buffer, std::size_t offset, std::size_t bytes) {
    glClearNamedBufferSubData(buffer.id(), GL_R32UI, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes),
                              GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
}

/// Fails, naming the limit, when `program` uses more shader storage blocks or bindings than this driver allows
/// (checked at create: a link that succeeds can still exceed a limit some drivers enforce only at dispatch).
Status check_storage_limits(const gfx::Program& program, const char* label, uint32_t bindings) {
    GLint blocks = 0, max_blocks = 0, max_bindings = 0, max_outputs = 0;
    glGetProgramInterfaceiv(program.id(), GL_SHADER_STORAGE_BLOCK, GL_ACTIVE_RESOURCES, &blocks);
    glGetIntegerv(GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, &max_blocks);
    glGetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &max_bindings);
    glGetIntegerv(GL_MAX_COMBINED_SHADER_OUTPUT_RESOURCES, &max_outputs);
    const auto fails = [&](const char* limit, GLint value, GLint need) {
        return Status::error(std::string(label) + ": needs " + std::to_string(need) + " for " + limit + ", the driver allows " +
                             std::to_string(value));
    };
    if (blocks > max_blocks) return fails("GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS", max_blocks, blocks);
    if (static_cast<GLint>(bindings) > max_bindings)
        return fails("GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS", max_bindings, static_cast<GLint>(bindings));
    if (blocks > max_outputs) return fails("GL_MAX_COMBINED_SHADER_OUTPUT_RESOURCES", max_outputs, blocks);
    return Status::success();
}

}  // namespace

void NodePath::set_lod(const LodSettings& lod) {
    lod_ = lod;
    max_sides_ = std::clamp<uint32_t>(lod.max_sides ? lod.max_sides : 32u, 3u, kMaxSides);
}

Expected<std::unique_ptr<NodePath>> NodePath::create(uint32_t retain_frames) {
    auto path = std::make_unique<NodePath>();
    auto curve = gfx::make_program({.label = "wire nodes: curves", .compute = curve_program_source()});
    if (!curve) return curve.error();
    auto rings = gfx::make_program({.label = "wire nodes: rings", .compute = ring_program_source()});
    if (!rings) return rings.error();
    path->curve_program_ = std::move(*curve);
    path->ring_program_ = std::move(*rings);
    if (Status st = check_storage_limits(path->curve_program_, "wire nodes: curves", kCurveBindings); !st) return st;
    if (Status st = check_storage_limits(path->ring_program_, "wire nodes: rings", kRingBindings); !st) return st;
    path->set_lod({});
    path->retain_frames_ = retain_frames ? retain_frames : 180;
    auto readback = gfx::make_buffer({.size_bytes = kReadbackSlots * kCounterBytes,
                                      .storage_flags = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT,
                                      .label = "wire nodes: ring counter readback"});
    if (!readback) return readback.error();
    path->readback_ = std::move(*readback);
    // New buffers hold whatever the driver's pool held: zero, so a slot never written reads as no rings.
    glClearNamedBufferData(path->readback_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    if (max_block > 0) path->max_block_bytes_ = static_cast<std::size_t>(max_block);
    path->readback_map_ = glMapNamedBufferRange(path->readback_.id(), 0, kReadbackSlots * kCounterBytes,
                                                GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT);
    if (path->readback_map_ == nullptr) return Error{"wire nodes: could not map the ring counter readback"};
    return path;
}

NodePath::~NodePath() {
    for (GLsync& fence : readback_fence_) {
        if (fence != nullptr) glDeleteSync(fence);
    }
}

std::size_t NodePath::gl_buffers() const {
    std::size_t n = 0;
    for (const gfx::Buffer* b : {&slot_headers_, &slot_state_, &motion_refs_, &segments_, &counts_, &scratch_, &jobs_, &draws_, &chunks_,
                                 &rings_, &buckets_, &commands_, &counter_, &templates_, &readback_, &visible_kept_}) {
        n += b->id() != 0 ? 1 : 0;
    }
    for (const gfx::Buffer& b : view_states_) n += b.id() != 0 ? 1 : 0;
    return n;
}

Status NodePath::ensure(gfx::Buffer& buffer, std::size_t& capacity, std::size_t bytes, const char* label,
                        bool keep_contents) {
    bytes = std::max<std::size_t>(bytes, 16);
    if (bytes <= capacity && buffer.id() != 0) return Status::success();
    const std::size_t size = std::max(bytes, capacity + capacity / 2);
    auto made = gfx::make_buffer({.size_bytes = size, .label = label});
    if (!made) return made.error();
    if (keep_contents && buffer.id() != 0 && capacity != 0) {
        glCopyNamedBufferSubData(buffer.id(), made->id(), 0, 0, static_cast<GLsizeiptr>(capacity));
    }
    buffer = std::move(*made);
    capacity = size;
    return Status::success();
}

Status NodePath::grow_slots(std::size_t slots) {
    if (slots <= slot_capacity_) return Status::success();
    const std::size_t want = std::max<std::size_t>(slots, std::max<std::size_t>(256, 2 * slot_capacity_));
    if (Status st = ensure(slot_headers_, slot_header_bytes_, want * sizeof(GpuCurveHeader), "wire nodes: headers", true); !st) return st;
    const std::size_t old = slot_state_bytes_;
    if (Status st = ensure(slot_state_, slot_state_bytes_, want * kSlotStateBytes, "wire nodes: slot state", true); !st) return st;
    if (slot_state_bytes_ > old) clear_range(slot_state_, old, slot_state_bytes_ - old);
    for (gfx::Buffer& state : view_states_) {
        if (state.id() == 0 || state.size_bytes() >= slot_state_bytes_) continue;
        auto made = gfx::make_buffer({.size_bytes = slot_state_bytes_, .label = "wire nodes: view slot state"});
        if (!made) return made.error();
        glCopyNamedBufferSubData(state.id(), made->id(), 0, 0, static_cast<GLsizeiptr>(state.size_bytes()));
        clear_range(*made, state.size_bytes(), slot_state_bytes_ - state.size_bytes());
        state = std::move(*made);
    }
    const std::size_t old_refs = motion_ref_bytes_;
    if (Status st = ensure(motion_refs_, motion_ref_bytes_, want * kMotionRefBytes, "wire nodes: motion references", true);
        !st) {
        return st;
    }
    if (motion_ref_bytes_ > old_refs) clear_range(motion_refs_, old_refs, motion_ref_bytes_ - old_refs);
    slot_capacity_ = want;
    return Status::success();
}

Status NodePath::grow_segments(std::size_t segments) {
    if (segments <= segment_capacity_) return Status::success();
    const std::size_t want = std::max<std::size_t>(segments, std::max<std::size_t>(4096, 2 * segment_capacity_));
    if (Status st = ensure(segments_, segment_bytes_, want * kSegmentBytes, "wire nodes: segments", true); !st) return st;
    if (Status st = ensure(counts_, count_bytes_, want * 4, "wire nodes: ring counts", true); !st) return st;
    segment_capacity_ = want;
    return Status::success();
}

const gfx::Buffer* NodePath::view_state(uint32_t view) {
    if (view == 0) return &slot_state_;
    if (view_states_.size() < view) view_states_.resize(view);
    gfx::Buffer& state = view_states_[view - 1];
    if (state.id() == 0 && slot_state_bytes_ != 0) {
        auto made = gfx::make_buffer({.size_bytes = slot_state_bytes_, .label = "wire nodes: view slot state"});
        if (!made) return nullptr;
        clear_range(*made, 0, slot_state_bytes_);  // every wire's LOD starts afresh in a new view
        state = std::move(*made);
    }
    return &state;
}

void NodePath::clear_slot_state(uint32_t index, std::size_t bytes) {
    clear_range(slot_state_, index * kSlotStateBytes, bytes);
    for (const gfx::Buffer& state : view_states_) {
        if (state.id() != 0) clear_range(state, index * kSlotStateBytes, bytes);
    }
}

std::optional<uint32_t> NodePath::acquire_slot() {
    uint32_t index = 0;
    if (free_slots_.empty()) {
        if (!grow_slots(std::size_t{slot_count_} + 1)) return std::nullopt;
        index = slot_count_++;
    } else {
        index = free_slots_.back();
        free_slots_.pop_back();
    }
    clear_slot_state(index, kSlotStateBytes);
    clear_range(motion_refs_, index * kMotionRefBytes, 32);  // no reference: nothing to fit against
    return index;
}

void NodePath::release_slot(uint32_t index, uint32_t segment_first, uint32_t segments) {
    free_segments(segment_first, segments);
    free_slots_.push_back(index);
}

bool NodePath::allocate_segments(uint32_t count, uint32_t& first) {
    std::optional<std::size_t> at = segment_ranges_.allocate(count);
    if (!at) {
        // No free range holds it: the storage grows (at least by the count), the new space joins the free list.
        if (!grow_segments(segment_capacity_ + std::size_t{count})) return false;
        segment_ranges_.grow(segment_capacity_);
        at = segment_ranges_.allocate(count);
        if (!at) return false;
    }
    first = static_cast<uint32_t>(*at);
    return true;
}
void NodePath::free_segments(uint32_t first, uint32_t count) {
    if (count != 0) segment_ranges_.free(first, count);
}

std::size_t NodePath::upload_bytes(const DrawList& list) {
    std::size_t headers = 0, nodes = 0, extras = 0;
    changed_item_.assign(list.items.size(), 0);
    item_slot_.assign(list.items.size(), nullptr);
    std::size_t visible = 0;
    for (std::size_t i = 0; i < list.items.size(); ++i) {
        const DrawItem& item = list.items[i];
        const bool has_curve = item.curve != nullptr && !item.curve->segments.empty();
        const bool packed = item.packed_nodes != nullptr && item.packed_nodes->nodes.size() >= 2;
        if (!has_curve && !packed && (item.nodes == nullptr || item.nodes->size() < 2)) continue;
        ++visible;
        const auto it = slots_.find(item.wire_id);
        if (it != slots_.end()) item_slot_[i] = &it->second;
        const bool changed = it == slots_.end() || !it->second.built || item.nodes_generation == 0 ||
                             item.nodes_generation != it->second.generation;
        if (!changed) continue;
        changed_item_[i] = 1;
        headers += sizeof(GpuCurveHeader);
        if (has_curve) {
            nodes += 64 * item.curve->segment_count();
            continue;
        }
        if (packed) {
            nodes += 16 * item.packed_nodes->nodes.size();
            extras += 16 * item.packed_nodes->extras.size();
            continue;
        }
        const std::size_t n = item.nodes->size();
        nodes += 16 * n;
        extras += 16 * n + 16 * ((n + 3) / 4);
    }
    // prepare()'s layout: each array at least one record (a buffer range of 0 bytes cannot be bound).
    visible += stream_ != nullptr ? stream_wires() : 0;  // the stream's unchanged wires are listed here too
    return align_up(std::max<std::size_t>(headers, 64)) + align_up(std::max<std::size_t>(nodes, 16)) +
           align_up(std::max<std::size_t>(extras, 16)) + align_up(std::max<std::size_t>(4 * visible, 4)) + kAlign;
}

bool NodePath::prepare(const DrawList& list, const LodView& view, uint32_t view_index, const gfx::StreamRegion& region,
                       const NodeDrawContext& ctx, DrawStats& stats) {
    ++frame_;
    // The ring buffer's size: the counts the GPU reported kReadbackSlots frames ago, read only once the fence
    // after their copy has signalled (else the capacity stays: a late GPU delays growth, never feeds it garbage),
    // and kept within what one shader storage block may hold.
    if (GLsync& fence = readback_fence_[frame_ % kReadbackSlots]; fence != nullptr) {
        const GLenum waited = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 0);
        if (waited == GL_ALREADY_SIGNALED || waited == GL_CONDITION_SATISFIED) {
            const auto* seen = static_cast<const uint32_t*>(readback_map_) + kCounterBytes / 4 * (frame_ % kReadbackSlots);
            const std::size_t most = max_block_bytes_ / sizeof(PackedRing) * 2 / 3;
            if (seen[0] > ring_capacity_ * 3 / 4) ring_capacity_ = std::min(std::size_t{seen[0]} * 3 / 2, most);
            stats.wires_coarse = seen[1];
            stats.triangles = seen[3];
            glDeleteSync(fence);
            fence = nullptr;
        }
    }
    thread_local WireUpload up;  // headers, and the nodes made here (not packed by the systems)
    up.clear();
    node_pieces_.clear(), extra_pieces_.clear();
    std::size_t node_total = 0, extra_total = 0;  // vec4s in the region's node and extra arrays
    visible_slots_.clear();
    dispatched_.clear(), listed_.clear(), changed_wires_.clear();
    material_used_.assign(ctx.materials.size(), 0);
    std::size_t segments_visible = 0;
    for (std::size_t i = 0; i < list.items.size(); ++i) {
        const DrawItem& item = list.items[i];
        const bool has_curve = item.curve != nullptr && !item.curve->segments.empty();
        const bool packed = item.packed_nodes != nullptr && item.packed_nodes->nodes.size() >= 2;
        if (!has_curve && !packed && (item.nodes == nullptr || item.nodes->size() < 2)) continue;
        if (item.material >= ctx.materials.size()) {
            // The other paths assert this; here the GPU would index past its buckets: skipped, said once.
            ++stats.wires_skipped;
            if (stats.status.ok()) stats.status = Status::error("wire " + std::to_string(item.wire_id) + ": material " +
                                         std::to_string(item.material) + " is out of range (" +
                                         std::to_string(ctx.materials.size()) + " materials): not drawn");
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
            // A second item with this wire_id: both would write one slot's curve and state. The first is drawn.
            ++stats.wires_skipped;
            if (stats.status.ok()) stats.status = Status::error("wire " + std::to_string(item.wire_id) +
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
            const std::size_t node_pieces_before = node_pieces_.size(), extra_pieces_before = extra_pieces_.size();
            const std::size_t node_total_before = node_total, extra_total_before = extra_total;
            if (packed) {
                // Packed by the systems: the header here, the nodes copied straight from them into the region.
                const PackedNodes& p = *item.packed_nodes;
                up.headers.push_back(packed_header(p, slot.segment_first, slot.index, item.material, item.caps,
                                                   {item.motion, item.fit_motion}, static_cast<uint32_t>(node_total),
                                                   static_cast<uint32_t>(extra_total)));
                node_pieces_.push_back({p.nodes.data(), 0, p.nodes.size(), node_total});
                node_total += p.nodes.size();
                if (!p.extras.empty()) {
                    extra_pieces_.push_back({p.extras.data(), 0, p.extras.size(), extra_total});
                    extra_total += p.extras.size();
                }
                segments = static_cast<uint32_t>(p.segment_count());
            } else {
                // Made here (a blended curve's segments; nodes not packed by the systems): into `up`, then copied.
                if (has_curve) {
                    append_segments(*item.curve, slot.segment_first, slot.index, item.material, item.caps,
                                    {item.motion, false}, up);
                    segments = static_cast<uint32_t>(item.curve->segment_count());
                } else if (!append_wire(*item.nodes, item.spline, slot.segment_first, slot.index, item.material,
                                        item.caps, {item.motion, item.fit_motion}, up, segments)) {
                    ++stats.wires_skipped;  // the systems validate; a kind the GPU does not build is skipped here
                    continue;
                }
                GpuCurveHeader& h = up.headers.back();
                h.node_first = static_cast<uint32_t>(node_total), h.extra_first = static_cast<uint32_t>(extra_total);
                node_pieces_.push_back({nullptr, nodes_before, up.nodes.size() - nodes_before, node_total});
                node_total += up.nodes.size() - nodes_before;
                extra_pieces_.push_back({nullptr, extras_before, up.extras.size() - extras_before, extra_total});
                extra_total += up.extras.size() - extras_before;
            }
            // The wire's most sides (the LOD's max_sides for it; its Style's): header bits 8-15.
            up.headers.back().flags |= std::min<uint32_t>(std::max<uint32_t>(item.sides, 3u), 255u) << 8;
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
    changed_ = up.headers.size();
    // The streamed wires (node_stream.cpp): their headers into the stream's region, the unchanged ones listed.
    stream_changed_ = 0;
    if (stream_ != nullptr) stream_changed_ = emit_stream(ctx.materials.size(), segments_visible, stats);
    unchanged_ = visible_slots_.size();
    visible_ = changed_ + stream_changed_ + unchanged_;
    stats.wires_uploaded = changed_ + stream_changed_;
    // The ring pass's order: the listed wires, then this frame's curve passes' (the list's, then the stream's).
    dispatched_ = listed_;
    dispatched_.insert(dispatched_.end(), changed_wires_.begin(), changed_wires_.end());
    dispatched_.insert(dispatched_.end(), stream_wires_.begin(), stream_wires_.end());
    if (visible_ == 0) return false;
    // A frame that cannot be computed draws nothing and says why; the wires it would have uploaded stay unbuilt
    // (their slots hold no curve), so the next frame sends them again.
    const auto fail = [&](const Status& why) {
        for (const Dispatched& d : changed_wires_) {
            if (auto it = slots_.find(d.wire_id); it != slots_.end()) it->second.built = false;
        }
        if (stream_ != nullptr) unbuild_stream();
        dispatched_.clear();
        stats.wires_skipped += visible_;
        stats.status = Status::error("wire nodes: " + why.message);
        return false;
    };

    // The region: headers | nodes | extras | visible slots of the unchanged wires.
    const std::size_t real_node_bytes = node_total * sizeof(glm::vec4);
    const std::size_t real_extra_bytes = extra_total * sizeof(glm::vec4);
    const std::size_t header_bytes = std::max<std::size_t>(up.headers.size() * sizeof(GpuCurveHeader), 64);
    const std::size_t node_bytes = std::max<std::size_t>(real_node_bytes, sizeof(glm::vec4));
    const std::size_t extra_bytes = std::max<std::size_t>(real_extra_bytes, sizeof(glm::vec4));
    const std::size_t visible_bytes = std::max<std::size_t>(visible_slots_.size() * 4, 4);
    const std::size_t list_bytes = std::max<std::size_t>(visible_ * 4, 4);  // unchanged, then the curve passes'
    const std::size_t node_at = align_up(header_bytes), extra_at = node_at + align_up(node_bytes);
    const std::size_t visible_at = extra_at + align_up(extra_bytes);
    if (visible_at + visible_bytes > region.size_bytes) {
        // Never (upload_bytes() sized the region for this layout); were it to, nothing is written past the region.
        return fail(Status::error("the stream region holds " + std::to_string(region.size_bytes) + " bytes, the frame needs " +
                                  std::to_string(visible_at + visible_bytes)));
    }
    std::byte* base = region.data;
    if (!up.headers.empty()) std::memcpy(base, up.headers.data(), up.headers.size() * sizeof(GpuCurveHeader));
    // The nodes, copied once from where they are (the systems' packed nodes) into the region: on worker threads
    // when there are many (the one per-byte cost of the frame on the render thread).
    const auto copy = [&](const std::vector<Piece>& pieces, const std::vector<glm::vec4>& own, std::byte* to,
                          std::size_t first, std::size_t last) {
        for (std::size_t k = first; k < last; ++k) {
            const Piece& piece = pieces[k];
            const glm::vec4* from = piece.src != nullptr ? piece.src : own.data() + piece.own;
            if (piece.count != 0) std::memcpy(to + piece.dst * sizeof(glm::vec4), from, piece.count * sizeof(glm::vec4));
        }
    };
    if (real_node_bytes >= (std::size_t{256} << 10) && node_pieces_.size() >= 64) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, node_pieces_.size(), 32), [&](const auto& r) {
            copy(node_pieces_, up.nodes, base + node_at, r.begin(), r.end());
        });
    } else {
        copy(node_pieces_, up.nodes, base + node_at, 0, node_pieces_.size());
    }
    copy(extra_pieces_, up.extras, base + extra_at, 0, extra_pieces_.size());
    // The list of unchanged visible wires stays on the GPU while it is the same (a still scene, or still wires
    // under a camera that keeps them in view): then nothing is sent for them.
    const bool same_list = visible_slots_ == last_visible_ && visible_kept_.id() != 0 && list_bytes <= visible_kept_bytes_;
    (void)visible_bytes;
    if (!same_list && !visible_slots_.empty()) {
        std::memcpy(base + visible_at, visible_slots_.data(), visible_slots_.size() * 4);
    }
    stats.bytes_uploaded = (changed_ ? up.headers.size() * sizeof(GpuCurveHeader) + real_node_bytes : 0) +
                           real_extra_bytes + (same_list ? 0 : visible_slots_.size() * 4) + stream_bytes_;
    const auto range = [&](GLuint binding, std::size_t offset, std::size_t bytes) {
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, binding, region.buffer,
                          static_cast<GLintptr>(region.offset_bytes + offset), static_cast<GLsizeiptr>(bytes));
    };

    // Per-frame GPU buffers.
    if (ring_capacity_ == 0) ring_capacity_ = std::max<std::size_t>(4096, 8 * segments_visible + visible_);
    side_slots_ = max_sides_ + 1;
    materials_ = ctx.materials.size();
    const std::size_t buckets = materials_ * side_slots_ * 6;
    // The reserve after the ring buffer's estimate: one ring a segment for every visible wire (what a wire that
    // does not fit is drawn with, until the buffer has grown from the count read back).
    const std::size_t reserve = segments_visible + visible_;
    const std::size_t chunk_capacity = (ring_capacity_ + reserve) / kChunkBands + 6 * visible_ + 1;
    // c2 scratch, 2 dvec4 a node: the list's wires', then the stream's (at an aligned offset).
    const std::size_t stream_scratch_at = changed_ ? align_up(node_total * 2 * 32) : 0;
    const std::size_t scratch_need = stream_scratch_at + (stream_changed_ ? stream_nodes() * 2 * 32 : 0);
    const auto need = [&](gfx::Buffer& b, std::size_t& capacity, std::size_t bytes, const char* label) {
        return ensure(b, capacity, bytes, label, false);
    };
    Status made = need(scratch_, scratch_bytes_, std::max<std::size_t>(scratch_need, 64), "wire nodes: c2 scratch");
    if (made) made = need(jobs_, job_bytes_, visible_ * kJobBytes, "wire nodes: jobs");
    if (made) made = need(draws_, draw_bytes_, visible_ * kDrawBytes, "wire nodes: draws");
    if (made) made = need(rings_, ring_bytes_, (ring_capacity_ + reserve) * sizeof(PackedRing), "wire nodes: rings");
    if (made) made = need(chunks_, chunk_bytes_, chunk_capacity * 8, "wire nodes: chunks");
    if (made) made = need(buckets_, bucket_bytes_, 2 * buckets * 4, "wire nodes: buckets");
    if (made) made = need(commands_, command_bytes_, buckets * 20, "wire nodes: commands");
    if (made) made = need(counter_, counter_bytes_, kCounterBytes, "wire nodes: ring counter");
    if (!made) return fail(made);
    if (template_sides_ != side_slots_ || template_patterns_ != ctx.pattern_first.size()) {
        // (index count, first index) of each (side count, chunk kind), as the gpu-rings path's commands.
        std::vector<uint32_t> t(2 * 6 * side_slots_, 0);
        for (uint32_t d = 1; d < side_slots_; ++d) {
            const uint32_t pattern = d < ctx.pattern_first.size() ? ctx.pattern_first[d] : 0;
            const uint32_t band_indices = d > 2 ? 6 * d : 6;
            for (uint32_t kind = 0; kind < kChunkKinds; ++kind) {
                const uint32_t count = kind == 0 ? (d > 2 ? 6 * d : 0) : chunk_kind_bands(kind) * band_indices;
                const uint32_t first = kind == 0 || d <= 2 ? pattern : pattern + 6 * d;
                t[2 * (6 * d + kind)] = count;
                t[2 * (6 * d + kind) + 1] = first;
            }
        }
        auto made = gfx::make_buffer(std::span<const uint32_t>(t), "wire nodes: command templates");
        if (!made) return fail(made.error());
        templates_ = std::move(*made);
        template_sides_ = side_slots_;
        template_patterns_ = ctx.pattern_first.size();
    }
    clear_range(counter_, 0, kCounterBytes);
    clear_range(buckets_, 0, buckets * 4);
    if (!same_list) {
        // The unchanged wires' slots, kept for the next frames: copied on the GPU out of the region (the curve
        // passes write the changed wires' after them).
        if (Status st = ensure(visible_kept_, visible_kept_bytes_, list_bytes, "wire nodes: visible slots", false); !st)
            return fail(st);
        if (!visible_slots_.empty()) {
            glCopyNamedBufferSubData(region.buffer, visible_kept_.id(), static_cast<GLintptr>(region.offset_bytes + visible_at),
                                     0, static_cast<GLsizeiptr>(visible_slots_.size() * 4));
        }
        last_visible_ = visible_slots_;
    }

    // (1) Curves of the wires whose nodes changed, into their slots' segments and headers: the list's (headers and
    // nodes in this frame's region), then the stream's (in the stream's region). Both write disjoint slots, list
    // entries and c2 scratch (the stream's after the list's), so they need no barrier between them.
    const auto curve_pass = [&](unsigned buffer, std::size_t header_at, std::size_t header_size, std::size_t nodes_at,
                                std::size_t nodes_size, std::size_t scratch_at, std::size_t wires, std::size_t list_first) {
        curve_program_.use();
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kCurveHeaders, buffer, static_cast<GLintptr>(header_at),
                          static_cast<GLsizeiptr>(header_size));
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kCurveNodes, buffer, static_cast<GLintptr>(nodes_at),
                          static_cast<GLsizeiptr>(nodes_size));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCurveSegments, segments_.id());
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kCurveScratch, scratch_.id(), static_cast<GLintptr>(scratch_at),
                          static_cast<GLsizeiptr>(scratch_bytes_ - scratch_at));
        range(kCurveExtras, extra_at, extra_bytes);  // the streamed wires carry none (the list's range, unread)
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCurveSlotHeaders, slot_headers_.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCurveMotionRefs, motion_refs_.id());
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCurveSlotList, visible_kept_.id());
        glUniform1ui(curve_program_.uniform_location("u_wires"), static_cast<GLuint>(wires));
        glUniform1i(curve_program_.uniform_location("u_persist"), 1);
        glUniform1i(curve_program_.uniform_location("u_motion"), 1);
        glUniform1i(curve_program_.uniform_location("u_list"), 1);
        glUniform1ui(curve_program_.uniform_location("u_list_first"), static_cast<GLuint>(list_first));
        glDispatchCompute(static_cast<GLuint>((wires + 63) / 64), 1, 1);
    };
    if (changed_ != 0) {
        curve_pass(region.buffer, region.offset_bytes, header_bytes, region.offset_bytes + node_at, node_bytes, 0, changed_,
                   unchanged_);
    }
    if (stream_changed_ != 0) {
        const StreamLayout layout = stream_layout();
        curve_pass(layout.buffer, layout.header_at, layout.header_bytes, layout.node_at, layout.node_bytes,
                   stream_scratch_at, stream_changed_, unchanged_ + changed_);
    }
    if (changed_ + stream_changed_ != 0) glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    // (2) LOD, (3) commands, (4) rings and records, over the visible wires. They overwrite the per-frame buffers the
    // last draw read (the previous view of this frame, or the last frame): the barrier orders those reads first.
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    ring_program_.use();
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingHeaders, slot_headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingSegments, segments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingJobs, jobs_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingCounts, counts_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingRings, rings_.id());
    const gfx::Buffer* state = view_state(view_index);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingSlots, state != nullptr ? state->id() : slot_state_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingCounter, counter_.id());
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kRingVisible, visible_kept_.id(), 0, static_cast<GLsizeiptr>(list_bytes));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingDraws, draws_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingChunks, chunks_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingBuckets, buckets_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingCommands, commands_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingTemplates, templates_.id());
    const auto at = [&](const char* name) { return ring_program_.uniform_location(name); };
    set_lod_uniforms(ring_program_, view, lod_);
    glUniform1i(at("u_lod"), 1);
    glUniform1i(at("u_draw"), 1);
    glUniform1ui(at("u_wires"), static_cast<GLuint>(visible_));
    glUniform1ui(at("u_unchanged"), static_cast<GLuint>(unchanged_));
    glUniform1ui(at("u_ring_capacity"), static_cast<GLuint>(std::min<std::size_t>(ring_capacity_, 0xffffffffu)));
    glUniform1ui(at("u_ring_reserve"), static_cast<GLuint>(std::min<std::size_t>(reserve, 0xffffffffu)));
    glUniform1ui(at("u_buckets"), static_cast<GLuint>(buckets));
    glUniform1ui(at("u_side_slots"), side_slots_);
    const auto groups = static_cast<GLuint>((visible_ + 63) / 64);
    glUniform1ui(at("u_stage"), 1u);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUniform1ui(at("u_stage"), 2u);
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    glUniform1ui(at("u_stage"), 3u);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    // The counter, read kReadbackSlots frames later (the ring buffer's size).
    glCopyNamedBufferSubData(counter_.id(), readback_.id(), 0,
                             static_cast<GLintptr>(kCounterBytes * (frame_ % kReadbackSlots)), kCounterBytes);
    GLsync& fence = readback_fence_[frame_ % kReadbackSlots];
    if (fence != nullptr) glDeleteSync(fence);  // an older copy into the slot, not read: this one supersedes it
    fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glUseProgram(0);
    buckets_used_ = buckets;
    stats.draw_items = visible_;
    stats.indirect_commands = buckets;
    return true;
}

void NodePath::submit(const NodeDrawContext& ctx, DrawStats& stats, Lines lines) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, draws_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, rings_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ctx.circle);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, chunks_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, rings_.id());
    ctx.vao.bind();
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, commands_.id());
    const std::size_t per_material = std::size_t{side_slots_} * 6;
    const auto draw = [&](std::size_t m, uint32_t first_slot, uint32_t slots) {
        const Material& material = ctx.materials[m];
        ctx.program.set("u_tint", material.tint);
        ctx.program.set("u_roughness", material.roughness);
        ctx.textures[material.texture].bind(0);
        const auto* indirect =
            reinterpret_cast<const void*>((m * per_material + std::size_t{first_slot} * 6) * 20);
        glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, indirect, static_cast<GLsizei>(slots * 6), 0);
        ++stats.multi_draw_calls;
    };
    // Opaque (tubes and strips: side slots 2 ..), then the blended phone-wire lines (slot 1).
    for (std::size_t m = 0; m < materials_; ++m) {
        if (m < material_used_.size() && material_used_[m]) draw(m, 2, side_slots_ - 2);
    }
    if (lines == Lines::blended) {
        glEnable(GL_BLEND);
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
        glDepthMask(GL_FALSE);
    }
    for (std::size_t m = 0; lines != Lines::skipped && m < materials_; ++m) {
        if (m < material_used_.size() && material_used_[m]) draw(m, 1, 1);
    }
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
}

Status NodePath::read_rings(std::vector<DrawnRings>& out) const {
    out.clear();
    if (dispatched_.empty()) return Status::success();
    // glGetNamedBufferSubData waits for the dispatches; the last stage's barrier has BUFFER_UPDATE.
    std::vector<Job> jobs(dispatched_.size());
    glGetNamedBufferSubData(jobs_.id(), 0, static_cast<GLsizeiptr>(jobs.size() * sizeof(Job)), jobs.data());
    std::vector<uint32_t> counts;
    std::vector<PackedRing> packed;
    for (std::size_t w = 0; w < dispatched_.size(); ++w) {
        const Dispatched& d = dispatched_[w];
        const Job& job = jobs[w];
        if (job.ring_count == 0) continue;  // culled on the GPU (or, past the reserve, not drawn)
        GpuCurveHeader header;
        glGetNamedBufferSubData(slot_headers_.id(), static_cast<GLintptr>(std::size_t{d.slot} * sizeof(header)),
                                sizeof(header), &header);
        const bool closed = (header.flags & kHeaderClosed) != 0;
        const bool coarse = (job.flags & kJobFromReserve) != 0;
        counts.assign(d.segments, 1u);  // the reserve's one ring a segment
        if (!coarse && d.segments != 0) {
            glGetNamedBufferSubData(counts_.id(), static_cast<GLintptr>(std::size_t{d.segment_first} * 4),
                                    static_cast<GLsizeiptr>(std::size_t{d.segments} * 4), counts.data());
        }
        DrawnRings& drawn = out.emplace_back();
        drawn.wire_id = d.wire_id;
        drawn.sides = job.sides;
        drawn.coarse = coarse;
        RingSet& r = drawn.rings;
        place_rings(counts, closed, r.params);
        if (r.params.size() != job.ring_count) {
            out.clear();
            return Status::error("wire " + std::to_string(d.wire_id) + ": the GPU drew " +
                                 std::to_string(job.ring_count) + " rings, its counts place " +
                                 std::to_string(r.params.size()));
        }
        packed.resize(job.ring_count);
        glGetNamedBufferSubData(rings_.id(), static_cast<GLintptr>(std::size_t{job.ring_first} * sizeof(PackedRing)),
                                static_cast<GLsizeiptr>(packed.size() * sizeof(PackedRing)), packed.data());
        r.closed = closed;
        r.origin_m = glm::dvec3(header.origin_m[0], header.origin_m[1], header.origin_m[2]);
        r.length_m = job.totals[1];
        const std::size_t n = packed.size();
        r.rings.resize(n), r.frames.resize(n), r.centre_m.resize(n), r.u.resize(n + (closed ? 1 : 0));
        r.arc_length_m.clear();
        for (std::size_t i = 0; i < n; ++i) {
            const PackedRing& p = packed[i];
            const DecodedFrame f = unpack_frame(p);
            const glm::vec3 centre(p.centre_m[0], p.centre_m[1], p.centre_m[2]);
            r.rings[i] = Ring{centre, p.radius_m, f.normal, p.u, f.binormal, r.params[i].segment};
            r.frames[i] = Frame{glm::dvec3(f.tangent), glm::dvec3(f.normal), glm::dvec3(f.binormal)};
            r.centre_m[i] = glm::dvec3(centre);
            r.u[i] = p.u;
        }
        if (closed) r.u[n] = job.totals[0];
    }
    return Status::success();
}

}  // namespace wire::render::detail
