// Shadow maps: a depth texture drawn from a light's view (engine/scene/light_view.hpp) and the GLSL that looks it
// up, shared by every renderer that receives shadows (the wire renderer, LitRenderer, the tunnel's pieces) so a
// cable's shadow falls the same way on a wire and on a wall.
//
// Receiving: shadow_glsl() declares `float shadow_visibility(vec3 rel_m, vec3 n)` (1 lit, 0 in shadow) for a point
// given relative to the draw's eye and its unit normal; set_shadow_uniforms() feeds it. It compares 3 x 3 bilinear
// taps (hardware comparison: an edge about 3 texels wide, symmetric, so the darkening's centroid and integral stay
// where the hard edge is) against the receiver's depth less a bias: a constant plus the depth the receiver's plane
// gains across the filter's footprint (slope_bias_texels times the tangent of its angle to the light). That bias is
// along the light, never sideways: a shadow does not move (a normal offset, off by default, would shift it by up to
// its size). Why no acne: a lit surface's own depth stays within the bias over the footprint. Where the bias costs:
// a caster closer to its receiver than the bias (along the light) leaves no shadow there: a cable lying on a wall
// loses the sliver of shadow under its own body (about bias / tan of the light's angle across), which the cable hides
// from most views. Points outside the map are lit; points beyond its far plane are behind every caster; surfaces
// facing away from the light are in shadow (0).
#pragma once

#include "engine/core/expected.hpp"
#include "engine/gfx/resources.hpp"
#include "engine/scene/camera.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <string_view>

namespace engine::gfx {

/// Texture unit the shadow map is bound to while receiving (shadow_glsl()'s sampler binding).
inline constexpr unsigned kShadowTextureUnit = 7;

/// A square depth texture (32-bit float) with its framebuffer, sampled with depth comparison. `light` is the view
/// it was drawn from: set it before drawing the casters, the receivers read it. Move-only.
class ShadowMap {
public:
    /// size_px: 16 .. 16384. Needs a current GL 4.5 context.
    static Expected<ShadowMap> create(int size_px);
    ShadowMap();
    ShadowMap(ShadowMap&&) noexcept;
    ShadowMap& operator=(ShadowMap&&) noexcept;
    ~ShadowMap();

    /// Binds its framebuffer with a size_px viewport and clears the depth to 1 (the bound framebuffer and viewport
    /// are saved for end()). Draw the casters from `light` with depth output between begin() and end().
    void begin();
    /// Restores the framebuffer and viewport begin() found.
    void end();

    [[nodiscard]] unsigned texture() const { return texture_; }
    [[nodiscard]] int size_px() const { return size_px_; }

    scene::Camera light{};              ///< the light's view (directional_light_view, spot_light_view)
    float normal_offset_texels = 0.0f;  ///< how far along its normal a receiver looks the map up, in texels
    float depth_bias_texels = 0.5f;     ///< constant depth bias, in texels (world size at the receiver)
    float slope_bias_texels = 1.5f;     ///< depth bias per unit tangent of the angle to the light, in texels

private:
    void release();
    unsigned texture_ = 0, framebuffer_ = 0;
    int size_px_ = 0;
    int saved_framebuffer_ = 0;
    int saved_viewport_[4] = {0, 0, 0, 0};
};

/// GLSL (no #version) declaring the uniforms below and `float shadow_visibility(vec3 rel_m, vec3 n)`.
std::string_view shadow_glsl();

/// The light's clip coordinates of positions relative to `eye_m` (computed in double, then float).
glm::mat4 shadow_from_relative(const scene::Camera& light, const glm::dvec3& eye_m);

/// Sets `program`'s shadow uniforms (it must be in use and include shadow_glsl()) for a draw whose positions are
/// relative to eye_m, and binds the map to kShadowTextureUnit; null: no shadow (visibility 1).
void set_shadow_uniforms(const Program& program, const ShadowMap* map, const glm::dvec3& eye_m);

}  // namespace engine::gfx
