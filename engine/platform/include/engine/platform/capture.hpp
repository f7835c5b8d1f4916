// Frame capture: read back the framebuffer a Context renders into, write and read PNG files.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "engine/platform/context.hpp"
#include "engine/core/expected.hpp"

namespace engine::platform {

/// RGBA8 pixels, rows top to bottom (image order, not GL order).
struct Image {
    int width = 0;                   ///< pixels
    int height = 0;                  ///< pixels
    std::vector<std::uint8_t> rgba;  ///< width * height * 4 bytes

    /// The 4 bytes (R, G, B, A) of pixel (x, y), y = 0 the top row. No bounds check.
    const std::uint8_t* pixel(int x, int y) const {
        return rgba.data() + (static_cast<std::size_t>(y) * width + x) * 4;
    }
};

/// Reads the whole framebuffer of the current frame of ctx (call after drawing, before or after end_frame()
/// headless; before end_frame() for a window, whose back buffer is undefined after a swap).
Image read_pixels(const Context& ctx);
/// Reads a rectangle of the currently bound read framebuffer `fbo` (GL name, 0 = default) into an Image.
Image read_framebuffer(unsigned fbo, int width, int height);

/// Writes an RGBA8 PNG; creates missing parent directories. Errors name the path.
Status write_png(const std::filesystem::path& path, const Image& image);
/// Reads any PNG into RGBA8.
Expected<Image> read_png(const std::filesystem::path& path);
/// read_pixels + write_png.
Status capture_png(const Context& ctx, const std::filesystem::path& path);

}  // namespace engine::platform
