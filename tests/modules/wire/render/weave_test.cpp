// wire::render::make_weave_rgba: plain CPU, no GL.
#include <gtest/gtest.h>

#include <cstdint>

#include "wire/render/weave.hpp"

namespace {

TEST(WeaveTest, SizeGreyOpaqueAndTiles) {
    const int n = 64;
    const std::vector<uint8_t> rgba = wire::render::make_weave_rgba({.size_px = n});
    ASSERT_EQ(rgba.size(), static_cast<std::size_t>(n * n * 4));
    int min = 255, max = 0;
    for (std::size_t i = 0; i < rgba.size(); i += 4) {
        EXPECT_EQ(rgba[i], rgba[i + 1]);
        EXPECT_EQ(rgba[i], rgba[i + 2]);
        EXPECT_EQ(rgba[i + 3], 255);
        min = std::min<int>(min, rgba[i]);
        max = std::max<int>(max, rgba[i]);
    }
    EXPECT_LT(min, 80);   // gaps are dark
    EXPECT_GT(max, 240);  // strand crowns are bright
    auto at = [&](int x, int y) {
        return rgba[(static_cast<std::size_t>((y + n) % n) * n + (x + n) % n) * 4];
    };
    // Symmetric under the mirror x -> -x, y -> -y (pixel centres: x -> n-1-x) and under the swap (x, y) ->
    // (y, x) combined with a shift, so the pattern has no preferred direction around the wire.
    for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
            ASSERT_EQ(at(x, y), at(n - 1 - x, n - 1 - y)) << x << "," << y;
        }
    }
}

}  // namespace
