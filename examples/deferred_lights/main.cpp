// deferred_lights: a few hanging cables drawn into a G-buffer by the wire renderer (Output::gbuffer: world normal,
// albedo, roughness; depth) and lit in a second, full-screen pass by several coloured point lights that reads the
// G-buffer and rebuilds each pixel's position from the depth, the way an engine's deferred renderer lights them.
//
//   build/bin/deferred_lights --out deferred.png [--lights 6] [--size 960x540]
#include <engine/gfx/lit_renderer.hpp>
#include <engine/gfx/resources.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <engine/scene/camera.hpp>
#include <wire/draw.hpp>
#include <wire/nodes.hpp>
#include <wire/render/wire_renderer.hpp>

#include <CLI/CLI.hpp>
#include <epoxy/gl.h>
#include <glm/gtc/matrix_inverse.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

namespace {

constexpr const char* kFullScreen = R"(#version 450 core
out vec2 v_uv;
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  v_uv = p;
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

// The lights' pass: position from depth (eye-relative), the wire renderer's normal and albedo, Blinn-Phong per light
// with the G-buffer's roughness, inverse-square falloff.
constexpr const char* kLighting = R"(#version 450 core
in vec2 v_uv;
layout(binding = 0) uniform sampler2D g_normal;
layout(binding = 1) uniform sampler2D g_albedo;
layout(binding = 2) uniform sampler2D g_material;
layout(binding = 3) uniform sampler2D g_depth;
uniform mat4 u_rel_from_clip;  // inverse of the camera's clip_from_relative()
uniform int u_lights;
uniform vec3 u_light_rel[16];
uniform vec3 u_light_color[16];
out vec4 o_color;
void main() {
  float depth = texture(g_depth, v_uv).r;
  if (depth >= 1.0) { o_color = vec4(0.02, 0.02, 0.03, 1.0); return; }
  vec4 p = u_rel_from_clip * vec4(v_uv * 2.0 - 1.0, depth * 2.0 - 1.0, 1.0);
  vec3 rel = p.xyz / p.w;
  vec3 n = normalize(texture(g_normal, v_uv).xyz * 2.0 - 1.0);
  vec3 albedo = texture(g_albedo, v_uv).rgb;
  float roughness = texture(g_material, v_uv).r;
  float shininess = mix(128.0, 4.0, roughness);
  vec3 to_eye = normalize(-rel);
  vec3 c = 0.04 * albedo;
  for (int i = 0; i < u_lights; ++i) {
    vec3 to_light = u_light_rel[i] - rel;
    float d2 = dot(to_light, to_light);
    vec3 l = to_light * inversesqrt(d2);
    float diffuse = max(dot(n, l), 0.0);
    float spec = diffuse > 0.0 ? pow(max(dot(n, normalize(l + to_eye)), 0.0), shininess) * (1.0 - roughness) : 0.0;
    c += (albedo * diffuse + spec) * u_light_color[i] / (1.0 + d2);
  }
  o_color = vec4(c, 1.0);
}
)";

/// A cable hanging between (x0, 1, z) and (x1, 1.2, z), sagging `sag` metres.
wire::WireNodes hanging(double x0, double x1, double z, double sag) {
    wire::WireNodes nodes;
    for (int i = 0; i <= 16; ++i) {
        const double t = i / 16.0;
        nodes.positions.push_back({x0 + (x1 - x0) * t, 1.0 + 0.2 * t - 4.0 * sag * t * (1.0 - t), z});
    }
    return nodes;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"deferred_lights: wires in a G-buffer lit by several point lights in a deferred pass (writes a PNG)"};
    std::string out = "deferred.png";
    int lights = 6, width = 960, height = 540;
    app.add_option("--out", out, "PNG to write (default deferred.png)");
    app.add_option("--lights", lights, "point lights, 1 .. 16 (default 6)")->check(CLI::Range(1, 16));
    app.add_option("--width", width, "image width (default 960)")->check(CLI::Range(16, 8192));
    app.add_option("--height", height, "image height (default 540)")->check(CLI::Range(16, 8192));
    CLI11_PARSE(app, argc, argv);

    auto context = engine::platform::create_headless_context(
        {.backend = engine::platform::Backend::headless, .width = width, .height = height, .quiet = true});
    if (!context) {
        std::fprintf(stderr, "deferred_lights: no headless GL context: %s\n", context.error().message.c_str());
        return 1;
    }
    auto made = wire::render::WireRenderer::create();
    if (!made) {
        std::fprintf(stderr, "deferred_lights: %s\n", made.error().message.c_str());
        return 1;
    }
    wire::render::WireRenderer renderer = std::move(*made);
    renderer.set_material(0, {.tint = {0.9f, 0.9f, 0.9f}, .texture = 0, .roughness = 0.35f});
    auto program = engine::gfx::make_program({.vertex = kFullScreen, .fragment = kLighting, .label = "deferred lights"});
    if (!program) {
        std::fprintf(stderr, "deferred_lights: %s\n", program.error().message.c_str());
        return 1;
    }

    // The G-buffer: the default layout (normal, albedo, material) and a depth texture the lights read.
    GLuint fbo = 0, tex[4] = {0, 0, 0, 0};
    glCreateFramebuffers(1, &fbo);
    glCreateTextures(GL_TEXTURE_2D, 4, tex);
    for (int i = 0; i < 3; ++i) {
        glTextureStorage2D(tex[i], 1, i == 0 ? GL_RGBA16F : GL_RGBA8, width, height);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0 + i, tex[i], 0);
    }
    glTextureStorage2D(tex[3], 1, GL_DEPTH_COMPONENT32F, width, height);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, tex[3], 0);
    for (GLuint t : tex) {
        glTextureParameteri(t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    const GLenum buffers[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glNamedFramebufferDrawBuffers(fbo, 3, buffers);
    if (glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        std::fprintf(stderr, "deferred_lights: the G-buffer framebuffer is incomplete\n");
        return 1;
    }

    std::vector<wire::WireNodes> cables;
    for (int k = 0; k < 5; ++k) cables.push_back(hanging(-2.0, 2.0, -0.6 + 0.3 * k, 0.15 + 0.1 * k));
    wire::DrawList list;
    list.path = wire::UploadPath::gpu_nodes;
    for (std::size_t k = 0; k < cables.size(); ++k) {
        wire::DrawItem item;
        item.wire_id = k + 1;
        item.nodes = &cables[k];
        item.nodes_generation = 1;
        item.spline.radius_m = 0.03f;
        item.sides = 32;
        list.items.push_back(item);
    }
    engine::scene::Camera camera;
    camera.position = {0.0, 1.6, 3.2};
    camera.target = {0.0, 0.8, 0.0};
    camera.aspect = static_cast<float>(width) / static_cast<float>(height);

    (*context)->begin_frame();
    GLint frame_fbo = 0;  // the context's framebuffer (headless: its own)
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &frame_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
    const float zero[4] = {0, 0, 0, 0}, one = 1.0f;
    for (int i = 0; i < 3; ++i) glClearNamedFramebufferfv(fbo, GL_COLOR, i, zero);
    glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &one);
    const wire::render::DrawStats drawn = renderer.draw(list, camera, {.output = wire::render::Output::gbuffer});
    if (!drawn.status.ok()) {
        std::fprintf(stderr, "deferred_lights: %s\n", drawn.status.message.c_str());
        return 1;
    }
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(frame_fbo));

    // The lights' pass over the whole screen.
    glDisable(GL_DEPTH_TEST);
    program->use();
    program->set("u_rel_from_clip", glm::inverse(camera.clip_from_relative()));
    program->set("u_lights", lights);
    for (int i = 0; i < lights; ++i) {
        const double a = 2.0 * std::numbers::pi * i / lights;
        const glm::vec3 at(static_cast<float>(1.8 * std::cos(a)), 1.4f + 0.3f * static_cast<float>(i % 2),
                           static_cast<float>(1.2 * std::sin(a)));
        const glm::vec3 color(0.5f + 0.5f * static_cast<float>(std::cos(a)), 0.5f + 0.5f * static_cast<float>(std::cos(a + 2.1)),
                              0.5f + 0.5f * static_cast<float>(std::cos(a + 4.2)));
        const std::string k = "[" + std::to_string(i) + "]";
        program->set(("u_light_rel" + k).c_str(), at - glm::vec3(camera.position));
        program->set(("u_light_color" + k).c_str(), 2.0f * color);
    }
    for (int i = 0; i < 4; ++i) glBindTextureUnit(static_cast<GLuint>(i), tex[i]);
    GLuint empty_vao = 0;
    glCreateVertexArrays(1, &empty_vao);
    glBindVertexArray(empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    glDeleteVertexArrays(1, &empty_vao);
    glEnable(GL_DEPTH_TEST);
    const engine::Status written = engine::platform::write_png(out, engine::platform::read_pixels(**context));
    (*context)->end_frame();
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(4, tex);
    if (!written.ok()) {
        std::fprintf(stderr, "deferred_lights: %s\n", written.message.c_str());
        return 1;
    }
    std::printf("deferred_lights: %zu wires in the G-buffer, %d point lights: wrote %s\n", list.items.size(), lights,
                out.c_str());
    return 0;
}
