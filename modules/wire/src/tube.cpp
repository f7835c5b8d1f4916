// Tube mesh from ring records: sides with a duplicated seam, flat caps, closed loops; no allocation per call.
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

uint32_t effective_sides(const TubeSettings& s) { return s.sides == 0 ? 8u : std::max(s.sides, 3u); }

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
inline Quad quad(float a, float b, float c, float d) { return _mm_setr_ps(a, b, c, d); }
#else
using Quad = std::array<float, 4>;
inline Quad quad(float a, float b, float c, float d) { return Quad{a, b, c, d}; }
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
        const Row row{quad(ring.centre_m.x, ring.centre_m.y, ring.centre_m.z, -tb.x), quad(-tb.y, -tb.z, u, 0.0f),
                      quad(rr.x, rr.y, rr.z, ra.x),  quad(ra.y, ra.z, 0.0f, 0.0f),
                      quad(sr.x, sr.y, sr.z, sa.x),  quad(sa.y, sa.z, 0.0f, 0.0f)};
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
        const float ds = glm::length(rings[hi].centre_m - rings[i].centre_m) +
                         glm::length(rings[i].centre_m - rings[lo].centre_m);
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
            const float centre_vertex[8] = {ring.centre_m.x, ring.centre_m.y, ring.centre_m.z, normal.x, normal.y,
                                            normal.z, 0.5f, 0.5f};
            store_vertex(v++, centre_vertex, stream);
            // Rim positions by the side loop's exact expression, so they weld with the side vertices.
            const glm::vec3 rr = ring.radius_m * ring.normal;
            const glm::vec3 sr = ring.radius_m * ring.binormal;
            const Row row{quad(ring.centre_m.x, ring.centre_m.y, ring.centre_m.z, normal.x),
                          quad(normal.y, normal.z, 0.5f, 0.5f),
                          quad(rr.x, rr.y, rr.z, 0.0f), quad(0.0f, 0.0f, 0.5f, 0.0f),
                          quad(sr.x, sr.y, sr.z, 0.0f), quad(0.0f, 0.0f, 0.0f, 0.5f)};
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

glm::vec3 ring_frame_quaternion_xyz(const Ring& ring) {
    const glm::dvec3 r(ring.normal), s(ring.binormal);
    const glm::dquat q = glm::normalize(glm::quat_cast(glm::dmat3(r, s, glm::cross(r, s))));
    const double sign = q.w < 0.0 ? -1.0 : 1.0;
    return glm::vec3(sign * q.x, sign * q.y, sign * q.z);
}

TubeCounts strip_counts(std::size_t ring_count, bool closed) {
    if (ring_count == 0) return {};
    const std::size_t rows = ring_count + (closed ? 1 : 0);
    return {.vertices = rows * 2, .indices = (rows - 1) * 6};
}

namespace {
/// Rings per pass of write_strip: their frames and quaternions live in stack buffers (no per-thread vectors to
/// look up and resize per wire), small enough to stay in L1 between the passes. A multiple of 8 (the padding).
constexpr std::size_t kStripChunk = 64;
static_assert(kStripChunk % 8 == 0);

/// The frames of n <= kStripChunk rings as 6 float rows of kStripChunk (normal x, y, z, binormal x, y, z): four
/// rings at a time by 4x4 transposes of their record quads (the compiler does not vectorize the strided gather).
void gather_frames(const Ring* rings, std::size_t n, float (*f)[kStripChunk]) {
    static_assert(offsetof(Ring, normal) == 16 && offsetof(Ring, binormal) == 32, "record quads");
    std::size_t k = 0;
#if defined(__SSE2__)
    for (; k + 4 <= n; k += 4) {
        for (int half = 0; half < 2; ++half) {  // normal, then binormal
            const float* at = half == 0 ? &rings[k].normal.x : &rings[k].binormal.x;
            constexpr std::size_t stride = sizeof(Ring) / sizeof(float);
            __m128 a = _mm_loadu_ps(at), b = _mm_loadu_ps(at + stride), c = _mm_loadu_ps(at + 2 * stride),
                   d = _mm_loadu_ps(at + 3 * stride);
            _MM_TRANSPOSE4_PS(a, b, c, d);  // a: x of the 4 rings, b: y, c: z (d: u or segment, unused)
            _mm_storeu_ps(&f[3 * half][k], a);
            _mm_storeu_ps(&f[3 * half + 1][k], b);
            _mm_storeu_ps(&f[3 * half + 2][k], c);
        }
    }
#endif
    for (; k < n; ++k) {
        f[0][k] = rings[k].normal.x;
        f[1][k] = rings[k].normal.y;
        f[2][k] = rings[k].normal.z;
        f[3][k] = rings[k].binormal.x;
        f[4][k] = rings[k].binormal.y;
        f[5][k] = rings[k].binormal.z;
    }
}

/// ring_frame_quaternion_xyz() of n <= kStripChunk frames (gather_frames' rows) into 3 rows q[0..2]: each float
/// promoted to double, then glm::quat_cast's operations (its four candidates, the largest by the same strict
/// comparisons, taken by selects instead of a switch), glm::normalize's and the sign flip, in the same order, so
/// the result is bit for bit the one-ring function's; the loop vectorizes.
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL void frame_quaternions(const float (*__restrict f)[kStripChunk], std::size_t n,
                                                             float (*__restrict q)[kStripChunk]) {
    for (std::size_t k = 0; k < n; ++k) {
        const double rx = f[0][k], ry = f[1][k], rz = f[2][k];
        const double sx = f[3][k], sy = f[4][k], sz = f[5][k];
        // glm::cross(r, s): the matrix's third column.
        const double tx = ry * sz - sy * rz, ty = rz * sx - sz * rx, tz = rx * sy - sx * ry;
        // m[c][r] of dmat3(r, s, t).
        const double m00 = rx, m01 = ry, m02 = rz, m10 = sx, m11 = sy, m12 = sz, m20 = tx, m21 = ty, m22 = tz;
        const double four_x = m00 - m11 - m22;
        const double four_y = m11 - m00 - m22;
        const double four_z = m22 - m00 - m11;
        const double four_w = m00 + m11 + m22;
        double big = four_w;
        int index = 0;
        index = four_x > big ? 1 : index;
        big = four_x > big ? four_x : big;
        index = four_y > big ? 2 : index;
        big = four_y > big ? four_y : big;
        index = four_z > big ? 3 : index;
        big = four_z > big ? four_z : big;
        const double value = std::sqrt(big + 1.0) * 0.5;
        const double mult = 0.25 / value;
        const double a = (m12 - m21) * mult, b = (m20 - m02) * mult, c = (m01 - m10) * mult;
        const double d = (m01 + m10) * mult, e = (m20 + m02) * mult, g = (m12 + m21) * mult;
        const double w = index == 0 ? value : (index == 1 ? a : (index == 2 ? b : c));
        const double x = index == 0 ? a : (index == 1 ? value : (index == 2 ? d : e));
        const double y = index == 0 ? b : (index == 1 ? d : (index == 2 ? value : g));
        const double z = index == 0 ? c : (index == 1 ? e : (index == 2 ? g : value));
        const double len = std::sqrt((w * w + x * x) + (y * y + z * z));
        const double inv = 1.0 / len;
        const bool zero = len <= 0.0;  // glm::normalize's identity quaternion
        const double nw = zero ? 1.0 : w * inv;
        const double sign = nw < 0.0 ? -1.0 : 1.0;
        q[0][k] = static_cast<float>(sign * (zero ? 0.0 : x * inv));
        q[1][k] = static_cast<float>(sign * (zero ? 0.0 : y * inv));
        q[2][k] = static_cast<float>(sign * (zero ? 0.0 : z * inv));
    }
}

#if defined(__SSE2__)
/// Strip row: vertices (centre, q, (u, -R)) and (centre, q, (u, +R)) as four 16-byte stores; `quat` = qx qy qz -.
inline void store_strip_row(const Ring& ring, __m128 quat, float u, TubeVertex* out) {
    static_assert(offsetof(Ring, radius_m) == 12 && offsetof(TubeVertex, uv) == 24, "packed floats");
    const __m128 head = _mm_loadu_ps(&ring.centre_m.x);                                // cx cy cz R
    const __m128 cz_qx = _mm_shuffle_ps(head, quat, _MM_SHUFFLE(0, 0, 2, 2));          // cz cz qx qx
    const __m128 first = _mm_shuffle_ps(head, cz_qx, _MM_SHUFFLE(2, 0, 1, 0));         // cx cy cz qx
    const __m128 u_r = _mm_shuffle_ps(_mm_set_ss(u), head, _MM_SHUFFLE(3, 3, 0, 0));   // u u R R
    const __m128 plus = _mm_shuffle_ps(quat, u_r, _MM_SHUFFLE(2, 0, 2, 1));            // qy qz u R
    const __m128 minus = _mm_xor_ps(plus, _mm_setr_ps(0.0f, 0.0f, 0.0f, -0.0f));       // qy qz u -R
    float* f = reinterpret_cast<float*>(out);
    _mm_storeu_ps(f, first);
    _mm_storeu_ps(f + 4, minus);
    _mm_storeu_ps(f + 8, first);
    _mm_storeu_ps(f + 12, plus);
}
#endif
}  // namespace

TubeCounts write_strip(std::span<const Ring> rings, bool closed, float u_close, std::span<TubeVertex> vertices,
                       std::span<uint32_t> indices, uint32_t base_vertex) {
    const TubeCounts c = strip_counts(rings.size(), closed);
    assert(vertices.size() >= c.vertices && indices.size() >= c.indices);
    const std::size_t n = rings.size();
    // A chunk of rings at a time: frames gathered, their quaternions in one vectorized pass, then the rows.
    float frames[6][kStripChunk];
    float q[3][kStripChunk];
    glm::vec3 q0{};  // ring 0's quaternion, repeated by a closed wire's last row
    TubeVertex* out = vertices.data();
    for (std::size_t first = 0; first < n; first += kStripChunk) {
        const std::size_t count = std::min(kStripChunk, n - first);
        const Ring* chunk = rings.data() + first;
        gather_frames(chunk, count, frames);
        // Rounded up to a multiple of 8 rings with identity frames (their results unused): the kernel's 8-wide
        // epilogue takes the rest, where its scalar tail took up to 7 rings one by one (a third of its time on
        // ~20-ring wires: the divides and square roots bound it).
        const std::size_t padded = (count + 7) / 8 * 8;
        for (std::size_t k = count; k < padded; ++k) {
            for (std::size_t row = 0; row < 6; ++row) frames[row][k] = row == 0 || row == 4 ? 1.0f : 0.0f;
        }
        frame_quaternions(frames, padded, q);
        if (first == 0) q0 = {q[0][0], q[1][0], q[2][0]};
        std::size_t k = 0;
#if defined(__SSE2__)
        for (; k + 4 <= count; k += 4, out += 8) {
            // Four rings' quaternions, one per register.
            __m128 a = _mm_loadu_ps(&q[0][k]), b = _mm_loadu_ps(&q[1][k]), c4 = _mm_loadu_ps(&q[2][k]),
                   d = _mm_setzero_ps();
            _MM_TRANSPOSE4_PS(a, b, c4, d);
            store_strip_row(chunk[k], a, chunk[k].u, out);
            store_strip_row(chunk[k + 1], b, chunk[k + 1].u, out + 2);
            store_strip_row(chunk[k + 2], c4, chunk[k + 2].u, out + 4);
            store_strip_row(chunk[k + 3], d, chunk[k + 3].u, out + 6);
        }
        for (; k < count; ++k, out += 2) {
            store_strip_row(chunk[k], _mm_setr_ps(q[0][k], q[1][k], q[2][k], 0.0f), chunk[k].u, out);
        }
#else
        for (; k < count; ++k, out += 2) {
            const glm::vec3 qk(q[0][k], q[1][k], q[2][k]);
            out[0] = {chunk[k].centre_m, qk, {chunk[k].u, -chunk[k].radius_m}};
            out[1] = {chunk[k].centre_m, qk, {chunk[k].u, chunk[k].radius_m}};
        }
#endif
    }
    if (closed && n > 0) {
#if defined(__SSE2__)
        store_strip_row(rings[0], _mm_setr_ps(q0.x, q0.y, q0.z, 0.0f), u_close, out);
#else
        out[0] = {rings[0].centre_m, q0, {u_close, -rings[0].radius_m}};
        out[1] = {rings[0].centre_m, q0, {u_close, rings[0].radius_m}};
#endif
    }
    const std::size_t bands = c.vertices / 2 - (c.vertices > 0 ? 1 : 0);
    uint32_t* o = indices.data();
    std::size_t b = 0;
#if defined(__SSE2__)
    // Two bands (12 indices) as three 16-byte stores of a fixed pattern plus their first vertex.
    const __m128i p0 = _mm_setr_epi32(1, 3, 2, 1), p1 = _mm_setr_epi32(2, 0, 3, 5), p2 = _mm_setr_epi32(4, 3, 4, 2);
    for (; b + 2 <= bands; b += 2, o += 12) {
        const __m128i a = _mm_set1_epi32(static_cast<int>(base_vertex + 2 * b));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(o), _mm_add_epi32(a, p0));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(o + 4), _mm_add_epi32(a, p1));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(o + 8), _mm_add_epi32(a, p2));
    }
#endif
    for (; b < bands; ++b, o += 6) {
        const auto a = static_cast<uint32_t>(base_vertex + 2 * b);
        o[0] = a + 1, o[1] = a + 3, o[2] = a + 2, o[3] = a + 1, o[4] = a + 2, o[5] = a;
    }
    return c;
}

void build_strip(const RingSet& rings, TubeMesh& out) {
    const TubeCounts c = strip_counts(rings.rings.size(), rings.closed);
    out.origin_m = rings.origin_m;
    out.vertices.resize(c.vertices);
    out.indices.resize(c.indices);
    const float u_close = rings.closed && !rings.u.empty() ? static_cast<float>(rings.u.back()) : 0.0f;
    write_strip(rings.rings, rings.closed, u_close, out.vertices, out.indices);
}

}  // namespace wire
