// The tunnel level's private state, shared by the files that implement Level (level.cpp and those it names):
// not part of the level's interface.
#pragma once

#include "tunnel/level.hpp"
#include "tunnel/piece_meshes.hpp"
#include "tunnel/piece_renderer.hpp"
#include "tunnel/rope_contact.hpp"

#include <curved_space/chain.hpp>
#include <engine/ecs/registry.hpp>
#include <engine/gfx/gpu_timer.hpp>
#include <engine/gfx/shadow.hpp>
#include <optional>
#include <wire/nodes.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace tunnel {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kWallRadius = 2.5;
// Subdivision levels cached at 720 p (LevelSettings::max_subdivision_level -1); set_viewport adds what a larger
// viewport needs.
inline constexpr int kDefaultMaxSubdivisionLevel = 4;

// Wire materials (indices into the WireRenderer's table; 0 is its copper weave).
enum WireMaterial : uint32_t { copper = 0, rubber, orange, yellow, blue, red };

// One segment's bend over time: angle and direction, each a base plus a slow sine.
struct SegmentAnimation {
    double base_angle = 0.0;
    double angle_amp = 0.0;
    double angle_freq = 0.0;
    double angle_phase = 0.0;
    double dir_amp = 0.0;
    double dir_freq = 0.0;
    double dir_phase = 0.0;
};

// A cable fixed along the wall.
struct FixedCable {
    double x = 0.0, y = 0.0;  // unbent cross-section position
    std::size_t cable = 0;
};

// Where a hanging cable's ends sit (hooks of one or two pieces) and the bend at its piece.
struct RopeEnds {
    int piece_a = 0;
    std::size_t anchor_a = 0;
    int piece_b = 0;
    std::size_t anchor_b = 0;
    std::size_t cable = 0;
    glm::dmat4 world_from_piece{1.0};  // the piece's frame when the rope was last moved with it
    double inset_m = 0.0;              // ends moved this far from the hook toward the axis (festoons)
    double lift_m = 0.0;               // ends raised this far (the cable rests on the hook)
    double z_scale = 1.0;              // smallest stretch of z by the bend over the rope's piece (this frame)
};

// Deterministic [0, 1) from an integer (no library distribution: the same phases everywhere).
inline double hash01(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return static_cast<double>(x) / 4294967296.0;
}

// Everything the level owns besides what level.hpp shows.
/// The head lamp's view (level_render.cpp): 0.9 m above and 0.6 m right of the eye, looking where the camera looks.
engine::scene::Camera head_lamp_view(const engine::scene::Camera& camera);

struct Level::State {
    LevelSettings settings;
    engine::ecs::Registry registry;
    wire::systems::WireContext context;
    wire::render::WireRenderer wires;
    PieceRenderer pieces;
    std::optional<engine::gfx::ShadowMap> head_lamp;  ///< the head lamp's shadow map (options.shadows)
    std::vector<Group> groups;
    std::vector<glm::dvec3> anchors;  // unbent, in piece space
    std::vector<SegmentAnimation> animation;
    std::vector<curved_space::Segment> segments;
    std::vector<FixedCable> fixed;
    std::vector<RopeEnds> rope_ends;
    wire::WireNodes scratch;
    int width_px = 1280;
    int height_px = 720;
    double time_s = 0.0;
    double fly_distance_m = 0.0;
    double rope_time_s = 0.0;  // simulated rope time since frame 0 (drives the gusts)
    double flight_z_m = 0.0;   // unbent z of the fly camera
    wire::render::DrawStats wire_stats{};
    std::vector<float> bucket;
    engine::gfx::GpuTimer pieces_timer, wires_timer;  // GPU ms per pass, read back a few frames later
    std::map<uint64_t, std::pair<double, double>> gpu_results;  // frame -> (pieces, wires) ms, -1 = not yet
    LevelShapes shapes;
    std::vector<std::array<int, kGroups>> levels;  // per piece and group, -1: not visible
};

}  // namespace tunnel
