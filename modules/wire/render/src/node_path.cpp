// The nodes path's resources (node_path.hpp): its programs, persistent and per-view buffers, slots and segment
// ranges, the region size a frame needs, the draws (submit) and the read-back of what was drawn. A frame's CPU side
// is in node_path_gather.cpp, its GPU side in node_path_frame.cpp.
#include "node_path.hpp"

#include "gpu_wire_data.hpp"
#include "shaders.hpp"

#include "wire/render/upload_plan.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <optional>
#include <string>

namespace wire::render::detail {
namespace {

namespace gfx = engine::gfx;

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

void clear_range(const gfx::Buffer& buffer, std::size_t offset, std::size_t bytes) {
    glClearNamedBufferSubData(buffer.id(), GL_R32UI, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes),
                              GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
}

void NodePath::set_lod(const LodSettings& lod) {
    lod_ = lod;
    max_sides_ = std::min(lod.resolved().max_sides, kMaxSides);
}

Expected<std::unique_ptr<NodePath>> NodePath::create(uint32_t retain_frames) {
    auto path = std::make_unique<NodePath>();
    auto curve = gfx::make_program({.label = "wire nodes: curves", .compute = curve_program_source()});
    if (!curve) return curve.error();
    path->curve_program_ = std::move(*curve);
    if (Status st = check_storage_limits(path->curve_program_, "wire nodes: curves", kCurveBindings); !st) return st;
    // The ring pass: one program per stage, each checked as it is made (the first that fails is the one named).
    const struct {
        const char* label;
        std::string source;
        gfx::Program& program;
    } ring_programs[] = {
        {"wire nodes: ring LOD", ring_lod_program_source(), path->ring_lod_program_},
        {"wire nodes: ring place", ring_place_program_source(), path->ring_place_program_},
        {"wire nodes: ring commands", ring_commands_program_source(), path->ring_commands_program_},
        {"wire nodes: rings", ring_build_program_source(), path->ring_build_program_},
    };
    for (const auto& [label, source, program] : ring_programs) {
        auto made = gfx::make_program({.label = label, .compute = source});
        if (!made) return made.error();
        program = std::move(*made);
        if (Status st = check_storage_limits(program, label, kRingBindings); !st) return st;
    }
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

std::size_t NodePath::gl_programs() const {
    std::size_t n = 0;
    for (const gfx::Program* p :
         {&curve_program_, &ring_lod_program_, &ring_place_program_, &ring_commands_program_, &ring_build_program_})
        n += p->id() != 0 ? 1 : 0;
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
    if (Status st = ensure(motion_refs_, motion_ref_bytes_, want * sizeof(MotionRef), "wire nodes: motion references", true);
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
    clear_range(motion_refs_, index * sizeof(MotionRef), 32);  // no reference: nothing to fit against
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
        const bool packed = item.packed_nodes != nullptr && item.packed_nodes->node_count >= 2;
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
            nodes += 8 * item.packed_nodes->records.size();
            extras += 16 * item.packed_nodes->extras.size();
            continue;
        }
        const std::size_t n = item.nodes->size();
        nodes += 16 * n;  // the float format's, at most (packed here by pack_nodes)
        extras += 16 * n + 16 * ((n + 3) / 4);
    }
    // prepare()'s layout: each array at least one record (a buffer range of 0 bytes cannot be bound).
    visible += stream_ != nullptr ? stream_wires() : 0;  // the stream's unchanged wires are listed here too
    return align_up(std::max<std::size_t>(headers, 64)) + align_up(std::max<std::size_t>(nodes, 16)) +
           align_up(std::max<std::size_t>(extras, 16)) + align_up(std::max<std::size_t>(4 * visible, 4)) + kSectionAlign;
}

void NodePath::submit(const NodeDrawContext& ctx, DrawStats& stats, Lines lines) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, draws_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, rings_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ctx.circle);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, chunks_.id());
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

Status NodePath::read_draw_order(std::vector<DrawnChunk>& out) const {
    out.clear();
    if (dispatched_.empty() || buckets_used_ == 0) return Status::success();
    // glGetNamedBufferSubData waits for the dispatches; the last stage's barrier has BUFFER_UPDATE.
    std::vector<uint32_t> commands(buckets_used_ * 5);
    glGetNamedBufferSubData(commands_.id(), 0, static_cast<GLsizeiptr>(commands.size() * 4), commands.data());
    std::size_t chunk_total = 0;
    for (std::size_t b = 0; b < buckets_used_; ++b) chunk_total += commands[5 * b + 1];
    if (chunk_total > chunk_capacity()) {
        return Status::error("read_draw_order: the commands count " + std::to_string(chunk_total) +
                             " chunks, the chunk buffer holds " + std::to_string(chunk_capacity()));
    }
    std::vector<uint32_t> chunks(2 * chunk_total);
    if (chunk_total != 0)
        glGetNamedBufferSubData(chunks_.id(), 0, static_cast<GLsizeiptr>(chunks.size() * 4), chunks.data());
    const std::size_t per_material = std::size_t{side_slots_} * kChunkKinds;
    // submit()'s order: per material its tubes' and strips' commands (side slots 2 ..), then per material its lines'.
    const auto emit = [&](std::size_t m, uint32_t first_slot, uint32_t slots) -> Status {
        for (std::size_t b = m * per_material + std::size_t{first_slot} * kChunkKinds;
             b < m * per_material + std::size_t{first_slot + slots} * kChunkKinds; ++b) {
            const uint32_t count = commands[5 * b + 1], first = commands[5 * b + 4];
            for (uint32_t i = first; i < first + count; ++i) {
                if (std::size_t{i} >= chunk_total || chunks[2 * i] >= dispatched_.size())
                    return Status::error("read_draw_order: chunk " + std::to_string(i) + " is out of range");
                out.push_back({.wire_id = dispatched_[chunks[2 * i]].wire_id,
                               .material = static_cast<uint32_t>(m),
                               .sides = static_cast<uint32_t>(b % per_material / kChunkKinds),
                               .kind = static_cast<uint32_t>(b % kChunkKinds),
                               .first_band = chunks[2 * i + 1]});
            }
        }
        return Status::success();
    };
    for (uint32_t pass = 0; pass < 2; ++pass) {
        for (std::size_t m = 0; m < materials_; ++m) {
            if (m >= material_used_.size() || !material_used_[m]) continue;
            Status st = pass == 0 ? emit(m, 2, side_slots_ - 2) : emit(m, 1, 1);
            if (!st) {
                out.clear();
                return st;
            }
        }
    }
    return Status::success();
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
        r.length_m = job.totals.y;
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
        if (closed) r.u[n] = job.totals.x;
    }
    return Status::success();
}

}  // namespace wire::render::detail
