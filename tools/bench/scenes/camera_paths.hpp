// The benches' cameras: the wire systems bench's camera paths, one position and target per frame of each
// scene (field_scenes.hpp), and the accuracy bench's fixed view of one whole wire (reference_scenes.hpp).
#pragma once

#include "bench/scenes/field_scenes.hpp"

#include <engine/scene/camera.hpp>
#include <wire/lod.hpp>

#include <glm/vec3.hpp>

#include <vector>

namespace wiretool::bench {

/// standard/swaying: flies slowly into the field, swaying, so every frame moves the camera. offscreen: the
/// same motion sideways, 12 m in front of the field and looking away from it: every wire is behind the
/// camera. far: flying over the landscape 45 m up along a gentle curve. Sets `cam`'s position and target
/// only.
void place_camera(engine::scene::Camera& cam, SceneKind kind, int frame);

/// A camera that sees the whole wire through `positions` at 1920x1080, 60 degrees, from slightly above and to
/// the side.
wire::LodView whole_wire_view(const std::vector<glm::dvec3>& positions);

}  // namespace wiretool::bench
