// Perspective camera: position, look-at target, vertical field of view; GL clip conventions (z in [-1, 1],
// right-handed view space looking down -z), as glm::perspective and glm::lookAt produce them.
#pragma once

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

/// Camera and frustum.
namespace engine::scene {

/// A perspective camera looking from `position` at `target` (see the file comment for the conventions).
struct Camera {
    glm::vec3 position{0.0f, 0.0f, 5.0f};   ///< eye, world metres
    glm::vec3 target{0.0f};                 ///< the point looked at, world metres
    glm::vec3 up{0.0f, 1.0f, 0.0f};         ///< world up (not parallel to target - position)
    float fov_y_rad = glm::radians(60.0f);  ///< vertical field of view, radians
    float aspect = 16.0f / 9.0f;            ///< width / height
    float near_m = 0.1f;                    ///< near clip distance, metres
    float far_m = 1000.0f;                  ///< far clip distance, metres

    /// View matrix (world -> view space), glm::lookAt.
    glm::mat4 view() const { return glm::lookAt(position, target, up); }
    /// Projection matrix (view -> clip space), glm::perspective.
    glm::mat4 projection() const { return glm::perspective(fov_y_rad, aspect, near_m, far_m); }
    /// projection() * view(): world -> clip space.
    glm::mat4 view_projection() const { return projection() * view(); }
    /// Unit vector from position toward target.
    glm::vec3 forward() const { return glm::normalize(target - position); }

    /// Focal length in pixels for a viewport `height_px` tall: (H/2) / tan(fovY/2). A length L at view depth
    /// z covers L * focal_px / z pixels.
    float focal_px(float height_px) const { return 0.5f * height_px / std::tan(0.5f * fov_y_rad); }
};

}  // namespace engine::scene
