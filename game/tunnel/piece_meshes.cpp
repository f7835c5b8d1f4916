// The tunnel's piece meshes (see piece_meshes.hpp).
#include "tunnel/piece_meshes.hpp"

#include <engine/assets/gltf.hpp>

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>

namespace tunnel {

namespace {

// Appends src to dst (dst's origin is zero: src's positions are moved by src.origin; missing uvs are zero).
void append(engine::assets::MeshData& dst, const engine::assets::MeshData& src) {
    const auto base = static_cast<uint32_t>(dst.vertex_count());
    for (std::size_t v = 0; v < src.vertex_count(); ++v) {
        const glm::dvec3 p =
            src.origin + glm::dvec3(src.positions[3 * v], src.positions[3 * v + 1], src.positions[3 * v + 2]);
        dst.positions.insert(dst.positions.end(),
                             {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
        dst.normals.insert(dst.normals.end(),
                           {src.normals[3 * v], src.normals[3 * v + 1], src.normals[3 * v + 2]});
        if (src.uvs.size() == 2 * src.vertex_count()) {
            dst.uvs.insert(dst.uvs.end(), {src.uvs[2 * v], src.uvs[2 * v + 1]});
        } else {
            dst.uvs.insert(dst.uvs.end(), {0.0f, 0.0f});
        }
    }
    for (uint32_t i : src.indices) dst.indices.push_back(base + i);
}

// The error model of a group: the worst of its meshes'.
engine::assets::RefinementErrorModel merge(const engine::assets::RefinementErrorModel& a,
                                           const engine::assets::RefinementErrorModel& b) {
    return {std::max(a.shape_error_m, b.shape_error_m), std::max(a.max_axial_extent_m, b.max_axial_extent_m),
            std::max(a.max_radius_m, b.max_radius_m)};
}

}  // namespace

std::vector<Group> make_groups() {
    return {{.name = "wall", .surface = Surface::concrete, .albedo = {0.62f, 0.60f, 0.56f}},
            {.name = "ribs", .surface = Surface::steel, .albedo = {0.26f, 0.28f, 0.31f}},
            {.name = "walkway", .surface = Surface::grating, .albedo = {0.55f, 0.50f, 0.42f}},
            {.name = "hooks", .surface = Surface::steel, .albedo = {0.90f, 0.72f, 0.12f}},
            {.name = "clips", .surface = Surface::steel, .albedo = {0.42f, 0.44f, 0.47f}}};
}

engine::Status load_piece_meshes(const std::string& asset_dir, std::vector<Group>& groups) {
    std::vector<engine::assets::MeshData> meshes;
    for (const char* file : {"straight_section.glb", "wall_details.glb", "cable_hooks.glb"}) {
        const std::string path = asset_dir + "/" + file;
        std::vector<engine::assets::MeshData> file_meshes;  // read_gltf replaces its output
        if (auto st = engine::assets::read_gltf(path, file_meshes); !st.ok()) return Error{st.message};
        for (auto& m : file_meshes) meshes.push_back(std::move(m));
    }
    for (const engine::assets::MeshData& m : meshes) {
        Group* g = m.name == "tunnel_wall"           ? &groups[0]
                   : m.name.rfind("rib_", 0) == 0    ? &groups[1]
                   : m.name == "walkway"             ? &groups[2]
                   : m.name.rfind("anchor_", 0) == 0 ? &groups[3]
                                                     : nullptr;
        if (g == nullptr) continue;
        engine::assets::ControlMesh control;
        if (auto st = engine::assets::make_control_mesh(m, control); !st.ok()) return Error{st.message};
        g->model = merge(g->model, engine::assets::refinement_error_model(control));
        g->controls.push_back(std::move(control));
    }
    return {};
}

namespace {

// Level `lvl` of every control mesh of `g`, combined, uploaded and appended to g.meshes / g.vertices.
engine::Status refine_level(Group& g, int lvl, PieceRenderer& pieces, engine::assets::MeshData& combined) {
    combined = {};
    combined.name = g.name;
    for (const engine::assets::ControlMesh& c : g.controls) {
        engine::assets::MeshData refined;
        if (auto st = engine::assets::subdivide(c, lvl, refined); !st.ok()) return st;
        append(combined, refined);
    }
    auto handle = pieces.add_mesh(combined, g.name + " level " + std::to_string(lvl));
    if (!handle) return engine::Status::error(handle.error().message);
    g.meshes.push_back(handle.value());
    g.vertices.push_back(combined.vertex_count());
    return {};
}

}  // namespace

engine::Status refine_group(Group& g, int max_level, PieceRenderer& pieces) {
    for (int lvl = 0; lvl <= max_level; ++lvl) {
        engine::assets::MeshData combined;
        if (auto st = refine_level(g, lvl, pieces, combined); !st.ok()) return st;
        if (lvl == max_level) {
            g.inner_radius_m = 1e30;
            for (std::size_t v = 0; v < combined.vertex_count(); ++v)
                g.inner_radius_m = std::min<double>(
                    g.inner_radius_m, std::hypot(combined.positions[3 * v], combined.positions[3 * v + 1]));
            g.top = std::move(combined);
        }
    }
    return {};
}

engine::Status extend_group(Group& g, int max_level, PieceRenderer& pieces) {
    for (int lvl = static_cast<int>(g.meshes.size()); lvl <= max_level; ++lvl) {
        engine::assets::MeshData combined;
        if (auto st = refine_level(g, lvl, pieces, combined); !st.ok()) return st;
    }
    return {};
}

LevelShapes measure_shapes(const std::vector<Group>& groups) {
    LevelShapes shapes;
    shapes.piece_length_m = kPieceLength;
    shapes.wall_radius_m = groups[0].inner_radius_m;
    shapes.rib_inner_radius_m = groups[1].inner_radius_m;
    for (const engine::assets::ControlMesh& c : groups[1].controls) {
        double z0 = 1e30, z1 = -1e30;
        for (std::size_t v = 2; v < c.positions.size(); v += 3) {
            z0 = std::min(z0, c.origin.z + c.positions[v]);
            z1 = std::max(z1, c.origin.z + c.positions[v]);
        }
        shapes.rib_z_m.emplace_back(z0, z1);
    }
    {
        const engine::assets::MeshData& w = groups[2].top;
        shapes.walkway_min_m = glm::dvec2(1e30);
        shapes.walkway_max_m = glm::dvec2(-1e30);
        for (std::size_t v = 0; v < w.vertex_count(); ++v) {
            const glm::dvec2 q(w.origin.x + w.positions[3 * v], w.origin.y + w.positions[3 * v + 1]);
            shapes.walkway_min_m = glm::min(shapes.walkway_min_m, q);
            shapes.walkway_max_m = glm::max(shapes.walkway_max_m, q);
        }
    }
    return shapes;
}

}  // namespace tunnel
