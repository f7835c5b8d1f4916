// Quads and boxes appended to plain meshes (see mesh_building.hpp).
#include "engine/assets/mesh_building.hpp"

#include <glm/geometric.hpp>

#include <cassert>
#include <cstdint>
#include <utility>

namespace engine::assets {

void add_quad(MeshData& m, const Quad& quad) {
    std::array<glm::vec3, 4> p = quad.corners;
    std::array<glm::vec2, 4> uv = quad.uvs;
    glm::vec3 n = quad.normal;
    if (n == glm::vec3(0.0f)) {
        n = glm::cross(p[1] - p[0], p[2] - p[0]);
        if (glm::dot(n, quad.facing) < 0.0f) {
            std::swap(p[1], p[3]);
            std::swap(uv[1], uv[3]);
            n = -n;
        }
        n = glm::normalize(n);
    }
    const auto base = static_cast<std::uint32_t>(m.vertex_count());
    for (std::size_t k = 0; k < 4; ++k) {
        m.positions.insert(m.positions.end(), {p[k].x, p[k].y, p[k].z});
        m.normals.insert(m.normals.end(), {n.x, n.y, n.z});
        m.uvs.insert(m.uvs.end(), {uv[k].x, uv[k].y});
    }
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

void add_box(MeshData& m, const glm::dvec3& centre_m, const glm::dvec3& u, const glm::dvec3& v,
             const glm::dvec3& w, const glm::dvec3& half_m) {
    const glm::dvec3 axes[3] = {u * half_m.x, v * half_m.y, w * half_m.z};
    for (std::size_t a = 0; a < 3; ++a) {
        const glm::dvec3 n = axes[a];
        const glm::dvec3 s = axes[(a + 1) % 3];
        const glm::dvec3 t = axes[(a + 2) % 3];
        for (double sign : {1.0, -1.0}) {
            const glm::dvec3 f = centre_m + sign * n;
            const glm::vec3 normal(glm::normalize(sign * n));
            // Counter-clockwise seen from outside on both faces of the axis.
            const std::array<glm::dvec3, 4> corners =
                sign > 0.0 ? std::array<glm::dvec3, 4>{f - s - t, f + s - t, f + s + t, f - s + t}
                           : std::array<glm::dvec3, 4>{f - s - t, f - s + t, f + s + t, f + s - t};
            add_quad(m, {.corners = {glm::vec3(corners[0]), glm::vec3(corners[1]), glm::vec3(corners[2]),
                                     glm::vec3(corners[3])},
                         .normal = normal});
        }
    }
}

void add_box_along_z(MeshData& m, const glm::vec3& lo, const glm::vec3& hi, int segments_z) {
    assert(segments_z >= 1 && "add_box_along_z needs at least one segment");
    for (int s = 0; s < segments_z; ++s) {
        const float z0 = lo.z + (hi.z - lo.z) * static_cast<float>(s) / static_cast<float>(segments_z);
        const float z1 = lo.z + (hi.z - lo.z) * static_cast<float>(s + 1) / static_cast<float>(segments_z);
        const std::array<glm::vec2, 4> uv{glm::vec2(0, z0), {1, z0}, {1, z1}, {0, z1}};
        add_quad(
            m, {.corners = {glm::vec3(lo.x, hi.y, z0), {hi.x, hi.y, z0}, {hi.x, hi.y, z1}, {lo.x, hi.y, z1}},
                .uvs = uv,
                .facing = {0, 1, 0}});
        add_quad(
            m, {.corners = {glm::vec3(lo.x, lo.y, z0), {hi.x, lo.y, z0}, {hi.x, lo.y, z1}, {lo.x, lo.y, z1}},
                .uvs = uv,
                .facing = {0, -1, 0}});
        add_quad(
            m, {.corners = {glm::vec3(lo.x, lo.y, z0), {lo.x, hi.y, z0}, {lo.x, hi.y, z1}, {lo.x, lo.y, z1}},
                .uvs = uv,
                .facing = {-1, 0, 0}});
        add_quad(
            m, {.corners = {glm::vec3(hi.x, lo.y, z0), {hi.x, hi.y, z0}, {hi.x, hi.y, z1}, {hi.x, lo.y, z1}},
                .uvs = uv,
                .facing = {1, 0, 0}});
    }
    add_quad(
        m,
        {.corners = {glm::vec3(lo.x, lo.y, lo.z), {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z}},
         .facing = {0, 0, -1}});
    add_quad(
        m,
        {.corners = {glm::vec3(lo.x, lo.y, hi.z), {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}},
         .facing = {0, 0, 1}});
}

}  // namespace engine::assets
