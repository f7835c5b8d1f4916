// The LOD's view: LodView (perspective, world -> view -> pixels) and a sphere's screen bound.
#include "wire/lod.hpp"

#include "lod/view.hpp"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace wire {

using namespace lod_stage;

LodView LodView::perspective(const glm::dvec3& eye_m, const glm::dvec3& target_m, const glm::dvec3& up,
                             double fov_y_rad, double width_px, double height_px, double near_m, double far_m) {
    LodView v;
    v.eye_m = eye_m;
    v.view_from_world = glm::lookAt(eye_m, target_m, up);
    const double aspect = width_px / height_px;
    v.clip_from_world = glm::perspective(fov_y_rad, aspect, near_m, far_m) * v.view_from_world;
    v.tan_half_y = std::tan(0.5 * fov_y_rad);
    v.tan_half_x = v.tan_half_y * aspect;
    v.focal_px = 0.5 * height_px / v.tan_half_y;
    v.near_m = near_m;
    v.far_m = far_m;
    v.width_px = width_px;
    v.height_px = height_px;
    // Gribb & Hartmann, in double: rows of clip_from_world.
    const glm::dmat4 m = glm::transpose(v.clip_from_world);
    const std::array<glm::dvec4, 6> raw = {m[3] + m[0], m[3] - m[0], m[3] + m[1],
                                           m[3] - m[1], m[3] + m[2], m[3] - m[2]};
    for (std::size_t i = 0; i < 6; ++i) {
        v.planes[i] = raw[i] / glm::length(glm::dvec3(raw[i]));
    }
    return v;
}

double LodView::orthographic_back_m(double half_height_m, double near_m, double far_m) {
    return 100.0 * std::max(far_m - near_m, half_height_m);
}

LodView LodView::orthographic(const glm::dvec3& eye_m, const glm::dvec3& target_m, const glm::dvec3& up,
                              double half_height_m, double width_px, double height_px, double near_m, double far_m) {
    // Perspective from `back` behind the eye, its near plane on the box's near face with the box's half height
    // there: the frustum widens with depth, so it holds the box, and pixels per metre fall from the box's value
    // at its near face by (back + near) / (back + far) >= 1 - (far - near) / back = 0.99 at its far face.
    const double back = orthographic_back_m(half_height_m, near_m, far_m);
    const glm::dvec3 forward = glm::normalize(target_m - eye_m);
    const glm::dvec3 far_eye = eye_m - forward * back;
    const double fov_y = 2.0 * std::atan(half_height_m / (back + near_m));
    return perspective(far_eye, target_m, up, fov_y, width_px, height_px, back + near_m, back + far_m);
}

glm::dvec3 LodView::to_view(const glm::dvec3& world_m) const {
    const glm::dvec4 q = view_from_world * glm::dvec4(world_m, 1.0);
    return {q.x, q.y, -q.z};
}

glm::dvec2 LodView::view_to_px(const glm::dvec3& view) const {
    return {0.5 * width_px + focal_px * view.x / view.z, 0.5 * height_px - focal_px * view.y / view.z};
}

SphereScreenBound sphere_screen_bound(const glm::dvec3& centre_m, double radius_m, const LodView& view,
                                      double tolerance_px) {
    SphereScreenBound b;
    const ViewTransform tf(view);
    const glm::dvec3 q = tf(centre_m);
    const PlaneTest out(view, radius_m);
    b.outside = out.outside(q);
    const double r = radius_m;
    b.inside = q.x + q.z * out.tx >= out.rx && q.z * out.tx - q.x >= out.rx && q.y + q.z * out.ty >= out.ry &&
               q.z * out.ty - q.y >= out.ry && q.z - view.near_m >= r && view.far_m - q.z >= r;
    b.z_lo_m = std::max(q.z - r, view.near_m);
    b.z_hi_m = q.z + r;
    double a = view.tan_half_x, c = view.tan_half_y;
    if (q.z - r > 0.0) {
        a = std::min(a, (std::abs(q.x) + r) / (q.z - r));
        c = std::min(c, (std::abs(q.y) + r) / (q.z - r));
    }
    b.k = std::sqrt(1.0 + a * a + c * c);
    b.eps_world_m = tolerance_or_default(tolerance_px) * b.z_lo_m / (view.focal_px * b.k);
    return b;
}

LodSettings LodSettings::resolved() const {
    using namespace lod_stage;
    LodSettings r = *this;
    r.tolerance_px = tolerance_or_default(tolerance_px);
    r.max_rings_per_segment = max_rings_per_segment ? max_rings_per_segment : default_max_rings;
    r.max_sides = std::max<uint32_t>(max_sides ? max_sides : default_max_sides, 3);
    r.hysteresis_band = hysteresis_band == 0.0 ? default_band : hysteresis_band;
    r.strip_radius_px = strip_radius_px == 0.0 ? default_strip_radius_px : strip_radius_px;
    r.line_radius_px = line_radius_px == 0.0 ? default_line_radius_px : line_radius_px;
    return r;
}

}  // namespace wire
