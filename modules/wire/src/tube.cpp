// Tube mesh from ring records: sides with a duplicated seam, flat caps, closed loops; no allocation per call.
// The camera-facing strips of thin wires are in strip.cpp.
#include "wire/tube.hpp"

#include "wire/detail/segment_soa.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES, WIRE_SELECT_KERNEL

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace wire {
namespace {

constexpr uint32_t kCachedSides = 64;

uint32_t effective_sides(const TubeSettings& s) {
    return s.sides == 0 ? 8u : std::max(s.sides, 3u);
}

/// Per side count, built once per thread: cos, sin and v of phi_j = 2 pi j / n for j = 0..n (entry n repeats entry
/// 0's cos/sin exactly so the seam welds, with v = 1), and the index pattern of one band of quads relative to its
/// first vertex (6 n entries).
struct SideTable {
    std::vector<float> cos_phi, sin_phi, v;
    std::vector<uint32_t> band;
};

const SideTable& side_table(uint32_t n) {
    thread_local std::array<SideTable, kCachedSides + 1> cached;
    thread_local SideTable large;
    SideTable& table = n <= kCachedSides ? cached[n] : large;
    if (table.cos_phi.size() != n + 1) {
        table.cos_phi.resize(n + 1);
        table.sin_phi.resize(n + 1);
        table.v.resize(n + 1);
        for (uint32_t j = 0; j < n; ++j) {
            const double phi = 2.0 * std::numbers::pi * j / n;
            table.cos_phi[j] = static_cast<float>(std::cos(phi));
            table.sin_phi[j] = static_cast<float>(std::sin(phi));
            table.v[j] = static_cast<float>(j) / static_cast<float>(n);
        }
        table.cos_phi[n] = table.cos_phi[0];
        table.sin_phi[n] = table.sin_phi[0];
        table.v[n] = 1.0f;
        table.band.resize(6 * std::size_t{n});
        const uint32_t stride = n + 1;
        for (uint32_t j = 0; j < n; ++j) {
            // Counter-clockwise from outside: (a_j, a_j+1, b_j), (a_j+1, b_j+1, b_j) with t = r x s.
            const uint32_t k[6] = {j, j + 1, stride + j, j + 1, stride + j + 1, stride + j};
            std::copy(k, k + 6, table.band.begin() + 6 * std::ptrdiff_t{j});
        }
    }
    return table;
}

#if defined(__SSE2__)
using Quad = __m128;
inline Quad quad(float a, float b, float c, float d) {
    return _mm_setr_ps(a, b, c, d);
}
#else
using Quad = std::array<float, 4>;
inline Quad quad(float a, float b, float c, float d) {
    return Quad{a, b, c, d};
}
#endif

/// One row of vertices as two 4-float halves of a TubeVertex (position xyz + normal x | normal yz + uv):
/// vertex_j = base + (cos_j along_r + sin_j along_s) + v_j v_weight (last lane). Built in registers (no
/// store-forwarding stalls); side rows and cap rims both go through emit_row, so equal inputs give bit-identical
/// positions and the mesh welds.
struct Row {
    Quad base0, base1, r0, r1, s0, s1;
};

/// Writes `count` vertices of `row`; returns the vertex after the last one written.
TubeVertex* emit_row(const Row& row, const float* cos_phi, const float* sin_phi, const float* v_of, float v_weight,
                     uint32_t count, TubeVertex* v, bool stream) {
    float* out = reinterpret_cast<float*>(v);
#if defined(__SSE2__)
    // x86-64 always has SSE2; no -march needed.
    const __m128 lane_v = _mm_setr_ps(0.0f, 0.0f, 0.0f, v_weight);
    for (uint32_t j = 0; j < count; ++j, out += 8) {
        const __m128 cj = _mm_set1_ps(cos_phi[j]);
        const __m128 sj = _mm_set1_ps(sin_phi[j]);
        const __m128 vj = _mm_set1_ps(v_of[j]);
        const __m128 o0 = _mm_add_ps(row.base0, _mm_add_ps(_mm_mul_ps(cj, row.r0), _mm_mul_ps(sj, row.s0)));
        const __m128 o1 = _mm_add_ps(_mm_add_ps(row.base1, _mm_mul_ps(vj, lane_v)),
                                     _mm_add_ps(_mm_mul_ps(cj, row.r1), _mm_mul_ps(sj, row.s1)));
        if (stream) {
            _mm_stream_ps(out, o0);
            _mm_stream_ps(out + 4, o1);
        } else {
            _mm_storeu_ps(out, o0);
            _mm_storeu_ps(out + 4, o1);
        }
    }
#else
    (void)stream;
    for (uint32_t j = 0; j < count; ++j, out += 8) {
        float o[8];
        for (int k = 0; k < 4; ++k) {
            o[k] = row.base0[k] + (cos_phi[j] * row.r0[k] + sin_phi[j] * row.s0[k]);
            o[4 + k] = row.base1[k] + (cos_phi[j] * row.r1[k] + sin_phi[j] * row.s1[k]);
        }
        o[7] += v_of[j] * v_weight;
        std::memcpy(out, o, sizeof(o));
    }
#endif
    return v + count;
}

/// 32 bytes to dst; with `stream`, non-temporal (the caller checked 16-byte alignment).
inline void store_vertex(TubeVertex* dst, const float (&o)[8], bool stream) {
#if defined(__SSE2__)
    if (stream) {
        float* f = reinterpret_cast<float*>(dst);
        _mm_stream_ps(f, _mm_loadu_ps(o));
        _mm_stream_ps(f + 4, _mm_loadu_ps(o + 4));
        return;
    }
#else
    (void)stream;
#endif
    std::memcpy(static_cast<void*>(dst), o, sizeof(o));
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
    const SideTable& table = side_table(n);
    const float* cos_phi = table.cos_phi.data();
    const float* sin_phi = table.sin_phi.data();
    const float* v_of = table.v.data();
    const std::size_t ring_n = rings.size();
    static_assert(offsetof(TubeVertex, normal) == 12 && offsetof(TubeVertex, uv) == 24, "8 packed floats");
    const bool stream = settings.streaming_stores && reinterpret_cast<std::uintptr_t>(vertices.data()) % 16 == 0;

    TubeVertex* v = vertices.data();
    auto emit_ring = [&](const Ring& ring, float u, float slope) {
        // vertex_j = base + cos_j along_r + sin_j along_s + v_j lane_v as 8 floats (position, normal, uv): one
        // fixed-width loop the compiler vectorizes. The normal of a cone with dR/ds = slope is
        // (d - slope t) / sqrt(1 + slope^2), d the radial direction.
        const float a = 1.0f / std::sqrt(1.0f + slope * slope);
        const glm::vec3 tb = (slope * a) * glm::cross(ring.normal, ring.binormal);
        const glm::vec3 rr = ring.radius_m * ring.normal;
        const glm::vec3 sr = ring.radius_m * ring.binormal;
        const glm::vec3 ra = a * ring.normal;
        const glm::vec3 sa = a * ring.binormal;
        const Row row{quad(ring.centre_m.x, ring.centre_m.y, ring.centre_m.z, -tb.x),
                      quad(-tb.y, -tb.z, u, 0.0f),
                      quad(rr.x, rr.y, rr.z, ra.x),
                      quad(ra.y, ra.z, 0.0f, 0.0f),
                      quad(sr.x, sr.y, sr.z, sa.x),
                      quad(sa.y, sa.z, 0.0f, 0.0f)};
        v = emit_row(row, cos_phi, sin_phi, v_of, 1.0f, n + 1, v, stream);
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
        const float ds =
            glm::length(rings[hi].centre_m - rings[i].centre_m) + glm::length(rings[i].centre_m - rings[lo].centre_m);
        // A cone steeper than 1e18 is a disc: clamped so that 1 + slope^2 stays finite (a radius jump of 1e38 m
        // over a few centimetres overflowed it, and the normal became 0 * inf = NaN).
        return ds > 0.0f ? std::clamp(dr / ds, -1e18f, 1e18f) : 0.0f;
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
    const uint32_t* band = table.band.data();
    const std::size_t band_size = 6 * std::size_t{n};
    for (std::size_t i = 0; i + 1 < rows; ++i) {
        const uint32_t a0 = base_vertex + static_cast<uint32_t>(i) * stride;
#if defined(__SSE2__)
        if (stream) {
            for (std::size_t k = 0; k < band_size; ++k) {
                _mm_stream_si32(reinterpret_cast<int*>(idx + k), static_cast<int>(a0 + band[k]));
            }
            idx += band_size;
            continue;
        }
#endif
        for (std::size_t k = 0; k < band_size; ++k) {
            idx[k] = a0 + band[k];
        }
        idx += band_size;
    }

    if (!closed && settings.caps) {
        auto emit_cap = [&](const Ring& ring, float sign) {
            const uint32_t centre = base_vertex + static_cast<uint32_t>(v - vertices.data());
            const glm::vec3 normal = sign * glm::cross(ring.normal, ring.binormal);
            const float centre_vertex[8] = {
                ring.centre_m.x, ring.centre_m.y, ring.centre_m.z, normal.x, normal.y, normal.z, 0.5f, 0.5f};
            store_vertex(v++, centre_vertex, stream);
            // Rim positions by the side loop's exact expression, so they weld with the side vertices.
            const glm::vec3 rr = ring.radius_m * ring.normal;
            const glm::vec3 sr = ring.radius_m * ring.binormal;
            const Row row{quad(ring.centre_m.x, ring.centre_m.y, ring.centre_m.z, normal.x),
                          quad(normal.y, normal.z, 0.5f, 0.5f),
                          quad(rr.x, rr.y, rr.z, 0.0f),
                          quad(0.0f, 0.0f, 0.5f, 0.0f),
                          quad(sr.x, sr.y, sr.z, 0.0f),
                          quad(0.0f, 0.0f, 0.0f, 0.5f)};
            v = emit_row(row, cos_phi, sin_phi, v_of, 0.0f, n, v, stream);
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
#if defined(__SSE2__)
    if (stream) {
        _mm_sfence();  // streamed stores are weakly ordered: publish them before the caller hands the arena on
    }
#endif
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
