// Procedural weave texture: two strand families, over/under on a checkerboard of crossings.
#include "wire/render/weave.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace wire::render {

std::vector<uint8_t> make_weave_rgba(const WeaveDesc& desc) {
    const int size = desc.size_px > 0 ? desc.size_px : 256;
    const int strands = desc.strands > 0 ? desc.strands : 4;
    const double width = desc.strand_width > 0.0f ? std::min(1.0, double{desc.strand_width}) : 0.82;
    std::vector<uint8_t> rgba(static_cast<std::size_t>(size) * size * 4);

    // Brightness across one strand (f in [0, 1) of the pitch): a rounded profile, 0 in the gap between
    // strands.
    auto profile = [width](double f) {
        const double d = std::abs(2.0 * f - 1.0) / width;  // 0 on the strand's centre line, 1 at its edge
        return d >= 1.0 ? 0.0 : std::sqrt(1.0 - d * d);
    };
    auto weave = [&](double x, double y) {
        const double a = (x + y) * strands;
        const double b = (x - y) * strands + strands;  // keep it positive for floor()
        const double ia = std::floor(a);
        const double ib = std::floor(b);
        const double pa = profile(a - ia);
        const double pb = profile(b - ib);
        // Which family is on top alternates from crossing to crossing (plain weave).
        const bool a_on_top = (static_cast<long>(ia + ib) & 1) == 0;
        const double top = a_on_top ? pa : pb;
        const double under = a_on_top ? pb : pa;
        if (top > 0.0) return 0.45 + 0.55 * top;
        if (under > 0.0) return 0.25 + 0.35 * under;  // the lower strand seen through the gap, in shadow
        return 0.18;
    };
    for (int py = 0; py < size; ++py) {
        for (int px = 0; px < size; ++px) {
            // Pixel centres; averaging with the point mirror (x, y) -> (1 - x, 1 - y) makes the pixels
            // exactly symmetric even where a strand edge falls on a pixel centre (floor() is not symmetric
            // there).
            const double x = (px + 0.5) / size;
            const double y = (py + 0.5) / size;
            const double value = 0.5 * (weave(x, y) + weave(1.0 - x, 1.0 - y));
            const auto level = static_cast<uint8_t>(std::lround(std::clamp(value, 0.0, 1.0) * 255.0));
            uint8_t* p = rgba.data() + (static_cast<std::size_t>(py) * size + px) * 4;
            p[0] = level;
            p[1] = level;
            p[2] = level;
            p[3] = 255;
        }
    }
    return rgba;
}

}  // namespace wire::render
