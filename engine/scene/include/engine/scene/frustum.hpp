// View frustum as six normalized planes extracted from a view-projection matrix (Gribb & Hartmann), with
// conservative visibility tests: a test returns false only when the shape is certainly outside.
#pragma once

#include <array>
#include <span>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace engine::scene {

/// Points p with dot(normal, p) + d >= 0 are on the inner side. |normal| = 1, so the value is a distance.
struct Plane {
    glm::vec3 normal{0.0f, 0.0f, 1.0f};  ///< unit normal, pointing to the inner side
    float d = 0.0f;                      ///< offset: dot(normal, p) + d = 0 on the plane

    /// Signed distance of p (positive on the inner side).
    float distance(const glm::vec3& p) const { return glm::dot(normal, p) + d; }
};

/// The six planes of a view frustum, normals pointing inward.
struct Frustum {
    /// Index of a plane in `planes`.
    enum Side { left, right, bottom, top, near, far };
    std::array<Plane, 6> planes{};  ///< indexed by Side

    /// clip_from_world with GL clip conventions (-w <= x, y, z <= w), e.g. Camera::view_projection().
    static Frustum from_view_projection(const glm::mat4& clip_from_world) {
        const glm::mat4 m = glm::transpose(clip_from_world);  // rows of the matrix as columns
        const glm::vec4 r0 = m[0];
        const glm::vec4 r1 = m[1];
        const glm::vec4 r2 = m[2];
        const glm::vec4 r3 = m[3];
        const std::array<glm::vec4, 6> raw = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 + r2, r3 - r2};
        Frustum f;
        for (std::size_t i = 0; i < 6; ++i) {
            const float length = glm::length(glm::vec3(raw[i]));
            f.planes[i] = Plane{glm::vec3(raw[i]) / length, raw[i].w / length};
        }
        return f;
    }

    /// p is inside or on every plane.
    bool contains_point(const glm::vec3& p) const {
        for (const Plane& plane : planes) {
            if (plane.distance(p) < 0.0f) return false;
        }
        return true;
    }

    /// False only if the sphere lies entirely outside one plane.
    bool intersects_sphere(const glm::vec3& center, float radius) const {
        for (const Plane& plane : planes) {
            if (plane.distance(center) < -radius) return false;
        }
        return true;
    }

    /// False only if the box lies entirely outside one plane (tests the corner farthest along each normal).
    bool intersects_aabb(const glm::vec3& min, const glm::vec3& max) const {
        for (const Plane& plane : planes) {
            const glm::vec3 positive(plane.normal.x >= 0.0f ? max.x : min.x,
                                     plane.normal.y >= 0.0f ? max.y : min.y,
                                     plane.normal.z >= 0.0f ? max.z : min.z);
            if (plane.distance(positive) < 0.0f) return false;
        }
        return true;
    }

    /// Convex hull of the points (e.g. a Bezier control polygon): culled only if every point is outside the
    /// same plane. Conservative: a hull that straddles a frustum corner from outside still counts as visible.
    /// An empty set is not visible.
    bool intersects_points(std::span<const glm::vec3> points) const {
        if (points.empty()) return false;
        for (const Plane& plane : planes) {
            bool all_outside = true;
            for (const glm::vec3& p : points) {
                if (plane.distance(p) >= 0.0f) {
                    all_outside = false;
                    break;
                }
            }
            if (all_outside) return false;
        }
        return true;
    }
};

}  // namespace engine::scene
