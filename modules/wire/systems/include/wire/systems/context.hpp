// What the wire systems share for one scene: the camera and settings the game sets each frame, the frame's
// DrawList and statistics they produce, and their work lists. One WireContext per registry and schedule.
#pragma once

#include "wire/draw.hpp"
#include "wire/lod.hpp"

#include <engine/ecs/entity.hpp>
#include <engine/scene/camera.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace wire::systems {

/// Counts of one frame (reset by the curve system, filled by each system). "Rebuilt" counts are the work done.
struct RunStats {
    std::size_t wires = 0;             ///< wire entities (with Nodes and Style)
    std::size_t curves_built = 0;      ///< curve stage runs (changed nodes/style, or an ongoing blend)
    std::size_t lod_updates = 0;       ///< update_lod runs (hull tests); 0 when nothing moved
    std::size_t curves_released = 0;   ///< culled moving wires holding no curve after this frame: released by the
                                       ///< LOD stage, or rebuilt in the curve stage's per-thread buffer only
                                       ///< (still outside the view; WireCurve)
    std::size_t curves_restored = 0;   ///< released curves rebuilt (the view turned to them, or invalid nodes)
    std::size_t visible_wires = 0;     ///< wires in the draw list (valid curve, inside the view)
    std::size_t culled_wires = 0;      ///< wires with a valid curve outside the view
    std::size_t rings_built = 0;       ///< wires whose rings were rebuilt
    std::size_t meshes_built = 0;      ///< wires whose mesh was rebuilt (cpu_mesh path)
    std::size_t rings = 0;             ///< rings of the visible wires
    std::size_t vertices = 0;          ///< mesh vertices of the visible wires (cpu_mesh), or rings * (sides + 1)
    std::size_t indices = 0;           ///< mesh indices of the visible wires (cpu_mesh)
    std::size_t draw_items = 0;        ///< items in WireContext::draw_list
    std::size_t errors = 0;            ///< wires with a WireError
};

/// A wire error as reported once.
struct ErrorReport {
    engine::ecs::Entity entity = engine::ecs::null_entity;  ///< the wire
    std::string message;  ///< WireError::message, e.g. "wire entity 12 (index 12, version 0): node 3:
                          ///< position.y is NaN"
};

/// What the wire systems share for one scene: the game sets the camera, viewport and settings before
/// Schedule::run; the systems leave the frame's draw list, statistics and new errors here. One per registry
/// and schedule; it must outlive the schedule it was installed on (install()).
struct WireContext {
    // ---- set by the game ----
    engine::scene::Camera camera{};      ///< the camera the wires are seen from (LOD and culling)
    double viewport_width_px = 1920.0;   ///< viewport the frame is drawn into, pixels (LOD screen error)
    double viewport_height_px = 1080.0;  ///< viewport height, pixels
    /// The other views the frame draws the list from (a light's shadow map, a second camera): on the nodes path a
    /// wire inside any of them, or the camera, stays in the draw list (each view then culls and chooses its LOD on
    /// the GPU), so a cable above the camera's view still casts its shadow into it. cpu-mesh builds rings for the
    /// camera only and ignores them.
    std::vector<engine::scene::Camera> other_views;
    LodSettings lod{};                           ///< tolerance (px), max rings per segment, hysteresis
    UploadPath path = UploadPath::cpu_mesh;      ///< cpu_mesh builds meshes; gpu_nodes packs nodes
    bool pop_free = true;                        ///< blend when node ids appear or vanish (pop_free.hpp)
    /// A wire whose curve changed goes on through lod, rings and mesh right after its curve, on the same thread,
    /// while its curve and rings are still in cache (a moving wire's intermediates are not written out and read
    /// back by the next pass over all wires). Same results either way; false: stage by stage (to compare).
    bool fused_stages = true;
    /// Called once per new error (after the curve system, in entity order). Empty: nothing is called.
    std::function<void(const ErrorReport&)> on_error;

    // ---- produced by the systems each frame ----
    DrawList draw_list;                          ///< valid until the systems run again
    RunStats stats;                            ///< counts of the last Schedule::run
    std::vector<ErrorReport> new_errors;         ///< errors that appeared this frame

    // ---- the systems' own bookkeeping ----
    LodView view{};                              ///< the camera as the LOD sees it (double)
    std::vector<LodView> other_lod_views;        ///< other_views as the cull sees them (nodes path)
    uint64_t view_generation = 0;                ///< +1 whenever `view` or the LOD settings change
    LodSettings seen_lod{};                      ///< the LOD settings `view_generation` was taken with
    bool has_view = false;                       ///< `view` was computed at least once
    uint64_t lod_pass_generation = 0;            ///< view_generation the LOD last visited every wire for
    std::vector<engine::ecs::Entity> curve_changed;  ///< wires whose curve changed this frame
    std::vector<engine::ecs::Entity> blending;       ///< wires in a blend (their curve changes next frame)
    /// The path the curve stage last ran for: a change rebuilds every wire (the nodes path keeps packed nodes and
    /// no curve, the others a curve; each needs its own).
    UploadPath seen_path = UploadPath::cpu_mesh;
    bool has_seen_path = false;
};

}  // namespace wire::systems
