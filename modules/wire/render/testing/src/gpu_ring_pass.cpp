// The ring pass's LOD and rings programs driven alone (see gpu_ring_pass.hpp).
#include "wire/render/testing/gpu_ring_pass.hpp"

#include "shaders.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <string>

namespace wire::render {
namespace {

using detail::GpuCurveHeader;
using detail::Job;
using detail::SlotState;

}  // namespace

engine::Expected<GpuRingPass> GpuRingPass::create() {
    engine::Expected<engine::gfx::Program> lod =
        engine::gfx::make_program({.label = "wire gpu ring LOD", .compute = detail::ring_lod_program_source()});
    if (!lod) return lod.error();
    engine::Expected<engine::gfx::Program> place =
        engine::gfx::make_program({.label = "wire gpu ring place", .compute = detail::ring_place_program_source()});
    if (!place) return place.error();
    engine::Expected<engine::gfx::Program> rings =
        engine::gfx::make_program({.label = "wire gpu rings", .compute = detail::ring_build_program_source()});
    if (!rings) return rings.error();
    GpuRingPass pass;
    pass.lod_program_ = std::move(*lod);
    pass.place_program_ = std::move(*place);
    pass.ring_program_ = std::move(*rings);
    return pass;
}

Status GpuRingPass::build(const GpuCurvePass& curves, std::span<const GpuRingJob> jobs,
                          const GpuLodFrame* lod) {
    const std::vector<GpuCurveHeader>& headers = curves.header_data_;
    if (jobs.size() != headers.size()) {
        return Status::error("the ring pass got " + std::to_string(jobs.size()) +
                             " jobs for the curve pass's " + std::to_string(headers.size()) + " wires");
    }
    const uint32_t max_rings = lod == nullptr || lod->settings.max_rings_per_segment == 0
                                   ? 256u
                                   : lod->settings.max_rings_per_segment;
    std::vector<Job> job_data(jobs.size());
    std::vector<uint32_t> counts, count_first(jobs.size()), segments(jobs.size()), visible(jobs.size());
    std::size_t rings = 0, count_total = 0;
    bool carry_last = false;
    for (std::size_t w = 0; w < jobs.size(); ++w) {
        const GpuCurveHeader& h = headers[w];
        const bool closed = (h.flags & detail::kHeaderClosed) != 0;
        const std::size_t segs = closed ? h.node_count : h.node_count - 1;
        Job& j = job_data[w];
        count_first[w] = h.segment_first;
        segments[w] = static_cast<uint32_t>(segs);
        visible[w] = h.slot;
        count_total += segs;
        if (!jobs[w].carry_last)
            j.flags = detail::kJobGivesPrevious | (jobs[w].has_previous_normal ? detail::kJobHasPrevious : 0u);
        carry_last = carry_last || jobs[w].carry_last;
        j.previous_normal = {jobs[w].previous_normal.x, jobs[w].previous_normal.y, jobs[w].previous_normal.z, 0.0f};
        if (lod != nullptr) {
            rings += (closed ? 0 : 1) + segs * max_rings;
            continue;
        }
        if (jobs[w].counts.size() != segs) {
            return Status::error("wire " + std::to_string(w) + ": " + std::to_string(jobs[w].counts.size()) +
                                 " ring counts for its " + std::to_string(segs) + " segments");
        }
        // place_rings: counts[k] rings on segment k (segment 0 at least one), an open wire one more at the
        // end.
        rings += closed ? 0 : 1;
        for (std::size_t k = 0; k < segs; ++k)
            rings += k == 0 ? std::max<uint32_t>(jobs[w].counts[k], 1) : jobs[w].counts[k];
        counts.insert(counts.end(), jobs[w].counts.begin(), jobs[w].counts.end());
    }
    if (lod != nullptr && lod->ring_capacity != 0) rings = lod->ring_capacity;
    if (jobs.empty()) {
        count_first_.clear(), segments_.clear();
        return Status::success();
    }
    // The counts and the LOD's per-wire state stay on the GPU while the wires' layout does (the hysteresis).
    const bool keep = lod != nullptr && lod_ && count_first == count_first_ && segments == segments_;
    if (!keep) {
        if (counts.empty()) counts.assign(count_total, 0);
        auto count_buffer =
            engine::gfx::make_buffer(std::span<const uint32_t>(counts), "wire gpu ring counts");
        std::vector<SlotState> state(jobs.size());
        if (carry_last && state_wires_ == jobs.size()) {
            // The first normals carry over to the same wires (the LOD's state restarts with the new layout).
            glGetNamedBufferSubData(state_.id(), 0, static_cast<GLsizeiptr>(state.size() * sizeof(SlotState)),
                                    state.data());
            for (SlotState& st : state) st.lod = {};
        }
        auto state_buffer =
            engine::gfx::make_buffer(std::span<const SlotState>(state), "wire gpu slot state");
        if (!count_buffer) return Status::error(count_buffer.error().message);
        if (!state_buffer) return Status::error(state_buffer.error().message);
        counts_ = std::move(*count_buffer), state_ = std::move(*state_buffer);
    } else {
        for (std::size_t w = 0; w < jobs.size(); ++w) {
            if (!jobs[w].restart_lod) continue;
            glClearNamedBufferSubData(state_.id(), GL_RGBA32UI,
                                      static_cast<GLintptr>(visible[w] * sizeof(SlotState)),
                                      sizeof(SlotState::lod), GL_RGBA_INTEGER, GL_UNSIGNED_INT, nullptr);
        }
    }
    auto job_buffer = engine::gfx::make_buffer(std::span<const Job>(job_data), "wire gpu ring jobs");
    const uint32_t zero_counter[4] = {0, 0, 0, 0};
    auto counter = engine::gfx::make_buffer(std::span<const uint32_t>(zero_counter), "wire gpu ring counter");
    auto visible_buffer =
        engine::gfx::make_buffer(std::span<const uint32_t>(visible), "wire gpu visible slots");
    if (!job_buffer) return Status::error(job_buffer.error().message);
    if (!counter) return Status::error(counter.error().message);
    if (!visible_buffer) return Status::error(visible_buffer.error().message);
    jobs_ = std::move(*job_buffer), counter_ = std::move(*counter), visible_ = std::move(*visible_buffer);
    if (rings > ring_capacity_ || !rings_) {
        auto ring_buffer = engine::gfx::make_buffer(
            {.size_bytes = std::max<std::size_t>(rings, 1) * sizeof(PackedRing), .label = "wire gpu rings"});
        if (!ring_buffer) return Status::error(ring_buffer.error().message);
        rings_ = std::move(*ring_buffer);
        ring_capacity_ = std::max<std::size_t>(rings, 1);
    }
    count_first_ = std::move(count_first), segments_ = std::move(segments);
    state_wires_ = jobs.size();
    count_total_ = count_total;
    lod_ = lod != nullptr;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingHeaders, curves.headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingSegments, curves.segments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingJobs, jobs_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingCounts, counts_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingRings, rings_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingSlots, state_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingCounter, counter_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingVisible, visible_.id());
    const auto groups = static_cast<GLuint>((jobs.size() + 63) / 64);
    // The LOD program: the counts (the LOD's or the caller's) and ring ranges, the caller's job flags kept.
    lod_program_.use();
    const auto at = [&](const char* name) { return lod_program_.uniform_location(name); };
    glUniform1ui(at("u_wires"), static_cast<GLuint>(jobs.size()));
    glUniform1i(at("u_keep_job_flags"), 1);
    // Every wire is "changed" (its header's motion turns its kept first normal) when a job carries the last
    // one.
    glUniform1ui(at("u_unchanged"), carry_last ? 0u : static_cast<GLuint>(jobs.size()));
    glUniform1i(at("u_draw"), 0);
    glUniform1i(at("u_lod"), lod != nullptr ? 1 : 0);
    if (lod != nullptr) detail::set_lod_uniforms(lod_program_, lod->view, lod->settings);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    // The place program's ring ranges, in wire order.
    place_program_.use();
    const auto place_at = [&](const char* name) { return place_program_.uniform_location(name); };
    glUniform1ui(place_at("u_stage"), 0u);
    glUniform1i(place_at("u_draw"), 0);
    glUniform1ui(place_at("u_wires"), static_cast<GLuint>(jobs.size()));
    glUniform1ui(place_at("u_ring_capacity"),
                 static_cast<GLuint>(std::min<std::size_t>(ring_capacity_, detail::kMaxRingRecords)));
    glUniform1ui(place_at("u_ring_reserve"), 0u);  // a wire that does not fit is reported (GpuRingResult::overflow)
    glUniform1ui(place_at("u_max_wire_rings"), 0xffffffffu);  // the caller's counts, whatever they total
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    // The rings program: the rings in the ranges the jobs hold.
    ring_program_.use();
    glUniform1ui(ring_program_.uniform_location("u_wires"), static_cast<GLuint>(jobs.size()));
    glUniform1i(ring_program_.uniform_location("u_draw"), 0);
    glDispatchCompute(groups, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glUseProgram(0);
    return Status::success();
}

void GpuRingPass::read(std::vector<GpuRingResult>& out) const {
    out.clear();
    if (count_first_.empty()) return;
    uint32_t counter[2] = {0, 0};
    glGetNamedBufferSubData(counter_.id(), 0, sizeof(counter), counter);
    const std::size_t used = std::min<std::size_t>(counter[0], ring_capacity_);
    std::vector<PackedRing> rings(used);
    if (used != 0) {
        glGetNamedBufferSubData(rings_.id(), 0, static_cast<GLsizeiptr>(used * sizeof(PackedRing)),
                                rings.data());
    }
    std::vector<Job> jobs(count_first_.size());
    glGetNamedBufferSubData(jobs_.id(), 0, static_cast<GLsizeiptr>(jobs.size() * sizeof(Job)), jobs.data());
    std::vector<uint32_t> counts(count_total_);
    glGetNamedBufferSubData(counts_.id(), 0, static_cast<GLsizeiptr>(counts.size() * sizeof(uint32_t)),
                            counts.data());
    std::vector<SlotState> state(jobs.size());
    if (lod_)
        glGetNamedBufferSubData(state_.id(), 0, static_cast<GLsizeiptr>(state.size() * sizeof(SlotState)),
                                state.data());
    out.resize(jobs.size());
    for (std::size_t w = 0; w < out.size(); ++w) {
        GpuRingResult& r = out[w];
        const Job& j = jobs[w];
        const bool fits = j.ring_count != 0 && std::size_t{j.ring_first} + j.ring_count <= used;
        if (fits) r.rings.assign(rings.begin() + j.ring_first, rings.begin() + j.ring_first + j.ring_count);
        r.counts.assign(counts.begin() + count_first_[w], counts.begin() + count_first_[w] + segments_[w]);
        r.first_normal = glm::vec3(j.first_normal.x, j.first_normal.y, j.first_normal.z);
        r.sides = j.sides;
        r.u_close = j.totals.x;
        r.length_m = j.totals.y;
        r.holonomy_rad = j.totals.z;
        r.radius_px = j.totals.w;
        if (lod_) {
            r.sides = state[w].lod.x;
            r.drawn_sides = state[w].lod.y;
            r.visible = state[w].lod.w != 0;
            r.overflow = r.visible && !fits;
        } else {
            r.overflow = !fits;
        }
    }
}

}  // namespace wire::render
