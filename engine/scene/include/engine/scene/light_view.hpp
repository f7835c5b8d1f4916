// The view a light casts shadows from, as an engine::scene::Camera: a directional light's orthographic box around
// a bounding sphere, or a spot light's perspective cone. Draw the shadow casters from it into a shadow map
// (engine/gfx/shadow.hpp); the receivers look the map up through the same camera.
#pragma once

#include "engine/scene/camera.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace engine::scene {

/// An up vector not parallel to `forward` (world y, or x where forward is nearly vertical).
inline glm::dvec3 up_for(const glm::dvec3& forward) {
    return std::abs(glm::normalize(forward).y) > 0.99 ? glm::dvec3(1.0, 0.0, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
}

/// A directional light's view: orthographic, looking along -to_light, the box just holding the sphere (centre_m,
/// radius_m): every caster and receiver inside the sphere is in the map. Square (aspect 1): draw it into a square
/// shadow map. A texel is 2 radius_m / map size wide.
inline Camera directional_light_view(const glm::dvec3& to_light, const glm::dvec3& centre_m, double radius_m) {
    const glm::dvec3 l = glm::normalize(to_light);
    const double r = std::max(radius_m, 1e-6);
    Camera c;
    c.position = centre_m + l * (2.0 * r);
    c.target = centre_m;
    c.up = up_for(l);
    c.aspect = 1.0f;
    c.near_m = static_cast<float>(r);
    c.far_m = static_cast<float>(3.0 * r);
    c.ortho_half_height_m = static_cast<float>(r);
    return c;
}

/// A spot light's view: perspective from position_m along direction, the cone's full angle 2 half_angle_rad,
/// casters from near_m to range_m. Square (aspect 1).
inline Camera spot_light_view(const glm::dvec3& position_m, const glm::dvec3& direction, float half_angle_rad,
                              float range_m, float near_m = 0.05f) {
    Camera c;
    c.position = position_m;
    c.target = position_m + glm::normalize(direction);
    c.up = up_for(direction);
    c.aspect = 1.0f;
    c.fov_y_rad = 2.0f * half_angle_rad;
    c.near_m = near_m;
    c.far_m = range_m;
    return c;
}

}  // namespace engine::scene
