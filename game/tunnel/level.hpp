// The tunnel level: a chain of curved-space segments whose bends animate slowly, the tunnel pieces
// (wall, ribs, walkway, cable hooks) instanced along it and bent on the GPU at the subdivision level each
// piece needs, cables fixed along the bent walls, hanging cables simulated as ropes that refine and coarsen
// themselves, and a camera flying along the bent centre line. Everything runs as named systems of one
// engine::ecs::Schedule (timed per system):
//   tunnel.animate  segment angles at time t -> Chain; fly camera; wire context camera/viewport
//   tunnel.ropes    ropes simulated in the UNBENT tunnel space (where walkway, ribs, walls and wall cables
//   are
//                   simple shapes): Verlet/PBD step with bending, contacts and friction, rope-rope contacts,
//                   node insertion/removal
//   tunnel.cables   wall cables and rope nodes bent by the CPU transform -> wire entities; rope metrics
//   wire.curve .. wire.draw_list   (wire::systems::install)
//   tunnel.shadows  the head lamp's shadow map: the pieces' coarsest level and the wires (Output::shadow)
//   tunnel.pieces   clear, per-piece subdivision level, bent instanced pieces (GL)
//   wire.render     WireRenderer draws the frame's DrawList (GL)
// Needs a current GL 4.5 context (engine::platform::Context) for create() and frame(). level.cpp lists the
// files that implement the level, one concept each.
#pragma once

#include "tunnel/rope.hpp"
#include "tunnel/rope_contact.hpp"

#include <curved_space/chain.hpp>
#include <engine/assets/mesh_data.hpp>
#include <engine/ecs/entity.hpp>
#include <engine/ecs/schedule.hpp>
#include <engine/core/expected.hpp>
#include <engine/scene/camera.hpp>
#include <wire/curve.hpp>
#include <wire/draw.hpp>
#include <wire/nodes.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace tunnel {

using engine::Error;
using engine::Expected;
using engine::Status;

/// Fixed at creation. Zero means default.
struct LevelSettings {
    int pieces = 0;                  ///< tunnel pieces of 4 m (= curved-space segments); 0 -> 16
    uint32_t seed = 0;               ///< phases of the bend animation; 0 -> 1
    double bend_scale = 0.0;         ///< multiplies the base bend angles; 0 -> 1
    std::string asset_dir{};         ///< folder of straight_section.glb, wall_details.glb, cable_hooks.glb,
                                     ///< anchors.json; empty -> assets/tunnel, relative to the working directory
                                     ///< (the tunnel program passes the folder it found beside itself)
    int max_subdivision_level = -1;  ///< highest refinement level cached; -1 -> 4, and more as set_viewport needs
    double prewarm_s = 0.0;          ///< rope simulation before frame 0 (settles the cables); 0 -> 3 s
};

enum class CameraMode { fly, free };

/// Changeable at run time (debug panel).
struct LevelOptions {
    wire::SplineKind spline = wire::SplineKind::catmull_rom;
    double lod_tolerance_px = 0.5;
    /// Level::create sets it to the wire renderer's preferred_path() (the nodes path where compute is there).
    wire::UploadPath upload_path = wire::UploadPath::cpu_mesh;
    bool wireframe = false;
    bool pop_free = true;
    bool animate_bends = true;
    bool simulate_ropes = true;
    bool adapt_ropes = true;  ///< node insertion/removal on the hanging cables
    bool gusts = true;        ///< gusts of wind travel down the tunnel and swing the hanging cables
    bool draw_pieces = true;
    bool draw_wires = true;
    /// The head lamp (on the camera rig, 0.9 m up and 0.6 m right of the eye) casts shadows: the wires, ropes and the
    /// pieces (their coarsest level) are drawn into its map; the pieces and wires receive them.
    bool shadows = true;
    double subdivision_tolerance_px = 0.5;  ///< predicted geometric error of a piece on screen
    int max_subdivision_level =
        4;                 ///< clamp of the per-piece level (<= LevelSettings::max_subdivision_level)
    bool close_up = true;  ///< the fly camera glides to the right wall (unbent z 7.5..14) for close-ups
    double flight_speed_mps = 2.5;
    CameraMode camera_mode = CameraMode::fly;
};

/// Counts and costs of one frame.
struct LevelFrameStats {
    uint64_t frame = 0;
    double time_s = 0.0;
    std::size_t wires = 0;
    std::size_t wires_drawn = 0;    ///< draw items the wire renderer drew
    std::size_t wire_vertices = 0;  ///< cpu_mesh: uploaded; gpu_nodes: 0 (expanded on the GPU)
    std::size_t wire_triangles = 0;
    std::size_t wire_bytes_uploaded = 0;
    bool wire_waited_for_gpu =
        false;  ///< the wire renderer waited on a fence (llvmpipe: the frame's raster work)
    std::size_t segment_bytes_uploaded = 0;  ///< curved-space segment records (SSBO)
    std::size_t piece_triangles = 0;         ///< tunnel triangles drawn
    std::size_t piece_vertices = 0;          ///< tunnel vertices drawn (bent by the vertex shader)
    std::size_t rope_nodes = 0;              ///< nodes of all hanging cables
    int nodes_inserted = 0;                  ///< by the rope adaptation this frame
    int nodes_removed = 0;
    std::array<int, 8> piece_levels{};  ///< pieces per subdivision level (wall)
    std::size_t curves_built = 0;
    std::size_t rings = 0;
    /// GPU ms of the tunnel and wire passes (GL_TIME_ELAPSED, engine::gfx::GpuTimer): the newest results read
    /// back without stalling, measured in frame gpu_ms_frame (a few frames ago; -1 and 0 ms before the
    /// first).
    double pieces_gpu_ms = 0.0;
    double wires_gpu_ms = 0.0;
    int64_t gpu_ms_frame = -1;
    double rope_max_turn_deg = 0.0;   ///< largest angle between consecutive elements of any rope (bent nodes)
    double rope_penetration_m = 0.0;  ///< deepest penetration of a rope's tube (its rendered curve) into the
                                      ///< walkway, ribs, walls, wall cables or another rope (0: none)
    double piece_max_error_px = 0.0;  ///< worst predicted geometric error on screen of a visible piece
    double camera_rope_m = 0.0;       ///< distance from the eye to the nearest rope centre line
    double camera_cable_m = 0.0;      ///< distance from the eye to the nearest wall cable centre line
};

/// A cable of the level, for tests and the debug panel.
struct CableInfo {
    engine::ecs::Entity entity{};
    bool hanging = false;  ///< rope-simulated (else fixed along the wall)
    bool across = false;   ///< hanging from one wall to the other (else a festoon along one wall)
    int rope = -1;         ///< index into the ropes when hanging
    uint32_t material = 0;
    float radius_m = 0.0f;
    glm::dvec2 section_m{0.0};  ///< fixed cables: unbent cross-section position (x, y); runs along all z
};

class Level {
public:
    /// Loads the pieces, refines and uploads the cached subdivision levels, compiles the shaders, spawns the
    /// cables and pre-simulates the ropes. Errors name the file or shader that failed.
    static Expected<std::unique_ptr<Level>> create(const LevelSettings& settings = {});
    ~Level();
    Level(const Level&) = delete;
    Level& operator=(const Level&) = delete;

    /// Framebuffer size the frame is rendered at (camera aspect, LOD).
    void set_viewport(int width_px, int height_px);
    /// Advances by dt_s (use a fixed step for reproducible images) and renders into the bound framebuffer.
    void frame(double dt_s);
    /// Renders the current state again without advancing (e.g. after toggling draw_wires).
    void render();

    LevelOptions& options() { return options_; }
    /// The camera of the last frame; in CameraMode::free the game moves it.
    engine::scene::Camera& camera() { return camera_; }
    [[nodiscard]] const curved_space::Chain& chain() const { return chain_; }
    [[nodiscard]] const LevelFrameStats& stats() const { return stats_; }
    [[nodiscard]] std::span<const engine::ecs::SystemStats> system_stats() const { return schedule_.stats(); }
    [[nodiscard]] const std::vector<CableInfo>& cables() const { return cables_; }
    [[nodiscard]] const std::vector<Rope>& ropes() const { return ropes_; }
    /// The nodes the wire systems currently hold for a cable.
    [[nodiscard]] const wire::WireNodes& cable_nodes(std::size_t cable) const;
    /// The curve the wire systems draw for a cable (pop-free: blended while rope nodes appear or vanish). Empty
    /// while a moving cable is culled (the systems release its curve until it is in view again: WireCurve).
    [[nodiscard]] const wire::Curve& cable_curve(std::size_t cable) const;
    /// Bent world position of an anchor of piece `piece` (anchor index as in anchors.json).
    [[nodiscard]] glm::dvec3 anchor_world(int piece, std::size_t anchor) const;
    /// Unbent z (along the chain) of the fly camera in the last frame.
    [[nodiscard]] double flight_z_m() const;
    [[nodiscard]] int piece_count() const;
    [[nodiscard]] double piece_length_m() const;
    /// The tunnel wall radius (m) of the pieces.
    [[nodiscard]] double wall_radius_m() const;
    /// What the ropes collide with (unbent space).
    [[nodiscard]] const LevelShapes& shapes() const;
    /// The subdivision level `group` (0 wall, 1 ribs, 2 walkway, 3 hooks, 4 clips) is cached up to, refined.
    [[nodiscard]] const engine::assets::MeshData& refined_mesh(std::size_t group) const;

private:
    struct State;  // level_state.hpp
    Level();
    // Creation, in order (create()): pieces (piece_meshes), anchors, chain (level_animation), wire renderer
    // (level_render), fixed cables and clips (level_cables), ropes (rope_driving), settling, systems.
    Status load_pieces();
    void build_chain();
    Status create_wire_renderer();
    Status spawn_fixed_cables();
    void spawn_ropes();
    void settle();
    void install_systems();
    // The frame's systems and their parts.
    void animate(double time_s);
    void update_ropes(double dt_s);
    void update_cables();
    void choose_piece_levels();
    void draw_pieces();
    void measure_ropes();
    void draw_wires();
    void draw_shadow_map();
    void apply_options();
    glm::dvec3 rope_end(int piece, std::size_t anchor, double inset_m, double lift_m) const;

    std::unique_ptr<State> state_;
    LevelOptions options_{};
    LevelOptions applied_{};
    engine::scene::Camera camera_{};
    curved_space::Chain chain_{};
    engine::ecs::Schedule schedule_{};
    LevelFrameStats stats_{};
    std::vector<CableInfo> cables_;
    std::vector<Rope> ropes_;
};

}  // namespace tunnel
