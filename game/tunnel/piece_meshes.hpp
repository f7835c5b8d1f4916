// The tunnel's piece meshes: the pieces' glTF files sorted into groups drawn alike (wall, ribs, walkway,
// hooks, and the clips the level adds), each group's control meshes refined once at every cached subdivision
// level and uploaded, and the contact shapes the ropes collide with, measured on the refined meshes.
#pragma once

#include "tunnel/piece_renderer.hpp"
#include "tunnel/rope_contact.hpp"

#include <engine/assets/mesh_data.hpp>
#include <engine/assets/subdivide.hpp>
#include <engine/core/expected.hpp>

#include <glm/vec3.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace tunnel {

inline constexpr double kPieceLength = 4.0;  // the assets' length along +z
inline constexpr std::size_t kGroups = 5;    // wall, ribs, walkway, hooks, clips

/// Piece meshes drawn with one surface and colour, refined and uploaded together.
struct Group {
    std::string name;
    Surface surface = Surface::concrete;
    glm::vec3 albedo{1.0f};
    std::vector<engine::assets::ControlMesh> controls{};
    engine::assets::RefinementErrorModel model{};
    std::vector<PieceRenderer::MeshHandle> meshes{};  // per level
    std::vector<std::size_t> vertices{};              // per level
    engine::assets::MeshData top{};                   // refined at the highest cached level
    double inner_radius_m = 0.0;                      // smallest distance of `top` from the axis
};

/// The kGroups groups, named and coloured, without meshes: wall, ribs, walkway, hooks, clips.
std::vector<Group> make_groups();

/// Reads straight_section.glb, wall_details.glb and cable_hooks.glb from asset_dir and adds each mesh's
/// control mesh to its group ("tunnel_wall": wall, "rib_*": ribs, "walkway", "anchor_*": hooks; others are
/// ignored). Errors name the file or the mesh.
engine::Status load_piece_meshes(const std::string& asset_dir, std::vector<Group>& groups);

/// Refines every control mesh of `g` at levels 0..max_level, uploads each level's combined mesh to `pieces`,
/// and keeps the vertex counts, the highest level (top) and its smallest distance from the axis.
engine::Status refine_group(Group& g, int max_level, PieceRenderer& pieces);
/// More levels for a refined group, up to `max_level` (a larger viewport needs them): uploaded like refine_group's,
/// but the group's measurements (inner radius, the top mesh the contact shapes come from) stay those of its first
/// refinement, so the ropes touch the same tunnel at every screen size.
engine::Status extend_group(Group& g, int max_level, PieceRenderer& pieces);

/// What the ropes collide with, measured on the refined wall, ribs and walkway (within a fraction of a
/// millimetre of the limit surfaces at level 4; the wall's and ribs' refined polygons lie inside their limit
/// circles). The wall cables are the level's to add.
LevelShapes measure_shapes(const std::vector<Group>& groups);

}  // namespace tunnel
