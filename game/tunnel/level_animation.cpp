// The tunnel's motion: the chain of bends (an S-shaped run, each bend wobbling slowly in angle and direction)
// and the fly camera along the bent centre line (system tunnel.animate).
#include "tunnel/level_state.hpp"

#include <glm/common.hpp>
#include <glm/trigonometric.hpp>

#include <algorithm>
#include <cmath>

namespace tunnel {

namespace {

// Unbent (x, y) of the eye at the closest point of the close-up.
constexpr glm::dvec2 kCloseUpEye{1.70, -0.20};

}  // namespace

// One bend per piece: an S-shaped run (scaled by bend_scale) with per-segment wobble phases from the seed.
void Level::build_chain() {
    State& s = *state_;
    for (int i = 0; i < s.settings.pieces; ++i) {
        const auto u = static_cast<uint32_t>(i) * 8u + s.settings.seed * 7919u;
        SegmentAnimation a;
        // Straight-ish first piece (the camera starts there), then an S: left, right, left...
        a.base_angle = s.settings.bend_scale * 0.30 * std::sin(0.9 + 0.45 * i) * std::min(1.0, 0.4 * i);
        a.angle_amp = 0.05 + 0.03 * hash01(u + 1);
        a.angle_freq = 0.5 + 0.4 * hash01(u + 2);
        a.angle_phase = 2.0 * kPi * hash01(u + 3);
        a.dir_amp = 0.25 + 0.15 * hash01(u + 4);
        a.dir_freq = 0.25 + 0.2 * hash01(u + 5);
        a.dir_phase = 2.0 * kPi * hash01(u + 6);
        s.animation.push_back(a);
        s.segments.push_back({.length_m = kPieceLength, .angle_rad = a.base_angle, .direction_rad = 0.0});
    }
}

void Level::animate(double dt_s) {
    State& s = *state_;
    if (options_.animate_bends) s.time_s += dt_s;
    const double t = s.time_s;
    for (std::size_t i = 0; i < s.segments.size(); ++i) {
        const SegmentAnimation& a = s.animation[i];
        s.segments[i].angle_rad = a.base_angle + a.angle_amp * std::sin(a.angle_freq * t + a.angle_phase);
        s.segments[i].direction_rad = a.dir_amp * std::sin(a.dir_freq * t + a.dir_phase);
    }
    (void)curved_space::make_chain(s.segments, chain_);  // finite lengths and angles by construction

    // Fly along the bent centre line, looking ahead; loop before the end.
    const double total = chain_.total_length_m();
    s.fly_distance_m += options_.flight_speed_mps * dt_s;
    const double span = std::max(1.0, total - 18.0);
    const double z = 3.0 + std::fmod(s.fly_distance_m, span);
    s.flight_z_m = z;
    camera_.aspect = static_cast<float>(s.width_px) / static_cast<float>(s.height_px);
    camera_.fov_y_rad = glm::radians(70.0f);
    camera_.near_m = 0.05f;
    camera_.far_m = 200.0f;
    if (options_.camera_mode == CameraMode::fly) {
        // Close-up (unbent z 7.5..14, frames ~55..130 of the default run): the camera glides to the right
        // wall, past the festoon of piece 2 and the wall cables, looking at them, then back to the axis.
        auto smooth = [](double e0, double e1, double x) {
            const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
            return t * t * (3.0 - 2.0 * t);
        };
        const double u = options_.close_up ? smooth(7.5, 9.5, z) * (1.0 - smooth(12.5, 14.0, z)) : 0.0;
        const glm::dvec3 eye_unbent(kCloseUpEye.x * u, 0.35 + (kCloseUpEye.y - 0.35) * u, z);
        const glm::dvec3 look =
            glm::mix(glm::dvec3(0.0, 0.05, z + 7.0), glm::dvec3(2.2, -0.45, z + 2.0), 0.8 * u);
        const curved_space::BentVertex eye = chain_.transform(eye_unbent, {0.0, 1.0, 0.0});
        camera_.position = eye.position;
        camera_.target = chain_.transform_point(look);
        camera_.up = eye.normal;
    }
    s.context.camera = camera_;
    s.context.other_views.clear();
    if (options_.shadows) s.context.other_views.push_back(head_lamp_view(camera_));  // its casters stay listed
    s.context.viewport_width_px = s.width_px;
    s.context.viewport_height_px = s.height_px;
}

}  // namespace tunnel
