// Perspective camera: position, look-at target, vertical field of view; GL clip conventions (z in [-1, 1],
// right-handed view space looking down -z), as glm::perspective and glm::lookAt produce them.
#pragma once

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat4x4.hpp>
#include <glm/trigonometric.hpp>
#include <glm/vec3.hpp>

namespace engine::scene {

struct Camera {
    glm::vec3 position{0.0f, 0.0f, 5.0f};
    glm::vec3 target{0.0f};
    glm::vec3 up{0.0f, 1.0f, 0.0f};
    float fov_y_rad = glm::radians(60.0f);
    float aspect = 16.0f / 9.0f;  // width / height
    float near_m = 0.1f;
    float far_m = 1000.0f;

    glm::mat4 view() const { return glm::lookAt(position, target, up); }
    glm::mat4 projection() const { return glm::perspective(fov_y_rad, aspect, near_m, far_m); }
    glm::mat4 view_projection() const { return projection() * view(); }
    glm::vec3 forward() const { return glm::normalize(target - position); }

    // Focal length in pixels for a viewport `height_px` tall: (H/2) / tan(fovY/2). A length L at view depth z
    // covers L * focal_px / z pixels.
    float focal_px(float height_px) const { return 0.5f * height_px / std::tan(0.5f * fov_y_rad); }
};

}  // namespace engine::scene
