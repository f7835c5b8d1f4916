// The coarse tunnel pieces, authored in code: quads written as triangle pairs (a,b,c), (a,c,d) so that
// engine::assets::make_control_mesh recovers them for Catmull-Clark refinement.
#pragma once

#include <engine/assets/mesh_data.hpp>

#include <string>
#include <vector>

namespace tunnel {

/// Dimensions shared by every piece (metres). The pieces run along +z from 0 to length_m, the tunnel axis is
/// x = y = 0 (the curved_space bend axis), +y is up.
struct TunnelSpec {
    float length_m = 4.0f;
    float radius_m = 2.5f;      ///< inner wall polygon's vertex radius
    int around = 12;            ///< wall segments around
    int along = 4;              ///< wall segments along (1 m each)
    float walkway_top_y_m = -1.85f;
};

/// A cable anchor: where a cable rests on a hook, in the piece's unbent space.
struct Anchor {
    std::string name;  ///< "anchor_0", ... (also the name of the hook mesh whose origin it is)
    double x = 0, y = 0, z = 0;
};

/// straight_section.glb: "tunnel_wall", the inner wall tube (normals toward the axis, open ends).
std::vector<engine::assets::MeshData> straight_section(const TunnelSpec& spec = {});
/// wall_details.glb: "rib_0".."rib_3" (closed ring bands at z = 0, 1, 2, 3) and "walkway" (a closed slab).
std::vector<engine::assets::MeshData> wall_details(const TunnelSpec& spec = {});
/// cable_hooks.glb: one J-bracket per anchor, mesh name = anchor name, mesh origin = anchor position.
std::vector<engine::assets::MeshData> cable_hooks(const TunnelSpec& spec = {});
/// The anchors of cable_hooks(), in the same order.
std::vector<Anchor> anchors(const TunnelSpec& spec = {});
/// anchors.json text: {"units": "m", "space": ..., "anchors": [{"name": "anchor_0", "position": [x, y, z]}, ...]}.
std::string anchors_json(const std::vector<Anchor>& anchors);

}  // namespace tunnel
