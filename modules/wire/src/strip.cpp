// Camera-facing strip mesh from ring records (thin wires): two vertices a ring, spread across the view by the vertex
// shader, each carrying the ring frame's quaternion.
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
    const __m128 head = _mm_loadu_ps(&ring.centre_m.x);                               // cx cy cz R
    const __m128 cz_qx = _mm_shuffle_ps(head, quat, _MM_SHUFFLE(0, 0, 2, 2));         // cz cz qx qx
    const __m128 first = _mm_shuffle_ps(head, cz_qx, _MM_SHUFFLE(2, 0, 1, 0));        // cx cy cz qx
    const __m128 u_r = _mm_shuffle_ps(_mm_set_ss(u), head, _MM_SHUFFLE(3, 3, 0, 0));  // u u R R
    const __m128 plus = _mm_shuffle_ps(quat, u_r, _MM_SHUFFLE(2, 0, 2, 1));           // qy qz u R
    const __m128 minus = _mm_xor_ps(plus, _mm_setr_ps(0.0f, 0.0f, 0.0f, -0.0f));      // qy qz u -R
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
