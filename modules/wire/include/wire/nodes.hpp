// Input of the curve stage: a wire's lumped-element nodes (struct of arrays) and the spline settings.
#pragma once

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

/// The wire module: curves through lumped-element nodes, rotation-minimizing frames, rings, tube meshes,
/// tessellation and screen-space LOD on plain arrays (no GL, no ECS); see wire::systems and wire::render.
namespace wire {

/// One wire's nodes in struct-of-arrays form. Only `positions` is required; every other array is either
/// empty (use the default named below) or exactly as long as `positions`.
struct WireNodes {
    std::vector<glm::dvec3> positions;  ///< metres, world space, ordered along the wire
    std::vector<uint32_t> ids;          ///< stable across frames (multiresolution); empty: id = index
    std::vector<float> stretch;         ///< L_current / L_rest of the element starting at this node; empty: 1; must be > 0
    std::vector<float> radius_m;        ///< tube radius at this node; 0 (or empty): the wire's radius; negative: error

    // Optional physics per node for the thesis' curvature-driven tension R = theta*Iz*L / (A*dL^2).
    // Used when SplineSettings::curvature_tension is set and all five arrays are present.
    std::vector<double> theta_rad;       ///< angle between the node's two adjacent elements
    std::vector<double> iz_m4;           ///< second moment of inertia about the neutral axis
    std::vector<double> length_m;        ///< length of the two adjacent elements
    std::vector<double> delta_length_m;  ///< stretch (elongation) of the two adjacent elements; 0: no tension
    std::vector<double> area_m2;         ///< cross-section area (> 0)

    // Optional per-node Kochanek-Bartels parameters; when present they replace the wire-wide values.
    std::vector<float> kb_tension;     ///< per-node Kochanek-Bartels tension
    std::vector<float> kb_bias;        ///< per-node Kochanek-Bartels bias
    std::vector<float> kb_continuity;  ///< per-node Kochanek-Bartels continuity

    /// Number of nodes (positions.size()).
    [[nodiscard]] std::size_t size() const { return positions.size(); }
};

/// Calls f(name, member) for each optional per-node array of WireNodes (every one but positions), in declaration
/// order, with its name as in error messages and a pointer to the member (`nodes.*member` is the array): the one
/// list of them that inserting and removing a node, copying, sizing and validating walk.
template <class F>
constexpr void for_each_node_array(F&& f) {
    f("ids", &WireNodes::ids);
    f("stretch", &WireNodes::stretch);
    f("radius_m", &WireNodes::radius_m);
    f("theta_rad", &WireNodes::theta_rad);
    f("iz_m4", &WireNodes::iz_m4);
    f("length_m", &WireNodes::length_m);
    f("delta_length_m", &WireNodes::delta_length_m);
    f("area_m2", &WireNodes::area_m2);
    f("kb_tension", &WireNodes::kb_tension);
    f("kb_bias", &WireNodes::kb_bias);
    f("kb_continuity", &WireNodes::kb_continuity);
}
static_assert(sizeof(WireNodes) == 12 * sizeof(std::vector<double>),
              "WireNodes: an array added? list it in for_each_node_array");

/// The curve through the nodes.
enum class SplineKind : uint8_t {
    catmull_rom = 0,  ///< local, C1; any alpha; cardinal tension / Kochanek-Bartels / curvature tension apply
    c2,               ///< global C2 interpolating cubic, chordal knots (Thomas / Sherman-Morrison solve)
    automatic,        ///< nu-spline under tension: c2 where turning is spread out, straight runs at concentrated turns (spline.hpp)
    linear,           ///< straight segments (degenerate cubics), for baselines
};

/// The radius of a wire whose settings and nodes give none (0): 1 cm. Metres.
inline constexpr float kDefaultWireRadius_m = 0.01f;

/// Largest accepted |coordinate| of a node, metres (the curve stage refuses a node beyond it): the tube's float
/// vertices (relative to ring 0) and squared chord lengths must stay finite; 1e12 m is far beyond any scene.
inline constexpr double kMaxCoordinate_m = 1e12;

/// Settings of the curve stage. Default-initialized (`SplineSettings{}` or `{.closed = true}`) is sensible:
/// centripetal Catmull-Rom, no tension, open wire, radius 1 cm, merge epsilon 1e-9 of the scene scale.
struct SplineSettings {
    SplineKind kind = SplineKind::catmull_rom;  ///< curve family
    double alpha = 0.5;       ///< knot exponent: 0 uniform, 0.5 centripetal, 1 chordal; any finite value
    double tension = 0.0;     ///< cardinal / Kochanek-Bartels tension, wire-wide (1 = straight segments)
    double bias = 0.0;        ///< Kochanek-Bartels bias, wire-wide
    double continuity = 0.0;  ///< Kochanek-Bartels continuity, wire-wide (non-zero breaks C1 on purpose)
    bool curvature_tension = true;  ///< use R = theta*Iz*L/(A*dL^2) for nodes that carry the physics arrays
    bool closed = false;            ///< closed loop: the last node connects back to the first
    /// The wire's radius, used where a node's radius is 0; must be > 0 (0: kDefaultWireRadius_m, 1 cm).
    float radius_m = kDefaultWireRadius_m;
    /// Nodes closer than merge_epsilon_rel * max(bounding-box diagonal, 1e-300) are merged (the first one is kept).
    /// 1e-9 sits ~3 decades below any physical spacing (a 100,000-node wire spaces at 1e-5 of its diagonal, the
    /// DESIGN spacing ratio 1e6 at 1e-6) and ~6 decades above double rounding (2.2e-16 relative), so it merges
    /// only nodes that are coincident up to noise. 0: default 1e-9. A floor of 64 ulps of the coordinates
    /// (far from the origin) is always applied.
    double merge_epsilon_rel = 1e-9;

    friend bool operator==(const SplineSettings&, const SplineSettings&) = default;
};

}  // namespace wire
