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
//
// Below the node resolution (LodSettings::keep_node_resolution off, the default): one ring interval may span
// several segments. For a span [s, e) of segments with chord C from its first point to its last, every point of
// the span's curve is within `deviation` of C, computed once per curve (LodBounds): a segment's deviation is the
// smaller of its control hull's distance to its chord (the distance to a segment is convex, so its maximum over
// the hull is at a control point) and Wang's 3M/4 for one ring; a merged span of two halves with chords A-M and
// M-B has deviation max(d_left, d_right) + dist(M, A-B) (a point within d of A-M is within d + dist(M, A-B) of
// A-B, again by convexity). The span's curve and chord lie in a sphere enclosing its control points, so the
// projection argument above holds with z_min and k bounded over that sphere: the span is one interval when
// deviation * f_px * k <= eps_px * z_lo. k: over the wire's sphere when it lies inside the frustum (the screen
// edge caps it); otherwise over the span's own sphere, uncapped (a span's chord may leave the screen). The rings of
// a span still sit at t = 0 of a segment, so every ring keeps its segment and t; a segment with count 0 is crossed
// by the interval that starts before it. Spans whose inflated sphere is outside the frustum are merged too
// (coarse_offscreen_segments). A loop keeps at least 3 intervals. Hysteresis: a span merged in the previous update
// stays merged while it meets the tolerance; a new one merges only below tolerance / (1 + band).
//
// The cheap pass (DESIGN 4.5, issue 11): a per-wire conservative bound (sphere_screen_bound) decides most wires
// without per-segment Wang work: when the wire's sphere lies inside the frustum, either the whole wire merges into
// one span, or every segment needs one ring (max M <= 4/3 eps_world at the sphere's nearest depth); the exact
// side count then needs the segments' depths only when the conservative one is above 3. A wire partly out of view
// whose side count the sphere fixes at 3 decides each segment by its own sphere (hull test only where that sphere
// straddles a plane). The span walk visits only the hierarchy levels the wire's depth range leaves open, and a
// bounded wire whose decisions cannot have changed for the new camera keeps its state (WireLod::Coherence). All
// of it gives exactly what the per-segment evaluation gives (tested); the other wires take the per-segment pass,
// laid out as structure-of-arrays loops.
#pragma once

#include "wire/curve.hpp"
#include "wire/spline.hpp"
#include "wire/tessellate.hpp"

#include <glm/mat3x3.hpp>
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
/// Build it with LodView::perspective() (or orthographic()); the fields are derived and compared as a whole to
/// detect camera motion.
struct LodView {
    glm::dvec3 eye_m{};                  ///< camera position, world metres
    glm::dmat4 view_from_world{1.0};     ///< view matrix (glm::lookAt)
    glm::dmat4 clip_from_world{1.0};     ///< projection * view
    std::array<glm::dvec4, 6> planes{};  ///< world-space frustum planes (xyz unit normal, w offset): inside >= 0
    double focal_px = 1.0;               ///< (H/2) / tan(fovY/2)
    double tan_half_x = 1.0;             ///< tan of half the horizontal field of view
    double tan_half_y = 1.0;             ///< tan of half the vertical field of view
    double near_m = 0.1;                 ///< near plane distance
    double far_m = 1000.0;               ///< far plane distance
    double width_px = 1920.0;            ///< viewport width
    double height_px = 1080.0;           ///< viewport height

    /// A look-at camera (glm::lookAt) with vertical field of view fov_y_rad over a width_px x height_px viewport.
    [[nodiscard]] static LodView perspective(const glm::dvec3& eye_m, const glm::dvec3& target_m, const glm::dvec3& up,
                                             double fov_y_rad, double width_px, double height_px, double near_m,
                                             double far_m);

    /// An orthographic view (glm::ortho(-h aspect, h aspect, -h, h, near, far) looking from eye_m at target_m, h =
    /// half_height_m) as the LOD sees it: the perspective view from a point far behind eye_m whose frustum holds the
    /// orthographic box and whose pixels per metre inside it are within 1% of the box's (the tangent is chosen so
    /// the near face is exactly the box's; the eye is 100 box depths back). The LOD's perspective bounds therefore
    /// hold within that 1%. Its eye_m is the far eye: the renderer places positions relative to it and draws them
    /// with the orthographic projection moved back by the same distance (orthographic_back_m()).
    [[nodiscard]] static LodView orthographic(const glm::dvec3& eye_m, const glm::dvec3& target_m, const glm::dvec3& up,
                                              double half_height_m, double width_px, double height_px, double near_m,
                                              double far_m);
    /// How far behind an orthographic view's eye orthographic() puts the LOD's eye: 100 box depths (far - near),
    /// at least 100 half heights.
    [[nodiscard]] static double orthographic_back_m(double half_height_m, double near_m, double far_m);

    /// View-space position (x right, y up, z = depth in front of the camera, positive).
    [[nodiscard]] glm::dvec3 to_view(const glm::dvec3& world_m) const;
    /// Pixel position (x right, y down, origin at the top-left corner) of a view-space point with z > 0.
    [[nodiscard]] glm::dvec2 view_to_px(const glm::dvec3& view) const;

    /// Every field equal (camera motion is detected by comparing views).
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
    /// true: at least one ring per segment (the resolution of the nodes). false (default): a ring interval may
    /// span several segments where the screen error allows (see the header comment); counts of 0 then mark the
    /// segments an interval crosses.
    bool keep_node_resolution = false;
    /// Thin wires (DESIGN 4.5). Below a projected radius of strip_radius_px a wire is drawn as a camera-facing
    /// strip (WireLod::drawn_sides 2: 2 vertices a ring, shaded as the tube it stands for), below line_radius_px
    /// as a one-pixel phone-wire line with opacity = true width / drawn width (drawn_sides 1). 0 -> 2 px and
    /// 0.5 px (a wire one pixel across); negative: never.
    double strip_radius_px = 0.0;
    double line_radius_px = 0.0;

    /// These settings as every LOD reads them, on the CPU (update_lod) and on the GPU (the nodes path): each 0
    /// replaced by its default (0.5 px, 256 rings, 32 sides, band 0.25, strips below 2 px, lines below 0.5 px), a
    /// tolerance that is not positive (or NaN) by 0.5 px and one below 1e-6 px by 1e-6 px, max_sides below 3 by 3.
    /// resolved() of a resolved value is itself; update_lod gives the same result for both.
    [[nodiscard]] LodSettings resolved() const;

    friend bool operator==(const LodSettings&, const LodSettings&) = default;
};

/// One wire's LOD state for one camera (kept between frames for hysteresis).
/// counts[i] == 0 (only without keep_node_resolution): segment i has no ring of its own; the ring interval that
/// starts on an earlier segment crosses it. counts[0] is >= 1 whenever the wire is visible.
struct LodBounds;

struct WireLod {
    std::vector<uint32_t> counts;    ///< per segment: rings used (after hysteresis; >= required[i]); empty if culled
    std::vector<uint32_t> required;  ///< per segment: rings the tolerance needs now (Wang count, or the spans)
    uint32_t sides = 0;              ///< radial sides used (>= required_sides); 0 if culled
    uint32_t required_sides = 0;     ///< radial sides the tolerance needs now
    /// What the wire is drawn with: `sides` (a tube), 2 (a camera-facing strip) or 1 (a phone-wire line),
    /// from radius_px against LodSettings::strip_radius_px / line_radius_px; 0 if culled.
    uint32_t drawn_sides = 0;
    /// Largest projected radius of the wire's visible part (pixels, at z_min_m with the off-axis factor).
    double radius_px = 0.0;
    bool visible = false;            ///< the wire's control hull, inflated by its radius, meets the frustum
    uint32_t visible_segments = 0;   ///< segments whose inflated hull meets the frustum
    uint32_t clamped_segments = 0;   ///< segments whose required count hit max_rings_per_segment (bound not met)
    uint32_t changed_counts = 0;     ///< segments whose count changed in the last update (flicker metric)
    double z_min_m = 0.0;            ///< nearest depth of the visible segments (clamped to the near plane); a lower
                                     ///< bound of it when `bounded` and the side count is 3
    uint32_t spans = 0;              ///< ring intervals that cross more than one segment (in counts)
    bool bounded = false;            ///< the per-wire bound decided the counts (no per-segment Wang evaluation)
    uint64_t reused = 0;             ///< updates answered by the coherence test (statistics)

    /// Coherence of the cheap pass: after an update the per-wire bound decided with 3 sides, the camera it was
    /// made for and by what factor the span decisions' ratios (deviation * f * k / depth) may change before one
    /// crosses a threshold. A later update whose camera moved so little that no point of the wire's sphere moved
    /// enough in view space (and k changed little enough) keeps the state: a full update would give the same.
    struct Coherence {
        bool valid = false;
        const LodBounds* bounds = nullptr;
        uint64_t bounds_version = 0;
        glm::dvec3 eye_m{};
        glm::dmat3 rotation{1.0};
        double z_lo_m = 0.0, k = 1.0, margin = 1.0;
        double tolerance_px = 0.0, band = 0.0;
        uint32_t max_sides = 0, max_rings = 0;
        bool coarse_offscreen = true, keep_node_resolution = false;
        bool whole = false;  ///< the whole wire was one interval (else: one ring per segment before the spans)
        bool exact_sides = false;           ///< sides from the segments' depths (wire_z_m, wire_k), not the sphere
        double wire_z_m = 0.0, wire_k = 1.0;
    } coherence;
};

/// A sphere enclosing a wire's tube: every control point of the curve, inflated by its largest radius. Computed
/// once when the curve changes (O(control points)); tested against the frustum in O(1) every frame.
struct BoundingSphere {
    glm::dvec3 centre_m{};   ///< world metres
    double radius_m = -1.0;  ///< < 0: unknown (update_lod then skips the quick test)
    /// The largest tube radius of the curve (what radius_m was inflated by), where known (< 0: not known);
    /// compute_lod_bounds() given the sphere takes it as LodBounds::radius_max_m instead of computing it again.
    double tube_radius_m = -1.0;
};

/// The bounding sphere of `curve` (centre of the control points' box, radius its half diagonal plus the largest
/// tube radius, which it keeps as tube_radius_m). An empty curve gives radius -1.
[[nodiscard]] BoundingSphere curve_bounding_sphere(const Curve& curve);

/// A sphere enclosing the curve build_curve makes of `nodes` (every control point, inflated by the largest tube
/// radius), from the nodes alone, for the kinds whose control points stay near their nodes: linear and
/// Catmull-Rom / Kochanek-Bartels. A control point is B0 +- t/3 with |t| <= 2 |1 - tension| (1 + |bias|)
/// (1 + |continuity|) max(|chord in|, |chord out|) for any alpha in [0, 1] (and the curvature-driven tension only
/// shrinks t), so the nodes' box grown by 2/3 of that times the longest chord holds them. c2 and automatic: radius
/// -1 (unknown: the global solve's overshoot has no local bound), as for an empty curve.
[[nodiscard]] BoundingSphere node_bounding_sphere(const WireNodes& nodes, const SplineSettings& settings);


/// A node of the span hierarchy: a sphere around the span's control points (not inflated by the tube radius)
/// and its chord deviation (every curve point of the span is within it of the chord from the span's first point
/// to its last; see the header comment).
struct SpanNode {
    glm::dvec3 centre_m{};
    double radius_m = 0.0;
    double deviation_m = 0.0;
};

/// View-independent LOD data of one curve, computed when the curve changes (O(segments)); update_lod() reads it
/// every frame. The span hierarchy: level 0 holds one node per segment, level l one node per 2^l segments (the
/// last node of a level may be shorter), up to one root node for the whole wire; node j of level l covers
/// segments [j 2^l, min((j+1) 2^l, n)). Everything per frame lives in one allocation, the root level first (the
/// LOD pass of 10,000 wires is bound by cache misses, not arithmetic).
struct LodBounds {
    BoundingSphere sphere{};    ///< curve_bounding_sphere(curve)
    double radius_max_m = 0.0;  ///< largest tube radius
    double wang_m_max = 0.0;    ///< max over segments of wang_m()
    std::size_t segments = 0;
    uint32_t levels = 0;                        ///< hierarchy levels (0 for an empty curve)
    uint64_t version = 0;                       ///< new (unique) each time compute_lod_bounds() fills it
    /// Set by a caller that computes the bounds for one update_lod() only (a wire whose curve changes every
    /// frame): no WireLod::Coherence is kept for them (it could never be used: the next update has new bounds),
    /// so the update skips its bookkeeping. compute_lod_bounds() leaves it as it is.
    bool transient = false;
    std::array<uint32_t, 34> level_start{};     ///< index of node 0 of each level (root level first in memory)
    /// Per level (min, max) deviation; per level (root first) five arrays of level_width() values: centre x,
    /// centre y, centre z, radius, deviation (structure of arrays: built and read by vectorized loops); Wang's M
    /// per segment.
    std::vector<double> data;

    [[nodiscard]] std::size_t level_width(std::size_t level) const {
        return (segments + (std::size_t{1} << level) - 1) >> level;
    }
    /// The five arrays of a level, one after the other (field f of node j at [f * level_width(level) + j]).
    [[nodiscard]] const double* level_data(std::size_t level) const {
        return data.data() + 2 * levels + 5 * std::size_t{level_start[level]};
    }
    [[nodiscard]] double* level_data(std::size_t level) {
        return data.data() + 2 * levels + 5 * std::size_t{level_start[level]};
    }
    [[nodiscard]] SpanNode node(std::size_t level, std::size_t j) const {
        const double* d = level_data(level);
        const std::size_t w = level_width(level);
        return {{d[j], d[w + j], d[2 * w + j]}, d[3 * w + j], d[4 * w + j]};
    }
    [[nodiscard]] double level_deviation_min(std::size_t level) const { return data[2 * level]; }
    [[nodiscard]] double level_deviation_max(std::size_t level) const { return data[2 * level + 1]; }
    /// Wang's M = max |B_i - 2B_{i+1} + B_{i+2}| of segment i.
    [[nodiscard]] double wang_m(std::size_t i) const { return data[data.size() - segments + i]; }
};

/// Fills `out` for `curve` (reuses its capacity).
void compute_lod_bounds(const Curve& curve, LodBounds& out);
/// The same, given the wire's sphere: `sphere` must be curve_bounding_sphere(curve) (which is what the first form
/// computes for LodBounds::sphere, bit for bit); it is taken as it is instead of being computed again.
void compute_lod_bounds(const Curve& curve, LodBounds& out, const BoundingSphere& sphere);

/// The per-wire conservative bound: what one sphere (centre_m, radius_m) tells about the view without looking
/// inside it. Shared by the LOD pass and anything else that must decide a wire in O(1) per camera.
struct SphereScreenBound {
    unsigned outside = 0;      ///< frustum planes the sphere lies entirely outside of (non-zero: nothing visible)
    bool inside = false;       ///< the sphere lies entirely inside the frustum
    double z_lo_m = 0.0;       ///< lower bound of the depth over the sphere, clamped to the near plane
    double z_hi_m = 0.0;       ///< upper bound of the depth over the sphere
    double k = 1.0;            ///< upper bound of the off-axis factor over the sphere's on-screen points
    double eps_world_m = 0.0;  ///< tolerance_px converted at (z_lo_m, k): tolerance_px * z_lo_m / (focal_px * k)
};
[[nodiscard]] SphereScreenBound sphere_screen_bound(const glm::dvec3& centre_m, double radius_m, const LodView& view,
                                                    double tolerance_px);

/// The O(1) test update_lod() starts with: true if `sphere` (radius >= 0; false for an unknown one) lies
/// entirely outside one frustum plane, after inflating it by a bound of the rounding of the view transform.
/// update_lod() gives a wire whose sphere this culls the state cull_lod() gives, without any other work, so a
/// caller may test this first and skip computing the wire's LodBounds.
[[nodiscard]] bool sphere_outside_view(const BoundingSphere& sphere, const LodView& view);

/// Puts `lod` in the state update_lod() leaves a culled wire in (visible false, counts and required empty, sides
/// 0, coherence invalid); returns whether it was visible or had counts before.
bool cull_lod(WireLod& lod);

/// True if, by the bound, every segment of the wire needs exactly one ring: Wang's count is 1 for every segment
/// when max M <= 4/3 eps_world (a strict margin is kept against rounding).
[[nodiscard]] bool one_ring_per_segment(const LodBounds& bounds, const SphereScreenBound& b);

/// Updates `lod` for `curve` seen by `view`, evaluating every segment (the reference for the cheap pass below).
/// With `bounds` (from curve_bounding_sphere), a wire whose sphere is
/// outside one frustum plane is culled in O(1) before any per-segment work: the result is the same as the hull
/// test's (the sphere contains every inflated control point), only cheaper, so an off-screen wire costs one
/// sphere test per camera change. Culled wires (no visible segment) get visible = false, empty counts
/// and sides 0: the caller builds no rings. Otherwise counts holds segment_count() entries, >= 1 with
/// keep_node_resolution (else 0 for segments a span crosses), each at least what the tolerance requires
/// (hysteresis may keep more, never fewer), and sides in [3, max_sides].
/// If the segment count differs from the previous update, hysteresis restarts from the raw counts.
/// Returns whether counts or sides changed (the ring stage can skip the wire otherwise).
bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const BoundingSphere* bounds = nullptr);

/// The same with the curve's LodBounds (what the wire systems call every frame): the sphere cull, then the
/// per-wire bound, then the per-segment pass for the wires the bound does not decide. The result equals the
/// per-segment evaluation's (update_lod without LodBounds) in counts, required, sides, visible, visible_segments
/// and spans; only z_min_m may be a lower bound (when `bounded`).
bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const LodBounds& bounds);

/// compute_lod_bounds(curve, bounds, sphere) with bounds.transient set, then update_lod(curve, view, settings, lod,
/// bounds), for bounds that serve this one update (a wire whose curve changes every frame): the same result,
/// but the hierarchy levels the update cannot read are not built (for a wire inside the frustum, the levels above
/// the first whose every span fails at the sphere's far depth), and the bounds are per-thread working memory.
/// `sphere` must be curve_bounding_sphere(curve), and sphere_outside_view(sphere, view) false: the caller has
/// tested it (what update_lod gives a wire it culls is cull_lod()'s state), so it is not tested again.
bool update_lod_once(const Curve& curve, const BoundingSphere& sphere, const LodView& view,
                     const LodSettings& settings, WireLod& lod);

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
    double worst_t = 0.0;       ///< parameter in [0, 1] of that reference point inside its segment
    std::size_t samples = 0;    ///< reference points that were on screen (the others carry no guarantee)
};

/// Centre-line screen error of a tessellation: samples every segment at samples_per_segment + 1 parameters, keeps
/// the points on screen (depth in [near, far], inside the viewport), and measures each one's pixel distance to the
/// projected ring polyline near it (the pieces of its own segment and one piece on either side, clipped at the near
/// plane). An upper bound of the distance to the whole polyline. `params` as place_rings() gives them.
[[nodiscard]] ScreenError measure_screen_error(const Curve& curve, std::span<const RingParam> params,
                                               const LodView& view, int samples_per_segment = 256);

}  // namespace wire
