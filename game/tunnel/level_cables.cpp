// The cables fixed along the walls, on clips on the ribs' inner faces, and every frame the wire nodes of all
// cables: fixed ones and the hanging ropes, bent by the chain (system tunnel.cables).
#include "tunnel/level_state.hpp"

#include <engine/assets/mesh_building.hpp>
#include <engine/assets/subdivide.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace tunnel {

Status Level::spawn_fixed_cables() {
    State& s = *state_;
    LevelShapes& shapes = s.shapes;
    // Cables fixed along the walls, on clips on the ribs' inner faces: just above the hooks, and high on each
    // wall. A clip holds its cable kClipGap clear of the rib (no cable touches a rib); the clips are a
    // fifth piece group, refined like the others.
    const double total = kPieceLength * s.settings.pieces;
    struct FixedSpec {
        double side, y;  // side -1 left, +1 right; height of the cable's axis
        uint32_t material;
        float radius;
    };
    const FixedSpec fixed_specs[] = {{-1.0, -0.06, rubber, 0.035f}, {1.0, -0.06, blue, 0.03f},
                                     {-1.0, 0.06, copper, 0.022f},  {1.0, 0.05, red, 0.022f},
                                     {-1.0, 1.05, yellow, 0.025f},  {1.0, 1.05, rubber, 0.03f}};
    constexpr double kClipGap = 0.012;
    engine::assets::MeshData clips;
    clips.name = "clips";
    for (const FixedSpec& f : fixed_specs) {
        const double rho = shapes.rib_inner_radius_m - f.radius - kClipGap;
        const double x = f.side * std::sqrt(rho * rho - f.y * f.y);
        const glm::dvec3 u = glm::normalize(glm::dvec3(x, f.y, 0.0));  // radial
        const glm::dvec3 w(0.0, 0.0, 1.0);
        const glm::dvec3 v = glm::cross(w, u);
        // Saddle from the cable's axis into the rib; as wide as the cable plus 8 mm, 8 cm along the tunnel.
        const double r0 = rho - 0.3 * f.radius;
        const double r1 = shapes.rib_inner_radius_m + 0.02;
        for (const glm::dvec2& rz : shapes.rib_z_m)
            engine::assets::add_box(clips, glm::dvec3(0.0, 0.0, 0.5 * (rz.x + rz.y)) + u * (0.5 * (r0 + r1)),
                                    u, v, w, {0.5 * (r1 - r0), f.radius + 0.008, 0.04});
        wire::WireNodes nodes;
        for (double z = 0.0; z <= total + 1e-9; z += 0.5)
            nodes.positions.push_back(chain_.transform_point({x, f.y, z}));
        const auto e = wire::systems::spawn_wire(s.registry, std::move(nodes),
                                                 {.radius_m = f.radius, .material = f.material});
        s.fixed.push_back({x, f.y, cables_.size()});
        shapes.cables.push_back({{x, f.y}, f.radius});
        cables_.push_back({.entity = e,
                           .hanging = false,
                           .material = f.material,
                           .radius_m = f.radius,
                           .section_m = {x, f.y}});
    }
    {
        Group& g = s.groups[4];
        engine::assets::ControlMesh control;
        if (auto st = engine::assets::make_control_mesh(clips, control); !st.ok()) return Error{st.message};
        g.model = engine::assets::refinement_error_model(control);
        g.controls.push_back(std::move(control));
        if (auto st = refine_group(g, s.settings.max_subdivision_level, s.pieces); !st.ok())
            return Error{st.message};
    }
    return {};
}

void Level::update_cables() {
    State& s = *state_;
    for (const FixedCable& f : s.fixed) {
        wire::WireNodes& nodes = wire::systems::edit_nodes(s.registry, cables_[f.cable].entity);
        for (std::size_t i = 0; i < nodes.positions.size(); ++i)
            nodes.positions[i] = chain_.transform_point({f.x, f.y, 0.5 * static_cast<double>(i)});
    }
    // Turns, on the bent nodes the wire systems draw.
    stats_.rope_max_turn_deg = 0.0;
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
        ropes_[r].write_nodes(s.scratch);
        auto& x = s.scratch.positions;
        for (glm::dvec3& p : x) p = chain_.transform_point(p);
        for (std::size_t i = 1; i + 1 < x.size(); ++i) {
            const glm::dvec3 a = x[i] - x[i - 1];
            const glm::dvec3 b = x[i + 1] - x[i];
            const double la = glm::length(a), lb = glm::length(b);
            if (la < 1e-12 || lb < 1e-12) continue;
            const double turn = std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0)) * 180.0 / kPi;
            stats_.rope_max_turn_deg = std::max(stats_.rope_max_turn_deg, turn);
        }
        wire::systems::set_nodes(s.registry, cables_[s.rope_ends[r].cable].entity, s.scratch);
    }
    measure_ropes();
}

}  // namespace tunnel
