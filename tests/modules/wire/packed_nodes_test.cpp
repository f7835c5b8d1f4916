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
        EXPECT_EQ(packed.node_count, 2u);
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
        Curve curve, held_curve;
        ASSERT_TRUE(build_curve(w, s, curve).ok());
        PackedNodes packed;
        ASSERT_TRUE(pack_nodes(w, s, packed).ok());
        // The packed sphere holds the curve of the nodes the GPU holds (quantised or float-rounded) as well.
        WireNodes held = w;
        for (glm::dvec3& p : held.positions) p = packed.held(p);
        ASSERT_TRUE(build_curve(held, s, held_curve).ok());
        for (const auto& [sphere, drawn] : {std::pair{node_bounding_sphere(w, s), &curve},
                                            std::pair{packed_bounding_sphere(packed), &curve},
                                            std::pair{packed_bounding_sphere(packed), &held_curve}}) {
            ASSERT_GE(sphere.radius_m, 0.0);
            double needed = 0.0;
            for (const CubicBezier& c : drawn->segments)
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

// The two node formats over random families (catenaries, taut zig-zags, helices, wrapped cables, each scaled 0.01-
// 1000x and up to 1e6 m out, one radius of 0.1 mm-10 cm or per-node radii, every kind): what node() decodes is
// exactly where held() puts the input node, the radius is the node's; a quantised node lies within half a quantum
// of the input on each axis, so within sqrt(3) kQuantumOfRadius of the radius and sqrt(3) kQuantumOfChord of the
// shortest chord; the format is chosen as packed_nodes.hpp says, and a swaying-bench-like wire (64 nodes, 10 m, 1
// cm) is quantised on every kind.
TEST(PackedNodes, QuantisedNodesStayWithinTheirBoundsOverRandomFamilies) {
    wire::testing::Random rng{6002};
    std::vector<WireNodes> wires;
    for (const auto& c : families::catenaries(51, 80)) wires.push_back(c.nodes);
    for (const auto& c : families::zigzags(52, 60)) wires.push_back(c.nodes);
    for (const auto& c : families::helices(53, 60)) wires.push_back(c.nodes);
    for (const auto& c : families::wrapped(54, 60)) wires.push_back(c.nodes);
    const SplineKind kinds[] = {SplineKind::linear, SplineKind::catmull_rom, SplineKind::c2, SplineKind::automatic};
    std::vector<double> of_radius, of_chord;  // a quantised wire's largest node error / radius, / shortest chord
    std::size_t quantised = 0, cases = 0, per_node_radius = 0;
    for (std::size_t i = 0; i < wires.size(); ++i) {
        WireNodes w = wires[i];
        const double scale = rng.log_uniform(0.01, 1000.0);
        const glm::dvec3 shift = rng.uniform(0.0, 1.0) < 0.3 ? rng.log_uniform(1.0, 1e6) * rng.unit() : glm::dvec3(0.0);
        for (glm::dvec3& p : w.positions) p = scale * p + shift;
        SplineSettings s;
        s.kind = kinds[i % 4];
        s.radius_m = static_cast<float>(rng.log_uniform(1e-4, 0.1));
        const bool varies = rng.uniform(0.0, 1.0) < 0.2;
        if (varies) {
            for (std::size_t k = 0; k < w.size(); ++k) w.radius_m.push_back(static_cast<float>(rng.log_uniform(1e-3, 0.1)));
        }
        PackedNodes p;
        ASSERT_TRUE(pack_nodes(w, s, p).ok()) << "wire " << i;
        ASSERT_EQ(p.node_count, w.size()) << "wire " << i << ": the families merge nothing";
        ASSERT_EQ(p.records.size(), p.quantised ? w.size() + 1 : 2 * w.size()) << "wire " << i;
        double shortest = HUGE_VAL;
        for (std::size_t k = 0; k + 1 < w.size(); ++k)
            shortest = std::min(shortest, glm::length(w.positions[k + 1] - w.positions[k]));
        const double half_quantum = std::ldexp(0.5, p.quantum_exp);
        double most = 0.0;
        for (std::size_t j = 0; j < w.size(); ++j) {
            const glm::vec4 n = p.node(j);
            const glm::dvec3 decoded = p.origin_m + glm::dvec3(glm::vec3(n));
            ASSERT_EQ(decoded, p.held(w.positions[j])) << "wire " << i << " node " << j;
            ASSERT_EQ(n.w, w.radius_m.empty() ? s.radius_m : w.radius_m[j]) << "wire " << i << " node " << j;
            if (!p.quantised) continue;
            const glm::dvec3 d = glm::abs(decoded - w.positions[j]);
            ASSERT_LE(std::max({d.x, d.y, d.z}), half_quantum) << "wire " << i << " node " << j;
            most = std::max(most, glm::length(d));
        }
        ++cases;
        per_node_radius += varies ? 1 : 0;
        if (varies) {
            EXPECT_FALSE(p.quantised) << "wire " << i << ": per-node radii need the float format";
        }
        if (!p.quantised) continue;
        ++quantised;
        EXPECT_LE(most, std::sqrt(3.0) * kQuantumOfRadius * s.radius_m) << "wire " << i;
        EXPECT_LE(most, std::sqrt(3.0) * kQuantumOfChord * shortest) << "wire " << i;
        of_radius.push_back(most / s.radius_m);
        of_chord.push_back(most / shortest);
    }
    ASSERT_GT(quantised, cases / 8) << "the families should exercise the quantised format";
    ASSERT_LT(quantised, cases - per_node_radius) << "... and the float one beside per-node radii";
    std::sort(of_radius.begin(), of_radius.end());
    std::sort(of_chord.begin(), of_chord.end());
    const auto q = [](const std::vector<double>& v, double f) { return v[static_cast<std::size_t>(f * (v.size() - 1))]; };
    std::printf("node formats over %zu wires: %zu quantised; their largest node error / radius median %.3g, p90 %.3g, "
                "max %.3g (bound %.3g); / shortest chord median %.3g, p90 %.3g, max %.3g (bound %.3g)\n",
                cases, quantised, q(of_radius, 0.5), q(of_radius, 0.9), q(of_radius, 1.0), std::sqrt(3.0) * kQuantumOfRadius,
                q(of_chord, 0.5), q(of_chord, 0.9), q(of_chord, 1.0), std::sqrt(3.0) * kQuantumOfChord);

    // The swaying bench's wire: a 10 m catenary of 64 nodes, 1 cm thick, 1e4 m out, on every kind.
    for (const SplineKind kind : kinds) {
        WireNodes w;
        for (int k = 0; k < 64; ++k) {
            const double t = k / 63.0;
            w.positions.push_back(glm::dvec3(1e4 + 10.0 * t, 5.0 - 1.2 * 4.0 * t * (1.0 - t), -3e3));
        }
        PackedNodes p;
        ASSERT_TRUE(pack_nodes(w, {.kind = kind, .radius_m = 0.01f}, p).ok());
        EXPECT_TRUE(p.quantised) << "kind " << static_cast<int>(kind);
        EXPECT_EQ(p.records.size() * 8, 64u * 8 + 8);
    }
}

}  // namespace
}  // namespace wire
