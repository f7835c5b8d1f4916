// Test inputs for the ring stage built by hand (no spline code): helices with exact tangents, polylines, loops,
// plus property checks shared by the frame, ring and tube tests.
#pragma once

#include "wire/curve.hpp"
#include "wire/frames.hpp"
#include "wire/rings.hpp"
#include "wire/tessellate.hpp"
#include "wire/tube.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <algorithm>
#include <numbers>
#include <random>
#include <vector>

namespace wire::test {

inline constexpr double kPi = std::numbers::pi;

/// Cubic Hermite piece (p0, m0) -> (p1, m1) in Bezier form (m are derivatives per unit t).
inline CubicBezier hermite(const glm::dvec3& p0, const glm::dvec3& m0, const glm::dvec3& p1, const glm::dvec3& m1) {
    return CubicBezier{p0, p0 + m0 / 3.0, p1 - m1 / 3.0, p1};
}

/// A Curve from segments with one radius for every node and stretch 1.
inline Curve make_curve(std::vector<CubicBezier> segs, float radius_m, bool closed = false) {
    Curve c;
    const std::size_t nodes = closed ? segs.size() : segs.size() + 1;
    c.segments = std::move(segs);
    c.closed = closed;
    c.source_node.resize(nodes);
    for (std::size_t i = 0; i < nodes; ++i) c.source_node[i] = static_cast<uint32_t>(i);
    c.radius_m.assign(nodes, radius_m);
    c.stretch.assign(c.segments.size(), 1.0f);
    return c;
}

/// Helix x(th) = (a cos th, a sin th, b th) through `nodes_per_turn` nodes per turn for `turns` turns, as Hermite
/// segments with the exact derivative (so the tangents at nodes are exact; between nodes the cubic approximates).
inline Curve helix_curve(double a, double b, int turns, int nodes_per_turn, const glm::dvec3& offset = {},
                         float radius_m = 0.05f) {
    const double h = 2.0 * kPi / nodes_per_turn;
    auto x = [&](double th) { return offset + glm::dvec3(a * std::cos(th), a * std::sin(th), b * th); };
    auto dx = [&](double th) { return h * glm::dvec3(-a * std::sin(th), a * std::cos(th), b); };
    std::vector<CubicBezier> segs;
    for (int i = 0; i < turns * nodes_per_turn; ++i) {
        const double t0 = i * h;
        const double t1 = (i + 1) * h;
        segs.push_back(hermite(x(t0), dx(t0), x(t1), dx(t1)));
    }
    return make_curve(std::move(segs), radius_m);
}

/// Straight segments through points (control points at thirds).
inline Curve polyline_curve(const std::vector<glm::dvec3>& p, float radius_m, bool closed = false) {
    std::vector<CubicBezier> segs;
    const std::size_t n = closed ? p.size() : p.size() - 1;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec3 a = p[i];
        const glm::dvec3 b = p[(i + 1) % p.size()];
        segs.push_back(CubicBezier{a, a + (b - a) / 3.0, a + 2.0 * (b - a) / 3.0, b});
    }
    return make_curve(std::move(segs), radius_m, closed);
}

/// Catmull-Rom (uniform) through points with analytic Hermite tangents, open or closed.
inline Curve catmull_rom_curve(const std::vector<glm::dvec3>& p, float radius_m, bool closed = false) {
    const std::size_t n = p.size();
    auto at = [&](long i) {
        if (closed) return p[static_cast<std::size_t>((i % static_cast<long>(n) + static_cast<long>(n)) % n)];
        if (i < 0) return 2.0 * p[0] - p[1];
        if (i >= static_cast<long>(n)) return 2.0 * p[n - 1] - p[n - 2];
        return p[static_cast<std::size_t>(i)];
    };
    std::vector<CubicBezier> segs;
    const long segments = static_cast<long>(closed ? n : n - 1);
    for (long i = 0; i < segments; ++i) {
        const glm::dvec3 m0 = 0.5 * (at(i + 1) - at(i - 1));
        const glm::dvec3 m1 = 0.5 * (at(i + 2) - at(i));
        segs.push_back(hermite(at(i), m0, at(i + 1), m1));
    }
    return make_curve(std::move(segs), radius_m, closed);
}

inline RingSet rings_for(const Curve& curve, uint32_t rings_per_segment, const RingSettings& settings = {}) {
    std::vector<uint32_t> counts;
    segment_ring_counts(curve, TessellateSettings{.rings_per_segment = rings_per_segment}, counts);
    std::vector<RingParam> params;
    place_rings(curve, counts, params);
    RingSet set;
    build_rings(curve, params, settings, set);
    return set;
}

/// Signed angle (radians) from a to b about axis t (a, b orthogonal to unit t).
inline double angle_about(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& t) {
    return std::atan2(glm::dot(glm::cross(a, b), t), glm::dot(a, b));
}

inline bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Frames finite, unit, mutually orthogonal and right-handed to `tol`; float ring records unit to 1e-5.
inline double expect_orthonormal(const RingSet& set, double tol = 1e-5) {
    std::size_t bad = 0;
    double worst = 0.0;
    for (std::size_t i = 0; i < set.frames.size(); ++i) {
        const Frame& f = set.frames[i];
        worst = std::max({worst, std::abs(glm::length(f.r) - 1.0), std::abs(glm::dot(f.t, f.r)),
                          std::abs(glm::length(f.s) - 1.0), std::abs(glm::dot(f.t, f.s))});
        const bool ok = finite(f.t) && finite(f.r) && finite(f.s) && std::abs(glm::length(f.t) - 1.0) < tol &&
                        std::abs(glm::length(f.r) - 1.0) < tol && std::abs(glm::length(f.s) - 1.0) < tol &&
                        std::abs(glm::dot(f.t, f.r)) < tol && std::abs(glm::dot(f.t, f.s)) < tol &&
                        std::abs(glm::dot(f.r, f.s)) < tol && glm::length(glm::cross(f.r, f.s) - f.t) < tol;
        const Ring& r = set.rings[i];
        const bool ring_ok = finite(r.centre_m) && finite(r.normal) && finite(r.binormal) &&
                             std::abs(glm::length(r.normal) - 1.0f) < 1e-5f &&
                             std::abs(glm::length(r.binormal) - 1.0f) < 1e-5f &&
                             std::abs(glm::dot(r.normal, r.binormal)) < 1e-5f && std::isfinite(r.radius_m) &&
                             std::isfinite(r.u);
        if (!ok || !ring_ok) {
            if (bad++ < 5) ADD_FAILURE() << "frame " << i << " not orthonormal/finite";
        }
    }
    EXPECT_EQ(bad, 0u);
    return worst;
}

/// u strictly increasing where the wire has length (non-decreasing everywhere) and finite.
inline void expect_u_monotonic(const RingSet& set) {
    std::size_t bad = 0;
    for (std::size_t i = 1; i < set.u.size(); ++i) {
        if (!(set.u[i] >= set.u[i - 1]) || !std::isfinite(set.u[i])) ++bad;
    }
    EXPECT_EQ(bad, 0u) << "u not monotonic";
}

struct WeldReport {
    std::size_t triangles = 0;             ///< after dropping zero-area ones (repeated welded vertex)
    std::size_t degenerate_triangles = 0;
    std::size_t bad_edges = 0;             ///< undirected edges not shared by exactly two triangles
    std::size_t inconsistent_edges = 0;    ///< directed edges used twice (winding flips)
};

/// Welds vertices by exact position, drops triangles with a repeated welded vertex, counts edge uses.
inline WeldReport weld_check(const TubeMesh& mesh) {
    std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> keys(mesh.vertices.size());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        std::memcpy(keys[i].first.data(), &mesh.vertices[i].position, sizeof(keys[i].first));
        keys[i].second = static_cast<uint32_t>(i);
    }
    std::sort(keys.begin(), keys.end());
    std::vector<uint32_t> weld(mesh.vertices.size());
    uint32_t id = 0;
    for (std::size_t i = 0; i < keys.size(); ++i) {
        if (i > 0 && keys[i].first != keys[i - 1].first) ++id;
        weld[keys[i].second] = id;
    }
    WeldReport rep;
    std::vector<uint64_t> directed;
    auto edge = [](uint32_t a, uint32_t b) { return (static_cast<uint64_t>(a) << 32) | b; };
    for (std::size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
        const uint32_t a = weld[mesh.indices[k]], b = weld[mesh.indices[k + 1]], c = weld[mesh.indices[k + 2]];
        if (a == b || b == c || a == c) {
            ++rep.degenerate_triangles;
            continue;
        }
        ++rep.triangles;
        directed.push_back(edge(a, b));
        directed.push_back(edge(b, c));
        directed.push_back(edge(c, a));
    }
    std::sort(directed.begin(), directed.end());
    auto count_of = [&](uint64_t e) {
        const auto r = std::equal_range(directed.begin(), directed.end(), e);
        return r.second - r.first;
    };
    for (std::size_t i = 0; i < directed.size();) {
        std::size_t j = i;
        while (j < directed.size() && directed[j] == directed[i]) ++j;
        const auto count = static_cast<std::ptrdiff_t>(j - i);
        const uint64_t e = directed[i];
        if (count != 1) ++rep.inconsistent_edges;
        if (count_of(edge(static_cast<uint32_t>(e & 0xffffffffu), static_cast<uint32_t>(e >> 32))) != count) {
            ++rep.bad_edges;
        }
        i = j;
    }
    return rep;
}

}  // namespace wire::test
