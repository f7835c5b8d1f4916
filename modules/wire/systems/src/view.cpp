// engine::scene::Camera -> wire::LodView.
#include "wire/systems/view.hpp"

namespace wire::systems {

LodView lod_view(const engine::scene::Camera& camera, double width_px, double height_px) {
    if (camera.orthographic()) {
        return LodView::orthographic(camera.position, camera.target, camera.up,
                                     static_cast<double>(camera.ortho_half_height_m), width_px, height_px,
                                     static_cast<double>(camera.near_m), static_cast<double>(camera.far_m));
    }
    return LodView::perspective(camera.position, camera.target, camera.up,
                                static_cast<double>(camera.fov_y_rad), width_px, height_px,
                                static_cast<double>(camera.near_m), static_cast<double>(camera.far_m));
}

}  // namespace wire::systems
