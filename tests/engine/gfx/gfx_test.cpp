// engine/gfx on a real headless GL 4.5 context (Mesa llvmpipe): typed handles, shader errors, buffers,
// textures, debug output, mesh upload, PNG capture round trip.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include <unistd.h>

#include "engine/gfx/debug.hpp"
#include "engine/gfx/lit_renderer.hpp"
#include "engine/gfx/mesh.hpp"
#include "engine/gfx/resources.hpp"
#include "engine/platform/capture.hpp"
#include "engine/platform/context.hpp"

namespace gfx = engine::gfx;
namespace platform = engine::platform;

// A handle of the wrong type does not convert.
static_assert(!std::is_convertible_v<gfx::Buffer, gfx::Texture>);
static_assert(!std::is_constructible_v<gfx::Texture, gfx::Buffer&&>);
static_assert(!std::is_constructible_v<gfx::Program, gfx::VertexArray&&>);
static_assert(!std::is_copy_constructible_v<gfx::Buffer>);
static_assert(std::is_nothrow_move_constructible_v<gfx::Texture>);

namespace {

constexpr const char* kVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
void main() { gl_Position = vec4(a_position, 1.0); }
)";
constexpr const char* kFragment = R"(#version 450 core
out vec4 o_color;
void main() { o_color = vec4(1.0, 0.5, 0.25, 1.0); }
)";

class GfxTest : public ::testing::Test {
protected:
    void SetUp() override {
        auto ctx = platform::create_headless_context({.width = 64, .height = 48, .debug = true});
        // CI has Mesa: a missing context is a failure, not a skip.
        ASSERT_TRUE(ctx.ok()) << ctx.error().message;
        context = std::move(ctx).value();
    }
    std::unique_ptr<platform::Context> context;
};

TEST_F(GfxTest, HeadlessContextIsGl45Core) {
    EXPECT_EQ(context->backend(), platform::Backend::headless);
    EXPECT_NE(context->gl_version().find("4.5"), std::string::npos) << context->gl_version();
    GLint mask = 0;
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &mask);
    EXPECT_TRUE(mask & GL_CONTEXT_CORE_PROFILE_BIT);
    EXPECT_EQ(context->framebuffer_size().width, 64);
    EXPECT_EQ(context->framebuffer_size().height, 48);
    EXPECT_NE(context->framebuffer(), 0u);
}

// The headless backend says which EGL display it chose: a hardware EGL device when there is one, Mesa
// surfaceless otherwise (these machines: no hardware device, llvmpipe).
TEST_F(GfxTest, HeadlessDisplayChoiceIsReported) {
    const std::string chosen = platform::headless_display();
    std::printf("headless display: %s; GL renderer: %s\n", chosen.c_str(), context->gl_renderer().c_str());
    const bool hardware = chosen.rfind("hardware EGL device", 0) == 0;
    const bool surfaceless = chosen.rfind("Mesa surfaceless", 0) == 0;
    EXPECT_TRUE(hardware || surfaceless) << chosen;
    if (hardware) {
        EXPECT_EQ(context->gl_renderer().find("llvmpipe"), std::string::npos);
    }
}

// WIRE_EGL_PLATFORM forces the choice; a bad value is an error naming it. The display is chosen when the first
// context of a process is made, so this runs with no other context alive.
TEST(HeadlessDisplayTest, ChoiceCanBeForced) {
    ::setenv("WIRE_EGL_PLATFORM", "bogus", 1);
    auto bad = platform::create_headless_context({.width = 8, .height = 8, .quiet = true});
    ASSERT_FALSE(bad.ok());
    EXPECT_NE(bad.error().message.find("WIRE_EGL_PLATFORM"), std::string::npos) << bad.error().message;
    ::setenv("WIRE_EGL_PLATFORM", "surfaceless", 1);
    {
        auto ctx = platform::create_headless_context({.width = 8, .height = 8, .quiet = true});
        ::unsetenv("WIRE_EGL_PLATFORM");
        ASSERT_TRUE(ctx.ok()) << ctx.error().message;
        EXPECT_NE(platform::headless_display().find("forced"), std::string::npos) << platform::headless_display();
    }
    ::unsetenv("WIRE_EGL_PLATFORM");
}

TEST_F(GfxTest, BrokenVertexShaderReturnsDriverLog) {
    auto program =
        gfx::make_program({.vertex = "#version 450 core\nvoid main() { gl_Position = undefined_thing; }\n",
                           .fragment = kFragment,
                           .label = "broken"});
    ASSERT_FALSE(program.ok());
    const std::string& message = program.error().message;
    EXPECT_NE(message.find("vertex shader of 'broken' failed to compile"), std::string::npos) << message;
    EXPECT_NE(message.find("undefined_thing"), std::string::npos) << "driver log missing: " << message;
    EXPECT_NE(message.find("error"), std::string::npos) << message;
}

TEST_F(GfxTest, BrokenFragmentShaderReturnsDriverLog) {
    auto program =
        gfx::make_program({.vertex = kVertex,
                           .fragment = "#version 450 core\nout vec4 c;\nvoid main() { c = vec3(1); }\n",
                           .label = "frag"});
    ASSERT_FALSE(program.ok());
    EXPECT_NE(program.error().message.find("fragment shader of 'frag' failed to compile:\n"),
              std::string::npos)
        << program.error().message;
    EXPECT_GT(program.error().message.size(),
              std::string("fragment shader of 'frag' failed to compile:\n").size());
}

TEST_F(GfxTest, LinkErrorReturnsDriverLog) {
    // The fragment stage reads a varying the vertex stage never writes.
    auto program = gfx::make_program({.vertex = kVertex,
                                      .fragment = "#version 450 core\nin vec3 v_missing;\nout vec4 c;\n"
                                                  "void main() { c = vec4(v_missing, 1); }\n",
                                      .label = "unlinked"});
    ASSERT_FALSE(program.ok());
    EXPECT_NE(program.error().message.find("program 'unlinked' failed to link"), std::string::npos)
        << program.error().message;
    EXPECT_NE(program.error().message.find("v_missing"), std::string::npos) << program.error().message;
}

TEST_F(GfxTest, ValidProgramLinks) {
    auto program = gfx::make_program({.vertex = kVertex, .fragment = kFragment, .label = "ok"});
    ASSERT_TRUE(program.ok()) << program.error().message;
    EXPECT_NE(program->id(), 0u);
    EXPECT_EQ(program->uniform_location("no_such_uniform"), -1);
}

TEST_F(GfxTest, BufferHoldsDataAndUpdates) {
    const std::array<float, 4> data{1.0f, 2.0f, 3.0f, 4.0f};
    auto buffer = gfx::make_buffer(std::span<const float>(data), "floats", /*dynamic=*/true);
    ASSERT_TRUE(buffer.ok()) << buffer.error().message;
    EXPECT_EQ(buffer->size_bytes(), sizeof data);
    const std::array<float, 2> patch{7.0f, 8.0f};
    buffer->update(sizeof(float), std::as_bytes(std::span<const float>(patch)));
    std::array<float, 4> back{};
    glGetNamedBufferSubData(buffer->id(), 0, sizeof back, back.data());
    EXPECT_EQ(back, (std::array<float, 4>{1.0f, 7.0f, 8.0f, 4.0f}));
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(GfxTest, EmptyBufferIsAnError) {
    auto buffer = gfx::make_buffer({.label = "nothing"});
    ASSERT_FALSE(buffer.ok());
    EXPECT_EQ(buffer.error().message, "buffer 'nothing': size is zero");
}

TEST_F(GfxTest, MovedHandleOwnsNameOnce) {
    auto made = gfx::make_buffer({.size_bytes = 64});
    ASSERT_TRUE(made.ok());
    gfx::Buffer a = std::move(made).value();
    const unsigned id = a.id();
    gfx::Buffer b = std::move(a);
    EXPECT_EQ(a.id(), 0u);  // NOLINT(bugprone-use-after-move): moved-from handles are empty by contract
    EXPECT_EQ(b.id(), id);
    EXPECT_TRUE(glIsBuffer(id));
    b = gfx::Buffer{};
    EXPECT_FALSE(glIsBuffer(id));
}

TEST_F(GfxTest, TextureFromRgbaReadsBack) {
    std::vector<std::uint8_t> pixels(4 * 3 * 4);
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(i * 5);
    auto texture = gfx::make_texture({.width = 4, .height = 3, .rgba = pixels, .label = "ramp"});
    ASSERT_TRUE(texture.ok()) << texture.error().message;
    EXPECT_EQ(texture->width(), 4);
    EXPECT_EQ(texture->height(), 3);
    EXPECT_EQ(texture->read_rgba(), pixels);
}

TEST_F(GfxTest, TextureWithWrongPixelCountIsAnError) {
    std::vector<std::uint8_t> pixels(10);
    auto texture = gfx::make_texture({.width = 4, .height = 4, .rgba = pixels, .label = "short"});
    ASSERT_FALSE(texture.ok());
    EXPECT_EQ(texture.error().message, "texture 'short': 10 bytes of pixels, expected 64 (RGBA8)");
}

TEST_F(GfxTest, DebugOutputReachesSink) {
    std::vector<gfx::DebugMessage> messages;
    gfx::enable_debug_output({.min_severity = gfx::DebugSeverity::notification,
                              .sink = [&](const gfx::DebugMessage& m) { messages.push_back(m); }});
    glDebugMessageInsert(GL_DEBUG_SOURCE_APPLICATION, GL_DEBUG_TYPE_MARKER, 42, GL_DEBUG_SEVERITY_HIGH, -1,
                         "hello gl");
    glBindBuffer(GL_ARRAY_BUFFER,
                 123456);  // not a name from glCreate/GenBuffers in core profile: an API error
    gfx::disable_debug_output();
    ASSERT_FALSE(messages.empty());
    EXPECT_EQ(messages[0].text, "hello gl");
    EXPECT_EQ(messages[0].id, 42u);
    EXPECT_EQ(messages[0].source, "application");
    EXPECT_EQ(messages[0].severity, gfx::DebugSeverity::high);
    bool saw_error = false;
    for (const auto& m : messages) saw_error = saw_error || m.type == "error";
    EXPECT_TRUE(saw_error) << "no API error message for glBindBuffer(unknown name)";
    while (glGetError() != GL_NO_ERROR) {
    }
}

TEST(MeshTest, CylinderCountsAndNormals) {
    const gfx::PrimitiveMesh m = gfx::make_cylinder_mesh({.radius_m = 2.0f, .half_height_m = 1.0f, .sides = 8});
    EXPECT_EQ(m.vertices.size(), 2u * 9u + 2u * 9u);
    EXPECT_EQ(m.indices.size(), 8u * 6u + 2u * 8u * 3u);
    for (const gfx::Vertex& v : m.vertices) {
        EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-6f);
        EXPECT_LE(std::abs(v.position.y), 1.0f + 1e-6f);
        EXPECT_LE(glm::length(glm::vec2(v.position.x, v.position.z)), 2.0f + 1e-5f);
    }
    // Every triangle faces outward: its geometric normal agrees with its vertex normals.
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const gfx::Vertex& a = m.vertices[m.indices[t]];
        const gfx::Vertex& b = m.vertices[m.indices[t + 1]];
        const gfx::Vertex& c = m.vertices[m.indices[t + 2]];
        const glm::vec3 n = glm::cross(b.position - a.position, c.position - a.position);
        EXPECT_GT(glm::dot(n, a.normal + b.normal + c.normal), 0.0f) << "triangle " << t / 3;
    }
}

TEST(MeshTest, BoxAndSphereFaceOutward) {
    for (const gfx::PrimitiveMesh& m : {gfx::make_box_mesh(glm::vec3(1, 2, 3)), gfx::make_sphere_mesh(1.0f, 12, 6),
                                   gfx::make_plane_mesh(2.0f)}) {
        for (std::size_t t = 0; t < m.indices.size(); t += 3) {
            const gfx::Vertex& a = m.vertices[m.indices[t]];
            const gfx::Vertex& b = m.vertices[m.indices[t + 1]];
            const gfx::Vertex& c = m.vertices[m.indices[t + 2]];
            const glm::vec3 n = glm::cross(b.position - a.position, c.position - a.position);
            if (glm::length(n) < 1e-7f) continue;  // degenerate pole triangles of the UV sphere
            EXPECT_GT(glm::dot(n, a.normal + b.normal + c.normal), 0.0f) << "triangle " << t / 3;
        }
    }
}

TEST_F(GfxTest, UploadedMeshDraws) {
    auto renderer = gfx::LitRenderer::create();
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    auto mesh = gfx::upload_mesh(gfx::make_box_mesh(glm::vec3(0.5f)), "box");
    ASSERT_TRUE(mesh.ok()) << mesh.error().message;
    context->begin_frame();
    gfx::clear({0, 0, 0, 1});
    renderer->begin(glm::mat4(1.0f), {.to_light = {0, 0, 1}, .ambient = 0.0f});
    renderer->draw(*mesh, glm::mat4(1.0f), glm::vec3(1.0f, 0.0f, 0.0f));
    context->end_frame();
    const platform::Image image = platform::read_pixels(*context);
    // The front face (z = +0.5 faces +z, toward the light) covers the middle half of the framebuffer.
    const std::uint8_t* center = image.pixel(32, 24);
    EXPECT_EQ(center[0], 255);
    EXPECT_EQ(center[1], 0);
    const std::uint8_t* corner = image.pixel(2, 2);
    EXPECT_EQ(corner[0], 0);
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST_F(GfxTest, PngCaptureRoundTrip) {
    context->begin_frame();
    gfx::clear({0.0f, 0.0f, 1.0f, 1.0f});
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, 16, 8);  // GL origin is bottom-left: this marks the bottom-left corner of the image
    gfx::clear({1.0f, 0.0f, 0.0f, 1.0f});
    glDisable(GL_SCISSOR_TEST);
    context->end_frame();

    const platform::Image image = platform::read_pixels(*context);
    ASSERT_EQ(image.width, 64);
    ASSERT_EQ(image.height, 48);
    EXPECT_EQ(image.pixel(0, 47)[0], 255);  // bottom-left is red after the row flip
    EXPECT_EQ(image.pixel(0, 0)[2], 255);   // top-left is blue

    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("gfx_test_" + std::to_string(::getpid())) / "capture.png";
    const engine::Status written = platform::capture_png(*context, path);
    ASSERT_TRUE(written.ok()) << written.message;
    auto read = platform::read_png(path);
    ASSERT_TRUE(read.ok()) << read.error().message;
    EXPECT_EQ(read->width, image.width);
    EXPECT_EQ(read->height, image.height);
    EXPECT_EQ(read->rgba, image.rgba);
    std::filesystem::remove_all(path.parent_path());
}

TEST(PngTest, MissingFileIsAnError) {
    auto read = platform::read_png("/nonexistent/dir/none.png");
    ASSERT_FALSE(read.ok());
    EXPECT_NE(read.error().message.find("/nonexistent/dir/none.png"), std::string::npos);
}

TEST(PlatformTest, WindowWithoutDisplayIsAnErrorNotACrash) {
    if (platform::display_available()) GTEST_SKIP() << "a display is available here";
    auto ctx = platform::create_window_context({.width = 32, .height = 32});
    ASSERT_FALSE(ctx.ok());
    EXPECT_NE(ctx.error().message.find("no display"), std::string::npos) << ctx.error().message;
}

TEST(PlatformTest, AutomaticFallsBackToHeadlessWithoutDisplay) {
    if (platform::display_available()) GTEST_SKIP() << "a display is available here";
    auto ctx = platform::create_context({.width = 32, .height = 16, .quiet = true});
    ASSERT_TRUE(ctx.ok()) << ctx.error().message;
    EXPECT_TRUE((*ctx)->headless());
    EXPECT_EQ((*ctx)->framebuffer_size().width, 32);
}

TEST(PlatformTest, HeadlessResizeCallsBackAndReallocates) {
    auto ctx = platform::create_headless_context({.width = 16, .height = 16});
    ASSERT_TRUE(ctx.ok()) << ctx.error().message;
    int seen_w = 0;
    int seen_h = 0;
    (*ctx)->set_resize_callback([&](int w, int h) {
        seen_w = w;
        seen_h = h;
    });
    (*ctx)->resize(40, 20);
    EXPECT_EQ(seen_w, 40);
    EXPECT_EQ(seen_h, 20);
    (*ctx)->begin_frame();
    gfx::clear({0, 1, 0, 1});
    const platform::Image image = platform::read_pixels(**ctx);
    EXPECT_EQ(image.width, 40);
    EXPECT_EQ(image.pixel(39, 19)[1], 255);
}

}  // namespace
