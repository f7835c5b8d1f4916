// Framebuffer read-back and PNG files (stb_image_write / stb_image from Debian's libstb).
#include "engine/platform/capture.hpp"

#include <epoxy/gl.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <cstring>
#include <system_error>

namespace engine::platform {

Image read_framebuffer(unsigned fbo, int width, int height) {
    Image image;
    image.width = width;
    image.height = height;
    const std::size_t row = static_cast<std::size_t>(width) * 4;
    std::vector<std::uint8_t> gl_rows(row * static_cast<std::size_t>(height));
    GLint previous = 0;
    glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &previous);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
    if (fbo == 0) glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, gl_rows.data());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, static_cast<GLuint>(previous));
    // GL's first row is the bottom one.
    image.rgba.resize(gl_rows.size());
    for (int y = 0; y < height; ++y) {
        std::memcpy(image.rgba.data() + static_cast<std::size_t>(y) * row,
                    gl_rows.data() + static_cast<std::size_t>(height - 1 - y) * row, row);
    }
    return image;
}

Image read_pixels(const Context& ctx) {
    const Extent e = ctx.framebuffer_size();
    return read_framebuffer(ctx.framebuffer(), e.width, e.height);
}

Status write_png(const std::filesystem::path& path, const Image& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgba.size() !=
            static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 4) {
        return Error{"write_png: " + path.string() +
                     ": image is empty or its size does not match its pixels"};
    }
    if (path.has_parent_path()) {
        std::error_code ec;
        std::filesystem::create_directories(path.parent_path(), ec);
        if (ec)
            return Error{"write_png: cannot create directory " + path.parent_path().string() + ": " +
                         ec.message()};
    }
    if (stbi_write_png(path.string().c_str(), image.width, image.height, 4, image.rgba.data(),
                       image.width * 4) == 0) {
        return Error{"write_png: cannot write " + path.string()};
    }
    return {};
}

Expected<Image> read_png(const std::filesystem::path& path) {
    int w = 0;
    int h = 0;
    int channels = 0;
    stbi_uc* data = stbi_load(path.string().c_str(), &w, &h, &channels, 4);
    if (data == nullptr) {
        const char* reason = stbi_failure_reason();
        return Error{"read_png: " + path.string() + ": " + (reason != nullptr ? reason : "unknown error")};
    }
    Image image;
    image.width = w;
    image.height = h;
    image.rgba.assign(data, data + static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
    stbi_image_free(data);
    return image;
}

Status capture_png(const Context& ctx, const std::filesystem::path& path) {
    return write_png(path, read_pixels(ctx));
}

}  // namespace engine::platform
