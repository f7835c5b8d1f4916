// The ring expansion's static index patterns, one per side count (upload_plan.hpp: caps, then kChunkBands
// bands), the side table the vertex shader places rim vertices with, and the chunk-index attribute's buffer
// where the draw-parameters extension is missing: what the nodes path draws its rings with.
#include "renderer_state.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace wire::render {
namespace {

/// Indices of the ring-expansion pattern for `n` sides (upload_plan.hpp): start cap, end cap, kChunkBands
/// bands, in write_tube's winding.
void append_pattern(uint32_t n, std::vector<uint32_t>& out) {
    for (uint32_t cap = 0; cap < 2; ++cap) {
        const uint32_t centre = kCapVertexBase + cap * (n + 1);
        for (uint32_t j = 0; j < n; ++j) {
            const uint32_t rim_j = centre + 1 + j, rim_k = centre + 1 + (j + 1) % n;
            // Start cap faces -t: (centre, rim_k, rim_j); end cap faces +t: (centre, rim_j, rim_k).
            out.insert(out.end(), {centre, cap == 0 ? rim_k : rim_j, cap == 0 ? rim_j : rim_k});
        }
    }
    for (uint32_t b = 0; b < kChunkBands; ++b) {
        for (uint32_t j = 0; j < n; ++j) {
            const uint32_t a = b * (n + 1) + j, c = (b + 1) * (n + 1) + j;
            out.insert(out.end(), {a, a + 1, c, a + 1, c + 1, c});
        }
    }
}

}  // namespace

Status WireRenderer::State::ensure_patterns(uint32_t max_sides) {
    if (max_sides <= pattern_max_sides) return {};
    const uint32_t top = std::max(max_sides, std::max(detail::kPatternMinSides, 2 * pattern_max_sides));
    std::vector<uint32_t> indices;
    std::vector<uint32_t> first(top + 1, 0);
    // Strip and line pattern first (first[1] = first[2] = 0): wire::write_strip's band triangles.
    for (uint32_t b = 0; b < kChunkBands; ++b) {
        const uint32_t a = 2 * b;
        indices.insert(indices.end(), {a + 1, a + 3, a + 2, a + 1, a + 2, a});
    }
    for (uint32_t n = 3; n <= top; ++n) {
        first[n] = static_cast<uint32_t>(indices.size());
        append_pattern(n, indices);
    }
    Expected<detail::gfx::Buffer> made =
        detail::gfx::make_buffer(std::span<const uint32_t>(indices), "wire ring pattern");
    if (!made) return made.error();
    // Side table as wire::write_tube computes it: entry (n, j) at n (n + 1) / 2 - 6 + j.
    std::vector<float> table;
    for (uint32_t n = 3; n <= top; ++n) {
        for (uint32_t j = 0; j <= n; ++j) {
            const double phi = 2.0 * std::numbers::pi * (j == n ? 0 : j) / n;
            table.push_back(static_cast<float>(std::cos(phi)));
            table.push_back(static_cast<float>(std::sin(phi)));
        }
    }
    Expected<detail::gfx::Buffer> circle_made =
        detail::gfx::make_buffer(std::span<const float>(table), "wire ring circle");
    if (!circle_made) return circle_made.error();
    circle = std::move(circle_made).value();
    pattern = std::move(made).value();  // draws in flight keep the old one alive (GL deletes it later)
    pattern_first = std::move(first);
    pattern_max_sides = top;
    glVertexArrayElementBuffer(rings_vao.id(), pattern.id());
    return {};
}

Status WireRenderer::State::ensure_draw_index_capacity(std::size_t n) {
    if (draw_parameters || n <= draw_index_capacity) return {};
    const std::size_t capacity = std::max<std::size_t>(n, std::max<std::size_t>(1024, 2 * draw_index_capacity));
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

}  // namespace wire::render
