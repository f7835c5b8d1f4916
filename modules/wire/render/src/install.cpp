// The "wire.render" system (see install.hpp).
#include "wire/render/install.hpp"

namespace wire::render {

std::shared_ptr<RenderStep> install(engine::ecs::Schedule& schedule, WireRenderer& renderer,
                                    const systems::WireContext& context, const DrawSettings& settings) {
    auto step = std::make_shared<RenderStep>();
    step->settings = settings;
    schedule.add("wire.render",
                 [step, &renderer, &context](engine::ecs::Registry&, const engine::ecs::FrameContext&) {
                     step->stats = renderer.draw(context.draw_list, context.camera, step->settings);
                     ++step->frames;
                 });
    return step;
}

}  // namespace wire::render
