// gpu-rings' back end (renderer_state.hpp): each wire's packed rings kept resident in the retained storage
// while unchanged (or streamed every frame), one draw record per wire and one chunk record per chunk of
// bands, expanded into the tube by the vertex shader over the side count's index pattern.
#include "renderer_state.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <numeric>

namespace wire::render {

using detail::DrawElementsIndirectCommand;
using detail::ListFrame;

void WireRenderer::State::copy_packed(const DrawItem& item, std::byte* out) {
    if (item.packed.size() == item.rings.size()) {
        std::memcpy(out, item.packed.data(), item.packed.size_bytes());
        return;
    }
    packed.resize(item.rings.size());
    pack_rings(item.rings, packed.data());
    std::memcpy(out, packed.data(), packed.size() * sizeof(PackedRing));
}

void WireRenderer::State::retain(const DrawList& list, DrawStats& stats) {
    ring_storage.begin_frame();
    residency.begin_frame();
    ring_word.clear();
    streamed.clear();
    retained_ring_bytes = 0;
    std::size_t kept = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
        const DrawItem& item = list.items[order[k]];
        RingResidency::Touch t = residency.touch(item);
        if (t.replaced && t.replaced->size_bytes > 0)
            ring_storage.free(
                {.offset_bytes = t.replaced->offset_bytes, .size_bytes = t.replaced->size_bytes});
        if (t.upload) {
            const std::size_t bytes = item.rings.size() * sizeof(PackedRing);
            Expected<detail::gfx::RetainedRange> range = ring_storage.allocate(bytes);
            if (!range) {
                residency.forget(item.wire_id);
                continue;
            }
            copy_packed(item, static_cast<std::byte*>(range->data));  // write-only mapped memory
            t.entry->offset_bytes = range->offset_bytes;
            t.entry->size_bytes = bytes;
            retained_ring_bytes += bytes;
            stats.ring_bytes_uploaded += bytes;
            ++stats.wires_uploaded;
            stats.buffer_grew = stats.buffer_grew || range->grew;
        }
        if (t.stream) ++stats.wires_streamed;  // written into the frame's region by prepare_rings()
        streamed.push_back(t.stream ? 1 : 0);
        ring_word.push_back(static_cast<uint32_t>(t.entry->offset_bytes / 4));
        order[kept++] = order[k];
    }
    order.resize(kept);
    for (const Residency& gone : residency.evict()) {
        if (gone.size_bytes > 0)
            ring_storage.free({.offset_bytes = gone.offset_bytes, .size_bytes = gone.size_bytes});
        ++stats.wires_evicted;
    }
}

Status WireRenderer::State::ensure_draw_index_capacity(std::size_t n) {
    if (draw_parameters || n <= draw_index_capacity) return {};
    const std::size_t capacity =
        std::max<std::size_t>(n, std::max<std::size_t>(1024, 2 * draw_index_capacity));
    std::vector<uint32_t> iota(capacity);
    std::iota(iota.begin(), iota.end(), 0u);
    Expected<detail::gfx::Buffer> made =
        detail::gfx::make_buffer(std::span<const uint32_t>(iota), "wire draw index");
    if (!made) return made.error();
    draw_index_buffer = std::move(made).value();
    draw_index_capacity = capacity;
    glVertexArrayVertexBuffer(rings_vao.id(), 1, draw_index_buffer.id(), 0, sizeof(uint32_t));
    return {};
}

Status WireRenderer::State::prepare_rings(const DrawList& list, const glm::dvec3& eye, ListFrame& f,
                                          DrawStats& stats) {
    const bool retained = desc.retain_rings;
    const std::size_t n = order.size();
    run_first.clear();
    run_command.clear();
    commands.clear();
    chunks.clear();
    // Runs of equal (class, material); within a run, the items of one side count share a pattern and get one
    // instanced command per chunk kind. The count never depends on the number of wires.
    for (std::size_t r0 = 0; r0 < n;) {
        const DrawItem& head = list.items[order[r0]];
        if (r0 == 0 || !detail::same_run(list, order[r0 - 1], order[r0])) {
            run_first.push_back(static_cast<uint32_t>(r0));
            run_command.push_back(static_cast<uint32_t>(commands.size()));
        }
        std::size_t r1 = r0 + 1;
        while (r1 < n && detail::same_run(list, order[r0], order[r1]) &&
               list.items[order[r1]].sides == head.sides) {
            ++r1;
        }
        std::array<uint32_t, kChunkKinds> counts{};
        for (std::size_t k = r0; k < r1; ++k) {
            const DrawItem& item = list.items[order[k]];
            const std::array<uint32_t, kChunkKinds> c = chunk_counts(item);
            for (uint32_t kind = 0; kind < kChunkKinds; ++kind) counts[kind] += c[kind];
            if (!retained || streamed[k]) f.geometry_bytes += item.rings.size() * sizeof(PackedRing);
        }
        const uint32_t sides = head.sides;
        const uint32_t pattern = pattern_first[sides];
        const uint32_t band_indices = sides > 2 ? 6 * sides : 6;  // strips and lines: 2 triangles a band
        std::array<uint32_t, kChunkKinds> next{};                 // per kind: the next chunk record to write
        auto cursor = static_cast<uint32_t>(chunks.size() / 2);
        for (uint32_t kind = 0; kind < kChunkKinds; ++kind) {
            if (counts[kind] == 0) continue;
            next[kind] = cursor;
            // Caps: [start cap 3n][end cap 3n] at the pattern's start; bands follow them (tubes only).
            const uint32_t count = kind == 0 ? 6 * sides : chunk_kind_bands(kind) * band_indices;
            const uint32_t first = kind == 0 || sides <= 2 ? pattern : pattern + 6 * sides;
            commands.push_back({count, counts[kind], first, 0, cursor});
            cursor += counts[kind];
        }
        chunks.resize(2 * std::size_t{cursor});
        auto put = [&](uint32_t kind, std::size_t k, uint32_t first_band) {
            const uint32_t at = next[kind]++;
            chunks[2 * at] = static_cast<uint32_t>(k);
            chunks[2 * at + 1] = first_band;
        };
        for (std::size_t k = r0; k < r1; ++k) {
            const std::array<uint32_t, kChunkKinds> c = chunk_counts(list.items[order[k]]);
            if (c[0] != 0) put(0, k, 0);
            uint32_t band = 0;
            for (uint32_t i = 0; i < c[1]; ++i, band += kChunkBands) put(1, k, band);
            for (uint32_t kind = 2; kind < kChunkKinds; ++kind) {
                if (c[kind] == 0) continue;
                put(kind, k, band);
                band += chunk_kind_bands(kind);
            }
        }
        r0 = r1;
    }
    run_first.push_back(static_cast<uint32_t>(n));
    run_command.push_back(static_cast<uint32_t>(commands.size()));
    const std::size_t chunk_count_total = chunks.size() / 2;
    if (Status st = ensure_draw_index_capacity(chunk_count_total); !st) return st;

    f.chunk_bytes = chunks.size() * sizeof(uint32_t);
    const std::size_t command_bytes = commands.size() * sizeof(DrawElementsIndirectCommand);
    Expected<detail::gfx::StreamRegion> begun = stream.begin(f.lay_out(n, command_bytes, 0));
    if (!begun) return begun.error();
    f.region = *begun;
    stats.buffer_grew = stats.buffer_grew || f.region.grew;
    stats.waited_for_gpu = f.region.waited;

    // Sequential writes only (write-combined memory: never read it back).
    std::byte* base = f.region.data;
    if (f.chunk_bytes > 0) std::memcpy(base + f.chunk_offset, chunks.data(), f.chunk_bytes);
    std::memcpy(base + f.command_offset, commands.data(), command_bytes);
    std::size_t geometry_cursor = 0;  // bytes into the streamed rings
    for (std::size_t k = 0; k < n; ++k) {
        const DrawItem& item = list.items[order[k]];
        const glm::vec3 offset(item.origin_m - eye);  // difference in double, then float
        detail::GpuDraw draw{};
        draw.offset_m = {offset.x, offset.y, offset.z};
        const uint32_t strip_flags = item.sides == 2 ? detail::kDrawStrip : item.sides == 1 ? detail::kDrawLine : 0u;
        const auto ring_count = static_cast<uint32_t>(item.rings.size());
        const bool stream_rings = !retained || streamed[k];
        if (stream_rings) {  // into this frame's region (binding 4); the retained path's moving wires too
            copy_packed(item, base + f.geometry_offset + geometry_cursor);
            draw.ring_first = static_cast<uint32_t>(geometry_cursor / 4);
            geometry_cursor += ring_count * sizeof(PackedRing);
            stats.ring_bytes_uploaded += ring_count * sizeof(PackedRing);
            ++stats.wires_uploaded;
        } else {
            draw.ring_first = ring_word[k];
        }
        draw.ring_count = ring_count;
        draw.sides = item.sides;
        // Normals tilt by the radius slope as write_tube's default does; a wire of constant radius has slope
        // 0 everywhere, so the shader skips the neighbour fetches per vertex for it.
        const float r0 = item.rings.front().radius_m;
        const bool varying = item.radius_varies
                                 ? *item.radius_varies
                                 : std::any_of(item.rings.begin(), item.rings.end(),
                                               [r0](const Ring& r) { return r.radius_m != r0; });
        draw.flags = (item.closed ? detail::kDrawClosed : 0u) | (item.caps ? detail::kDrawCaps : 0u) |
                     (varying ? detail::kDrawTilt : 0u) |
                     (stream_rings && retained ? detail::kDrawStreamedRings : 0u) | strip_flags;
        draw.u_close = item.u_close;
        stats.vertices += expanded_vertices(item);
        stats.triangles += expanded_triangles(item);
        std::memcpy(base + k * sizeof(detail::GpuDraw), &draw, sizeof(draw));
    }
    stats.bytes_uploaded = f.draws_bytes + f.chunk_bytes + command_bytes + f.geometry_bytes +
                           (retained ? retained_ring_bytes : 0);
    stats.draw_items = n;
    stats.chunks = chunk_count_total;
    stats.indirect_commands = commands.size();
    return Status::success();
}

void WireRenderer::State::bind_rings(const ListFrame& f) {
    // Binding 1: the rings a draw record addresses by default (retained storage, or the frame's region);
    // binding 4: the frame's region, for retained-path wires streamed this frame (kDrawStreamedRings).
    const GLuint buffer = f.region.buffer;
    const auto geometry_at = static_cast<GLintptr>(f.region.offset_bytes + f.geometry_offset);
    const auto geometry_size = static_cast<GLsizeiptr>(std::max<std::size_t>(f.geometry_bytes, 4));
    if (desc.retain_rings) {
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, ring_storage.buffer(), 0,
                          static_cast<GLsizeiptr>(ring_storage.capacity_bytes()));
    } else {
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, buffer, geometry_at, geometry_size);
    }
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 4, buffer, geometry_at, geometry_size);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, circle.id());
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 3, buffer,
                      static_cast<GLintptr>(f.region.offset_bytes + f.chunk_offset),
                      static_cast<GLsizeiptr>(std::max<std::size_t>(f.chunk_bytes, 8)));
    rings_vao.bind();  // its element buffer is the pattern
}

}  // namespace wire::render
