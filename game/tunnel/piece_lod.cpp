// Piece level of detail: per visible piece and group, the subdivision level its bend and its distance on
// screen need for the predicted geometric error to stay within the tolerance (engine::assets error model).
#include "tunnel/level_state.hpp"

#include <engine/assets/subdivide.hpp>
#include <engine/scene/frustum.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace tunnel {

void Level::choose_piece_levels() {
    State& s = *state_;
    stats_.piece_levels.fill(0);
    stats_.piece_max_error_px = 0.0;
    const glm::dvec3 eye = camera_.position;
    // Per piece: visible? and the level its bend and its distance on screen need, per group (the caches
    // hold every level up to the cap). The distance of a group: along the bent centre line to the piece, and
    // radially from the eye to the group's innermost surface (the wall's, the ribs' inner faces, ...).
    const engine::scene::Frustum frustum =
        engine::scene::Frustum::from_view_projection(camera_.clip_from_relative());  // offsets from the eye
    const double focal_px = camera_.focal_px(static_cast<float>(s.height_px));
    const int max_level = std::clamp(options_.max_subdivision_level, 0, s.settings.max_subdivision_level);
    const int n = piece_count();
    s.levels.assign(static_cast<std::size_t>(n), {-1, -1, -1, -1, -1});
    for (int k = 0; k < n; ++k) {
        const double z0 = kPieceLength * k;
        const curved_space::Aabb box = chain_.bounds({{-2.7, -2.7, z0}, {2.7, 2.7, z0 + kPieceLength}});
        if (!frustum.intersects_aabb(glm::vec3(box.min - eye), glm::vec3(box.max - eye))) continue;
        std::array<double, kGroups> distance;
        distance.fill(1e30);
        constexpr int kSamples = 8;
        for (int j = 0; j <= kSamples; ++j) {
            const double z = z0 + kPieceLength * j / kSamples;
            const glm::dvec3 c = chain_.transform_point({0.0, 0.0, z});
            const glm::dvec3 t = glm::normalize(chain_.transform_point({0.0, 0.0, z + 0.01}) - c);
            const glm::dvec3 v = eye - c;
            const double along = std::max(0.0, std::abs(glm::dot(v, t)) - 0.5 * kPieceLength / kSamples);
            const double radial = glm::length(v - glm::dot(v, t) * t);
            for (std::size_t g = 0; g < kGroups; ++g) {
                const double gap = std::max(0.0, s.groups[g].inner_radius_m - radial);
                distance[g] = std::min(distance[g], std::sqrt(along * along + gap * gap));
            }
        }
        const double curvature =
            std::abs(chain_.segment(static_cast<std::size_t>(k)).angle_rad) / kPieceLength;
        for (std::size_t g = 0; g < kGroups; ++g) {
            const int level = engine::assets::choose_subdivision_level(
                s.groups[g].model, {.curvature_per_m = curvature,
                                    .distance_m = distance[g],
                                    .focal_px = focal_px,
                                    .tolerance_px = options_.subdivision_tolerance_px,
                                    .max_level = max_level});
            s.levels[static_cast<std::size_t>(k)][g] = level;
            const double error_px = engine::assets::predicted_error_m(s.groups[g].model, curvature, level) *
                                    focal_px / std::max(distance[g], 0.01);
            stats_.piece_max_error_px = std::max(stats_.piece_max_error_px, error_px);
        }
        ++stats_.piece_levels[static_cast<std::size_t>(s.levels[static_cast<std::size_t>(k)][0])];
    }
}

}  // namespace tunnel
