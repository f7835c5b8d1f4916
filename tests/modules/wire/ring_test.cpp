// Rings: arc length, stretch-aware u (continuous, monotonic), radius interpolation, fold detection, big wires.
#include "ring_test_curves.hpp"

#include <cstdio>

namespace wire::test {
namespace {

TEST(Rings, RecordLayout) {
    EXPECT_EQ(sizeof(Ring), 48u);
    EXPECT_EQ(offsetof(Ring, radius_m), 12u);
    EXPECT_EQ(offsetof(Ring, u), 28u);
    EXPECT_EQ(offsetof(Ring, segment), 44u);
}

// u advances by length / (2 pi R stretch): the thesis' rule, exact on straight segments.
TEST(Rings, UFollowsLengthRadiusAndStretch) {
    Curve c = polyline_curve({{0, 0, 0}, {2, 0, 0}, {2, 3, 0}}, 0.1f);
    c.stretch = {1.0f, 2.0f};
    const RingSet set = rings_for(c, 4);
    const double per_m = 1.0 / (2 * kPi * static_cast<double>(0.1f));
    EXPECT_NEAR(set.u[4], 2.0 * per_m, 1e-9);               // end of segment 0
    EXPECT_NEAR(set.u.back(), 2.0 * per_m + 3.0 * per_m / 2.0, 1e-9);  // stretched: half the repeats per metre
    EXPECT_NEAR(set.length_m, 5.0, 1e-12);
    expect_u_monotonic(set);
}

// u is continuous: sampling finer gives the same u at shared rings (u at the end of segment i is u at the start of
// segment i+1), and the arc length matches a dense polyline.
TEST(Rings, UContinuousAndArcLengthAccurate) {
    Curve c = helix_curve(1.0, 0.3, 2, 5);
    for (std::size_t i = 0; i < c.radius_m.size(); ++i) c.radius_m[i] = 0.02f + 0.01f * static_cast<float>(i % 3);
    for (std::size_t i = 0; i < c.stretch.size(); ++i) c.stretch[i] = 1.0f + 0.25f * static_cast<float>(i % 2);
    const RingSet coarse = rings_for(c, 4);
    const RingSet fine = rings_for(c, 64);
    for (std::size_t i = 0; i < coarse.u.size(); ++i) {
        EXPECT_NEAR(coarse.u[i], fine.u[i * 16], 1e-6 * fine.u.back()) << i;
    }
    double dense = 0.0;
    for (const CubicBezier& s : c.segments) {
        for (int k = 0; k < 20000; ++k) dense += glm::length(position(s, (k + 1) / 20000.0) - position(s, k / 20000.0));
    }
    EXPECT_NEAR(coarse.length_m, dense, 1e-7 * dense);
    expect_u_monotonic(coarse);
    for (std::size_t i = 0; i < coarse.rings.size(); ++i) {
        EXPECT_FLOAT_EQ(coarse.rings[i].u, static_cast<float>(coarse.u[i]));
    }
}

TEST(Rings, RadiusInterpolationIsMonotoneAndHitsNodes) {
    Curve c = polyline_curve({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}}, 0.1f);
    c.radius_m = {0.1f, 0.3f, 0.2f, 0.2f, 1e-6f};
    for (uint32_t s = 0; s < 4; ++s) {
        EXPECT_FLOAT_EQ(static_cast<float>(radius_at(c, s, 0.0)), c.radius_m[s]);
        EXPECT_FLOAT_EQ(static_cast<float>(radius_at(c, s, 1.0)), c.radius_m[s + 1]);
        const double lo = std::min(c.radius_m[s], c.radius_m[s + 1]);
        const double hi = std::max(c.radius_m[s], c.radius_m[s + 1]);
        double prev = radius_at(c, s, 0.0);
        for (int k = 1; k <= 100; ++k) {
            const double r = radius_at(c, s, k / 100.0);
            EXPECT_GE(r, lo * (1 - 1e-6));
            EXPECT_LE(r, hi * (1 + 1e-6));
            EXPECT_GT(r, 0.0);
            EXPECT_TRUE(c.radius_m[s + 1] >= c.radius_m[s] ? r >= prev - 1e-12 : r <= prev + 1e-12);
            prev = r;
        }
    }
}

// A tube thicker than the bend's curvature radius folds: reported, output finite.
TEST(Rings, FoldDetected) {
    const Curve arc = helix_curve(0.1, 0.0, 1, 8, {}, 0.05f);  // circle of radius 0.1 m
    EXPECT_EQ(rings_for(arc, 8).fold_count, 0u);
    const Curve thick = helix_curve(0.1, 0.0, 1, 8, {}, 0.2f);
    const RingSet set = rings_for(thick, 8);
    EXPECT_EQ(set.fold_count, set.rings.size());
    EXPECT_EQ(set.first_fold_ring, 0u);
    expect_orthonormal(set);
    TubeMesh mesh;
    build_tube(set, TubeSettings{}, mesh);
    for (const TubeVertex& v : mesh.vertices) ASSERT_TRUE(finite(v.position) && finite(v.normal));
}

// 100,000 segments of a random smooth wire: finite, orthonormal, monotonic u, watertight mesh.
TEST(Rings, HundredThousandSegments) {
    std::mt19937 rng(11);
    std::normal_distribution<double> step(0.0, 0.05);
    std::vector<glm::dvec3> nodes(100001);
    glm::dvec3 dir(1, 0, 0);
    for (std::size_t i = 1; i < nodes.size(); ++i) {
        dir = glm::normalize(dir + glm::dvec3(step(rng), step(rng), step(rng)));
        nodes[i] = nodes[i - 1] + 0.01 * dir;
    }
    const Curve c = catmull_rom_curve(nodes, 0.002f);
    ASSERT_EQ(c.segment_count(), 100000u);
    const RingSet set = rings_for(c, 2);
    const double worst = expect_orthonormal(set);
    std::printf("  100,000 segments: worst orthonormality error %.1e\n", worst);
    EXPECT_LT(worst, 1e-12);
    expect_u_monotonic(set);
    TubeMesh mesh;
    build_tube(set, TubeSettings{.sides = 6}, mesh);
    const WeldReport w = weld_check(mesh);
    EXPECT_EQ(w.bad_edges, 0u);
    EXPECT_EQ(w.inconsistent_edges, 0u);
}

TEST(Rings, ReusedSetDoesNotReallocate) {
    const Curve c = helix_curve(1.0, 0.3, 2, 8);
    std::vector<uint32_t> counts;
    segment_ring_counts(c, TessellateSettings{}, counts);
    std::vector<RingParam> params;
    place_rings(c, counts, params);
    RingSet set;
    build_rings(c, params, RingSettings{}, set);
    const Ring* data = set.rings.data();
    const Frame* frames = set.frames.data();
    build_rings(c, params, RingSettings{}, set);
    EXPECT_EQ(set.rings.data(), data);
    EXPECT_EQ(set.frames.data(), frames);
}

}  // namespace
}  // namespace wire::test
