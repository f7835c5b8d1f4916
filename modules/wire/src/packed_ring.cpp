// Packing ring records into the 28-byte GPU form (packed_ring.hpp).
#include "wire/packed_ring.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace wire {
namespace {

constexpr uint32_t kFixedMax = (1u << 20) - 1;
constexpr double kInvSqrt2 = 0.70710678118654752440;

// Round to nearest (ties up) by truncating x + 0.5, clamped to [0, kFixedMax]: no libm call on the SSE2 baseline.
uint32_t encode(double v) {
    const double x = std::clamp((v * (0.5 / kInvSqrt2) + 0.5) * kFixedMax, 0.0, static_cast<double>(kFixedMax));
    return static_cast<uint32_t>(x + 0.5);
}

float decode(uint32_t k) {
    return (static_cast<float>(k) / static_cast<float>(kFixedMax) * 2.0f - 1.0f) * 0.70710678f;
}

}  // namespace

PackedRing pack_ring(const Ring& ring) {
    PackedRing p{};
    p.centre_m[0] = ring.centre_m.x;
    p.centre_m[1] = ring.centre_m.y;
    p.centre_m[2] = ring.centre_m.z;
    p.radius_m = ring.radius_m;
    p.u = ring.u;
    // Rotation matrix with columns r, s, t -> quaternion (x, y, z, w), branch on the largest diagonal term.
    const glm::dvec3 r(ring.normal), s(ring.binormal);
    const glm::dvec3 t = glm::cross(r, s);
    const double m00 = r.x, m10 = r.y, m20 = r.z, m01 = s.x, m11 = s.y, m21 = s.z, m02 = t.x, m12 = t.y,
                 m22 = t.z;
    double q[4];  // x, y, z, w
    const double trace = m00 + m11 + m22;
    if (trace > 0.0) {
        const double k = 2.0 * std::sqrt(trace + 1.0), inv = 1.0 / k;
        q[3] = 0.25 * k, q[0] = (m21 - m12) * inv, q[1] = (m02 - m20) * inv, q[2] = (m10 - m01) * inv;
    } else if (m00 > m11 && m00 > m22) {
        const double k = 2.0 * std::sqrt(std::max(1e-300, 1.0 + m00 - m11 - m22)), inv = 1.0 / k;
        q[3] = (m21 - m12) * inv, q[0] = 0.25 * k, q[1] = (m01 + m10) * inv, q[2] = (m02 + m20) * inv;
    } else if (m11 > m22) {
        const double k = 2.0 * std::sqrt(std::max(1e-300, 1.0 + m11 - m00 - m22)), inv = 1.0 / k;
        q[3] = (m02 - m20) * inv, q[0] = (m01 + m10) * inv, q[1] = 0.25 * k, q[2] = (m12 + m21) * inv;
    } else {
        const double k = 2.0 * std::sqrt(std::max(1e-300, 1.0 + m22 - m00 - m11)), inv = 1.0 / k;
        q[3] = (m10 - m01) * inv, q[0] = (m02 + m20) * inv, q[1] = (m12 + m21) * inv, q[2] = 0.25 * k;
    }
    // No renormalization: r and s are unit and orthogonal to float precision, so |q| = 1 within ~1e-7, far below
    // the 20-bit step (1.35e-6); the shader rebuilds the largest component from the other three anyway.
    int largest = 0;
    for (int i = 0; i < 4; ++i) {
        if (std::abs(q[i]) > std::abs(q[largest])) largest = i;
    }
    const double sign = q[largest] < 0.0 ? -1.0 : 1.0;
    uint64_t bits = static_cast<uint64_t>(largest);
    int shift = 2;
    for (int i = 0; i < 4; ++i) {
        if (i == largest) continue;
        bits |= static_cast<uint64_t>(encode(sign * q[i])) << shift;
        shift += 20;
    }
    p.frame[0] = static_cast<uint32_t>(bits);
    p.frame[1] = static_cast<uint32_t>(bits >> 32);
    return p;
}

void pack_rings(std::span<const Ring> rings, PackedRing* out) {
    for (std::size_t i = 0; i < rings.size(); ++i) out[i] = pack_ring(rings[i]);
}

DecodedFrame unpack_frame(const PackedRing& ring) {
    // Mirrors ring_frame() in shaders.cpp, in float.
    const uint32_t w0 = ring.frame[0], w1 = ring.frame[1];
    const uint32_t largest = w0 & 3u;
    const uint32_t k[3] = {(w0 >> 2) & kFixedMax, ((w0 >> 22) | (w1 << 10)) & kFixedMax, (w1 >> 10) & kFixedMax};
    float q[4];
    float sum = 0.0f;
    for (uint32_t i = 0, j = 0; i < 4; ++i) {
        if (i == largest) continue;
        q[i] = decode(k[j++]);
        sum += q[i] * q[i];
    }
    q[largest] = std::sqrt(std::max(0.0f, 1.0f - sum));
    const float x = q[0], y = q[1], z = q[2], w = q[3];
    DecodedFrame f;
    f.normal = {1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y + w * z), 2.0f * (x * z - w * y)};
    f.binormal = {2.0f * (x * y - w * z), 1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z + w * x)};
    f.tangent = {2.0f * (x * z + w * y), 2.0f * (y * z - w * x), 1.0f - 2.0f * (x * x + y * y)};
    return f;
}

}  // namespace wire
