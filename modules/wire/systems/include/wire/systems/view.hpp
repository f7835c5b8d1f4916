// The camera as the wire LOD sees it: engine::scene::Camera plus the viewport size -> wire::LodView
// (double).
#pragma once

#include "wire/lod.hpp"

#include <engine/scene/camera.hpp>

namespace wire::systems {

/// LodView of `camera` over a width_px x height_px viewport (width_px = camera.aspect * height_px for square
/// pixels). The camera's float position and target are widened to double.
[[nodiscard]] LodView lod_view(const engine::scene::Camera& camera, double width_px, double height_px);

}  // namespace wire::systems
