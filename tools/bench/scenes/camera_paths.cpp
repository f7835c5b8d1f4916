// The wire systems bench's camera paths (camera_paths.hpp).
#include "bench/scenes/camera_paths.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace wiretool::bench {

void place_camera(engine::scene::Camera& cam, SceneKind kind, int frame) {
    const float t = static_cast<float>(frame);
    if (kind == SceneKind::offscreen) {
        cam.position = {3.0f * std::sin(0.02f * t), 5.0f + std::sin(0.03f * t), 12.0f};
        cam.target = cam.position + glm::dvec3(0.4f * std::sin(0.01f * t), -0.15f, 1.0f);
        return;
    }
    if (kind == SceneKind::far) {
        // Flying over the landscape 45 m up, along a gentle curve, looking ahead and a little down.
        const float x = -700.0f + 2.5f * t, z = -600.0f + 1.5f * t + 40.0f * std::sin(0.01f * t);
        cam.position = {x, static_cast<float>(ground_m(x, z)) + 45.0f, z};
        cam.target = cam.position + glm::dvec3(0.8f + 0.1f * std::sin(0.02f * t), -0.12f, 0.6f);
        return;
    }
    cam.position = {3.0f * std::sin(0.02f * t), 5.0f + std::sin(0.03f * t), 8.0f - 0.15f * t};
    cam.target = cam.position + glm::dvec3(0.4f * std::sin(0.01f * t), -0.15f, -1.0f);
}

wire::LodView whole_wire_view(const std::vector<glm::dvec3>& positions) {
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const glm::dvec3& p : positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double radius = std::max(0.5 * glm::length(hi - lo), 0.1);
    const double fov = std::numbers::pi / 3.0;
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.25, 0.35, 1.0));
    return wire::LodView::perspective(centre + dir * (1.1 * radius / std::tan(0.5 * fov)), centre,
                                      glm::dvec3(0.0, 1.0, 0.0), fov, 1920.0, 1080.0, 0.1, 1000.0);
}

}  // namespace wiretool::bench
