// Shared inputs of the curve-stage tests and the report: the 20 m hanging cable and the stretched-then-bent run.
#pragma once

#include "wire/bezier.hpp"
#include "wire/pop_free.hpp"
#include "wire/nodes.hpp"
#include "wire/testing/reference.hpp"
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace wire::testing {

inline constexpr double kPi = 3.14159265358979323846;

/// Nodes at the given positions (no other per-node array).
inline WireNodes make_nodes(std::vector<glm::dvec3> p) {
    WireNodes n;
    n.positions = std::move(p);
    return n;
}

/// 20 m cable hanging between (0,0,0) and (16,2,0) (y up): the DESIGN 4.8 catenary.
inline Catenary hanging_cable() {
    Catenary c;
    (void)c.solve(glm::dvec3(0.0), glm::dvec3(16.0, 2.0, 0.0), 20.0);
    return c;
}

/// Nodes on the cable at equal arc lengths (dense_ends = false) or at s = L (1 - cos(pi i/(n-1)))/2
/// (multiresolution spacing, dense near the ends: neighbour ratio ~ 10 at 16 nodes).
inline WireNodes cable_nodes(const Catenary& c, int count, bool dense_ends = false) {
    std::vector<double> s(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) {
        const double f = static_cast<double>(i) / (count - 1);
        s[static_cast<std::size_t>(i)] = c.length_m() * (dense_ends ? 0.5 * (1.0 - std::cos(f * 3.14159265358979323846)) : f);
    }
    WireNodes n;
    n.positions = c.points_at_arc_lengths(s);
    for (int i = 0; i < count; ++i) n.ids.push_back(static_cast<uint32_t>(100 + 10 * i));
    return n;
}

/// Largest distance from the rendered curve (per_segment samples per segment) to the exact catenary.
inline double catenary_error_m(const Curve& curve, const Catenary& c, int per_segment = 64) {
    double worst = 0.0;
    for (const glm::dvec3& p : sample_curve(curve, per_segment)) worst = std::max(worst, c.distance(p));
    return worst;
}

/// A stretched straight run along +x (nodes every 2 m from x = 0 to 10), then a tight 90-degree bend down
/// (a 0.1 m element), then long elements again: the thesis' "stretched wire over a sharp corner".
inline WireNodes stretched_bend_nodes(float stretch) {
    WireNodes n;
    for (int i = 0; i <= 5; ++i) n.positions.emplace_back(2.0 * i, 0.0, 0.0);
    n.positions.emplace_back(10.0, -0.1, 0.0);
    n.positions.emplace_back(10.0, -2.1, 0.0);
    n.positions.emplace_back(10.0, -4.1, 0.0);
    n.stretch.assign(n.positions.size(), stretch);
    return n;
}

/// A taut wire whose nodes zig-zag +-2 cm off a straight 20 m line (nodes every 2 m, turning ~2.3 degrees):
/// with stretch > 1 the truth is the node polyline (a stretched cable runs straight between its nodes).
inline WireNodes kinked_taut_nodes(float stretch) {
    WireNodes n;
    for (int i = 0; i <= 10; ++i) n.positions.emplace_back(2.0 * i, (i % 2 ? 0.02 : -0.02), 0.0);
    n.stretch.assign(n.positions.size(), stretch);
    return n;
}

/// Max distance from the curve to the polyline through its nodes.
inline double polyline_deviation_m(const Curve& c, const WireNodes& n) {
    double worst = 0.0;
    for (const glm::dvec3& p : sample_curve(c, 128)) worst = std::max(worst, distance_to_polyline(p, n.positions));
    return worst;
}

struct BendNumbers {
    double straight_dev_m = 0.0;  ///< max distance off the line y = z = 0 over the straight run's segments 0..4
    double overshoot_m = 0.0;     ///< max distance past the corner line x = 10 (over the whole curve)
    double kink_deg = 0.0;        ///< max angle between the tangents either side of a node
};

inline BendNumbers measure_bend(const Curve& curve) {
    BendNumbers b;
    for (std::size_t k = 0; k < curve.segments.size(); ++k) {
        for (int i = 0; i <= 256; ++i) {
            const glm::dvec3 p = position(curve.segments[k], i / 256.0);
            if (k < 5) b.straight_dev_m = std::max(b.straight_dev_m, std::hypot(p.y, p.z));
            b.overshoot_m = std::max(b.overshoot_m, p.x - 10.0);
        }
        if (k > 0) {
            const glm::dvec3 t0 = derivative(curve.segments[k - 1], 1.0), t1 = derivative(curve.segments[k], 0.0);
            const double l0 = glm::length(t0), l1 = glm::length(t1);
            double deg = 180.0;  // atan2, not acos: acos cannot resolve angles below ~1e-6 deg (1 - cos rounds)
            if (l0 > 0.0 && l1 > 0.0) deg = std::atan2(glm::length(glm::cross(t0, t1)), glm::dot(t0, t1)) * 180.0 / 3.14159265358979323846;
            b.kink_deg = std::max(b.kink_deg, deg);
        }
    }
    return b;
}

struct NamedSettings {
    std::string name;
    SplineSettings settings;
};

/// The spline variants compared in the tests and the report.
inline std::vector<NamedSettings> spline_variants() {
    return {
        {"uniform", {.kind = SplineKind::catmull_rom, .alpha = 0.0}},
        {"centripetal", {.kind = SplineKind::catmull_rom, .alpha = 0.5}},
        {"chordal", {.kind = SplineKind::catmull_rom, .alpha = 1.0}},
        {"centripetal+tension1", {.kind = SplineKind::catmull_rom, .alpha = 0.5, .tension = 1.0}},
        {"c2", {.kind = SplineKind::c2}},
        {"automatic", {.kind = SplineKind::automatic}},
        {"linear", {.kind = SplineKind::linear}},
    };
}

/// The 16-node cable with one node inserted between nodes 7 and 8, exactly on the curve `kind` renders
/// (at the segment's parameter 0.5), or on the exact catenary at the same arc length (on_catenary = true).
inline WireNodes cable_with_inserted_node(const Catenary& cable, const SplineSettings& spline, bool on_catenary = false) {
    WireNodes n = cable_nodes(cable, 16);
    Curve c;
    (void)build_curve(n, spline, c);
    const glm::dvec3 p = on_catenary ? cable.point_at_arc_length(cable.length_m() * 7.5 / 15.0) : position(c.segments[7], 0.5);
    n.positions.insert(n.positions.begin() + 8, p);
    n.ids.insert(n.ids.begin() + 8, 175u);
    return n;
}

/// The 16-node cable without its node 8 (id 180).
inline WireNodes cable_with_removed_node(const Catenary& cable) {
    WireNodes n = cable_nodes(cable, 16);
    n.positions.erase(n.positions.begin() + 8);
    n.ids.erase(n.ids.begin() + 8);
    return n;
}

struct PopNumbers {
    double unblended_m = 0.0;    ///< jump of the exact curves from one state to the next
    double blended_max_m = 0.0;   ///< largest jump between consecutive rendered frames with the blend
    int frames = 0;              ///< frames until the blend ended
    double final_gap_m = 0.0;    ///< distance between the last rendered frame and the exact new curve
};

/// Shows `before` for two frames, then `after` until the blend ends (at most 1000 frames).
inline PopNumbers measure_pop(const SplineSettings& spline, const WireNodes& before, const WireNodes& after) {
    PopNumbers r;
    Curve a, b;
    (void)build_curve(before, spline, a);
    (void)build_curve(after, spline, b);
    r.unblended_m = curve_jump_m(a, b);
    PopFreeCurve m({.spline = spline});
    Curve prev, cur;
    (void)m.update(before, prev);
    (void)m.update(before, prev);
    for (int f = 0; f < 1000; ++f) {
        (void)m.update(after, cur);
        r.blended_max_m = std::max(r.blended_max_m, curve_jump_m(prev, cur));
        prev = cur;
        ++r.frames;
        if (!m.blending()) break;
    }
    r.final_gap_m = curve_jump_m(cur, m.target());
    return r;
}

}  // namespace wire::testing
