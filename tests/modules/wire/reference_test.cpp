// Tests of the exact catenary reference (wire/testing/reference.hpp) the curve tests measure against.
#include <gtest/gtest.h>

#include "curve_cases.hpp"
#include "wire/testing/reference.hpp"

#include <glm/geometric.hpp>

using namespace wire;
using namespace wire::testing;
using glm::dvec3;


TEST(WireCatenary, SolvesEndsArcLengthAndDistanceForAnySag) {
    for (double ratio : {1.0 + 1e-12, 1.0 + 1e-6, 1.05, 1.25, 3.0, 100.0}) {
        const dvec3 p1(1e6, 2.0, -3.0), p2 = p1 + dvec3(12.0, -2.0, 5.0);
        const double L = glm::length(p2 - p1) * ratio;
        Catenary c;
        ASSERT_TRUE(c.solve(p1, p2, L).ok()) << ratio;
        EXPECT_LT(glm::length(c.point_at_arc_length(L) - p2), 1e-9 * L) << ratio;
        EXPECT_NEAR(c.arc_length_at(c.span_m()), L, 1e-12 * L) << ratio;
        // Arc length of a dense polyline through the reference agrees with s(x).
        if (ratio < 10.0) {
            double poly = 0.0;
            dvec3 prev = c.point_at_x(0.0);
            for (int i = 1; i <= 20000; ++i) {
                const dvec3 p = c.point_at_x(c.span_m() * i / 20000.0);
                poly += glm::length(p - prev), prev = p;
            }
            EXPECT_NEAR(poly, L, 1e-6 * L) << ratio;
        }
        const dvec3 mid = c.point_at_arc_length(0.4 * L);
        EXPECT_LT(c.distance(mid), 1e-9) << ratio;
        EXPECT_LE(c.distance(mid + dvec3(0.0, 0.0, 1e-3)), 1e-3 + 1e-12) << ratio;  // at most the offset
    }
    Catenary c;
    EXPECT_FALSE(c.solve(dvec3(0.0), dvec3(1.0, 0.0, 0.0), 0.5).ok());
    EXPECT_FALSE(c.solve(dvec3(0.0), dvec3(0.0, 1.0, 0.0), 5.0).ok());
}

TEST(WireCatenary, DistanceOfAnOffsetPointIsTheOffset) {
    const Catenary c = hanging_cable();
    for (double s : {0.5, 5.0, 10.0, 17.0}) {
        const dvec3 p = c.point_at_arc_length(s);
        const double x = c.x_at_arc_length(s), slope = c.slope(x);
        const dvec3 normal = glm::normalize(dvec3(-slope, 1.0, 0.0));
        EXPECT_NEAR(c.distance(p + 0.01 * normal), 0.01, 1e-9) << s;
        EXPECT_NEAR(c.distance(p + dvec3(0.0, 0.0, 0.02)), 0.02, 1e-12) << s;
    }
}
