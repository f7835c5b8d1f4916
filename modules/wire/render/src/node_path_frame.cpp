// The nodes path's frame on the GPU (node_path.hpp): the region (headers, nodes, the listed slots), the
// per-frame buffers, the curve passes of the changed wires (the list's, then the stream's) and the ring pass's
// four programs (LOD, place: ring ranges, commands, place: chunk records, rings with their draw records).
#include "node_path.hpp"

#include "gpu_wire_data.hpp"
#include "shaders.hpp"

#include "wire/render/upload_plan.hpp"

#include <epoxy/gl.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <string>

namespace wire::render::detail {

namespace gfx = engine::gfx;

bool NodePath::prepare(const DrawList& list, const LodView& view, uint32_t view_index,
                       const gfx::StreamRegion& region, const NodeDrawContext& ctx, DrawStats& stats) {
    ++frame_;
    read_counts(stats);
    thread_local WireUpload up;  // headers, and the nodes made here (not packed by the systems)
    // The materials the nodes path draws: the renderer's, up to what the header's material field holds; an item or
    // streamed wire with another is out of range.
    materials_ = std::min<std::size_t>(ctx.materials.size(), kMaxMaterials);
    const Gathered gathered = gather(list, materials_, up, stats);
    const std::size_t node_total = gathered.node_total, extra_total = gathered.extra_total;
    std::size_t segments_visible = gathered.segments_visible;  // the stream's wires add theirs
    changed_ = up.headers.size();
    // The streamed wires (node_stream.cpp): their headers into the stream's region, the unchanged ones
    // listed.
    stream_changed_ = 0;
    if (stream_ != nullptr) stream_changed_ = emit_stream(materials_, segments_visible, stats);
    unchanged_ = visible_slots_.size();
    visible_ = changed_ + stream_changed_ + unchanged_;
    stats.wires_uploaded = changed_ + stream_changed_;
    // The ring pass's order: the listed wires, then this frame's curve passes' (the list's, then the
    // stream's).
    dispatched_ = listed_;
    dispatched_.insert(dispatched_.end(), changed_wires_.begin(), changed_wires_.end());
    dispatched_.insert(dispatched_.end(), stream_wires_.begin(), stream_wires_.end());
    if (visible_ == 0) return false;
    // A frame that cannot be computed draws nothing and says why; the wires it would have uploaded stay
    // unbuilt (their slots hold no curve), so the next frame sends them again.
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
    const std::size_t real_node_bytes = node_total * sizeof(glm::uvec2);
    const std::size_t real_extra_bytes = extra_total * sizeof(glm::vec4);
    const std::size_t header_bytes = std::max<std::size_t>(up.headers.size() * sizeof(GpuCurveHeader), 64);
    const std::size_t node_bytes = std::max<std::size_t>(real_node_bytes, sizeof(glm::vec4));
    const std::size_t extra_bytes = std::max<std::size_t>(real_extra_bytes, sizeof(glm::vec4));
    const std::size_t visible_bytes = std::max<std::size_t>(visible_slots_.size() * 4, 4);
    const std::size_t list_bytes =
        std::max<std::size_t>(visible_ * 4, 4);  // unchanged, then the curve passes'
    const std::size_t node_at = align_up(header_bytes), extra_at = node_at + align_up(node_bytes);
    const std::size_t visible_at = extra_at + align_up(extra_bytes);
    if (visible_at + visible_bytes > region.size_bytes) {
        // Never (upload_bytes() sized the region for this layout); were it to, nothing is written past the
        // region.
        return fail(Status::error("the stream region holds " + std::to_string(region.size_bytes) +
                                  " bytes, the frame needs " + std::to_string(visible_at + visible_bytes)));
    }
    std::byte* base = region.data;
    if (!up.headers.empty()) std::memcpy(base, up.headers.data(), up.headers.size() * sizeof(GpuCurveHeader));
    // The nodes, copied once from where they are (the systems' packed nodes) into the region: on worker
    // threads when there are many (the one per-byte cost of the frame on the render thread).
    const auto copy = [&](const std::vector<Piece>& pieces, const auto& own, std::byte* to, std::size_t first,
                          std::size_t last) {
        constexpr std::size_t unit = sizeof(own[0]);
        for (std::size_t k = first; k < last; ++k) {
            const Piece& piece = pieces[k];
            const void* from = piece.src != nullptr ? piece.src : own.data() + piece.own;
            if (piece.count != 0) std::memcpy(to + piece.dst * unit, from, piece.count * unit);
        }
    };
    if (real_node_bytes >= (std::size_t{256} << 10) && node_pieces_.size() >= 64) {
        // `up` is thread_local: named inside the worker threads' lambda it would be each worker's own (empty)
        // one, so the lambda reads this thread's through a reference.
        const std::vector<glm::uvec2>& own_nodes = up.nodes;
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, node_pieces_.size(), 32), [&](const auto& r) {
            copy(node_pieces_, own_nodes, base + node_at, r.begin(), r.end());
        });
    } else {
        copy(node_pieces_, up.nodes, base + node_at, 0, node_pieces_.size());
    }
    copy(extra_pieces_, up.extras, base + extra_at, 0, extra_pieces_.size());
    // The list of unchanged visible wires stays on the GPU while it is the same (a still scene, or still
    // wires under a camera that keeps them in view): then nothing is sent for them.
    const bool same_list =
        visible_slots_ == last_visible_ && visible_kept_.id() != 0 && list_bytes <= visible_kept_bytes_;
    (void)visible_bytes;
    if (!same_list && !visible_slots_.empty()) {
        std::memcpy(base + visible_at, visible_slots_.data(), visible_slots_.size() * 4);
    }
    stats.bytes_uploaded = (changed_ ? up.headers.size() * sizeof(GpuCurveHeader) + real_node_bytes : 0) +
                           real_extra_bytes + (same_list ? 0 : visible_slots_.size() * 4) + stream_bytes_;
    const auto range = [&](GLuint binding, std::size_t offset, std::size_t bytes) {
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, binding, region.buffer,
                          static_cast<GLintptr>(region.offset_bytes + offset),
                          static_cast<GLsizeiptr>(bytes));
    };

    // Per-frame GPU buffers.
    if (ring_capacity_ == 0) ring_capacity_ = std::max<std::size_t>(4096, 8 * segments_visible + visible_);
    side_slots_ = max_sides_ + 1;
    const std::size_t buckets = materials_ * side_slots_ * 6;
    // The reserve after the ring buffer's estimate: one ring a segment for every visible wire (what a wire
    // that does not fit is drawn with, until the buffer has grown from the count read back).
    const std::size_t reserve = segments_visible + visible_;
    const std::size_t chunk_capacity = (ring_capacity_ + reserve) / kChunkBands + 6 * visible_ + 1;
    // c2 scratch, 2 dvec4 an 8-byte node unit (the curve program indexes it by node_first): the list's wires',
    // then the stream's (at an aligned offset; 2 units a node).
    const std::size_t stream_scratch_at = changed_ ? align_up(node_total * 2 * 32) : 0;
    const std::size_t scratch_need = stream_scratch_at + (stream_changed_ ? stream_nodes() * 2 * 2 * 32 : 0);
    const auto need = [&](gfx::Buffer& b, std::size_t& capacity, std::size_t bytes, const char* label) {
        return ensure(b, capacity, bytes, label, false);
    };
    Status made =
        need(scratch_, scratch_bytes_, std::max<std::size_t>(scratch_need, 64), "wire nodes: c2 scratch");
    if (made) made = need(jobs_, job_bytes_, visible_ * kJobBytes, "wire nodes: jobs");
    if (made) made = need(draws_, draw_bytes_, visible_ * kDrawBytes, "wire nodes: draws");
    if (made)
        made =
            need(rings_, ring_bytes_, (ring_capacity_ + reserve) * sizeof(PackedRing), "wire nodes: rings");
    if (made) made = need(chunks_, chunk_bytes_, chunk_capacity * 8, "wire nodes: chunks");
    if (made) made = need(buckets_, bucket_bytes_, 2 * buckets * 4, "wire nodes: buckets");
    if (made) made = need(commands_, command_bytes_, buckets * 20, "wire nodes: commands");
    if (made) made = need(counter_, counter_bytes_, kCounterBytes, "wire nodes: ring counter");
    if (!made) return fail(made);
    if (template_sides_ != side_slots_ || template_patterns_ != ctx.pattern_first.size()) {
        // (index count, first index) of each (side count, chunk kind), as the ring patterns lay them out.
        std::vector<uint32_t> t(2 * 6 * side_slots_, 0);
        for (uint32_t d = 1; d < side_slots_; ++d) {
            const uint32_t pattern = d < ctx.pattern_first.size() ? ctx.pattern_first[d] : 0;
            const uint32_t band_indices = d > 2 ? 6 * d : 6;
            for (uint32_t kind = 0; kind < kChunkKinds; ++kind) {
                const uint32_t count =
                    kind == 0 ? (d > 2 ? 6 * d : 0) : chunk_kind_bands(kind) * band_indices;
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
        // The unchanged wires' slots, kept for the next frames: copied on the GPU out of the region (the
        // curve passes write the changed wires' after them).
        if (Status st =
                ensure(visible_kept_, visible_kept_bytes_, list_bytes, "wire nodes: visible slots", false);
            !st)
            return fail(st);
        if (!visible_slots_.empty()) {
            glCopyNamedBufferSubData(region.buffer, visible_kept_.id(),
                                     static_cast<GLintptr>(region.offset_bytes + visible_at), 0,
                                     static_cast<GLsizeiptr>(visible_slots_.size() * 4));
        }
        last_visible_ = visible_slots_;
    }

    // (1) Curves of the wires whose nodes changed, into their slots' segments and headers: the list's
    // (headers and nodes in this frame's region), then the stream's (in the stream's region). Both write
    // disjoint slots, list entries and c2 scratch (the stream's after the list's), so they need no barrier
    // between them.
    const auto curve_pass = [&](unsigned buffer, std::size_t header_at, std::size_t header_size,
                                std::size_t nodes_at, std::size_t nodes_size, std::size_t scratch_at,
                                std::size_t wires, std::size_t list_first) {
        curve_program_.use();
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kCurveHeaders, buffer, static_cast<GLintptr>(header_at),
                          static_cast<GLsizeiptr>(header_size));
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kCurveNodes, buffer, static_cast<GLintptr>(nodes_at),
                          static_cast<GLsizeiptr>(nodes_size));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kCurveSegments, segments_.id());
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kCurveScratch, scratch_.id(),
                          static_cast<GLintptr>(scratch_at),
                          static_cast<GLsizeiptr>(scratch_bytes_ - scratch_at));
        range(kCurveExtras, extra_at,
              extra_bytes);  // the streamed wires carry none (the list's range, unread)
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
        curve_pass(region.buffer, region.offset_bytes, header_bytes, region.offset_bytes + node_at,
                   node_bytes, 0, changed_, unchanged_);
    }
    if (stream_changed_ != 0) {
        const StreamLayout layout = stream_layout();
        curve_pass(layout.buffer, layout.header_at, layout.header_bytes, layout.node_at, layout.node_bytes,
                   stream_scratch_at, stream_changed_, unchanged_ + changed_);
    }
    if (changed_ + stream_changed_ != 0) glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    // (2) LOD, (3) commands, (4) rings and records, over the visible wires. They overwrite the per-frame
    // buffers the last draw read (the previous view of this frame, or the last frame): the barrier orders
    // those reads first.
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT);
    // One binding point per buffer (RingBinding), shared by the four programs: each reads the ones it declares.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingHeaders, slot_headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingSegments, segments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingJobs, jobs_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingCounts, counts_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingRings, rings_.id());
    const gfx::Buffer* state = view_state(view_index);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingSlots, state != nullptr ? state->id() : slot_state_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingCounter, counter_.id());
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, kRingVisible, visible_kept_.id(), 0,
                      static_cast<GLsizeiptr>(list_bytes));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingDraws, draws_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingChunks, chunks_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingBuckets, buckets_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingCommands, commands_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kRingTemplates, templates_.id());
    const auto groups = static_cast<GLuint>((visible_ + 63) / 64);
    // (2) The LOD: counts, sides, the rings each wire wants.
    {
        ring_lod_program_.use();
        const auto at = [&](const char* name) { return ring_lod_program_.uniform_location(name); };
        set_lod_uniforms(ring_lod_program_, view, lod_);
        glUniform1i(at("u_lod"), 1);
        glUniform1i(at("u_keep_job_flags"), 0);
        glUniform1i(at("u_draw"), 1);
        glUniform1ui(at("u_wires"), static_cast<GLuint>(visible_));
        glUniform1ui(at("u_unchanged"), static_cast<GLuint>(unchanged_));
        glUniform1ui(at("u_side_slots"), side_slots_);
        glDispatchCompute(groups, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    // (3) Placed in wire order (one workgroup): stage 0 the ring ranges and chunk counts per bucket, then the
    // indirect commands and each bucket's first chunk, then stage 1 the chunk records.
    const auto place = [&](uint32_t stage) {
        ring_place_program_.use();
        const auto at = [&](const char* name) { return ring_place_program_.uniform_location(name); };
        glUniform1ui(at("u_stage"), stage);
        glUniform1i(at("u_draw"), 1);
        glUniform1ui(at("u_wires"), static_cast<GLuint>(visible_));
        glUniform1ui(at("u_ring_capacity"),
                     static_cast<GLuint>(std::min<std::size_t>(ring_capacity_, kMaxRingRecords)));
        glUniform1ui(at("u_ring_reserve"), static_cast<GLuint>(std::min<std::size_t>(reserve, kMaxRingRecords)));
        glUniform1ui(at("u_max_wire_rings"), static_cast<GLuint>(kNodesPathMaxRings));
        glUniform1ui(at("u_buckets"), static_cast<GLuint>(buckets));
        glUniform1ui(at("u_side_slots"), side_slots_);
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    };
    place(0);
    {
        ring_commands_program_.use();
        const auto at = [&](const char* name) { return ring_commands_program_.uniform_location(name); };
        glUniform1ui(at("u_buckets"), static_cast<GLuint>(buckets));
        glUniform1ui(at("u_side_slots"), side_slots_);
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    place(1);
    // (4) The rings and the draw records.
    {
        ring_build_program_.use();
        const auto at = [&](const char* name) { return ring_build_program_.uniform_location(name); };
        glUniform3d(at("u_eye"), view.eye_m.x, view.eye_m.y, view.eye_m.z);
        glUniform1i(at("u_draw"), 1);
        glUniform1ui(at("u_wires"), static_cast<GLuint>(visible_));
        glUniform1ui(at("u_buckets"), static_cast<GLuint>(buckets));
        glUniform1ui(at("u_side_slots"), side_slots_);
        glDispatchCompute(groups, 1, 1);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_COMMAND_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    // The counter, read kReadbackSlots frames later (the ring buffer's size).
    glCopyNamedBufferSubData(counter_.id(), readback_.id(), 0,
                             static_cast<GLintptr>(kCounterBytes * (frame_ % kReadbackSlots)), kCounterBytes);
    GLsync& fence = readback_fence_[frame_ % kReadbackSlots];
    if (fence != nullptr)
        glDeleteSync(fence);  // an older copy into the slot, not read: this one supersedes it
    fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glUseProgram(0);
    buckets_used_ = buckets;
    stats.draw_items = visible_;
    stats.indirect_commands = buckets;
    return true;
}

}  // namespace wire::render::detail
