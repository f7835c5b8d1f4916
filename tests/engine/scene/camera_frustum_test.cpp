// engine/scene: camera matrices, focal length and frustum tests (plain math, no GL).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include <glm/gtc/constants.hpp>

#include "engine/scene/camera.hpp"
#include "engine/scene/frustum.hpp"

namespace scene = engine::scene;

namespace {

scene::Camera test_camera() {
    return {.position = {0, 0, 10},
            .target = {0, 0, 0},
            .fov_y_rad = glm::radians(90.0f),
            .aspect = 2.0f,
            .near_m = 1.0f,
            .far_m = 100.0f};
}

TEST(CameraTest, FocalLengthInPixels) {
    scene::Camera cam = test_camera();
    EXPECT_NEAR(cam.focal_px(600.0f), 300.0f, 1e-3f);  // tan(45 deg) = 1
    cam.fov_y_rad = glm::radians(60.0f);
    EXPECT_NEAR(cam.focal_px(720.0f), 360.0f / std::tan(glm::radians(30.0f)), 1e-2f);
}

TEST(CameraTest, ProjectsLikeAPinhole) {
    const scene::Camera cam = test_camera();
    const float height_px = 400.0f;
    const float width_px = height_px * cam.aspect;
    // A point 1 m right of the axis at depth 5 m lands focal * 1 / 5 px right of the center.
    const glm::vec4 clip = cam.view_projection() * glm::vec4(1.0f, 0.5f, 5.0f, 1.0f);
    const glm::vec3 ndc = glm::vec3(clip) / clip.w;
    const float x_px = (ndc.x * 0.5f) * width_px;
    const float y_px = (ndc.y * 0.5f) * height_px;
    EXPECT_NEAR(x_px, cam.focal_px(height_px) * 1.0f / 5.0f, 1e-3f);
    EXPECT_NEAR(y_px, cam.focal_px(height_px) * 0.5f / 5.0f, 1e-3f);
    EXPECT_NEAR(glm::length(cam.forward() - glm::dvec3(0, 0, -1)), 0.0, 1e-12);
}

TEST(FrustumTest, PlanesAreNormalizedAndPointInward) {
    const scene::Camera cam = test_camera();
    const scene::Frustum f = scene::Frustum::from_view_projection(cam.view_projection());
    for (const scene::Plane& p : f.planes) EXPECT_NEAR(glm::length(p.normal), 1.0f, 1e-5f);
    // Distances are metric: the near plane is 1 m in front of the eye, the far plane 100 m.
    EXPECT_NEAR(f.planes[scene::Frustum::near].distance({0, 0, 8}), 1.0f, 1e-3f);
    EXPECT_NEAR(f.planes[scene::Frustum::far].distance({0, 0, 8}), 98.0f, 1e-2f);
    // Side planes of a 90 deg vertical fov pass through the eye at 45 deg.
    EXPECT_NEAR(f.planes[scene::Frustum::top].distance({0, 0, 10}), 0.0f, 1e-4f);
    EXPECT_NEAR(f.planes[scene::Frustum::top].distance({0, 5, 5}), 0.0f, 1e-3f);
    EXPECT_TRUE(f.contains_point({0, 0, 0}));
    EXPECT_FALSE(f.contains_point({0, 0, 9.5f}));    // between eye and near plane
    EXPECT_FALSE(f.contains_point({0, 0, -95.0f}));  // beyond far
    EXPECT_FALSE(f.contains_point({0, 11, 0}));      // above the top plane at depth 10
    EXPECT_TRUE(f.contains_point({19, 9, 0}));       // half width is 2 * depth at aspect 2
    EXPECT_FALSE(f.contains_point({21, 0, 0}));
}

TEST(FrustumTest, SphereTests) {
    const scene::Frustum f = scene::Frustum::from_view_projection(test_camera().view_projection());
    EXPECT_TRUE(f.intersects_sphere({0, 0, 0}, 0.1f));
    // Top plane at depth 10 is y = 10, normal (0, -1, -1)/sqrt2 style: a sphere centered above it.
    const float dist_above = (12.0f - 10.0f) / std::sqrt(2.0f);
    EXPECT_FALSE(f.intersects_sphere({0, 12, 0}, dist_above - 0.01f));
    EXPECT_TRUE(f.intersects_sphere({0, 12, 0}, dist_above + 0.01f));
    EXPECT_FALSE(f.intersects_sphere({0, 0, 20}, 5.0f));  // behind the camera
    EXPECT_TRUE(f.intersects_sphere({0, 0, 20}, 12.0f));  // big enough to reach past the near plane
}

TEST(FrustumTest, AabbTests) {
    const scene::Frustum f = scene::Frustum::from_view_projection(test_camera().view_projection());
    EXPECT_TRUE(f.intersects_aabb({-1, -1, -1}, {1, 1, 1}));
    EXPECT_TRUE(f.intersects_aabb({-1000, -1000, -50}, {1000, 1000, -40}));  // frustum inside the box's slab
    EXPECT_FALSE(f.intersects_aabb({30, -1, -1}, {31, 1, 1}));
    EXPECT_FALSE(f.intersects_aabb({-1, -1, -200}, {1, 1, -150}));
    EXPECT_TRUE(f.intersects_aabb({-1, -1, -200}, {1, 1, -80}));
}

TEST(FrustumTest, PointSetCulledOnlyIfAllOutsideOnePlane) {
    const scene::Frustum f = scene::Frustum::from_view_projection(test_camera().view_projection());
    // A control hull to the right of the frustum: all outside the right plane.
    const std::array<glm::vec3, 4> right_of_view{glm::vec3(30, 0, 0), glm::vec3(31, 2, 0),
                                                 glm::vec3(32, -2, 0), glm::vec3(33, 0, 0)};
    EXPECT_FALSE(f.intersects_points(right_of_view));
    // A hull whose ends are outside opposite side planes but that spans the view: visible.
    const std::array<glm::vec3, 4> spanning{glm::vec3(-30, 0, 0), glm::vec3(-10, 1, 0), glm::vec3(10, 1, 0),
                                            glm::vec3(30, 0, 0)};
    for (const glm::vec3& p : {spanning[0], spanning[3]}) EXPECT_FALSE(f.contains_point(p));
    EXPECT_TRUE(f.intersects_points(spanning));
    // One point inside suffices.
    const std::array<glm::vec3, 2> one_inside{glm::vec3(0, 0, 0), glm::vec3(0, 0, 50)};
    EXPECT_TRUE(f.intersects_points(one_inside));
    EXPECT_FALSE(f.intersects_points(std::span<const glm::vec3>()));
}

TEST(FrustumTest, RandomPointsAgreeWithClipSpace) {
    const scene::Camera cam = test_camera();
    const glm::mat4 vp = cam.view_projection();
    const scene::Frustum f = scene::Frustum::from_view_projection(vp);
    unsigned state = 12345u;
    auto next = [&state] {
        state = state * 1664525u + 1013904223u;
        return static_cast<float>(state >> 8) / static_cast<float>(1u << 24) * 2.0f - 1.0f;
    };
    int checked = 0;
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 p(next() * 60.0f, next() * 40.0f, next() * 120.0f - 50.0f);
        const glm::vec4 c = vp * glm::vec4(p, 1.0f);
        const float margin = 1e-3f * std::abs(c.w) + 1e-4f;
        const bool inside = std::abs(c.x) <= c.w && std::abs(c.y) <= c.w && std::abs(c.z) <= c.w;
        const bool clearly = std::abs(std::abs(c.x) - c.w) > margin &&
                             std::abs(std::abs(c.y) - c.w) > margin && std::abs(std::abs(c.z) - c.w) > margin;
        if (!clearly) continue;
        ++checked;
        EXPECT_EQ(f.contains_point(p), inside) << p.x << " " << p.y << " " << p.z;
    }
    EXPECT_GT(checked, 19000);
}

}  // namespace
