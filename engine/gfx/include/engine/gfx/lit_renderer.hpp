// A minimal forward renderer for opaque meshes: Lambert diffuse from one directional light plus ambient, optionally
// shadowed by a shadow map (shadow.hpp). Used by the demo, the headless system test and `wiretool view --ground`;
// the shading is documented so tests can predict it:
//   color = albedo * (ambient + (1 - ambient) * max(0, dot(n, to_light)) * visibility) * light_color
// with visibility shadow_visibility() of the map (1 without one). World coordinates: exact near the origin.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/ext/vector_double3.hpp>
#include <glm/vec3.hpp>

#include "engine/gfx/mesh.hpp"
#include "engine/gfx/resources.hpp"

namespace engine::gfx {

class ShadowMap;  // shadow.hpp

/// The light of LitRenderer (see the shading formula in the file comment).
struct DirectionalLight {
    glm::vec3 to_light{0.3f, 1.0f, 0.5f};  ///< direction toward the light (normalized by the renderer)
    glm::vec3 color{1.0f};                 ///< light colour (linear RGB)
    float ambient = 0.15f;                 ///< fraction of albedo seen on the unlit side
};

/// Draws opaque GpuMeshes with one directional light (create, then begin() once per frame, draw() per mesh).
class LitRenderer {
public:
    /// Compiles the shaders; errors carry the driver's log.
    static Expected<LitRenderer> create();

    /// Sets the per-frame state: depth test on, back faces culled, program bound.
    void begin(const glm::mat4& clip_from_world, const DirectionalLight& light) const;
    /// As begin(), the meshes receiving `shadow` (null: none), in a frame whose origin is frame_origin_m in the
    /// world: world_from_model places meshes relative to it and clip_from_frame projects from it (origin 0: world
    /// coordinates; the camera position with Camera::clip_from_relative(): exact far from the world origin). Also
    /// draws casters into a shadow map: begin() the map, then this with the light's projection from the frame.
    void begin(const glm::mat4& clip_from_frame, const DirectionalLight& light, const ShadowMap* shadow,
               const glm::dvec3& frame_origin_m) const;
    /// Draws `mesh` placed by `world_from_model` in colour `albedo` (linear RGB). Call after begin().
    void draw(const GpuMesh& mesh, const glm::mat4& world_from_model, const glm::vec3& albedo) const;

private:
    Program program_;
};

/// Clears color (RGBA in [0, 1]) and depth of the bound framebuffer.
void clear(const glm::vec4& color);

}  // namespace engine::gfx
