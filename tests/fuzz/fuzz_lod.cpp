// libFuzzer target: the LOD (lod.hpp) with arbitrary curves, cameras, viewports and settings, several updates of
// one WireLod in a row (hysteresis, settings that change between frames). Cameras: sane ones, the eye inside
// the wire, a curve point exactly on the near plane or behind the eye, and degenerate ones (eye == target, up
// along the view direction, fov 0 or >= pi, empty or negative viewports, near 0 or beyond far, NaN/Inf).
// Properties of every update: no crash or UB; a culled wire has no counts and 0 sides; a visible one has one
// count per segment, each in [1, max_rings] (the stated cap; 0 -> 256; 0 allowed for a segment a ring span crosses
// without keep_node_resolution, but never for the first) and >= what the tolerance requires now, required counts
// <= max_rings, sides in [3, max_sides] (0 -> 32), z_min finite. For a valid camera the
// O(1) bounding-sphere test gives the same result as the hull test, and the decision is conservative: a curve
// point inside the frustum makes the wire visible and (with keep_node_resolution) its segment at least as finely
// tessellated as segment_ring_count_px asks, not coarse.
// WIRE_FUZZ_DUMP=1 prints the decoded cameras and settings.
#include "fuzz_checks.hpp"

#include <wire/lod.hpp>
#include <wire/spline.hpp>

#include <fuzzer/FuzzedDataProvider.h>

#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <vector>

namespace {

double special_or_raw(FuzzedDataProvider& in) {
    static constexpr double kSpecial[] = {0.0, -0.0, 1.0, -1.0, 1e-9, 1e-300, 5e-324, 1e6, 1e12, 1e300,
                                          std::numbers::pi, 0.5 * std::numbers::pi,
                                          std::numeric_limits<double>::infinity(),
                                          -std::numeric_limits<double>::infinity(),
                                          std::numeric_limits<double>::quiet_NaN()};
    return wire_fuzz::special_or_raw(in, kSpecial);
}

glm::dvec3 vec_in(FuzzedDataProvider& in, double lo, double hi) {
    return {in.ConsumeFloatingPointInRange<double>(lo, hi), in.ConsumeFloatingPointInRange<double>(lo, hi),
            in.ConsumeFloatingPointInRange<double>(lo, hi)};
}

/// A chain of cubic segments: a random walk of control points at a random scale and offset (within the
/// +-1e12 m contract of the curve stage), or build_curve of random nodes.
wire::Curve read_curve(FuzzedDataProvider& in) {
    wire::Curve c;
    c.closed = in.ConsumeBool();
    const double scale = std::pow(10.0, in.ConsumeFloatingPointInRange<double>(-4.0, 6.0));
    const glm::dvec3 offset = in.ConsumeBool() ? glm::dvec3(0.0) : vec_in(in, -1e12, 1e12);
    const std::size_t segments = in.ConsumeIntegralInRange<std::size_t>(1, 24);
    if (in.ConsumeBool()) {
        wire::WireNodes nodes;
        glm::dvec3 p = offset;
        for (std::size_t i = 0; i <= segments; ++i) {
            nodes.positions.push_back(p);
            p += scale * vec_in(in, -1.0, 1.0);
        }
        wire::SplineSettings s;
        s.kind = static_cast<wire::SplineKind>(in.ConsumeIntegralInRange<int>(0, 3));
        s.closed = c.closed;
        s.radius_m = static_cast<float>(scale * in.ConsumeFloatingPointInRange<double>(1e-3, 0.5));
        if (wire::build_curve(nodes, s, c).ok()) return c;
        c = wire::Curve{};
    }
    glm::dvec3 p = offset + scale * vec_in(in, -1.0, 1.0);
    const glm::dvec3 first = p;
    for (std::size_t i = 0; i < segments; ++i) {
        wire::CubicBezier b;
        b.b0 = p;
        b.b1 = p + scale * vec_in(in, -1.0, 1.0);
        b.b2 = p + scale * vec_in(in, -1.0, 1.0);
        b.b3 = c.closed && i + 1 == segments ? first : p + scale * vec_in(in, -1.0, 1.0);
        p = b.b3;
        c.segments.push_back(b);
    }
    const std::size_t nodes = c.closed ? segments : segments + 1;
    for (std::size_t i = 0; i < nodes; ++i) {
        c.source_node.push_back(static_cast<uint32_t>(i));
        const uint8_t pick = in.ConsumeIntegral<uint8_t>();
        const double r = pick < 240 ? scale * in.ConsumeFloatingPointInRange<double>(1e-4, 0.5)
                                    : std::abs(special_or_raw(in));
        c.radius_m.push_back(std::isfinite(static_cast<float>(r)) && static_cast<float>(r) > 0.0f ? static_cast<float>(r) : 0.01f);
    }
    c.stretch.assign(segments, 1.0f);
    return c;
}

wire::LodView read_view(FuzzedDataProvider& in, const wire::Curve& curve) {
    const uint8_t mode = in.ConsumeIntegralInRange<uint8_t>(0, 4);
    const glm::dvec3 some_point = wire::position(
        curve.segments[in.ConsumeIntegralInRange<std::size_t>(0, curve.segments.size() - 1)],
        in.ConsumeFloatingPointInRange<double>(0.0, 1.0));
    double scale = 1.0;
    for (const wire::CubicBezier& b : curve.segments) scale = std::max(scale, glm::length(b.b3 - b.b0));
    glm::dvec3 eye, target, up(0.0, 1.0, 0.0);
    double fov = in.ConsumeFloatingPointInRange<double>(0.01, 3.1);
    double width = in.ConsumeFloatingPointInRange<double>(1.0, 8192.0);
    double height = in.ConsumeFloatingPointInRange<double>(1.0, 8192.0);
    double near_m = std::pow(10.0, in.ConsumeFloatingPointInRange<double>(-4.0, 1.0));
    double far_m = near_m * std::pow(10.0, in.ConsumeFloatingPointInRange<double>(1e-6, 7.0));
    switch (mode) {
        case 0:  // outside, looking at or near the wire
            eye = some_point + scale * vec_in(in, -3.0, 3.0);
            target = some_point + scale * vec_in(in, -0.5, 0.5);
            break;
        case 1:  // inside the wire: the eye on the curve (or its tube), looking anywhere
            eye = some_point;
            target = eye + vec_in(in, -1.0, 1.0);
            break;
        case 2: {  // a curve point exactly on the near plane (or slightly in front/behind it)
            const glm::dvec3 dir = vec_in(in, -1.0, 1.0);
            const double len = glm::length(dir);
            const glm::dvec3 d = len > 0.0 ? dir / len : glm::dvec3(0, 0, 1);
            const double k = in.PickValueInArray({1.0, 1.0 - 1e-12, 1.0 + 1e-12, 0.5, 2.0});
            eye = some_point - (k * near_m) * d;
            target = some_point + d;
            break;
        }
        case 3: {  // the wire behind the eye
            eye = some_point + scale * vec_in(in, -1.0, 1.0);
            target = eye + (eye - some_point);
            break;
        }
        default:  // degenerate: anything goes
            eye = in.ConsumeBool() ? some_point : glm::dvec3(special_or_raw(in), special_or_raw(in), special_or_raw(in));
            target = in.ConsumeBool() ? eye : glm::dvec3(special_or_raw(in), special_or_raw(in), special_or_raw(in));
            up = in.ConsumeBool() ? target - eye : glm::dvec3(special_or_raw(in), special_or_raw(in), special_or_raw(in));
            if (in.ConsumeBool()) fov = special_or_raw(in);
            if (in.ConsumeBool()) width = special_or_raw(in);
            if (in.ConsumeBool()) height = special_or_raw(in);
            if (in.ConsumeBool()) near_m = special_or_raw(in);
            if (in.ConsumeBool()) far_m = special_or_raw(in);
            break;
    }
    if (in.ConsumeIntegral<uint8_t>() < 16) up = target - eye;  // up along the view direction
    if (std::getenv("WIRE_FUZZ_DUMP") != nullptr)
        std::fprintf(stderr,
                     "perspective(eye {%.17g, %.17g, %.17g}, target {%.17g, %.17g, %.17g}, up {%.17g, %.17g, %.17g}, "
                     "fov %.17g, %.17g x %.17g px, near %.17g, far %.17g), mode %d\n",
                     eye.x, eye.y, eye.z, target.x, target.y, target.z, up.x, up.y, up.z, fov, width, height, near_m,
                     far_m, int(mode));
    return wire::LodView::perspective(eye, target, up, fov, width, height, near_m, far_m);
}

wire::LodSettings read_settings(FuzzedDataProvider& in) {
    wire::LodSettings s;
    const uint8_t pick = in.ConsumeIntegral<uint8_t>();
    s.tolerance_px = pick < 160 ? in.ConsumeFloatingPointInRange<double>(0.01, 10.0) : pick < 192 ? 0.0 : special_or_raw(in);
    s.max_rings_per_segment = in.ConsumeBool() ? 0u : in.ConsumeIntegralInRange<uint32_t>(0, 1024);
    s.max_sides = in.ConsumeBool() ? 0u : in.ConsumeIntegralInRange<uint32_t>(0, 64);
    const uint8_t band = in.ConsumeIntegral<uint8_t>();
    s.hysteresis_band = band < 128 ? 0.0 : band < 192 ? in.ConsumeFloatingPointInRange<double>(-1.0, 2.0) : special_or_raw(in);
    s.coarse_offscreen_segments = in.ConsumeIntegral<uint8_t>() < 200;
    s.keep_node_resolution = in.ConsumeBool();
    return s;
}

/// A camera whose frustum is well defined: finite fields, 0 < near < far, 0 < fov < pi, a non-empty viewport
/// and an orthonormal view rotation.
bool valid_view(const wire::LodView& v) {
    if (!(v.near_m > 0.0 && v.far_m > v.near_m && std::isfinite(v.far_m) && v.width_px >= 1.0 && v.height_px >= 1.0 &&
          std::isfinite(v.width_px) && std::isfinite(v.height_px) && v.tan_half_x > 0.0 && v.tan_half_y > 0.0 &&
          std::isfinite(v.tan_half_x) && std::isfinite(v.tan_half_y) && std::isfinite(v.focal_px)))
        return false;
    const glm::dmat3 r(v.view_from_world);
    const glm::dmat3 rt_r = glm::transpose(r) * r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (!(std::abs(rt_r[i][j] - (i == j ? 1.0 : 0.0)) < 1e-9)) return false;
    return wire_fuzz::finite_vec(v.eye_m) && wire_fuzz::finite_vec(glm::dvec3(v.view_from_world[3]));
}

void dump(const wire::LodView& v, const wire::LodSettings& s, int update) {
    std::fprintf(stderr,
                 "update %d: eye %.17g %.17g %.17g tan %.17g %.17g focal %.17g near %.17g far %.17g viewport %.17g x "
                 "%.17g valid %d | tolerance %.17g max_rings %u max_sides %u band %.17g coarse %d\n",
                 update, v.eye_m.x, v.eye_m.y, v.eye_m.z, v.tan_half_x, v.tan_half_y, v.focal_px, v.near_m, v.far_m,
                 v.width_px, v.height_px, int(valid_view(v)), s.tolerance_px, s.max_rings_per_segment, s.max_sides,
                 s.hysteresis_band, int(s.coarse_offscreen_segments));
}

void check(const wire::Curve& curve, const wire::LodView& view, const wire::LodSettings& s, const wire::WireLod& lod) {
    const uint32_t max_rings = s.max_rings_per_segment ? s.max_rings_per_segment : 256u;
    const uint32_t max_sides = std::max<uint32_t>(s.max_sides ? s.max_sides : 32u, 3u);
    if (!lod.visible) {
        wire_fuzz::require(lod.counts.empty() && lod.sides == 0, "culled wire with counts or sides");
    } else {
        wire_fuzz::require(lod.counts.size() == curve.segment_count(), "count per segment missing");
        wire_fuzz::require(lod.required.size() == curve.segment_count(), "required count per segment missing");
        // Below the node resolution a ring interval may span segments: counts of 0 mark the segments it crosses.
        const uint32_t least = s.keep_node_resolution ? 1u : 0u;
        wire_fuzz::require(lod.counts.empty() || lod.counts[0] >= 1, "visible wire without a first ring");
        for (std::size_t i = 0; i < lod.counts.size(); ++i) {
            wire_fuzz::require(lod.required[i] >= least && lod.required[i] <= max_rings, "required count outside [least, max_rings]");
            wire_fuzz::require(lod.counts[i] >= least && lod.counts[i] <= max_rings, "count outside [least, max_rings]");
            wire_fuzz::require(lod.counts[i] >= lod.required[i], "count below what the tolerance requires");
        }
        wire_fuzz::require(lod.sides >= 3 && lod.sides <= max_sides, "sides outside [3, max_sides]");
        wire_fuzz::require(lod.required_sides >= 3 && lod.required_sides <= max_sides, "required sides outside [3, max_sides]");
        wire_fuzz::require(lod.visible_segments <= curve.segment_count(), "more visible segments than segments");
        wire_fuzz::require(std::isfinite(lod.z_min_m), "z_min not finite");
        wire_fuzz::require(!valid_view(view) || lod.z_min_m >= view.near_m || lod.visible_segments == 0,
                           "z_min in front of the near plane");
    }
    if (!valid_view(view)) return;

    // Conservative: a sample strictly inside the frustum (by a margin for rounding at large coordinates) makes
    // the wire visible and its segment tessellated for the tolerance, as segment_ring_count_px counts it.
    const double margin = 1e-9 * (glm::length(view.eye_m) + glm::length(curve.segments[0].b0)) + 1e-12;
    for (std::size_t i = 0; i < curve.segment_count(); ++i) {
        bool inside = false;
        for (int k = 0; k <= 32 && !inside; ++k) {
            const glm::dvec3 q = view.to_view(wire::position(curve.segments[i], k / 32.0));
            inside = q.z >= view.near_m + margin && q.z <= view.far_m - margin &&
                     std::abs(q.x) <= q.z * view.tan_half_x - margin && std::abs(q.y) <= q.z * view.tan_half_y - margin;
        }
        if (!inside) continue;
        if (!lod.visible) {
            std::fprintf(stderr, "segment %zu has a point inside the frustum\n", i);
            wire_fuzz::fail("wire culled although a curve point is on screen");
        }
        if (!s.keep_node_resolution) continue;  // spans decide counts across segments: visibility is the property
        const uint32_t need = wire::segment_ring_count_px(curve.segments[i], view, s.tolerance_px, s.max_rings_per_segment);
        // Conservative: never coarser than the tolerance needs (more is allowed: e.g. a denormal tolerance whose
        // world-space bound underflows takes max_rings on every path but a straight segment's own count of 1).
        if (lod.required[i] < need) {
            std::fprintf(stderr, "segment %zu: required %u, the tolerance needs %u\n", i, lod.required[i], need);
            wire_fuzz::fail("an on-screen segment is not tessellated for the tolerance");
        }
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    const wire::Curve curve = read_curve(in);
    if (curve.segments.empty()) return 0;
    static const bool want_dump = std::getenv("WIRE_FUZZ_DUMP") != nullptr;
    const wire::BoundingSphere bounds = wire::curve_bounding_sphere(curve);
    if (want_dump) {
        std::fprintf(stderr, "curve: %zu segments, closed %d, sphere centre %.17g %.17g %.17g radius %.17g\n",
                     curve.segment_count(), int(curve.closed), bounds.centre_m.x, bounds.centre_m.y, bounds.centre_m.z,
                     bounds.radius_m);
        for (const wire::CubicBezier& b : curve.segments)
            std::fprintf(stderr, "  %.17g %.17g %.17g | %.17g %.17g %.17g | %.17g %.17g %.17g | %.17g %.17g %.17g\n",
                         b.b0.x, b.b0.y, b.b0.z, b.b1.x, b.b1.y, b.b1.z, b.b2.x, b.b2.y, b.b2.z, b.b3.x, b.b3.y, b.b3.z);
        for (float r : curve.radius_m) std::fprintf(stderr, "  radius %.9g\n", double(r));
    }
    wire::WireLod lod;          // updated with the bounding sphere, as the systems do
    wire::WireLod hull_only;    // the same updates without it
    const int updates = in.ConsumeIntegralInRange<int>(1, 6);
    wire::LodSettings settings = read_settings(in);
    for (int u = 0; u < updates; ++u) {
        const wire::LodView view = read_view(in, curve);
        if (u > 0 && in.ConsumeIntegral<uint8_t>() < 64) settings = read_settings(in);
        if (want_dump) dump(view, settings, u);
        const wire::WireLod before = lod;
        const bool changed = wire::update_lod(curve, view, settings, lod, &bounds);
        (void)wire::update_lod(curve, view, settings, hull_only);
        check(curve, view, settings, lod);
        // The sphere stands for the hull only under a rigid view transform: compared for valid cameras (a
        // degenerate look-at, e.g. up along the view direction, skews the transform and the two may differ).
        if (valid_view(view)) {
            if (lod.visible != hull_only.visible)
                std::fprintf(stderr, "update %d: with the sphere visible %d, hull test alone visible %d\n", u,
                             int(lod.visible), int(hull_only.visible));
            wire_fuzz::require(lod.visible == hull_only.visible, "bounding-sphere cull differs from the hull test");
            wire_fuzz::require(lod.counts == hull_only.counts && lod.sides == hull_only.sides,
                               "counts with the bounding sphere differ from the hull test's");
        } else {
            check(curve, view, settings, hull_only);
            hull_only = lod;  // same history (hysteresis) for the next comparison
        }
        wire_fuzz::require(changed || (lod.counts == before.counts && lod.sides == before.sides && lod.visible == before.visible),
                           "update_lod changed counts or sides but returned false");
    }
    return 0;
}
