// Shadow maps (shadow.hpp).
#include "engine/gfx/shadow.hpp"

#include <epoxy/gl.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <string>
#include <utility>

namespace engine::gfx {

Expected<ShadowMap> ShadowMap::create(int size_px) {
    if (size_px < 16 || size_px > 16384) {
        return Error{"shadow map: size " + std::to_string(size_px) + " px is outside 16 .. 16384"};
    }
    ShadowMap m;
    m.size_px_ = size_px;
    glCreateTextures(GL_TEXTURE_2D, 1, &m.texture_);
    glTextureStorage2D(m.texture_, 1, GL_DEPTH_COMPONENT32F, size_px, size_px);
    glTextureParameteri(m.texture_, GL_TEXTURE_MIN_FILTER, GL_LINEAR);  // with comparison: 2 x 2 filtered taps
    glTextureParameteri(m.texture_, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(m.texture_, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTextureParameteri(m.texture_, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float far_depth[4] = {1.0f, 1.0f, 1.0f, 1.0f};  // outside the map: nothing in front, lit
    glTextureParameterfv(m.texture_, GL_TEXTURE_BORDER_COLOR, far_depth);
    glTextureParameteri(m.texture_, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTextureParameteri(m.texture_, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glObjectLabel(GL_TEXTURE, m.texture_, -1, "shadow map");
    glCreateFramebuffers(1, &m.framebuffer_);
    glNamedFramebufferTexture(m.framebuffer_, GL_DEPTH_ATTACHMENT, m.texture_, 0);
    glNamedFramebufferDrawBuffer(m.framebuffer_, GL_NONE);
    glNamedFramebufferReadBuffer(m.framebuffer_, GL_NONE);
    const GLenum status = glCheckNamedFramebufferStatus(m.framebuffer_, GL_DRAW_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        return Error{"shadow map: the depth framebuffer is incomplete (status " + std::to_string(status) + ")"};
    }
    return m;
}

ShadowMap::ShadowMap() = default;
ShadowMap::ShadowMap(ShadowMap&& o) noexcept
    : light(o.light),
      normal_offset_texels(o.normal_offset_texels),
      depth_bias_texels(o.depth_bias_texels),
      slope_bias_texels(o.slope_bias_texels),
      texture_(std::exchange(o.texture_, 0u)),
      framebuffer_(std::exchange(o.framebuffer_, 0u)),
      size_px_(std::exchange(o.size_px_, 0)) {}
ShadowMap& ShadowMap::operator=(ShadowMap&& o) noexcept {
    if (this != &o) {
        release();
        light = o.light;
        normal_offset_texels = o.normal_offset_texels;
        depth_bias_texels = o.depth_bias_texels;
        slope_bias_texels = o.slope_bias_texels;
        texture_ = std::exchange(o.texture_, 0u);
        framebuffer_ = std::exchange(o.framebuffer_, 0u);
        size_px_ = std::exchange(o.size_px_, 0);
    }
    return *this;
}
ShadowMap::~ShadowMap() { release(); }

void ShadowMap::release() {
    if (framebuffer_ != 0) glDeleteFramebuffers(1, &framebuffer_);
    if (texture_ != 0) glDeleteTextures(1, &texture_);
    framebuffer_ = texture_ = 0;
}

void ShadowMap::begin() {
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &saved_framebuffer_);
    glGetIntegerv(GL_VIEWPORT, saved_viewport_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffer_);
    glViewport(0, 0, size_px_, size_px_);
    glDepthMask(GL_TRUE);
    const float one = 1.0f;
    glClearNamedFramebufferfv(framebuffer_, GL_DEPTH, 0, &one);
}

void ShadowMap::end() {
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(saved_framebuffer_));
    glViewport(saved_viewport_[0], saved_viewport_[1], saved_viewport_[2], saved_viewport_[3]);
}

std::string_view shadow_glsl() {
    return R"(
layout(binding = 7) uniform sampler2DShadow u_shadow_map;
uniform bool u_shadow_on;
uniform mat4 u_shadow_from_rel;  // the light's clip coordinates of eye-relative positions
uniform float u_shadow_texel;    // a texel's world size at light clip w = 1 (orthographic: everywhere)
uniform bool u_shadow_ortho;
uniform float u_shadow_near, u_shadow_far;
uniform float u_shadow_size;     // texels across
uniform float u_shadow_offset;   // normal offset, texels
uniform float u_shadow_bias;     // constant depth bias, texels
uniform float u_shadow_slope;    // depth bias per unit tangent of the angle to the light, texels
uniform vec3 u_shadow_dir;       // orthographic: unit direction toward the light
uniform vec3 u_shadow_light_rel; // perspective: the light's position relative to the frame's origin
float shadow_visibility(vec3 rel_m, vec3 n) {
  if (!u_shadow_on) return 1.0;
  vec3 l = u_shadow_ortho ? u_shadow_dir : normalize(u_shadow_light_rel - rel_m);
  float cos_t = dot(n, l);
  if (cos_t <= 0.0) return 0.0;  // facing away from the light: its own body shadows it
  float w = max((u_shadow_from_rel * vec4(rel_m, 1.0)).w, 1e-6);
  float texel_m = u_shadow_texel * w;
  vec4 c = u_shadow_from_rel * vec4(rel_m + n * (u_shadow_offset * texel_m), 1.0);
  vec3 q = c.xyz / c.w * 0.5 + 0.5;
  if (q.x < 0.0 || q.y < 0.0 || q.x > 1.0 || q.y > 1.0) return 1.0;  // outside the map: lit
  q.z = min(q.z, 1.0);  // beyond the far plane: behind every caster the map holds
  // The receiver's depth varies by tan(angle) per texel across the filter's footprint: biased by that (clamped at
  // grazing angles, where the light's diffuse term is near 0 anyway) plus a constant.
  float tan_t = min(sqrt(max(1.0 - cos_t * cos_t, 0.0)) / cos_t, 8.0);
  float bias_m = (u_shadow_bias + u_shadow_slope * tan_t) * texel_m;
  // d(depth in [0, 1]) / d(distance from the light): orthographic 1 / (f - n); perspective f n / ((f - n) w^2).
  float f = u_shadow_far, nr = u_shadow_near;
  float per_m = u_shadow_ortho ? 1.0 / (f - nr) : f * nr / ((f - nr) * c.w * c.w);
  float ref = q.z - bias_m * per_m;
  float sum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) sum += texture(u_shadow_map, vec3(q.xy + vec2(x, y) / u_shadow_size, ref));
  return sum / 9.0;
}
)";
}

glm::mat4 shadow_from_relative(const scene::Camera& light, const glm::dvec3& eye_m) {
    const glm::dmat4 view = glm::lookAt(light.position, light.target, light.up);
    const glm::dmat4 m = glm::dmat4(light.projection()) * view * glm::translate(glm::dmat4(1.0), eye_m);
    return glm::mat4(m);
}

void set_shadow_uniforms(const Program& program, const ShadowMap* map, const glm::dvec3& eye_m) {
    program.set("u_shadow_on", map != nullptr && map->texture() != 0 ? 1 : 0);
    if (map == nullptr || map->texture() == 0) return;
    const scene::Camera& l = map->light;
    const auto size = static_cast<float>(map->size_px());
    program.set("u_shadow_from_rel", shadow_from_relative(l, eye_m));
    program.set("u_shadow_texel", l.orthographic() ? 2.0f * l.ortho_half_height_m / size
                                                   : 2.0f * std::tan(0.5f * l.fov_y_rad) / size);
    program.set("u_shadow_ortho", l.orthographic() ? 1 : 0);
    program.set("u_shadow_near", l.near_m);
    program.set("u_shadow_far", l.far_m);
    program.set("u_shadow_size", size);
    program.set("u_shadow_offset", map->normal_offset_texels);
    program.set("u_shadow_bias", map->depth_bias_texels);
    program.set("u_shadow_slope", map->slope_bias_texels);
    program.set("u_shadow_dir", glm::vec3(glm::normalize(l.position - l.target)));
    program.set("u_shadow_light_rel", glm::vec3(l.position - eye_m));
    glBindTextureUnit(kShadowTextureUnit, map->texture());
}

}  // namespace engine::gfx
