// Building plain meshes (engine::assets::MeshData) from quads and boxes: the coarse control meshes the tools
// author and the level adds at run time. Plain math, no GL. Every quad gets its own four vertices and the
// triangle pair (0,1,2), (0,2,3), which engine::assets::make_control_mesh recovers as one quad; its flat
// normal makes every edge to a differently facing quad a crease.
#pragma once

#include "engine/assets/mesh_data.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <array>

namespace engine::assets {

/// One quad. Zero means default: a zero normal is computed, a zero facing keeps the corners' order.
struct Quad {
    std::array<glm::vec3, 4> corners{};  ///< metres, relative to the mesh's origin
    std::array<glm::vec2, 4> uvs{glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)};
    /// The normal of all four vertices; zero: normalize(cross(c1 - c0, c2 - c0)) of the (possibly flipped)
    /// corners.
    glm::vec3 normal{0.0f};
    /// With a computed normal, the side the quad is seen from: when the corners' winding faces away from it,
    /// corners (and uvs) 1 and 3 are swapped so that the front faces it.
    glm::vec3 facing{0.0f};
};

/// Appends `quad` (positions, normals and uvs of four new vertices, six indices).
void add_quad(MeshData& m, const Quad& quad);

/// Appends a box centred at centre_m with half extents half_m along the orthonormal right-handed axes u, v,
/// w: six outward quads with unit uvs. Computed in double, stored as float.
void add_box(MeshData& m, const glm::dvec3& centre_m, const glm::dvec3& u, const glm::dvec3& v,
             const glm::dvec3& w, const glm::dvec3& half_m);

/// Appends the closed axis-aligned box between lo_m and hi_m whose four long sides (+y, -y, -x, +x) are split
/// into segments_z quads along z, with uvs (0..1 across, z along); the two end caps (-z, +z) have unit uvs.
void add_box_along_z(MeshData& m, const glm::vec3& lo_m, const glm::vec3& hi_m, int segments_z);

}  // namespace engine::assets
