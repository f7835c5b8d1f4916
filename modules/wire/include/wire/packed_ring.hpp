// The ring record as the GPU reads it: 28 bytes (seven 32-bit words) instead of wire::Ring's 48. Centre, radius
// and u stay float (the same values as wire::Ring); the frame (normal r, binormal s, tangent t = r x s) is a unit
// quaternion in "smallest three" form: the index of the largest component (2 bits) and the other three in
// [-1/sqrt 2, 1/sqrt 2] as 20-bit fixed point (step 1.35e-6), the largest made positive and rebuilt as
// sqrt(1 - a^2 - b^2 - c^2). Measured in upload_plan_test: frame angle error median 1.4e-6, max 3.6e-6 rad, so the rim moves
// < 0.01 px for tubes up to thousands of pixels in radius. The nodes path's ring pass writes these on the GPU and
// the ring vertex shader reads them; read_drawn_rings decodes them on the CPU (unpack_frame).
#pragma once

#include "wire/rings.hpp"

#include <glm/vec3.hpp>

#include <cstdint>
#include <span>

namespace wire {

/// See the file comment.
struct PackedRing {
    float centre_m[3];
    float radius_m;
    float u;
    uint32_t frame[2];
};
static_assert(sizeof(PackedRing) == 28, "PackedRing is the 28-byte GPU ring record");
inline constexpr uint32_t kPackedRingWords = sizeof(PackedRing) / 4;

[[nodiscard]] PackedRing pack_ring(const Ring& ring);
/// out[i] = pack_ring(rings[i]); out holds rings.size() records.
void pack_rings(std::span<const Ring> rings, PackedRing* out);

/// The frame a PackedRing decodes to, computed as the vertex shader does (float).
struct DecodedFrame {
    glm::vec3 normal{}, binormal{}, tangent{};
};
[[nodiscard]] DecodedFrame unpack_frame(const PackedRing& ring);

}  // namespace wire
