// engine/gfx draw calls and pipeline state on a headless llvmpipe context: instanced draws with a uniform
// array and a storage-buffer range, back-face culling, wireframe and its reset.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "engine/gfx/draw.hpp"
#include "engine/gfx/lit_renderer.hpp"
#include "engine/gfx/resources.hpp"
#include "engine/platform/capture.hpp"
#include "engine/platform/context.hpp"

namespace gfx = engine::gfx;
namespace platform = engine::platform;

namespace {

// Instance i: the quad moved by u_x[i] along x, coloured colors[i] (the bound storage range).
constexpr const char* kVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
uniform float u_x[4];
flat out int v_instance;
void main() {
    v_instance = gl_InstanceID;
    gl_Position = vec4(a_position.x + u_x[gl_InstanceID], a_position.yz, 1.0);
}
)";
constexpr const char* kFragment = R"(#version 450 core
layout(std430, binding = 5) readonly buffer Colors { vec4 colors[]; };
flat in int v_instance;
out vec4 o_color;
void main() { o_color = v_instance < colors.length() ? colors[v_instance] : vec4(1.0); }
)";

struct Quad {
    gfx::Buffer vertices;
    gfx::Buffer indices;
    gfx::VertexArray vao;
};

// The square [-h, h]^2 at z = 0, counter-clockwise seen from +z (front) unless `clockwise`.
Quad make_quad(float h, bool clockwise) {
    const std::array<float, 12> p{-h, -h, 0, h, -h, 0, h, h, 0, -h, h, 0};
    const std::array<std::uint32_t, 6> ccw{0, 1, 2, 0, 2, 3}, cw{0, 2, 1, 0, 3, 2};
    Quad q;
    q.vertices = gfx::make_buffer(std::span<const float>(p), "quad").value();
    q.indices = gfx::make_buffer(std::span<const std::uint32_t>(clockwise ? cw : ccw), "quad").value();
    q.vao = gfx::make_vertex_array({.vertex_buffer = &q.vertices,
                                    .stride_bytes = 12,
                                    .attributes = {{.location = 0, .components = 3}},
                                    .index_buffer = &q.indices,
                                    .label = "quad"});
    return q;
}

class DrawTest : public ::testing::Test {
protected:
    void SetUp() override {
        auto ctx = platform::create_headless_context({.width = 64, .height = 48, .debug = true});
        ASSERT_TRUE(ctx.ok()) << ctx.error().message;
        context = std::move(ctx).value();
        auto p = gfx::make_program({.vertex = kVertex, .fragment = kFragment, .label = "draw test"});
        ASSERT_TRUE(p.ok()) << p.error().message;
        program = std::move(p).value();
        // Grey padding of one alignment, then red, green, blue; the bound range holds red and green only.
        GLint align = 0;
        glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &align);
        offset_bytes = static_cast<std::size_t>(std::max(align, 16));
        std::vector<float> data(offset_bytes / sizeof(float), 0.5f);
        for (float c : {1.0f, 0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f})
            data.push_back(c);
        colors = gfx::make_buffer(std::span<const float>(data), "colors").value();
    }

    // Clears to black, sets the program and state, draws `instances` instances of `quad` at x offsets
    // (-0.5, 0.5, 0, 0) with colours (red, green): then the pixels.
    platform::Image draw(const Quad& quad, std::size_t instances, bool wireframe) {
        context->begin_frame();
        gfx::clear({0.0f, 0.0f, 0.0f, 1.0f});
        gfx::set_opaque_state();
        gfx::set_wireframe(wireframe);
        gfx::bind_storage_range(5, colors, offset_bytes, 8 * sizeof(float));
        program.use();
        const std::array<float, 4> x{-0.5f, 0.5f, 0.0f, 0.0f};
        program.set(program.uniform_location("u_x"), std::span<const float>(x));
        gfx::draw_instanced(quad.vao, 6, instances);
        gfx::set_wireframe(false);
        gfx::unbind_vertex_array();
        context->end_frame();
        return platform::read_pixels(*context);
    }

    std::unique_ptr<platform::Context> context;
    gfx::Program program;
    gfx::Buffer colors;
    std::size_t offset_bytes = 0;
};

::testing::AssertionResult is(const std::uint8_t* px, int r, int g, int b) {
    if (px[0] == r && px[1] == g && px[2] == b) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "pixel (" << int{px[0]} << ", " << int{px[1]} << ", " << int{px[2]} << "), expected (" << r
           << ", " << g << ", " << b << ")";
}

}  // namespace

TEST_F(DrawTest, InstancesTakeTheirUniformArrayEntryAndStorageRange) {
    const Quad quad = make_quad(0.2f, false);
    const platform::Image image = draw(quad, 2, false);
    EXPECT_TRUE(is(image.pixel(16, 24), 255, 0, 0)) << "instance 0: x - 0.5, colors[0] of the range (red)";
    EXPECT_TRUE(is(image.pixel(48, 24), 0, 255, 0)) << "instance 1: x + 0.5, colors[1] of the range (green)";
    EXPECT_TRUE(is(image.pixel(32, 24), 0, 0, 0)) << "no third instance at x + 0";
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(DrawTest, InstanceCountIsHonoured) {
    const Quad quad = make_quad(0.2f, false);
    const platform::Image image = draw(quad, 3, false);
    // The third instance lies beyond the two bound colours (blue is outside the range): white.
    EXPECT_TRUE(is(image.pixel(32, 24), 255, 255, 255));
    EXPECT_TRUE(is(image.pixel(16, 24), 255, 0, 0));
}

TEST_F(DrawTest, OpaqueStateCullsBackFaces) {
    const Quad quad = make_quad(0.2f, true);
    const platform::Image image = draw(quad, 2, false);
    EXPECT_TRUE(is(image.pixel(16, 24), 0, 0, 0));
    EXPECT_TRUE(is(image.pixel(48, 24), 0, 0, 0));
}

TEST_F(DrawTest, WireframeDrawsOutlinesAndResets) {
    const Quad quad = make_quad(0.2f, false);
    const platform::Image lines = draw(quad, 1, true);
    EXPECT_TRUE(is(lines.pixel(16, 24), 0, 0, 0)) << "inside the outline stays clear";
    int red = 0;
    for (int y = 0; y < lines.height; ++y)
        for (int x = 0; x < lines.width; ++x) red += lines.pixel(x, y)[0] == 255 ? 1 : 0;
    EXPECT_GT(red, 10) << "the outline is drawn";
    EXPECT_LT(red, 100) << "only the outline is drawn";
    // set_wireframe(false) at the end of draw(): filled again.
    const platform::Image filled = draw(quad, 1, false);
    EXPECT_TRUE(is(filled.pixel(16, 24), 255, 0, 0));
}
