// The repeating weave (braid) texture of the wire material, generated procedurally: plain CPU code, no GL.
#pragma once

#include <cstdint>
#include <vector>

namespace wire::render {

/// Zero means default.
struct WeaveDesc {
    int size_px = 0;         ///< square texture edge; 0 -> 256 (power of two keeps the mip chain exact)
    int strands = 0;         ///< strands per direction across one tile; 0 -> 4
    float strand_width = 0;  ///< fraction of the strand pitch a strand covers, (0, 1]; 0 -> 0.82
};

/// RGBA8 pixels (size_px^2 * 4 bytes) of a plain over/under weave of two families of helical strands along
/// x + y and x - y (x = u along the wire, y = v around it). Tiles seamlessly in x and y and is symmetric
/// under x -> -x and y -> -y (the two families swap). Grey levels (R = G = B, A = 255), so a material's tint
/// colours it.
[[nodiscard]] std::vector<uint8_t> make_weave_rgba(const WeaveDesc& desc = {});

}  // namespace wire::render
