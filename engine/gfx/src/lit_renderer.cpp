// LitRenderer: one program, one draw call per mesh.
#include "engine/gfx/lit_renderer.hpp"

#include "engine/gfx/draw.hpp"
#include "engine/gfx/shadow.hpp"

#include <epoxy/gl.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <string>

namespace engine::gfx {
namespace {

constexpr const char* kVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_clip_from_world;
uniform mat4 u_world_from_model;
uniform mat3 u_normal_matrix;
out vec3 v_normal;
out vec3 v_rel_m;
void main() {
  v_normal = u_normal_matrix * a_normal;
  vec4 world = u_world_from_model * vec4(a_position, 1.0);
  v_rel_m = world.xyz;  // relative to the frame's origin (shadow_from_relative of it)
  gl_Position = u_clip_from_world * world;
}
)";

constexpr const char* kFragmentHead = R"(#version 450 core
in vec3 v_normal;
in vec3 v_rel_m;
uniform vec3 u_to_light;
uniform vec3 u_light_color;
uniform float u_ambient;
uniform vec3 u_albedo;
out vec4 o_color;
)";
constexpr const char* kFragmentMain = R"(
void main() {
  vec3 n = normalize(v_normal);
  float diffuse = max(dot(n, u_to_light), 0.0) * shadow_visibility(v_rel_m, n);
  o_color = vec4(u_albedo * (u_ambient + (1.0 - u_ambient) * diffuse) * u_light_color, 1.0);
}
)";

}  // namespace

Expected<LitRenderer> LitRenderer::create() {
    const std::string fragment = std::string(kFragmentHead) + std::string(shadow_glsl()) + kFragmentMain;
    Expected<Program> program = make_program({.vertex = kVertex, .fragment = fragment, .label = "lit"});
    if (!program) return program.error();
    LitRenderer r;
    r.program_ = std::move(program).value();
    return r;
}

void LitRenderer::begin(const glm::mat4& clip_from_world, const DirectionalLight& light) const {
    begin(clip_from_world, light, nullptr, glm::dvec3(0.0));
}

void LitRenderer::begin(const glm::mat4& clip_from_world, const DirectionalLight& light, const ShadowMap* shadow,
                        const glm::dvec3& frame_origin_m) const {
    set_opaque_state();
    program_.use();
    program_.set("u_clip_from_world", clip_from_world);
    program_.set("u_to_light", glm::normalize(light.to_light));
    program_.set("u_light_color", light.color);
    program_.set("u_ambient", light.ambient);
    set_shadow_uniforms(program_, shadow, frame_origin_m);
}

void LitRenderer::draw(const GpuMesh& mesh, const glm::mat4& world_from_model,
                       const glm::vec3& albedo) const {
    program_.set("u_world_from_model", world_from_model);
    program_.set("u_normal_matrix", glm::transpose(glm::inverse(glm::mat3(world_from_model))));
    program_.set("u_albedo", albedo);
    gfx::draw(mesh);
}

void clear(const glm::vec4& color) {
    glClearColor(color.r, color.g, color.b, color.a);
    glClearDepth(1.0);
    glDepthMask(GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

}  // namespace engine::gfx
