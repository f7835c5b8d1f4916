// Tube mesh from ring records: sides with a duplicated seam, flat caps, closed loops; no allocation per call.
#include "wire/tube.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <numbers>

namespace wire {
namespace {

constexpr uint32_t kCachedSides = 64;

uint32_t effective_sides(const TubeSettings& s) { return s.sides == 0 ? 8u : std::max(s.sides, 3u); }

/// (cos, sin) of 2 pi j / n for j = 0..n; entry n repeats entry 0 exactly so the seam welds.
const glm::vec2* side_table(uint32_t n) {
    thread_local std::array<std::vector<glm::vec2>, kCachedSides + 1> cached;
    thread_local std::vector<glm::vec2> large;
    std::vector<glm::vec2>& table = n <= kCachedSides ? cached[n] : large;
    if (table.size() != n + 1) {
        table.resize(n + 1);
        for (uint32_t j = 0; j < n; ++j) {
            const double phi = 2.0 * std::numbers::pi * j / n;
            table[j] = glm::vec2(static_cast<float>(std::cos(phi)), static_cast<float>(std::sin(phi)));
        }
        table[n] = table[0];
    }
    return table.data();
}

}  // namespace

TubeCounts tube_counts(std::size_t ring_count, bool closed, const TubeSettings& settings) {
    const std::size_t n = effective_sides(settings);
    TubeCounts c;
    if (ring_count == 0) {
        return c;
    }
    const std::size_t rows = ring_count + (closed ? 1 : 0);
    c.vertices = rows * (n + 1);
    c.indices = (rows - 1) * 6 * n;
    if (!closed && settings.caps) {
        c.vertices += 2 * (n + 1);
        c.indices += 2 * 3 * n;
    }
    return c;
}

TubeCounts write_tube(std::span<const Ring> rings, bool closed, float u_close, const TubeSettings& settings,
                      std::span<TubeVertex> vertices, std::span<uint32_t> indices, uint32_t base_vertex) {
    const TubeCounts counts = tube_counts(rings.size(), closed, settings);
    assert(vertices.size() >= counts.vertices && indices.size() >= counts.indices && "write_tube: buffers too small");
    if (counts.vertices == 0) {
        return counts;
    }
    const uint32_t n = effective_sides(settings);
    const glm::vec2* cs = side_table(n);
    const std::size_t ring_n = rings.size();
    const float inv_n = 1.0f / static_cast<float>(n);

    TubeVertex* v = vertices.data();
    auto emit_ring = [&](const Ring& ring, float u, float slope) {
        const glm::vec3 c = ring.centre_m;
        const glm::vec3 r = ring.normal;
        const glm::vec3 s = ring.binormal;
        const float rad = ring.radius_m;
        // Normal of a cone with dR/ds = slope: (d - slope t) / sqrt(1 + slope^2), d the radial direction.
        const float a = 1.0f / std::sqrt(1.0f + slope * slope);
        const glm::vec3 tb = (slope * a) * glm::cross(r, s);
        for (uint32_t j = 0; j <= n; ++j) {
            const glm::vec3 d = cs[j].x * r + cs[j].y * s;
            v->position = c + rad * d;
            v->normal = a * d - tb;
            v->uv = glm::vec2(u, static_cast<float>(j) * inv_n);
            ++v;
        }
    };
    auto slope_at = [&](std::size_t i) -> float {
        if (!settings.tilt_normals || ring_n < 2) {
            return 0.0f;
        }
        // Central difference of radius over arc (chord) length; one-sided at open ends, wrapped when closed.
        std::size_t lo = i > 0 ? i - 1 : (closed ? ring_n - 1 : i);
        std::size_t hi = i + 1 < ring_n ? i + 1 : (closed ? 0 : i);
        const float dr = rings[hi].radius_m - rings[lo].radius_m;
        if (dr == 0.0f) {
            return 0.0f;
        }
        const float ds = glm::length(rings[hi].centre_m - rings[i].centre_m) +
                         glm::length(rings[i].centre_m - rings[lo].centre_m);
        return ds > 0.0f ? dr / ds : 0.0f;
    };

    for (std::size_t i = 0; i < ring_n; ++i) {
        emit_ring(rings[i], rings[i].u, slope_at(i));
    }
    if (closed) {
        emit_ring(rings[0], u_close, slope_at(0));
    }

    uint32_t* idx = indices.data();
    const std::size_t rows = ring_n + (closed ? 1 : 0);
    const uint32_t stride = n + 1;
    for (std::size_t i = 0; i + 1 < rows; ++i) {
        const uint32_t a0 = base_vertex + static_cast<uint32_t>(i) * stride;
        const uint32_t b0 = a0 + stride;
        for (uint32_t j = 0; j < n; ++j) {
            // Counter-clockwise from outside: (a_j, a_j+1, b_j), (a_j+1, b_j+1, b_j) with t = r x s.
            idx[0] = a0 + j;
            idx[1] = a0 + j + 1;
            idx[2] = b0 + j;
            idx[3] = a0 + j + 1;
            idx[4] = b0 + j + 1;
            idx[5] = b0 + j;
            idx += 6;
        }
    }

    if (!closed && settings.caps) {
        auto emit_cap = [&](const Ring& ring, float sign) {
            const uint32_t centre = base_vertex + static_cast<uint32_t>(v - vertices.data());
            const glm::vec3 normal = sign * glm::cross(ring.normal, ring.binormal);
            v->position = ring.centre_m;
            v->normal = normal;
            v->uv = glm::vec2(0.5f, 0.5f);
            ++v;
            for (uint32_t j = 0; j < n; ++j) {
                const glm::vec3 d = cs[j].x * ring.normal + cs[j].y * ring.binormal;
                v->position = ring.centre_m + ring.radius_m * d;  // same expression as the side: welds exactly
                v->normal = normal;
                v->uv = glm::vec2(0.5f + 0.5f * cs[j].x, 0.5f + 0.5f * cs[j].y);
                ++v;
            }
            for (uint32_t j = 0; j < n; ++j) {
                const uint32_t rim_j = centre + 1 + j;
                const uint32_t rim_k = centre + 1 + (j + 1) % n;
                // Start cap faces -t: (centre, rim_k, rim_j); end cap faces +t: (centre, rim_j, rim_k).
                idx[0] = centre;
                idx[1] = sign < 0.0f ? rim_k : rim_j;
                idx[2] = sign < 0.0f ? rim_j : rim_k;
                idx += 3;
            }
        };
        emit_cap(rings[0], -1.0f);
        emit_cap(rings[ring_n - 1], 1.0f);
    }
    assert(static_cast<std::size_t>(v - vertices.data()) == counts.vertices);
    assert(static_cast<std::size_t>(idx - indices.data()) == counts.indices);
    return counts;
}

void build_tube(const RingSet& rings, const TubeSettings& settings, TubeMesh& out) {
    const TubeCounts c = tube_counts(rings.rings.size(), rings.closed, settings);
    out.origin_m = rings.origin_m;
    out.vertices.resize(c.vertices);
    out.indices.resize(c.indices);
    const float u_close = rings.closed && !rings.u.empty() ? static_cast<float>(rings.u.back()) : 0.0f;
    write_tube(rings.rings, rings.closed, u_close, settings, out.vertices, out.indices);
}

}  // namespace wire
