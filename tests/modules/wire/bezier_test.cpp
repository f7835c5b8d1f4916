// Tests of the cubic Bezier segment's operations (wire/curve.hpp's evaluation, modules/wire/src/bezier.cpp):
// against exact cubics given in power form, whose values, derivatives, sub-pieces and arc lengths are known.
#include <gtest/gtest.h>

#include "wire/bezier.hpp"
#include "wire/curve.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace wire;
using glm::dvec3;

namespace {

// A cubic in power form, P(t) = p0 + p1 t + p2 t^2 + p3 t^3: the exact reference.
struct PowerCubic {
    dvec3 p0, p1, p2, p3;
    [[nodiscard]] dvec3 at(double t) const { return p0 + t * (p1 + t * (p2 + t * p3)); }
    [[nodiscard]] dvec3 d1(double t) const { return p1 + t * (2.0 * p2 + t * (3.0 * p3)); }
    [[nodiscard]] dvec3 d2(double t) const { return 2.0 * p2 + (6.0 * t) * p3; }
    // Its Bernstein (Bezier) control points: b0 = p0, b1 = p0 + p1/3, b2 = p0 + 2p1/3 + p2/3, b3 = P(1).
    [[nodiscard]] CubicBezier bezier() const {
        return {p0, p0 + p1 / 3.0, p0 + (2.0 / 3.0) * p1 + p2 / 3.0, p0 + p1 + p2 + p3};
    }
};

// x = t - t^3/3, y = t^2: speed |P'| = sqrt((1 - t^2)^2 + 4t^2) = 1 + t^2, so the arc length over [0, 1] is 4/3.
const PowerCubic kPolySpeed{{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {-1.0 / 3.0, 0.0, 0.0}};
// A general space cubic with every coefficient in use.
const PowerCubic kSpace{{1.5, -2.0, 0.25}, {3.0, 1.0, -2.0}, {-4.5, 2.5, 1.0}, {2.0, -1.25, 3.5}};

double dist(const dvec3& a, const dvec3& b) { return glm::length(a - b); }

}  // namespace

TEST(WireBezier, PositionAndDerivativesMatchThePowerForm) {
    for (const PowerCubic& p : {kPolySpeed, kSpace}) {
        const CubicBezier c = p.bezier();
        // The ends are exact (the Bernstein form's weights are 1 and 0 there).
        EXPECT_EQ(position(c, 0.0), c.b0);
        EXPECT_EQ(position(c, 1.0), c.b3);
        for (double t : {0.0, 0.1, 0.25, 0.5, 0.7, 0.9, 1.0}) {
            EXPECT_LT(dist(position(c, t), p.at(t)), 1e-14) << t;
            EXPECT_LT(dist(derivative(c, t), p.d1(t)), 1e-13) << t;
            EXPECT_LT(dist(second_derivative(c, t), p.d2(t)), 1e-13) << t;
        }
        // B'(0) = 3 (b1 - b0), B'(1) = 3 (b3 - b2).
        EXPECT_LT(dist(derivative(c, 0.0), 3.0 * (c.b1 - c.b0)), 1e-14);
        EXPECT_LT(dist(derivative(c, 1.0), 3.0 * (c.b3 - c.b2)), 1e-14);
    }
}

TEST(WireBezier, ControlHullBoundsTheSegment) {
    const CubicBezier c = kSpace.bezier();
    const dvec3 lo = glm::min(glm::min(c.b0, c.b1), glm::min(c.b2, c.b3));
    const dvec3 hi = glm::max(glm::max(c.b0, c.b1), glm::max(c.b2, c.b3));
    for (int i = 0; i <= 200; ++i) {
        const dvec3 q = position(c, i / 200.0);
        for (int a = 0; a < 3; ++a) {
            EXPECT_GE(q[a], lo[a] - 1e-14) << i;
            EXPECT_LE(q[a], hi[a] + 1e-14) << i;
        }
    }
}

TEST(WireBezier, SubSegmentIsTheSamePieceReparameterized) {
    const CubicBezier c = kSpace.bezier();
    for (const auto& [t0, t1] : {std::pair{0.0, 1.0}, {0.0, 0.3}, {0.3, 1.0}, {0.2, 0.65}, {0.9, 0.95}}) {
        const CubicBezier s = sub_segment(c, t0, t1);
        const double h = t1 - t0;
        for (double u : {0.0, 0.2, 0.5, 0.8, 1.0}) {
            const double t = t0 + u * h;
            EXPECT_LT(dist(position(s, u), kSpace.at(t)), 1e-13) << t0 << " " << t1 << " " << u;
            // The chain rule: d/du = h d/dt, d2/du2 = h^2 d2/dt2.
            EXPECT_LT(dist(derivative(s, u), h * kSpace.d1(t)), 1e-12) << t0 << " " << t1 << " " << u;
            EXPECT_LT(dist(second_derivative(s, u), (h * h) * kSpace.d2(t)), 1e-11) << t0 << " " << t1 << " " << u;
        }
    }
    // The whole segment is itself, and pieces cut at a shared parameter meet without a gap.
    const CubicBezier whole = sub_segment(c, 0.0, 1.0);
    EXPECT_LT(dist(whole.b0, c.b0) + dist(whole.b1, c.b1) + dist(whole.b2, c.b2) + dist(whole.b3, c.b3), 1e-14);
    const CubicBezier left = sub_segment(c, 0.0, 0.4), right = sub_segment(c, 0.4, 1.0);
    EXPECT_LT(dist(left.b3, right.b0), 1e-14);
    EXPECT_LT(dist(left.b0, c.b0), 1e-14);
    EXPECT_LT(dist(right.b3, c.b3), 1e-14);
}

TEST(WireBezier, ArcLengthOfExactCubics) {
    // Polynomial speed 1 + t^2: 4/3.
    EXPECT_NEAR(arc_length_m(kPolySpeed.bezier()), 4.0 / 3.0, 1e-12);
    // A straight segment, even with unevenly spaced inner control points (a non-uniform speed): its chord.
    const CubicBezier line{{1.0, 2.0, 3.0}, {1.1, 2.2, 3.3}, {2.5, 5.0, 7.5}, {4.0, 8.0, 12.0}};
    EXPECT_NEAR(arc_length_m(line), glm::length(line.b3 - line.b0), 1e-12);
    // A curve's length is the sum of its segments'; the halves of a split segment add up to it.
    Curve curve;
    curve.segments = {kPolySpeed.bezier(), line};
    EXPECT_NEAR(arc_length_m(curve), 4.0 / 3.0 + glm::length(line.b3 - line.b0), 1e-12);
    const CubicBezier c = kSpace.bezier();
    EXPECT_NEAR(arc_length_m(sub_segment(c, 0.0, 0.35)) + arc_length_m(sub_segment(c, 0.35, 1.0)), arc_length_m(c),
                1e-11);
}

TEST(WireBezier, SamplesAreThePositionsAtEvenParameters) {
    Curve curve;
    curve.segments = {kPolySpeed.bezier(), kSpace.bezier()};
    const std::vector<dvec3> s = sample_curve(curve, 8);
    ASSERT_EQ(s.size(), 2u * 8u + 1u);
    for (std::size_t k = 0; k < 2; ++k) {
        for (int i = 0; i < 8; ++i) {
            EXPECT_LT(dist(s[8 * k + i], position(curve.segments[k], i / 8.0)), 1e-15) << k << " " << i;
        }
    }
    EXPECT_EQ(s.back(), curve.segments[1].b3);
}

TEST(WireBezier, ClosestParameterFindsTheFootOfANormalOffset) {
    const CubicBezier c = kPolySpeed.bezier();  // planar (z = 0), curvature radius >= 0.5 on [0, 1]
    for (double t : {0.05, 0.37, 0.5, 0.81, 0.97}) {
        const dvec3 tangent = glm::normalize(kPolySpeed.d1(t));
        const dvec3 normal(-tangent.y, tangent.x, 0.0);
        for (double offset : {-0.05, 0.02, 0.1}) {
            const dvec3 p = kPolySpeed.at(t) + offset * normal + dvec3(0.0, 0.0, 0.03);
            EXPECT_NEAR(closest_parameter(c, p), t, 1e-9) << t << " " << offset;
        }
    }
    // Beyond the ends, along the end tangents: the ends.
    EXPECT_EQ(closest_parameter(c, kPolySpeed.at(0.0) - 0.5 * glm::normalize(kPolySpeed.d1(0.0))), 0.0);
    EXPECT_EQ(closest_parameter(c, kPolySpeed.at(1.0) + 0.5 * glm::normalize(kPolySpeed.d1(1.0))), 1.0);
}

TEST(WireBezier, DistanceToPolyline) {
    const std::vector<dvec3> poly = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {1.0, 1.0, 0.0}};
    EXPECT_DOUBLE_EQ(distance_to_polyline({0.5, 0.25, 0.0}, poly), 0.25);
    EXPECT_DOUBLE_EQ(distance_to_polyline({2.0, 0.5, 0.0}, poly), 1.0);
    EXPECT_DOUBLE_EQ(distance_to_polyline({-3.0, 0.0, 4.0}, poly), 5.0);  // beyond the first vertex
    EXPECT_DOUBLE_EQ(distance_to_polyline({1.0, 1.0, 0.0}, poly), 0.0);
}

TEST(WireBezier, CurveJumpIsTheDisplacement) {
    Curve a;
    a.segments = {kPolySpeed.bezier()};
    EXPECT_EQ(curve_jump_m(a, a), 0.0);
    // The same curve 1 cm out of its plane: every sample is 1 cm from the other's polyline, and no nearer.
    Curve b = a;
    for (CubicBezier& s : b.segments)
        for (dvec3* q : {&s.b0, &s.b1, &s.b2, &s.b3}) q->z += 0.01;
    EXPECT_NEAR(curve_jump_m(a, b), 0.01, 1e-15);
    // Symmetric: the larger of the two directed distances (a piece of a curve against the whole).
    Curve part;
    part.segments = {sub_segment(kPolySpeed.bezier(), 0.0, 0.5)};
    const double whole_end_to_part = glm::length(kPolySpeed.at(1.0) - kPolySpeed.at(0.5));
    EXPECT_NEAR(curve_jump_m(a, part), whole_end_to_part, 1e-12);
    EXPECT_NEAR(curve_jump_m(part, a), whole_end_to_part, 1e-12);
}
