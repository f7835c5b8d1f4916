// Plain triangle-mesh arrays exchanged with asset files (glTF) and the tools: no GL, no ECS.
#pragma once

#include "engine/core/status.hpp"

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace engine::assets {

/// One triangle mesh. Positions are float32 relative to `origin` (double, metres), so a mesh placed 1e6 m
/// from the world origin keeps millimetre precision. Arrays are tightly packed: positions and normals
/// xyz per vertex, uvs uv per vertex (may be empty), indices three per triangle.
struct MeshData {
    std::string name;
    glm::dvec3 origin{0.0};
    std::vector<float> positions;
    std::vector<float> normals;
    std::vector<float> uvs;
    std::vector<uint32_t> indices;

    [[nodiscard]] std::size_t vertex_count() const { return positions.size() / 3; }
    [[nodiscard]] std::size_t triangle_count() const { return indices.size() / 3; }
};

}  // namespace engine::assets
