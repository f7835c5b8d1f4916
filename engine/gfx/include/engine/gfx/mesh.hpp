// Simple indexed triangle meshes (position + normal): CPU generators for primitives and their GPU upload.
// The generators are plain math (no GL); upload_mesh needs a current context.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "engine/gfx/resources.hpp"

/// GL object handles, primitive meshes, a minimal lit forward renderer and GL debug output.
namespace engine::gfx {

/// A mesh vertex.
struct Vertex {
    glm::vec3 position{0.0f};            ///< metres, model space
    glm::vec3 normal{0.0f, 1.0f, 0.0f};  ///< unit normal
};

/// Counter-clockwise front faces, outward normals.
struct PrimitiveMesh {
    std::vector<Vertex> vertices{};        ///< the vertices
    std::vector<std::uint32_t> indices{};  ///< three per triangle, into vertices
};

/// Closed cylinder along +y centered on the origin; sides and caps have separate vertices (flat cap normals).
/// The side is the polygon with `sides` corners inscribed in the circle of radius radius_m.
struct CylinderDesc {
    float radius_m = 0.5f;       ///< circumradius of the side polygon
    float half_height_m = 0.5f;  ///< the cylinder spans y in [-half_height_m, half_height_m]
    int sides = 32;              ///< >= 3
    bool caps = true;            ///< close both ends
};
/// The cylinder described by `desc`.
PrimitiveMesh make_cylinder_mesh(const CylinderDesc& desc = {});

/// Axis-aligned box centered on the origin, flat normals.
PrimitiveMesh make_box_mesh(glm::vec3 half_extents_m = glm::vec3(0.5f));

/// Square in the y = 0 plane facing +y, centered on the origin.
PrimitiveMesh make_plane_mesh(float half_size_m = 1.0f);

/// UV sphere centered on the origin.
PrimitiveMesh make_sphere_mesh(float radius_m = 0.5f, int slices = 32, int stacks = 16);

/// A mesh on the GPU: vertex buffer (Vertex layout: location 0 position, 1 normal), index buffer and VAO.
struct GpuMesh {
    Buffer vertices;           ///< vertex buffer (Vertex layout)
    Buffer indices;            ///< uint32 index buffer
    VertexArray vertex_array;  ///< VAO binding both
    int index_count = 0;       ///< indices to draw
};

/// Errors: empty mesh, or buffer allocation failed.
Expected<GpuMesh> upload_mesh(const PrimitiveMesh& mesh, std::string_view label = {});

/// Draws all triangles with whatever program is in use.
void draw(const GpuMesh& mesh);

}  // namespace engine::gfx
