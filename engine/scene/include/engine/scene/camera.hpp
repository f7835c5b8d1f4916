// Camera: position, look-at target, and a vertical field of view (perspective) or a half height (orthographic:
// a directional light's shadow map, a top-down map); GL clip conventions (z in [-1, 1], right-handed view space
// looking down -z), as glm::perspective, glm::ortho and glm::lookAt produce them.
//
// Open-world coordinates: the eye and the target are double, so a camera 1e6 m from the origin still moves in
// 1 mm steps (a float there steps by 6 cm). Draw camera-relative: positions as offsets from the eye (computed
// in double, then float) and clip_from_relative(), which holds only the camera's rotation and projection.
// view() and view_projection() put the world origin in float and are exact only near the origin (tools,
// tests, small scenes).
#pragma once

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

/// Camera and frustum.
namespace engine::scene {

/// A camera looking from `position` at `target` (see the file comment for the conventions).
struct Camera {
    glm::dvec3 position{0.0, 0.0, 5.0};     ///< eye, world metres (double: see the file comment)
    glm::dvec3 target{0.0};                 ///< the point looked at, world metres
    glm::dvec3 up{0.0, 1.0, 0.0};           ///< world up (not parallel to target - position)
    float fov_y_rad = glm::radians(60.0f);  ///< vertical field of view, radians
    float aspect = 16.0f / 9.0f;            ///< width / height
    float near_m = 0.1f;                    ///< near clip distance, metres
    float far_m = 1000.0f;                  ///< far clip distance, metres
    /// > 0: orthographic, the view box +-ortho_half_height_m tall and +-aspect times that wide (fov_y_rad unused);
    /// 0: perspective.
    float ortho_half_height_m = 0.0f;

    /// View matrix (world -> view space), glm::lookAt computed in double and rounded to float: its
    /// translation is the eye in float, so prefer view_relative() away from the origin.
    glm::mat4 view() const { return glm::mat4(glm::lookAt(position, target, up)); }
    /// The view's rotation only (the eye at the origin): maps offsets from the eye (world metres) to view
    /// space.
    glm::mat4 view_relative() const { return glm::mat4(glm::lookAt(glm::dvec3(0.0), target - position, up)); }
    /// Projection matrix (view -> clip space), glm::perspective (glm::ortho when orthographic).
    glm::mat4 projection() const {
        if (orthographic()) {
            const float h = ortho_half_height_m;
            return glm::ortho(-h * aspect, h * aspect, -h, h, near_m, far_m);
        }
        return glm::perspective(fov_y_rad, aspect, near_m, far_m);
    }
    /// ortho_half_height_m > 0.
    [[nodiscard]] bool orthographic() const { return ortho_half_height_m > 0.0f; }
    /// projection() * view(): world -> clip space (exact near the origin only; see view()).
    glm::mat4 view_projection() const { return projection() * view(); }
    /// projection() * view_relative(): offsets from the eye -> clip space, exact at any distance from the
    /// origin.
    glm::mat4 clip_from_relative() const { return projection() * view_relative(); }
    /// Unit vector from position toward target.
    glm::dvec3 forward() const { return glm::normalize(target - position); }

    /// Focal length in pixels for a viewport `height_px` tall: (H/2) / tan(fovY/2). A length L at view depth
    /// z covers L * focal_px / z pixels. Orthographic: pixels per metre, (H/2) / ortho_half_height_m (clip w is 1).
    float focal_px(float height_px) const {
        return orthographic() ? 0.5f * height_px / ortho_half_height_m : 0.5f * height_px / std::tan(0.5f * fov_y_rad);
    }
};

}  // namespace engine::scene
