// The nodes path's CPU side (issue 30): pack_nodes checks what build_curve checks (the same messages), and the
// spheres the CPU culls with (node_bounding_sphere from the nodes, packed_bounding_sphere from what pack_nodes
// measured) hold every control point of the curve build_curve makes, inflated by the tube radius, over random
// families, alphas, wire-wide and per-node tension, bias and continuity, physics tension, and linear wires.
#include "wire/packed_nodes.hpp"

#include "wire/lod.hpp"
#include "wire/spline.hpp"
#include "wire/testing/families.hpp"
#include "wire/testing/random.hpp"

#include <glm/geometric.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace wire {
namespace {

TEST(PackedNodes, ChecksWhatBuildCurveChecksWithItsMessages) {
    WireNodes nan;
    nan.positions = {{0, 0, 0}, {1, 0, 0}, {2, std::numeric_limits<double>::quiet_NaN(), 0}};
    WireNodes single;
    single.positions = {{0, 0, 0}, {0, 0, 0}};
    WireNodes two;
    two.positions = {{0, 0, 0}, {1, 0, 0}};
    WireNodes bad_stretch = two;
    bad_stretch.stretch = {1.0f, -1.0f};
    const struct {
        const WireNodes* nodes;
        SplineSettings spline;
    } cases[] = {{&nan, {}}, {&single, {}}, {&two, {.closed = true}}, {&bad_stretch, {}},
                 {&two, {.alpha = std::numeric_limits<double>::infinity()}}};
    for (const auto& c : cases) {
        PackedNodes packed;
        Curve curve;
        const Status built = build_curve(*c.nodes, c.spline, curve);
        const Status p = pack_nodes(*c.nodes, c.spline, packed);
        ASSERT_FALSE(built.ok());
        EXPECT_FALSE(p.ok());
        EXPECT_EQ(p.message, built.message);
        EXPECT_EQ(check_curve_input(*c.nodes, c.spline).message, built.message);
    }
    // Every kind the CPU builds is packed (the GPU builds them all).
    for (const SplineKind kind : {SplineKind::linear, SplineKind::catmull_rom, SplineKind::c2, SplineKind::automatic}) {
        PackedNodes packed;
        EXPECT_TRUE(gpu_builds(kind));
        EXPECT_TRUE(pack_nodes(two, {.kind = kind}, packed).ok());
        EXPECT_EQ(packed.nodes.size(), 2u);
    }
}

// Every control point of build_curve's curve lies within the sphere less the tube radius.
TEST(PackedNodes, CullSpheresHoldTheCurveOverRandomFamilies) {
    wire::testing::Random rng{6001};
    std::vector<WireNodes> wires;
    for (const auto& c : families::catenaries(41, 60)) wires.push_back(c.nodes);
    for (const auto& c : families::zigzags(42, 40)) wires.push_back(c.nodes);
    for (const auto& c : families::helices(43, 40)) wires.push_back(c.nodes);
    for (const auto& c : families::wrapped(44, 40)) wires.push_back(c.nodes);
    std::vector<double> slack;  // sphere radius over the smallest radius about its centre holding the curve
    double worst = -1.0;
    std::size_t cases = 0;
    for (std::size_t i = 0; i < wires.size(); ++i) {
        WireNodes w = wires[i];
        const double scale = rng.log_uniform(0.05, 50.0);
        const glm::dvec3 shift = rng.uniform(0.0, 1.0) < 0.3 ? 1e5 * rng.unit() : glm::dvec3(0.0);
        for (glm::dvec3& p : w.positions) p = scale * p + shift;
        SplineSettings s;
        const int pick = rng.integer(0, 3);
        if (pick == 0) {
            s.kind = SplineKind::linear;
        } else {
            s.alpha = rng.uniform(0.0, 1.0);
            s.tension = rng.uniform(-1.0, 0.99);
            s.bias = rng.uniform(-1.0, 1.0);
            s.continuity = rng.uniform(-1.0, 1.0);
        }
        if (pick == 2) {
            for (std::size_t k = 0; k < w.size(); ++k) {
                w.kb_tension.push_back(rng.uniform(-1.0, 0.99));
                w.kb_bias.push_back(rng.uniform(-1.0, 1.0));
                w.kb_continuity.push_back(rng.uniform(-1.0, 1.0));
            }
        }
        if (pick == 3) {
            for (std::size_t k = 0; k < w.size(); ++k) w.radius_m.push_back(static_cast<float>(rng.log_uniform(0.001, 0.1)));
        }
        s.closed = rng.uniform(0.0, 1.0) < 0.15 && w.size() >= 3;
        Curve curve;
        ASSERT_TRUE(build_curve(w, s, curve).ok());
        PackedNodes packed;
        ASSERT_TRUE(pack_nodes(w, s, packed).ok());
        for (const BoundingSphere& sphere : {node_bounding_sphere(w, s), packed_bounding_sphere(packed)}) {
            ASSERT_GE(sphere.radius_m, 0.0);
            double needed = 0.0;
            for (const CubicBezier& c : curve.segments)
                for (const glm::dvec3* q : {&c.b0, &c.b1, &c.b2, &c.b3})
                    needed = std::max(needed, glm::length(*q - sphere.centre_m));
            const double room = sphere.radius_m - sphere.tube_radius_m;
            EXPECT_LE(needed, room * (1.0 + 1e-12) + 1e-9 * glm::length(sphere.centre_m)) << "wire " << i;
            slack.push_back(room / std::max(needed, 1e-30));
            worst = worst < 0.0 ? needed / room : std::max(worst, needed / room);
            ++cases;
        }
    }
    std::sort(slack.begin(), slack.end());
    std::printf("cull spheres over %zu cases: sphere / needed radius median %.3f, p90 %.3f, max %.3f; the tightest "
                "holds with %.4f of its room used\n",
                cases, slack[slack.size() / 2], slack[slack.size() * 9 / 10], slack.back(), worst);
}

}  // namespace
}  // namespace wire
