// The wire systems and their order. install() registers, in this order, on a schedule:
// \verbatim
//   wire.curve      wires whose Nodes or Style changed since it last ran (change tracking), plus wires in
//                   a blend: pop-free curve (pop_free.hpp); bad nodes -> WireError, reported once,
//                   wire skipped
//   wire.lod        if the camera (or LOD settings) changed: every wire; otherwise only wires whose curve
//                   changed: hull culling, per-segment ring counts, sides, hysteresis (lod.hpp); releases
//                   the curve of a wire culled while moving and rebuilds it when the view turns to it
//                   (WireCurve)
//   wire.rings      visible wires whose curve or counts changed: ring records, first normal carried over
//   wire.mesh       cpu_mesh path: visible wires whose rings or sides changed: TubeVertex + indices;
//                   gpu_nodes path: nothing (nor the rings before it: the GPU builds them)
//   wire.draw_list  the frame's DrawList: visible wires in entity order, spans into the per-wire arrays
// \endverbatim
// The renderer adds its upload/render systems after these, reading WireContext::draw_list.
// Per-wire work runs with tbb::parallel_for over a dense array of the wires to process; each wire writes
// only its own components, and lists are ordered by entity, so the output does not depend on the thread
// count.
#pragma once

#include "wire/systems/context.hpp"
#include "wire/rings.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>

#include <cstddef>
#include <cstdint>

namespace wire::systems {

/// Names of the systems install() adds, in run order (as engine::ecs::Schedule::stats() reports them).
inline constexpr const char* kCurveSystem = "wire.curve";
inline constexpr const char* kLodSystem = "wire.lod";      ///< second system, after kCurveSystem
inline constexpr const char* kRingsSystem = "wire.rings";  ///< third system
inline constexpr const char* kMeshSystem = "wire.mesh";    ///< fourth system
inline constexpr const char* kDrawListSystem =
    "wire.draw_list";  ///< last system: fills WireContext::draw_list

/// Adds the five wire systems to `schedule` in the order above. `context` must outlive the schedule.
void install(engine::ecs::Schedule& schedule, WireContext& context);

// The systems one by one (install() calls these; tests and tools may too).

/// Curve stage (wire.curve): rebuilds the curve of wires whose Nodes or Style changed since registry tick
/// `since` (the curve system's previous run, FrameContext::last_run_tick) and of wires in a blend; resets
/// WireContext::stats; reports new WireErrors.
void curve_system(engine::ecs::Registry& registry, WireContext& context, uint64_t since);
/// LOD stage (wire.lod): visibility and per-segment ring counts for the context's camera (every wire when the
/// camera or the LOD settings changed, otherwise only wires whose curve changed).
void lod_system(engine::ecs::Registry& registry, WireContext& context);
/// Ring stage (wire.rings): ring records of visible wires whose curve or LOD changed.
void rings_system(engine::ecs::Registry& registry, WireContext& context);
/// Mesh stage (wire.mesh, UploadPath::cpu_mesh only): tube vertices and indices of visible wires whose rings
/// or sides changed.
void mesh_system(engine::ecs::Registry& registry, WireContext& context);
/// Draw-list stage (wire.draw_list): fills WireContext::draw_list with the visible wires, in entity order.
void draw_list_system(engine::ecs::Registry& registry, WireContext& context);

/// Centre-line screen error of one wire's current tessellation against a dense reference of its rendered curve
/// (samples_per_segment per segment), seen by the context's camera; zero-sample result if the wire is culled.
[[nodiscard]] ScreenError wire_screen_error(engine::ecs::Registry& registry, const WireContext& context,
                                            engine::ecs::Entity wire, int samples_per_segment = 64);

/// The largest wire_screen_error over the visible wires of the last draw list.
[[nodiscard]] ScreenError scene_screen_error(engine::ecs::Registry& registry, const WireContext& context,
                                             int samples_per_segment = 64);

/// The wire's current rings with every per-ring array build_rings produces (double frames, centres, arc length,
/// u), which WireRings does not keep: recomputed from the wire's curve and ring parameters with the settings of
/// its last ring build, so it equals what the rings system built, bit for bit. False (out untouched) if the wire
/// has no rings for its current curve (culled, released, or not built yet).
bool wire_ring_set(engine::ecs::Registry& registry, engine::ecs::Entity wire, RingSet& out);

/// Heap memory the wire systems hold for their own per-wire state: the capacity of the containers in WireCurve
/// (curve, previous nodes, LOD bounds), WireLodState, WireRings and WireMesh, summed, plus the components' sizes,
/// split by the wire's last LOD visibility. What is kept: see WireCurve (a culled moving wire releases its curve,
/// a moving wire keeps no LodBounds), WireRings (a culled moving wire releases its rings) and WireMesh; a culled
/// wire keeps no LOD counts. Nodes (the game's input) is reported apart. The pop-free state's
/// private buffers are estimated from its target curve (target and rendered curve, one id per node) while it is
/// live; a released (stale) state holds nothing.
struct WireMemory {
    std::size_t visible_wires = 0;  ///< wires the LOD last found visible
    std::size_t culled_wires = 0;   ///< wires the LOD last culled (or not yet seen by the LOD)
    std::size_t visible_bytes = 0;  ///< systems' state of the visible wires, bytes
    std::size_t culled_bytes = 0;   ///< systems' state of the culled wires, bytes
    std::size_t curve_bytes = 0;    ///< WireCurve of all wires, bytes
    std::size_t lod_bytes = 0;      ///< WireLodState of all wires, bytes
    std::size_t rings_bytes = 0;    ///< WireRings of all wires, bytes
    std::size_t mesh_bytes = 0;     ///< WireMesh of all wires (the cpu_mesh path's output), bytes
    std::size_t nodes_bytes = 0;    ///< Nodes components (the game's input, not the systems' state), bytes
};

/// Sums the memory the wire systems hold for every wire of `registry` (see WireMemory); O(wires), no allocation.
[[nodiscard]] WireMemory wire_memory(engine::ecs::Registry& registry);
/// The same for one wire (all zero if it is not a wire).
[[nodiscard]] WireMemory wire_memory(engine::ecs::Registry& registry, engine::ecs::Entity wire);

}  // namespace wire::systems
