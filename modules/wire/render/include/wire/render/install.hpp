// The render step of a frame, as a system: wire::render::install() adds "wire.render" to a schedule after the
// wire systems (wire::systems::install), so a program's frame is one Schedule::run.
//
// \code
//   wire::systems::install(schedule, context);                       // curve -> lod -> rings -> mesh ->
//   draw_list auto step = wire::render::install(schedule, renderer, context);  // wire.render: draws
//   context.draw_list schedule.run(registry, dt);                                      // step->stats: what
//   the draw did
// \endcode
#pragma once

#include "wire/render/wire_renderer.hpp"
#include "wire/systems/context.hpp"

#include "engine/ecs/schedule.hpp"

#include <memory>

namespace wire::render {

/// The "wire.render" system's state, shared by the schedule and the caller.
struct RenderStep {
    /// The settings of each frame's draw (light, output, shadow map received...): the caller may change them
    /// between frames.
    DrawSettings settings{};
    /// What the last frame's draw did (DrawStats::status: whether it drew; a failure is also logged once).
    DrawStats stats{};
    /// Frames drawn so far.
    std::size_t frames = 0;
};

/// Adds the system "wire.render" to `schedule`: each frame it draws context.draw_list from context.camera
/// with the step's settings into the bound framebuffer (WireRenderer::draw: depth-tested, not cleared). The
/// list carries the systems' upload path and LOD, so the picture is the same on every path with nothing
/// copied by hand. Add it after wire::systems::install (and after the systems that draw what the wires are
/// depth-tested against). `renderer` and `context` must outlive the schedule. Returns the step (its settings,
/// the last frame's stats).
std::shared_ptr<RenderStep> install(engine::ecs::Schedule& schedule, WireRenderer& renderer,
                                    const systems::WireContext& context, const DrawSettings& settings = {});

}  // namespace wire::render
