// Quads and boxes appended to plain meshes: vertex layout, normals, the facing flip, and boxes that are closed,
// outward-facing and recovered as quads with creased edges by make_control_mesh.
#include <engine/assets/mesh_building.hpp>
#include <engine/assets/subdivide.hpp>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <cmath>
#include <cstdint>
#include <vector>

using engine::assets::MeshData;

namespace {

glm::vec3 position(const MeshData& m, std::size_t v) {
    return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}
glm::vec3 normal(const MeshData& m, std::size_t v) {
    return {m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2]};
}

// Every triangle: its winding's normal agrees with its vertices' normal, which points away from `inside`.
void expect_outward(const MeshData& m, const glm::vec3& inside) {
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const glm::vec3 a = position(m, m.indices[3 * t]), b = position(m, m.indices[3 * t + 1]),
                        c = position(m, m.indices[3 * t + 2]);
        const glm::vec3 wound = glm::normalize(glm::cross(b - a, c - a));
        const glm::vec3 n = normal(m, m.indices[3 * t]);
        EXPECT_NEAR(glm::dot(wound, n), 1.0f, 1e-5f) << "triangle " << t;
        EXPECT_GT(glm::dot((a + b + c) / 3.0f - inside, n), 0.0f) << "triangle " << t;
    }
}

}  // namespace

TEST(MeshBuildingTest, QuadWithGivenNormalKeepsCornersAndUnitUvs) {
    MeshData m;
    m.positions = {9, 9, 9};  // one vertex already there: the quad's indices start after it
    m.normals = {0, 1, 0};
    m.uvs = {0, 0};
    engine::assets::add_quad(m, {.corners = {glm::vec3(0, 0, 0), {1, 0, 0}, {1, 1, 0}, {0, 1, 0}},
                                 .normal = {0.0f, 0.0f, 2.0f}});
    ASSERT_EQ(m.vertex_count(), 5u);
    EXPECT_EQ(m.indices, (std::vector<uint32_t>{1, 2, 3, 1, 3, 4}));
    EXPECT_EQ(position(m, 2), glm::vec3(1, 0, 0));
    EXPECT_EQ(normal(m, 4), glm::vec3(0, 0, 2));  // given normals are stored as they are
    EXPECT_EQ(m.uvs, (std::vector<float>{0, 0, 0, 0, 1, 0, 1, 1, 0, 1}));
}

TEST(MeshBuildingTest, ComputedNormalFlipsTheWindingTowardFacing) {
    const std::array<glm::vec3, 4> ccw{glm::vec3(0, 0, 0), {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};  // front: +z
    const std::array<glm::vec2, 4> uv{glm::vec2(0, 0), {2, 0}, {2, 3}, {0, 3}};
    MeshData kept, flipped, unoriented;
    engine::assets::add_quad(kept, {.corners = ccw, .uvs = uv, .facing = {0, 0, 1}});
    engine::assets::add_quad(flipped, {.corners = ccw, .uvs = uv, .facing = {0, 0, -1}});
    engine::assets::add_quad(unoriented, {.corners = ccw, .uvs = uv});
    EXPECT_EQ(normal(kept, 0), glm::vec3(0, 0, 1));
    EXPECT_EQ(normal(unoriented, 0), glm::vec3(0, 0, 1));
    EXPECT_EQ(kept.positions, unoriented.positions);
    EXPECT_EQ(normal(flipped, 0), glm::vec3(0, 0, -1));
    // Corners 1 and 3 swapped, with their uvs.
    EXPECT_EQ(position(flipped, 1), glm::vec3(0, 1, 0));
    EXPECT_EQ(position(flipped, 3), glm::vec3(1, 0, 0));
    EXPECT_EQ(flipped.uvs, (std::vector<float>{0, 0, 0, 3, 2, 3, 2, 0}));
    expect_outward(flipped, glm::vec3(0.5f, 0.5f, 1.0f));
}

TEST(MeshBuildingTest, OrientedBoxIsClosedOutwardAndCreased) {
    MeshData m;
    const glm::dvec3 c(1.0, -2.0, 3.0);
    const glm::dvec3 u = glm::normalize(glm::dvec3(1.0, 1.0, 0.0));
    const glm::dvec3 w(0.0, 0.0, 1.0);
    const glm::dvec3 v = glm::cross(w, u);
    engine::assets::add_box(m, c, u, v, w, {0.1, 0.2, 0.3});
    ASSERT_EQ(m.vertex_count(), 24u);
    ASSERT_EQ(m.triangle_count(), 12u);
    expect_outward(m, glm::vec3(c));
    for (std::size_t i = 0; i < m.vertex_count(); ++i) {
        const glm::dvec3 d = glm::dvec3(position(m, i)) - c;
        EXPECT_NEAR(std::abs(glm::dot(d, u)), 0.1, 1e-6);
        EXPECT_NEAR(std::abs(glm::dot(d, v)), 0.2, 1e-6);
        EXPECT_NEAR(std::abs(glm::dot(d, w)), 0.3, 1e-6);
    }
    engine::assets::ControlMesh control;
    ASSERT_TRUE(engine::assets::make_control_mesh(m, control).ok());
    EXPECT_EQ(control.quad_count(), 6u);
    EXPECT_EQ(control.positions.size(), 3u * 8u);        // welded corners: closed
    EXPECT_EQ(control.crease_vertices.size(), 2u * 12u);  // every edge a crease
}

TEST(MeshBuildingTest, BoxAlongZIsClosedOutwardWithUvsAlongZ) {
    MeshData m;
    const glm::vec3 lo(-1.0f, -2.0f, 0.0f), hi(1.0f, -1.5f, 4.0f);
    engine::assets::add_box_along_z(m, lo, hi, 4);
    ASSERT_EQ(m.vertex_count(), 4u * (4u * 4u + 2u));
    expect_outward(m, 0.5f * (lo + hi));
    for (std::size_t i = 0; i < 4u * 4u * 4u; ++i)  // the long sides: v is z
        EXPECT_EQ(m.uvs[2 * i + 1], m.positions[3 * i + 2]) << "vertex " << i;
    engine::assets::ControlMesh control;
    ASSERT_TRUE(engine::assets::make_control_mesh(m, control).ok());
    EXPECT_EQ(control.quad_count(), 18u);
    EXPECT_EQ(control.positions.size(), 3u * 4u * 5u);  // four corners per ring, five rings: closed
}
