// Level of detail by screen-space error: Wang counts at the hull's nearest depth, sides from the projected
// radius, per-wire and per-segment hull culling, hysteresis, and the screen-error measurement.
#include "wire/lod.hpp"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace wire {
namespace {

constexpr double default_tolerance_px = 0.5;
constexpr uint32_t default_max_rings = 256;
constexpr uint32_t default_max_sides = 32;
constexpr double default_band = 0.25;

double tolerance_or_default(double tolerance_px) {
    return tolerance_px > 0.0 ? tolerance_px : default_tolerance_px;
}

// Nearest depth (clamped to near) and off-axis factor k of one segment's control hull.
struct HullDepth {
    double z_min = 0.0;
    double k = 1.0;
};

// A segment's four control points in view space (x right, y up, z depth).
using ViewHull = std::array<glm::dvec3, 4>;

// World -> view as a rotation and a translation (lookAt is rigid), taken once per wire.
struct ViewTransform {
    glm::dmat3 rotation;
    glm::dvec3 translation;
    explicit ViewTransform(const LodView& view)
        : rotation(view.view_from_world), translation(view.view_from_world[3]) {}
    [[nodiscard]] glm::dvec3 operator()(const glm::dvec3& p) const {
        const glm::dvec3 q = rotation * p + translation;
        return {q.x, q.y, -q.z};
    }
    [[nodiscard]] ViewHull hull(const CubicBezier& c) const {
        return {(*this)(c.b0), (*this)(c.b1), (*this)(c.b2), (*this)(c.b3)};
    }
};

HullDepth hull_depth(const ViewHull& p, const LodView& view) {
    double z_min = std::numeric_limits<double>::infinity();
    double a = 0.0;
    double b = 0.0;
    bool in_front = true;
    for (const glm::dvec3& q : p) {
        z_min = std::min(z_min, q.z);
        if (q.z >= view.near_m) {
            a = std::max(a, std::abs(q.x) / q.z);
            b = std::max(b, std::abs(q.y) / q.z);
        } else {
            in_front = false;
        }
    }
    if (!in_front) {
        // Part of the hull is behind the near plane: x/z is unbounded there, but only on-screen points count.
        a = view.tan_half_x;
        b = view.tan_half_y;
    }
    a = std::min(a, view.tan_half_x);
    b = std::min(b, view.tan_half_y);
    HullDepth h;
    h.z_min = std::max(z_min, view.near_m);
    h.k = std::sqrt(1.0 + a * a + b * b);
    return h;
}

// The frustum planes in view space, tested against points inflated by a radius: bit i is set when the point is
// farther than radius_m outside plane i (left, right, bottom, top, near, far: the planes of LodView::planes).
struct PlaneTest {
    double tx, ty, rx, ry, r, near, far;
    PlaneTest(const LodView& view, double radius_m)
        : tx(view.tan_half_x), ty(view.tan_half_y), rx(radius_m * std::sqrt(1.0 + tx * tx)),
          ry(radius_m * std::sqrt(1.0 + ty * ty)), r(radius_m), near(view.near_m), far(view.far_m) {}
    [[nodiscard]] unsigned outside(const glm::dvec3& q) const {
        unsigned m = 0;
        m |= (q.x + q.z * tx < -rx) ? 1u : 0u;
        m |= (q.z * tx - q.x < -rx) ? 2u : 0u;
        m |= (q.y + q.z * ty < -ry) ? 4u : 0u;
        m |= (q.z * ty - q.y < -ry) ? 8u : 0u;
        m |= (q.z - near < -r) ? 16u : 0u;
        m |= (far - q.z < -r) ? 32u : 0u;
        return m;
    }
    // Planes that all four points are outside of (0: the inflated hull may meet the frustum).
    [[nodiscard]] unsigned outside(const ViewHull& h) const {
        return outside(h[0]) & outside(h[1]) & outside(h[2]) & outside(h[3]);
    }
};

uint32_t wang_px(const CubicBezier& c, const HullDepth& h, const LodView& view, double tolerance_px,
                 uint32_t max_rings, bool* clamped) {
    const double eps_world = tolerance_px * h.z_min / (view.focal_px * h.k);
    const uint32_t n = wang_ring_count(c, eps_world, max_rings);
    if (clamped != nullptr && n >= max_rings) {
        // Clamped only if max_rings is really short of what the bound needs.
        const double m = std::max(glm::length(c.b0 - 2.0 * c.b1 + c.b2), glm::length(c.b1 - 2.0 * c.b2 + c.b3));
        *clamped = !(std::ceil(std::sqrt(3.0 * m / (4.0 * eps_world))) <= static_cast<double>(max_rings));
    }
    return n;
}

// Point-to-segment distance in 2D.
double distance_to_piece(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    double t = len2 > 0.0 ? glm::dot(p - a, ab) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return glm::length(p - (a + t * ab));
}

// Pixel distance from p to the view-space piece a-b after clipping it to z >= near; infinity if nothing is left.
double distance_to_view_piece(const glm::dvec2& p_px, glm::dvec3 a, glm::dvec3 b, const LodView& view) {
    const double n = view.near_m;
    if (a.z < n && b.z < n) return std::numeric_limits<double>::infinity();
    if (a.z < n) a = a + (b - a) * ((n - a.z) / (b.z - a.z));
    if (b.z < n) b = b + (a - b) * ((n - b.z) / (a.z - b.z));
    a.z = std::max(a.z, n);
    b.z = std::max(b.z, n);
    return distance_to_piece(p_px, view.view_to_px(a), view.view_to_px(b));
}

}  // namespace

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

glm::dvec3 LodView::to_view(const glm::dvec3& world_m) const {
    const glm::dvec4 q = view_from_world * glm::dvec4(world_m, 1.0);
    return {q.x, q.y, -q.z};
}

glm::dvec2 LodView::view_to_px(const glm::dvec3& view) const {
    return {0.5 * width_px + focal_px * view.x / view.z, 0.5 * height_px - focal_px * view.y / view.z};
}

bool hull_visible(std::span<const CubicBezier> segments, double radius_m, const LodView& view) {
    if (segments.empty()) return false;
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius_m);
    unsigned all = 63u;
    for (const CubicBezier& c : segments) {
        all &= planes.outside(tf.hull(c));
        if (all == 0) return true;
    }
    return false;
}

uint32_t segment_ring_count_px(const CubicBezier& segment, const LodView& view, double tolerance_px,
                               uint32_t max_rings) {
    return wang_px(segment, hull_depth(ViewTransform(view).hull(segment), view), view, tolerance_or_default(tolerance_px),
                   max_rings ? max_rings : default_max_rings, nullptr);
}

uint32_t sides_for_radius(double radius_m, double z_m, double k, const LodView& view, double tolerance_px,
                          uint32_t max_sides) {
    max_sides = std::max<uint32_t>(max_sides ? max_sides : default_max_sides, 3);
    const double eps = tolerance_or_default(tolerance_px);
    const double r_px = radius_m * view.focal_px * k / std::max(z_m, view.near_m);
    if (!(r_px > 0.0)) return 3;
    const double x = eps / r_px;
    if (x >= 2.0) return 3;  // the whole tube is within eps of its centre line
    const double n = std::ceil(std::numbers::pi / std::acos(1.0 - x));
    if (!(n < static_cast<double>(max_sides))) return max_sides;
    return std::max<uint32_t>(3, static_cast<uint32_t>(n));
}

uint32_t hysteresis_count(uint32_t old_count, uint32_t raw_count, double band) {
    if (old_count == 0 || raw_count >= old_count || band < 0.0) return raw_count;
    if (static_cast<double>(old_count) <= static_cast<double>(raw_count) * (1.0 + band) + 1.0) return old_count;
    return std::min(old_count, raw_count + 1 + raw_count / 8);
}

BoundingSphere curve_bounding_sphere(const Curve& curve) {
    if (curve.segments.empty()) return {};
    glm::dvec3 lo(std::numeric_limits<double>::infinity());
    glm::dvec3 hi(-std::numeric_limits<double>::infinity());
    for (const CubicBezier& c : curve.segments)
        for (const glm::dvec3& p : {c.b0, c.b1, c.b2, c.b3}) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
    double radius = 0.0;
    for (const float r : curve.radius_m) radius = std::max(radius, static_cast<double>(r));
    const glm::dvec3 centre = 0.5 * (lo + hi);
    // Round the radius up by a relative hair so rounding in the centre cannot leave a corner outside.
    return {centre, (0.5 * glm::length(hi - lo)) * (1.0 + 1e-12) + radius};
}

namespace {

void mark_culled(WireLod& lod, bool& changed) {
    changed = lod.visible || !lod.counts.empty();
    lod.visible = false;
    lod.counts.clear();
    lod.required.clear();
    lod.sides = 0;
    lod.required_sides = 0;
    lod.z_min_m = 0.0;
    lod.visible_segments = 0;
    lod.clamped_segments = 0;
    lod.changed_counts = 0;
}

}  // namespace

bool update_lod(const Curve& curve, const LodView& view, const LodSettings& settings, WireLod& lod,
                const BoundingSphere* bounds) {
    if (bounds != nullptr && bounds->radius_m >= 0.0) {
        const ViewTransform tf(view);
        if (PlaneTest(view, bounds->radius_m).outside(tf(bounds->centre_m)) != 0) {
            bool changed = false;
            mark_culled(lod, changed);
            return changed;
        }
    }
    const double eps = tolerance_or_default(settings.tolerance_px);
    const uint32_t max_rings = settings.max_rings_per_segment ? settings.max_rings_per_segment : default_max_rings;
    const uint32_t max_sides = std::max<uint32_t>(settings.max_sides ? settings.max_sides : default_max_sides, 3);
    const double band = settings.hysteresis_band == 0.0 ? default_band : settings.hysteresis_band;
    const std::size_t n = curve.segment_count();

    double radius = 0.0;
    for (const float r : curve.radius_m) radius = std::max(radius, static_cast<double>(r));

    lod.clamped_segments = 0;
    lod.changed_counts = 0;
    lod.visible_segments = 0;

    // The hull test: every control point to view space once, the planes each segment's hull is entirely outside
    // of, and their intersection over the wire (non-zero: the whole wire is outside one plane: culled).
    thread_local std::vector<ViewHull> hulls;
    thread_local std::vector<unsigned char> outside;
    hulls.resize(n);
    outside.resize(n);
    const ViewTransform tf(view);
    const PlaneTest planes(view, radius);
    unsigned wire_outside = 63u;
    for (std::size_t i = 0; i < n; ++i) {
        hulls[i] = tf.hull(curve.segments[i]);
        outside[i] = static_cast<unsigned char>(planes.outside(hulls[i]));
        wire_outside &= outside[i];
    }
    if (n == 0 || wire_outside != 0) {
        bool changed = false;
        mark_culled(lod, changed);
        return changed;
    }

    const bool restart = lod.counts.size() != n;
    if (restart) lod.counts.assign(n, 0);
    lod.required.resize(n);
    lod.visible = true;

    double wire_z = std::numeric_limits<double>::infinity();
    double wire_k = 1.0;
    bool changed = restart;
    for (std::size_t i = 0; i < n; ++i) {
        const CubicBezier& c = curve.segments[i];
        uint32_t raw = 1;
        const bool seg_visible = outside[i] == 0;
        if (seg_visible || !settings.coarse_offscreen_segments) {
            const HullDepth h = hull_depth(hulls[i], view);
            bool clamped = false;
            raw = wang_px(c, h, view, eps, max_rings, &clamped);
            lod.clamped_segments += clamped ? 1u : 0u;
            if (seg_visible) {
                ++lod.visible_segments;
                wire_z = std::min(wire_z, h.z_min);
                wire_k = std::max(wire_k, h.k);
            }
        }
        lod.required[i] = raw;
        const uint32_t next = hysteresis_count(lod.counts[i], raw, band);
        if (next != lod.counts[i]) {
            ++lod.changed_counts;
            changed = true;
        }
        lod.counts[i] = next;
    }
    if (lod.visible_segments == 0) {
        // The wire's hull meets the frustum but no single segment's does (the wire wraps around the view): draw
        // it coarsely with the fewest sides; nothing of it is on screen.
        wire_z = std::numeric_limits<double>::infinity();
    }
    lod.z_min_m = std::isfinite(wire_z) ? wire_z : 0.0;
    lod.required_sides = std::isfinite(wire_z) ? sides_for_radius(radius, wire_z, wire_k, view, eps, max_sides) : 3u;
    const uint32_t sides = restart ? lod.required_sides : hysteresis_count(lod.sides, lod.required_sides, band);
    changed = changed || sides != lod.sides;
    lod.sides = std::min(sides, max_sides);
    return changed;
}

ScreenError measure_screen_error(const Curve& curve, std::span<const RingParam> params, const LodView& view,
                                 int samples_per_segment) {
    ScreenError out;
    const std::size_t n_seg = curve.segment_count();
    const std::size_t n_rings = params.size();
    if (n_seg == 0 || n_rings == 0 || samples_per_segment < 1) return out;

    std::vector<glm::dvec3> centre(n_rings);
    for (std::size_t k = 0; k < n_rings; ++k) {
        centre[k] = view.to_view(position(curve.segments[params[k].segment], params[k].t));
    }
    // First ring of every segment (rings are in segment order).
    std::vector<std::size_t> first(n_seg + 1, n_rings);
    for (std::size_t k = n_rings; k-- > 0;) first[params[k].segment] = k;
    for (std::size_t i = n_seg; i-- > 0;) first[i] = std::min(first[i], first[i + 1]);

    const std::size_t n_pieces = curve.closed ? n_rings : n_rings - 1;
    auto piece_distance = [&](const glm::dvec2& p, std::ptrdiff_t j) {
        if (curve.closed) {
            j = (j % static_cast<std::ptrdiff_t>(n_pieces) + static_cast<std::ptrdiff_t>(n_pieces)) %
                static_cast<std::ptrdiff_t>(n_pieces);
        } else if (j < 0 || j >= static_cast<std::ptrdiff_t>(n_pieces)) {
            return std::numeric_limits<double>::infinity();
        }
        const std::size_t a = static_cast<std::size_t>(j);
        const std::size_t b = (a + 1) % n_rings;
        return distance_to_view_piece(p, centre[a], centre[b], view);
    };

    for (std::size_t i = 0; i < n_seg; ++i) {
        const std::size_t lo = first[i];
        const std::size_t hi = first[i + 1];  // one past the segment's last ring
        for (int s = 0; s <= samples_per_segment; ++s) {
            const double t = static_cast<double>(s) / samples_per_segment;
            const glm::dvec3 q = view.to_view(position(curve.segments[i], t));
            if (!(q.z >= view.near_m && q.z <= view.far_m)) continue;
            const glm::dvec2 p = view.view_to_px(q);
            if (!(p.x >= 0.0 && p.x <= view.width_px && p.y >= 0.0 && p.y <= view.height_px)) continue;
            // The piece that holds t: the last ring of this segment with param t <= t.
            std::ptrdiff_t k = static_cast<std::ptrdiff_t>(lo);
            while (static_cast<std::size_t>(k + 1) < hi && params[static_cast<std::size_t>(k + 1)].t <= t) ++k;
            if (lo == hi) k = static_cast<std::ptrdiff_t>(lo) - 1;  // no ring on this segment (count 0): neighbours
            const double d = std::min({piece_distance(p, k - 1), piece_distance(p, k), piece_distance(p, k + 1)});
            ++out.samples;
            if (d > out.max_px) {
                out.max_px = d;
                out.worst_segment = static_cast<uint32_t>(i);
                out.worst_t = t;
            }
        }
    }
    return out;
}

}  // namespace wire
