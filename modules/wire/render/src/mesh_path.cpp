// cpu-mesh's back end (renderer_state.hpp): every visible wire's tube vertices, a 4-byte draw index per
// vertex and its indices rebased while copying, so one command draws a run's wires without a base vertex per
// wire.
#include "renderer_state.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <cstring>

namespace wire::render {

using detail::DrawElementsIndirectCommand;
using detail::ListFrame;

Status WireRenderer::State::prepare_mesh(const DrawList& list, const glm::dvec3& eye, ListFrame& f,
                                         DrawStats& stats) {
    const std::size_t n = order.size();
    run_first.clear();
    run_command.clear();
    commands.clear();
    std::size_t vertex_total = 0, index_total = 0;
    for (std::size_t k = 0; k < n; ++k) {
        const DrawItem& item = list.items[order[k]];
        if (k == 0 || !detail::same_run(list, order[k - 1], order[k])) {
            run_first.push_back(static_cast<uint32_t>(k));
            run_command.push_back(static_cast<uint32_t>(commands.size()));
            commands.push_back({0, 1, static_cast<uint32_t>(index_total), 0, 0});  // first index: relative
        }
        f.geometry_bytes += item.vertices.size_bytes();
        vertex_total += item.vertices.size();
        index_total += item.indices.size();
        commands.back().count += static_cast<uint32_t>(item.indices.size());
    }
    run_first.push_back(static_cast<uint32_t>(n));
    run_command.push_back(static_cast<uint32_t>(commands.size()));

    const std::size_t command_bytes = commands.size() * sizeof(DrawElementsIndirectCommand);
    const std::size_t record_bytes = vertex_total * kVertexDrawIndexBytes;
    const std::size_t index_bytes = index_total * sizeof(uint32_t);
    const std::size_t index_offset = f.lay_out(n, command_bytes, record_bytes);
    Expected<detail::gfx::StreamRegion> begun = stream.begin(index_offset + index_bytes);
    if (!begun) return begun.error();
    f.region = *begun;
    stats.buffer_grew = stats.buffer_grew || f.region.grew;
    stats.waited_for_gpu = f.region.waited;

    // Sequential writes only (write-combined memory: never read it back).
    std::byte* base = f.region.data;
    const auto first_index_base =
        static_cast<uint32_t>((f.region.offset_bytes + index_offset) / sizeof(uint32_t));
    for (DrawElementsIndirectCommand& c : commands) c.first_index += first_index_base;
    std::memcpy(base + f.command_offset, commands.data(), command_bytes);
    std::size_t geometry_cursor = 0;  // bytes into the vertex section
    std::size_t index_cursor = 0;     // indices into the index section
    uint32_t vertex_cursor = 0;       // vertices into the vertex section
    auto* const vertex_records = reinterpret_cast<uint32_t*>(base + f.record_offset);
    auto* const indices = reinterpret_cast<uint32_t*>(base + index_offset);
    for (std::size_t k = 0; k < n; ++k) {
        const DrawItem& item = list.items[order[k]];
        const glm::vec3 offset(item.origin_m - eye);  // difference in double, then float
        detail::GpuDraw draw{};
        draw.offset_m = {offset.x, offset.y, offset.z};
        draw.flags = item.sides == 2 ? detail::kDrawStrip : item.sides == 1 ? detail::kDrawLine : 0u;
        const auto vertex_count = static_cast<uint32_t>(item.vertices.size());
        const std::size_t index_count = item.indices.size();
        std::memcpy(base + f.geometry_offset + geometry_cursor, item.vertices.data(),
                    item.vertices.size_bytes());
        std::fill_n(vertex_records + vertex_cursor, vertex_count, static_cast<uint32_t>(k));
        // Rebased while copying: one draw covers every wire of the run without a base vertex per wire.
        const uint32_t* src = item.indices.data();
        uint32_t* dst = indices + index_cursor;
        for (std::size_t i = 0; i < index_count; ++i) dst[i] = src[i] + vertex_cursor;
        geometry_cursor += item.vertices.size_bytes();
        index_cursor += index_count;
        vertex_cursor += vertex_count;
        stats.vertices += vertex_count;
        stats.triangles += index_count / 3;
        std::memcpy(base + k * sizeof(detail::GpuDraw), &draw, sizeof(draw));
    }
    stats.bytes_uploaded = f.draws_bytes + command_bytes + f.geometry_bytes + record_bytes + index_bytes;
    stats.draw_items = n;
    stats.indirect_commands = commands.size();
    return Status::success();
}

void WireRenderer::State::bind_mesh(const ListFrame& f) {
    const GLuint buffer = f.region.buffer;
    glVertexArrayVertexBuffer(cpu_vao.id(), 0, buffer,
                              static_cast<GLintptr>(f.region.offset_bytes + f.geometry_offset),
                              sizeof(TubeVertex));
    glVertexArrayVertexBuffer(cpu_vao.id(), 1, buffer,
                              static_cast<GLintptr>(f.region.offset_bytes + f.record_offset),
                              sizeof(uint32_t));
    glVertexArrayElementBuffer(cpu_vao.id(), buffer);
    cpu_vao.bind();
}

}  // namespace wire::render
