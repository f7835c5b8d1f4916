// Level of detail by screen-space error (DESIGN 4.5): per-segment ring counts and radial sides of one wire for
// one camera, with hysteresis, plus the measurement that proves the bound. Plain math on a Curve: no ECS, no GL.
//
// The bound, and what it covers. Two errors are kept apart, as the DESIGN asks:
// - Centre line (chord) error. Rings of segment i sit at t = k/N_i; the centre polyline through them stays within
//   eps_world of the cubic (Wang's formula, tessellate.hpp). A world offset d between a curve point and its chord
//   point projects to at most  f_px * k / z * |d|  pixels, where z is the view depth and k = sqrt(1 + a^2 + b^2)
//   with a = |x/z|, b = |y/z| (the projection's Jacobian has singular values f/z and f k/z). Curve and chord lie
//   in the segment's control hull, where depth is >= z_min (depth is linear: its minimum over the hull is at a
//   control point) and a, b are <= their values at the control points (a linear-fractional function peaks at a
//   vertex), capped at the screen edge's tan(fov/2) because only on-screen points count. Hence
//       eps_world = eps_px * z_min / (f_px * k),   f_px = (H/2) / tan(fovY/2)
//   keeps every visible point of the centre line within eps_px of the drawn polyline. This is the DESIGN's
//   formula times 1/k: on the optical axis k = 1; in a corner of a 16:9 60-degree view k = 1.55, and without it
//   a grazing segment in a corner exceeds the tolerance by that factor.
// - Radial (sides) error. An n-gon of circumradius R misses the circle by R (1 - cos(pi/n)); with the projected
//   radius R_px = R f_px k / z_min (largest radius of the wire, nearest visible depth) the DESIGN's
//   n = ceil(pi / acos(1 - eps_px / R_px)) keeps it within eps_px, clamped to [3, max_sides].
// Not covered: the tube surface's own chord error on the outer side of a bend grows by (1 + R kappa) over the
// centre line's; for wires thinner than their bend radius (every physical cable) that is a few per cent.
// z_min is clamped to the near plane: a segment that crosses it is refined as if it touched the near plane, which
// is what its visible part needs. Points behind the near plane are not on screen and carry no guarantee.
#pragma once

#include "wire/curve.hpp"
#include "wire/tessellate.hpp"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace wire {

/// A perspective camera as the LOD sees it, in double: GL conventions (right-handed view space looking down -z).
/// Build it with LodView::perspective(); the fields are derived and compared as a whole to detect camera motion.
struct LodView {
    glm::dvec3 eye_m{};
    glm::dmat4 view_from_world{1.0};
    glm::dmat4 clip_from_world{1.0};
    std::array<glm::dvec4, 6> planes{};  ///< world-space frustum planes (xyz unit normal, w offset): inside >= 0
    double focal_px = 1.0;               ///< (H/2) / tan(fovY/2)
    double tan_half_x = 1.0;             ///< tan of half the horizontal field of view
    double tan_half_y = 1.0;
    double near_m = 0.1;
    double far_m = 1000.0;
    double width_px = 1920.0;
    double height_px = 1080.0;

    /// A look-at camera (glm::lookAt) with vertical field of view fov_y_rad over a width_px x height_px viewport.
    [[nodiscard]] static LodView perspective(const glm::dvec3& eye_m, const glm::dvec3& target_m, const glm::dvec3& up,
                                             double fov_y_rad, double width_px, double height_px, double near_m,
                                             double far_m);

    /// View-space position (x right, y up, z = depth in front of the camera, positive).
    [[nodiscard]] glm::dvec3 to_view(const glm::dvec3& world_m) const;
    /// Pixel position (x right, y down, origin at the top-left corner) of a view-space point with z > 0.
    [[nodiscard]] glm::dvec2 view_to_px(const glm::dvec3& view) const;

    friend bool operator==(const LodView&, const LodView&) = default;
};

/// Zero means default.
struct LodSettings {
    double tolerance_px = 0.0;            ///< screen-space error bound for centre line and sides; 0 -> 0.5 px
    uint32_t max_rings_per_segment = 0;   ///< 0 -> 256 (segments that would need more are counted as clamped)
    uint32_t max_sides = 0;               ///< 0 -> 32; values below 3 become 3
    /// Hysteresis: a count that is no longer needed is kept while old <= raw * (1 + band) + 1 (raw = what the
    /// tolerance needs now); a count that is needed is taken at once. 0 -> 0.25. Negative: no hysteresis.
    double hysteresis_band = 0.0;
    /// Segments whose control hull (inflated by the radius) is outside the frustum get 1 ring: their coarse tube
    /// stays in the hull, so off-screen anyway. Off: they are tessellated like visible ones (with z_min clamped to
    /// the near plane, so a segment behind the camera gets the maximum).
    bool coarse_offscreen_segments = true;
};

/// One wire's LOD state for one camera (kept between frames for hysteresis).
struct WireLod {
    std::vector<uint32_t> counts;    ///< per segment: rings used (after hysteresis; >= required[i]); empty if culled
    std::vector<uint32_t> required;  ///< per segment: rings the tolerance needs now (raw Wang count)
    uint32_t sides = 0;              ///< radial sides used (>= required_sides); 0 if culled
    uint32_t required_sides = 0;
    bool visible = false;            ///< the wire's control hull, inflated by its radius, meets the frustum
    uint32_t visible_segments = 0;   ///< segments whose inflated hull meets the frustum
    uint32_t clamped_segments = 0;   ///< segments whose required count hit max_rings_per_segment (bound not met)
    uint32_t changed_counts = 0;     ///< segments whose count changed in the last update (flicker metric)
    double z_min_m = 0.0;            ///< nearest depth of the visible segments (clamped to the near plane)
};

/// A sphere enclosing a wire's tube: every control point of the curve, inflated by its largest radius. Computed
/// once when the curve changes (O(control points)); tested against the frustum in O(1) every frame.
struct BoundingSphere {
    glm::dvec3 centre_m{};
    double radius_m = -1.0;  ///< < 0: unknown (update_lod then skips the quick test)
};

/// The bounding sphere of `curve` (centre of the control points' box, radius its half diagonal plus the largest
/// tube radius). An empty curve gives radius -1.
[[nodiscard]] BoundingSphere curve_bounding_sphere(const Curve& curve);

/// Updates `lod` for `curve` seen by `view`. With `bounds` (from curve_bounding_sphere), a wire whose sphere is
/// outside one frustum plane is culled in O(1) before any per-segment work: the result is the same as the hull
/// test's (the sphere contains every inflated control point), only cheaper, so an off-screen wire costs one
/// sphere test per camera change. Culled wires (no visible segment) get visible = false, empty counts
/// and sides 0: the caller builds no rings. Otherwise counts holds segment_count() entries >= 1, each at least
/// what the tolerance requires (hysteresis may keep more, never fewer), and sides in [3, max_sides].
/// If the segment count differs from the previous update, hysteresis restarts from the raw counts.
/// Returns whether counts or sides changed (the ring stage can skip the wire otherwise).
bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const BoundingSphere* bounds = nullptr);

/// True if the control points of every segment, inflated by radius_m, are not all outside one frustum plane.
[[nodiscard]] bool hull_visible(std::span<const CubicBezier> segments, double radius_m, const LodView& view);

/// Rings needed on one segment for tolerance_px (no hysteresis, no culling); max_rings if that is not enough.
[[nodiscard]] uint32_t segment_ring_count_px(const CubicBezier& segment, const LodView& view, double tolerance_px,
                                             uint32_t max_rings);

/// Radial sides for a tube of radius_m whose nearest visible point is at depth z_m (clamped to near) with
/// off-axis factor k >= 1 (see the header comment; 1 on the optical axis): n = ceil(pi / acos(1 - eps/R_px)).
[[nodiscard]] uint32_t sides_for_radius(double radius_m, double z_m, double k, const LodView& view,
                                        double tolerance_px, uint32_t max_sides);

/// The hysteresis rule on one count: raw if raw >= old or old == 0; old while old <= raw * (1 + band) + 1;
/// otherwise min(old, raw + 1 + raw / 8) (a little headroom, so the next tiny move does not raise it again).
[[nodiscard]] uint32_t hysteresis_count(uint32_t old_count, uint32_t raw_count, double band);

/// Result of measure_screen_error().
struct ScreenError {
    double max_px = 0.0;        ///< largest distance of a reference point to the drawn centre polyline, pixels
    uint32_t worst_segment = 0; ///< segment of that reference point
    double worst_t = 0.0;
    std::size_t samples = 0;    ///< reference points that were on screen (the others carry no guarantee)
};

/// Centre-line screen error of a tessellation: samples every segment at samples_per_segment + 1 parameters, keeps
/// the points on screen (depth in [near, far], inside the viewport), and measures each one's pixel distance to the
/// projected ring polyline near it (the pieces of its own segment and one piece on either side, clipped at the near
/// plane). An upper bound of the distance to the whole polyline. `params` as place_rings() gives them.
[[nodiscard]] ScreenError measure_screen_error(const Curve& curve, std::span<const RingParam> params,
                                               const LodView& view, int samples_per_segment = 256);

}  // namespace wire
