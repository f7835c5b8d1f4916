// The wire systems and their order. install() registers, in this order, on a schedule:
//   wire.curve      wires whose Nodes or Style changed since it last ran (change tracking), plus wires in a
//                   geomorph: pop-free curve (multires.hpp); bad nodes -> WireError, reported once, wire skipped
//   wire.lod        if the camera (or LOD settings) changed: every wire; otherwise only wires whose curve changed:
//                   hull culling, per-segment ring counts, sides, hysteresis (lod.hpp)
//   wire.rings      visible wires whose curve or counts changed: ring records, first normal carried over
//   wire.mesh       cpu_mesh path: visible wires whose rings or sides changed: TubeVertex + indices;
//                   gpu_rings path: nothing
//   wire.draw_list  the frame's DrawList: visible wires in entity order, spans into the per-wire arrays
// The renderer adds its upload/render systems after these, reading WireContext::draw_list.
// Per-wire work runs with tbb::parallel_for over a dense array of the wires to process; each wire writes only
// its own components, and lists are ordered by entity, so the output does not depend on the thread count.
#pragma once

#include "wire/systems/context.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>

#include <cstdint>

namespace wire::systems {

/// Names of the systems install() adds, in run order.
inline constexpr const char* kCurveSystem = "wire.curve";
inline constexpr const char* kLodSystem = "wire.lod";
inline constexpr const char* kRingsSystem = "wire.rings";
inline constexpr const char* kMeshSystem = "wire.mesh";
inline constexpr const char* kDrawListSystem = "wire.draw_list";

/// Adds the five wire systems to `schedule` in the order above. `context` must outlive the schedule.
void install(engine::ecs::Schedule& schedule, WireContext& context);

// The systems one by one (install() calls these; tests and tools may too). `since` is the registry tick of the
// curve system's previous run (FrameContext::last_run_tick).
void curve_system(engine::ecs::Registry& registry, WireContext& context, uint64_t since);
void lod_system(engine::ecs::Registry& registry, WireContext& context);
void rings_system(engine::ecs::Registry& registry, WireContext& context);
void mesh_system(engine::ecs::Registry& registry, WireContext& context);
void draw_list_system(engine::ecs::Registry& registry, WireContext& context);

/// Centre-line screen error of one wire's current tessellation against a dense reference of its rendered curve
/// (samples_per_segment per segment), seen by the context's camera; zero-sample result if the wire is culled.
[[nodiscard]] ScreenError wire_screen_error(engine::ecs::Registry& registry, const WireContext& context,
                                            engine::ecs::Entity wire, int samples_per_segment = 64);

/// The largest wire_screen_error over the visible wires of the last draw list.
[[nodiscard]] ScreenError scene_screen_error(engine::ecs::Registry& registry, const WireContext& context,
                                             int samples_per_segment = 64);

}  // namespace wire::systems
