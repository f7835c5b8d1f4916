// Tests of the wire curve stage (nodes -> Curve), the catenary reference and pop-free multiresolution.
#include <gtest/gtest.h>

#include "curve_cases.hpp"
#include "wire/bezier.hpp"
#include "wire/curve.hpp"
#include "wire/nodes.hpp"
#include "wire/reference.hpp"
#include "wire/spline.hpp"
#include "wire/status.hpp"

#include <glm/geometric.hpp>

#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

using namespace wire;
using namespace wire::testing;
using glm::dvec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

bool finite(const dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

WireNodes make_nodes(std::vector<dvec3> p) {
    WireNodes n;
    n.positions = std::move(p);
    return n;
}

// Every control point finite, arrays consistent, segment ends exactly on their (merged) input nodes.
void expect_valid_interpolating(const Curve& c, const WireNodes& in, const std::string& what) {
    const std::size_t n = c.node_count();
    ASSERT_GE(n, 2u) << what;
    ASSERT_EQ(c.segment_count(), c.closed ? n : n - 1) << what;
    ASSERT_EQ(c.radius_m.size(), n) << what;
    ASSERT_EQ(c.stretch.size(), c.segment_count()) << what;
    for (std::size_t k = 0; k < c.segment_count(); ++k) {
        const CubicBezier& s = c.segments[k];
        ASSERT_TRUE(finite(s.b0) && finite(s.b1) && finite(s.b2) && finite(s.b3)) << what << " segment " << k;
        // Interpolation: the node positions are copied, so this is exact (far tighter than 1e-9 relative).
        EXPECT_EQ(s.b0, in.positions[c.source_node[k]]) << what << " segment " << k;
        EXPECT_EQ(s.b3, in.positions[c.source_node[(k + 1) % n]]) << what << " segment " << k;
        EXPECT_GT(c.stretch[k], 0.0f);
    }
    for (float r : c.radius_m) EXPECT_GT(r, 0.0f);
    for (std::size_t j = 1; j < n; ++j) EXPECT_LT(c.source_node[j - 1], c.source_node[j]) << what;
}

// Max over interior nodes of the angle between the tangents either side (radians); 0 for G1 curves.
double max_kink_rad(const Curve& c) {
    double worst = 0.0;
    const std::size_t segs = c.segment_count();
    for (std::size_t k = c.closed ? 0 : 1; k < segs; ++k) {
        const dvec3 a = derivative(c.segments[(k + segs - 1) % segs], 1.0), b = derivative(c.segments[k], 0.0);
        const double la = glm::length(a), lb = glm::length(b);
        if (la == 0.0 || lb == 0.0) return kPi;
        worst = std::max(worst, std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)));  // exact near 0, unlike acos
    }
    return worst;
}

// C1 in the global knot parameter: end tangent / d_in == start tangent / d_out with d = chord^alpha.
double max_c1_mismatch(const Curve& c, double alpha) {
    double worst = 0.0;
    const std::size_t segs = c.segment_count();
    for (std::size_t k = c.closed ? 0 : 1; k < segs; ++k) {
        const CubicBezier& in = c.segments[(k + segs - 1) % segs];
        const CubicBezier& out = c.segments[k];
        const double din = std::pow(glm::length(in.b3 - in.b0), alpha), dout = std::pow(glm::length(out.b3 - out.b0), alpha);
        const dvec3 a = derivative(in, 1.0) / din, b = derivative(out, 0.0) / dout;
        worst = std::max(worst, glm::length(a - b) / std::max(glm::length(a), glm::length(b)));
    }
    return worst;
}

// C2 in the chordal knot parameter: second derivatives / h^2 agree.
double max_c2_mismatch(const Curve& c) {
    double worst = 0.0;
    const std::size_t segs = c.segment_count();
    for (std::size_t k = c.closed ? 0 : 1; k < segs; ++k) {
        const CubicBezier& in = c.segments[(k + segs - 1) % segs];
        const CubicBezier& out = c.segments[k];
        const double hin = glm::length(in.b3 - in.b0), hout = glm::length(out.b3 - out.b0);
        const dvec3 a = second_derivative(in, 1.0) / (hin * hin), b = second_derivative(out, 0.0) / (hout * hout);
        worst = std::max(worst, glm::length(a - b) / std::max({glm::length(a), glm::length(b), 1e-300}));
    }
    return worst;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Validation: specific errors, never a crash, never NaN.

TEST(WireCurveValidation, TooFewNodes) {
    Curve c;
    for (std::size_t count : {0u, 1u}) {
        WireNodes n;
        for (std::size_t i = 0; i < count; ++i) n.positions.emplace_back(1.0 * i, 0.0, 0.0);
        const Status st = build_curve(n, {}, c);
        EXPECT_FALSE(st.ok);
        EXPECT_NE(st.message.find("at least 2 distinct nodes"), std::string::npos) << st.message;
        EXPECT_EQ(c.segment_count(), 0u);
    }
    // Two nodes that coincide merge into one: still too few.
    const Status st = build_curve(make_nodes({dvec3(1.0), dvec3(1.0)}), {}, c);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("after merging"), std::string::npos) << st.message;
}

TEST(WireCurveValidation, TwoNodesGiveAStraightSegment) {
    for (const NamedSettings& v : spline_variants()) {
        Curve c;
        const WireNodes n = make_nodes({dvec3(0.0), dvec3(3.0, 0.0, 4.0)});
        ASSERT_TRUE(build_curve(n, v.settings, c).ok) << v.name;
        expect_valid_interpolating(c, n, v.name);
        for (int i = 0; i <= 16; ++i) {
            const dvec3 p = position(c.segments[0], i / 16.0);
            EXPECT_NEAR(glm::length(glm::cross(p, dvec3(3.0, 0.0, 4.0))), 0.0, 1e-12) << v.name;
        }
    }
}

TEST(WireCurveValidation, NanAndInfNameTheNodeAndCoordinate) {
    WireNodes n = make_nodes({dvec3(0.0), dvec3(1.0, 0.0, 0.0), dvec3(2.0, 0.0, 0.0), dvec3(3.0, 0.0, 0.0)});
    n.positions[2].y = std::numeric_limits<double>::quiet_NaN();
    Curve c;
    Status st = build_curve(n, {}, c);
    EXPECT_FALSE(st.ok);
    EXPECT_EQ(st.node, 2);
    EXPECT_EQ(st.message, "node 2: position.y is NaN");
    n.positions[2].y = 0.0;
    n.positions[3].z = -std::numeric_limits<double>::infinity();
    st = build_curve(n, {}, c);
    EXPECT_EQ(st.node, 3);
    EXPECT_EQ(st.message, "node 3: position.z is -Inf");
    EXPECT_EQ(c.segment_count(), 0u);
}

TEST(WireCurveValidation, BadPerNodeValuesAndSettings) {
    const WireNodes base = make_nodes({dvec3(0.0), dvec3(1.0, 0.0, 0.0), dvec3(2.0, 1.0, 0.0)});
    Curve c;
    WireNodes n = base;
    n.radius_m = {0.01f, -0.5f, 0.0f};
    Status st = build_curve(n, {}, c);
    EXPECT_EQ(st.node, 1);
    EXPECT_NE(st.message.find("node 1: radius_m is -0.5"), std::string::npos) << st.message;
    n.radius_m = {0.01f, std::nanf(""), 0.0f};
    EXPECT_NE(build_curve(n, {}, c).message.find("node 1: radius_m is NaN"), std::string::npos);
    n = base;
    n.stretch = {1.0f, 1.0f, 0.0f};
    st = build_curve(n, {}, c);
    EXPECT_EQ(st.node, 2);
    EXPECT_NE(st.message.find("node 2: stretch is 0"), std::string::npos) << st.message;
    n = base;
    n.ids = {1, 2};
    EXPECT_NE(build_curve(n, {}, c).message.find("ids has 2 entries for 3 nodes"), std::string::npos);
    st = build_curve(base, {.alpha = std::nan("")}, c);
    EXPECT_EQ(st.message, "settings.alpha is NaN");
    st = build_curve(base, {.radius_m = -1.0f}, c);
    EXPECT_NE(st.message.find("settings.radius_m is -1"), std::string::npos) << st.message;
    n = base;
    n.kb_bias = {0.0f, std::numeric_limits<float>::infinity(), 0.0f};
    EXPECT_EQ(build_curve(n, {}, c).message, "node 1: kb_bias is +Inf");
    // Zero radius means "the wire's radius".
    n = base;
    n.radius_m = {0.0f, 0.2f, 0.0f};
    ASSERT_TRUE(build_curve(n, {.radius_m = 0.05f}, c).ok);
    EXPECT_EQ(c.radius_m, (std::vector<float>{0.05f, 0.2f, 0.05f}));
}

TEST(WireCurveValidation, ClosedLoopNeedsThreeDistinctNodes) {
    Curve c;
    Status st = build_curve(make_nodes({dvec3(0.0), dvec3(1.0, 0.0, 0.0)}), {.closed = true}, c);
    EXPECT_FALSE(st.ok);
    EXPECT_NE(st.message.find("closed loop needs at least 3 distinct nodes"), std::string::npos) << st.message;
    // 4 nodes whose last repeats the first: 3 distinct.
    const WireNodes n = make_nodes({dvec3(0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), dvec3(0.0)});
    for (const NamedSettings& v : spline_variants()) {
        SplineSettings s = v.settings;
        s.closed = true;
        ASSERT_TRUE(build_curve(n, s, c).ok) << v.name;
        EXPECT_EQ(c.node_count(), 3u);
        EXPECT_EQ(c.segment_count(), 3u);
        expect_valid_interpolating(c, n, v.name);
    }
}

// ---------------------------------------------------------------------------------------------------------
// Continuity where promised.

TEST(WireCurveContinuity, CatmullRomIsC1ForAnyAlphaAndC2IsC2) {
    const Catenary cable = hanging_cable();
    WireNodes n = cable_nodes(cable, 12, true);
    n.positions[5].z += 0.7;  // a 3D kink too
    for (double alpha : {0.0, 0.25, 0.5, 1.0, 1.5}) {
        for (bool closed : {false, true}) {
            Curve c;
            ASSERT_TRUE(build_curve(n, {.alpha = alpha, .tension = 0.3, .closed = closed}, c).ok);
            expect_valid_interpolating(c, n, "cr");
            EXPECT_LT(max_c1_mismatch(c, alpha), 1e-9) << "alpha " << alpha << " closed " << closed;
        }
    }
    for (bool closed : {false, true}) {
        Curve c;
        ASSERT_TRUE(build_curve(n, {.kind = SplineKind::c2, .closed = closed}, c).ok);
        expect_valid_interpolating(c, n, "c2");
        EXPECT_LT(max_c1_mismatch(c, 1.0), 1e-9) << closed;
        EXPECT_LT(max_c2_mismatch(c), 1e-7) << closed;
    }
    Curve c;
    ASSERT_TRUE(build_curve(n, {.kind = SplineKind::automatic}, c).ok);
    EXPECT_LT(max_kink_rad(c), 1e-9);  // automatic promises G1
}

TEST(WireCurveContinuity, KochanekBartelsContinuityKinksOnPurposeAndReducesToCatmullRom) {
    const WireNodes n = make_nodes({dvec3(0.0), dvec3(1.0, 0.5, 0.0), dvec3(2.0, 0.0, 0.0), dvec3(3.5, 0.7, 0.0)});
    Curve cr, kb;
    ASSERT_TRUE(build_curve(n, {.alpha = 0.5}, cr).ok);
    ASSERT_TRUE(build_curve(n, {.alpha = 0.5, .tension = 0.0, .bias = 0.0, .continuity = 0.0}, kb).ok);
    EXPECT_EQ(cr.segments[1].b1, kb.segments[1].b1);
    ASSERT_TRUE(build_curve(n, {.alpha = 0.5, .continuity = 0.5}, kb).ok);
    EXPECT_GT(max_kink_rad(kb), 0.05);
    WireNodes per_node = n;
    per_node.kb_tension = {0.0f, 1.0f, 0.0f, 0.0f};  // node 1 fully tensed: zero tangent (corner) there
    ASSERT_TRUE(build_curve(per_node, {}, kb).ok);
    EXPECT_EQ(kb.segments[0].b2, n.positions[1]);
    EXPECT_EQ(kb.segments[1].b1, n.positions[1]);
}

TEST(WireCurveContinuity, CurvatureTensionFollowsTheThesis) {
    EXPECT_EQ(curvature_tension(0.1, 1.0, 1.0, 0.0, 1.0), 0.0);           // no stretch: no tension
    EXPECT_EQ(curvature_tension(1.0, 200.0, 1.0, 1.0, 1.0), 0.0);         // R = 200 > 100
    EXPECT_NEAR(curvature_tension(1.0, 50.0, 1.0, 1.0, 1.0), 1.0 - std::tanh(1.0), 1e-15);  // R = 50
    EXPECT_NEAR(curvature_tension(0.0, 1.0, 1.0, 1.0, 1.0), 1.0, 1e-15);  // R = 0: straight
    WireNodes n = make_nodes({dvec3(0.0), dvec3(1.0, 0.5, 0.0), dvec3(2.0, 0.0, 0.0)});
    n.theta_rad = {0.0, 0.0, 0.0};
    n.iz_m4 = {1.0, 1.0, 1.0};
    n.length_m = {1.0, 1.0, 1.0};
    n.delta_length_m = {0.0, 1.0, 0.0};
    n.area_m2 = {1.0, 1.0, 1.0};
    Curve c;
    ASSERT_TRUE(build_curve(n, {}, c).ok);
    EXPECT_EQ(c.segments[0].b2, n.positions[1]);  // R = 0 at node 1: tension 1
    ASSERT_TRUE(build_curve(n, {.curvature_tension = false}, c).ok);
    EXPECT_NE(c.segments[0].b2, n.positions[1]);
    n.area_m2[1] = 0.0;
    EXPECT_EQ(build_curve(n, {}, c).message, "node 1: area_m2 is 0 (must be > 0)");
}
