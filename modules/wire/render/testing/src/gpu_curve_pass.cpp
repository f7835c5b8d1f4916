// The curve program driven alone (see gpu_curve_pass.hpp).
#include "wire/render/testing/gpu_curve_pass.hpp"

#include "shaders.hpp"

#include "wire/spline.hpp"

#include <epoxy/gl.h>

#include <string>

namespace wire::render {

using detail::GpuCurveHeader;

engine::Expected<GpuCurvePass> GpuCurvePass::create() {
    engine::Expected<engine::gfx::Program> program =
        engine::gfx::make_program({.label = "wire gpu curves", .compute = detail::curve_program_source()});
    if (!program) return program.error();
    GpuCurvePass pass;
    pass.program_ = std::move(*program);
    return pass;
}

bool GpuCurvePass::supported(const SplineSettings& spline, const WireNodes& nodes) {
    (void)nodes;
    return gpu_builds(spline.kind);
}

Status GpuCurvePass::build(std::span<const GpuCurveWire> wires) {
    thread_local detail::WireUpload up;
    up.clear();
    origins_.clear();
    uint32_t segment_first = 0;
    for (std::size_t w = 0; w < wires.size(); ++w) {
        const GpuCurveWire& wire = wires[w];
        const std::string name = "wire " + std::to_string(w) + ": ";
        if (wire.nodes == nullptr) return Status::error(name + "no nodes");
        uint32_t segs = 0;
        if (Status st = detail::append_wire(*wire.nodes, wire.spline, segment_first, static_cast<uint32_t>(w),
                                            0, true, {wire.motion, wire.fit_motion}, up, segs);
            !st) {
            return Status::error(name + st.message);
        }
        const GpuCurveHeader& h = up.headers.back();
        origins_.emplace_back(h.origin_m[0], h.origin_m[1], h.origin_m[2]);
        segment_first += segs;
    }
    header_data_ = up.headers;
    std::vector<glm::uvec2>& node_data = up.nodes;
    std::vector<glm::vec4>& extras = up.extras;
    segment_total_ = segment_first;
    node_bytes_ = node_data.size() * sizeof(glm::uvec2);
    header_bytes_ = header_data_.size() * sizeof(GpuCurveHeader);
    extra_bytes_ = extras.size() * sizeof(glm::vec4);
    if (extras.empty()) extras.emplace_back(0.0f);  // a buffer of size 0 cannot be bound
    if (wires.empty()) return Status::success();

    auto headers =
        engine::gfx::make_buffer(std::span<const GpuCurveHeader>(header_data_), "wire gpu curve headers");
    auto nodes = engine::gfx::make_buffer(std::span<const glm::uvec2>(node_data), "wire gpu curve nodes");
    auto segments = engine::gfx::make_buffer({.size_bytes = segment_total_ * 4 * sizeof(glm::vec4),
                                              .dynamic = true,
                                              .label = "wire gpu curve segments"});
    auto scratch = engine::gfx::make_buffer(
        {.size_bytes = node_data.size() * 2 * sizeof(glm::dvec4), .label = "wire gpu curve scratch"});
    auto extra_buffer = engine::gfx::make_buffer(std::span<const glm::vec4>(extras), "wire gpu curve extras");
    for (const auto* b : {&headers, &nodes, &segments, &scratch, &extra_buffer}) {
        if (!*b) return Status::error(b->error().message);
    }
    headers_ = std::move(*headers), nodes_ = std::move(*nodes), segments_ = std::move(*segments);
    scratch_ = std::move(*scratch), extras_ = std::move(*extra_buffer);
    if (motion_ref_wires_ != wires.size() ||
        !motion_refs_) {  // the wires' references, kept for the next build
        auto refs = engine::gfx::make_buffer({.size_bytes = wires.size() * sizeof(detail::MotionRef),
                                              .label = "wire gpu curve motion references"});
        if (!refs) return Status::error(refs.error().message);
        motion_refs_ = std::move(*refs);
        glClearNamedBufferData(motion_refs_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        motion_ref_wires_ = wires.size();
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveHeaders, headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveNodes, nodes_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveSegments, segments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveScratch, scratch_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveExtras, extras_.id());
    // Slot w is wire w: the headers go back onto themselves (with the motion the GPU fitted), the references
    // stay.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveSlotHeaders, headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveMotionRefs, motion_refs_.id());
    // No slot list here (u_list off); something is bound all the same, as some drivers check every block's
    // binding.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveSlotList, scratch_.id());
    program_.use();
    glUniform1ui(program_.uniform_location("u_wires"), static_cast<GLuint>(wires.size()));
    glUniform1i(program_.uniform_location("u_list"), 0);
    glUniform1i(program_.uniform_location("u_persist"), 1);
    glUniform1i(program_.uniform_location("u_motion"), 1);
    glDispatchCompute(static_cast<GLuint>((wires.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glUseProgram(0);
    return Status::success();
}

void GpuCurvePass::read_segments(std::vector<GpuCurveResult>& out) const {
    out.clear();
    if (header_data_.empty()) return;
    std::vector<glm::vec4> data(segment_total_ * 4);
    glGetNamedBufferSubData(segments_.id(), 0, static_cast<GLsizeiptr>(data.size() * sizeof(glm::vec4)),
                            data.data());
    out.resize(header_data_.size());
    for (std::size_t w = 0; w < header_data_.size(); ++w) {
        const GpuCurveHeader& h = header_data_[w];
        GpuCurveResult& r = out[w];
        r.origin_m = origins_[w];
        r.closed = (h.flags & detail::kHeaderClosed) != 0;
        const std::size_t segs = r.closed ? h.node_count : h.node_count - 1;
        r.segments.resize(segs);
        for (std::size_t k = 0; k < segs; ++k) {
            const glm::vec4* s = &data[4 * (h.segment_first + k)];
            const glm::dvec3 b0(s[0]), b1 = b0 + glm::dvec3(s[1]), b2 = b1 + glm::dvec3(s[2]);
            r.segments[k] = CubicBezier{b0, b1, b2, b2 + glm::dvec3(s[3])};
        }
    }
}

}  // namespace wire::render
