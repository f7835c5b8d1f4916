// CPU/GPU agreement of the curved-space bend: glsl_bend_source() run on llvmpipe (headless EGL) in a vertex
// shader with transform feedback and in a compute shader, compared with Chain::transform in double.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "curved_space/chain.hpp"
#include "curved_space/gpu.hpp"
#include "engine/platform/context.hpp"

namespace {

using curved_space::Chain;
using curved_space::Segment;
using glm::dvec3;

std::unique_ptr<engine::platform::Context> make_context() {
    auto context = engine::platform::create_headless_context(
        {.backend = engine::platform::Backend::headless, .width = 16, .height = 16, .quiet = true});
    // No skipping: a missing context is a failure of the environment this test exists to check.
    EXPECT_TRUE(context.ok()) << "headless GL context: " << context.error().message;
    if (!context.ok()) return nullptr;
    return std::move(context).value();
}

std::string compile_errors(GLuint shader) {
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok) return {};
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetShaderInfoLog(shader, length, nullptr, log.data());
    return log;
}

std::string link_errors(GLuint program) {
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (ok) return {};
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(std::max(length, 1)), '\0');
    glGetProgramInfoLog(program, length, nullptr, log.data());
    return log;
}

// One shader stage into a program; varyings (transform feedback, interleaved) set before linking.
GLuint build_program(GLenum stage, const std::string& source, const std::vector<const char*>& varyings) {
    const GLuint shader = glCreateShader(stage);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    const std::string compile_log = compile_errors(shader);
    EXPECT_TRUE(compile_log.empty()) << compile_log;
    const GLuint program = glCreateProgram();
    glAttachShader(program, shader);
    if (!varyings.empty())
        glTransformFeedbackVaryings(program, static_cast<GLsizei>(varyings.size()), varyings.data(),
                                    GL_INTERLEAVED_ATTRIBS);
    glLinkProgram(program);
    glDeleteShader(shader);
    const std::string link_log = link_errors(program);
    EXPECT_TRUE(link_log.empty()) << link_log;
    return program;
}

// A chain 1e6 m from the origin (the camera near it), turning several ways, and random unbent vertices
// before, along and after it. |x|, |y| <= 0.5 keeps 1 - kappa x >= 0.05 (no folding: the normal there
// is ill-conditioned in float).
struct Scene {
    Chain chain;
    dvec3 camera{0.0};
    std::vector<glm::vec4> vertices;  // position, normal interleaved (w unused)
};

Scene make_scene(std::size_t count) {
    Scene scene;
    glm::dmat4 world_from_chain(1.0);
    world_from_chain[3] = glm::dvec4(1e6, -2e6, 5e5, 1.0);
    const std::vector<Segment> segments{{4.0, 0.5, 0.0},  {2.0, -1.2, 0.3}, {3.0, 0.0, 1.0},
                                        {1.5, 2.0, 1.57}, {5.0, 0.8, -2.0}, {2.5, 1.0, 2.5}};
    const engine::Status status = curved_space::make_chain(segments, scene.chain, world_from_chain);
    EXPECT_TRUE(status.ok()) << status.message;
    scene.camera = scene.chain.transform_point({0.3, 0.0, 6.0}) + dvec3(2.0, 1.0, -1.5);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double total = scene.chain.total_length_m();
    for (std::size_t k = 0; k < count; ++k) {
        const glm::vec4 p(0.5 * u(rng), 0.5 * u(rng), -3.0 + (total + 6.0) * unit(rng), 1.0);
        const glm::vec4 n(glm::normalize(glm::vec3(u(rng), u(rng), u(rng))), 0.0f);
        scene.vertices.push_back(p);
        scene.vertices.push_back(n);
    }
    // Exactly on every segment boundary, and at the ends.
    for (std::size_t i = 0; i <= scene.chain.segment_count(); ++i) {
        scene.vertices.emplace_back(0.2f, -0.1f, static_cast<float>(scene.chain.z_start_m(i)), 1.0f);
        scene.vertices.emplace_back(0.0f, 0.6f, 0.8f, 0.0f);
    }
    return scene;
}

// Compares GPU output (position xyz + folded flag, normal xyz) with the CPU reference.
void compare(const Scene& scene, const std::vector<glm::vec4>& gpu, const char* path) {
    ASSERT_EQ(gpu.size(), scene.vertices.size());
    double worst_position = 0.0;
    double worst_normal = 0.0;
    for (std::size_t v = 0; v < scene.vertices.size() / 2; ++v) {
        const dvec3 p(scene.vertices[2 * v]);
        const dvec3 n(scene.vertices[2 * v + 1]);
        const curved_space::BentVertex ref = scene.chain.transform(p, n);
        const dvec3 expected = ref.position - scene.camera;  // camera-relative, in double
        const dvec3 got(gpu[2 * v]);
        // Relative to the camera distance, at least 1 m (float vertex input limits absolute precision).
        const double position_error = glm::length(got - expected) / std::max(glm::length(expected), 1.0);
        const double normal_error = glm::length(dvec3(gpu[2 * v + 1]) - ref.normal);
        worst_position = std::max(worst_position, position_error);
        worst_normal = std::max(worst_normal, normal_error);
        EXPECT_LT(position_error, 1e-4) << path << " vertex " << v;
        EXPECT_LT(normal_error, 1e-4) << path << " vertex " << v;
        EXPECT_EQ(gpu[2 * v].w != 0.0f, ref.folded) << path << " vertex " << v;
    }
    std::printf("[ measure  ] %s: %zu vertices, max relative position difference %.3g, max normal difference %.3g\n",
                path, scene.vertices.size() / 2, worst_position, worst_normal);
}

GLuint make_segment_buffer(const Scene& scene) {
    const std::vector<curved_space::GpuSegment> records = curved_space::gpu_segments(scene.chain, scene.camera);
    GLuint buffer = 0;
    glCreateBuffers(1, &buffer);
    glNamedBufferStorage(buffer, static_cast<GLsizeiptr>(records.size() * sizeof(curved_space::GpuSegment)),
                         records.data(), 0);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, curved_space::segment_buffer_binding, buffer);
    return buffer;
}

TEST(CurvedSpaceGpu, VertexShaderMatchesCpuReference) {
    const auto context = make_context();
    ASSERT_TRUE(context);
    std::printf("[ info     ] %s / %s\n", context->gl_version().c_str(), context->gl_renderer().c_str());
    GLint vertex_storage_blocks = 0;
    glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &vertex_storage_blocks);
    ASSERT_GE(vertex_storage_blocks, 1) << "the driver has no shader storage blocks in vertex shaders";

    const Scene scene = make_scene(4000);
    const std::string source = "#version 450 core\n" + std::string(curved_space::glsl_bend_source()) + R"glsl(
layout(location = 0) in vec4 in_position;
layout(location = 1) in vec4 in_normal;
out vec4 out_position;  // xyz, w = folded
out vec4 out_normal;
void main() {
    vec3 p;
    vec3 n;
    bool folded;
    cs_bend(in_position.xyz, in_normal.xyz, p, n, folded);
    out_position = vec4(p, folded ? 1.0 : 0.0);
    out_normal = vec4(n, 0.0);
    gl_Position = vec4(0.0, 0.0, 0.0, 1.0);
}
)glsl";
    const GLuint program = build_program(GL_VERTEX_SHADER, source, {"out_position", "out_normal"});
    const GLuint segments = make_segment_buffer(scene);

    const auto bytes = static_cast<GLsizeiptr>(scene.vertices.size() * sizeof(glm::vec4));
    GLuint input = 0;
    GLuint output = 0;
    glCreateBuffers(1, &input);
    glCreateBuffers(1, &output);
    glNamedBufferStorage(input, bytes, scene.vertices.data(), 0);
    glNamedBufferStorage(output, bytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
    GLuint vao = 0;
    glCreateVertexArrays(1, &vao);
    glVertexArrayVertexBuffer(vao, 0, input, 0, 2 * sizeof(glm::vec4));
    for (GLuint location : {0u, 1u}) {
        glEnableVertexArrayAttrib(vao, location);
        glVertexArrayAttribFormat(vao, location, 4, GL_FLOAT, GL_FALSE, location * sizeof(glm::vec4));
        glVertexArrayAttribBinding(vao, location, 0);
    }

    glUseProgram(program);
    glBindVertexArray(vao);
    glBindBufferBase(GL_TRANSFORM_FEEDBACK_BUFFER, 0, output);
    glEnable(GL_RASTERIZER_DISCARD);
    glBeginTransformFeedback(GL_POINTS);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(scene.vertices.size() / 2));
    glEndTransformFeedback();
    glDisable(GL_RASTERIZER_DISCARD);
    std::vector<glm::vec4> result(scene.vertices.size());
    glGetNamedBufferSubData(output, 0, bytes, result.data());
    ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    compare(scene, result, "vertex shader + transform feedback");

    glDeleteVertexArrays(1, &vao);
    for (GLuint b : {input, output, segments}) glDeleteBuffers(1, &b);
    glDeleteProgram(program);
}

TEST(CurvedSpaceGpu, ComputeShaderMatchesCpuReference) {
    const auto context = make_context();
    ASSERT_TRUE(context);
    const Scene scene = make_scene(3000);
    const std::string source = "#version 450 core\n" + std::string(curved_space::glsl_bend_source()) + R"glsl(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Inputs { vec4 inputs[]; };
layout(std430, binding = 1) writeonly buffer Outputs { vec4 outputs[]; };
void main() {
    uint v = gl_GlobalInvocationID.x;
    if (2u * v >= uint(inputs.length())) return;
    vec3 p;
    vec3 n;
    bool folded;
    cs_bend(inputs[2u * v].xyz, inputs[2u * v + 1u].xyz, p, n, folded);
    outputs[2u * v] = vec4(p, folded ? 1.0 : 0.0);
    outputs[2u * v + 1u] = vec4(n, 0.0);
}
)glsl";
    const GLuint program = build_program(GL_COMPUTE_SHADER, source, {});
    const GLuint segments = make_segment_buffer(scene);
    const auto bytes = static_cast<GLsizeiptr>(scene.vertices.size() * sizeof(glm::vec4));
    GLuint input = 0;
    GLuint output = 0;
    glCreateBuffers(1, &input);
    glCreateBuffers(1, &output);
    glNamedBufferStorage(input, bytes, scene.vertices.data(), 0);
    glNamedBufferStorage(output, bytes, nullptr, GL_DYNAMIC_STORAGE_BIT);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, input);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, output);
    glUseProgram(program);
    const auto vertices = static_cast<GLuint>(scene.vertices.size() / 2);
    glDispatchCompute((vertices + 63) / 64, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    std::vector<glm::vec4> result(scene.vertices.size());
    glGetNamedBufferSubData(output, 0, bytes, result.data());
    ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    compare(scene, result, "compute shader");
    for (GLuint b : {input, output, segments}) glDeleteBuffers(1, &b);
    glDeleteProgram(program);
}

}  // namespace
