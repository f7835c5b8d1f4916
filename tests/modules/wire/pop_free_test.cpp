// Tests of pop-free multiresolution (modules/wire/src/pop_free.cpp): node insertions and removals blend in without
// a pop, bad states keep the previous curve, closed loops and replaced end nodes.
#include <gtest/gtest.h>

#include "curve_cases.hpp"
#include "wire/bezier.hpp"
#include "wire/curve.hpp"
#include "wire/pop_free.hpp"
#include "wire/nodes.hpp"
#include "wire/spline.hpp"
#include "wire/status.hpp"
#include "wire/testing/pop_free_family.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

using namespace wire;
using namespace wire::testing;
using glm::dvec3;

// 20 m cable, 16 nodes; the metric is curve_jump_m (symmetric Hausdorff distance between dense samples of
// consecutive rendered curves).

namespace {

bool finite(const dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void expect_joined(const Curve& c, const std::string& what) {
    ASSERT_EQ(c.node_count(), c.segment_count() + 1) << what;
    ASSERT_EQ(c.radius_m.size(), c.node_count()) << what;
    ASSERT_EQ(c.stretch.size(), c.segment_count()) << what;
    for (std::size_t k = 0; k < c.segment_count(); ++k) {
        const CubicBezier& s = c.segments[k];
        ASSERT_TRUE(finite(s.b0) && finite(s.b1) && finite(s.b2) && finite(s.b3)) << what;
        if (k > 0) {
            ASSERT_EQ(c.segments[k - 1].b3, s.b0) << what << " segment " << k;
        }
    }
}

}  // namespace

TEST(PopFree, InsertingOnTheCurveAndRemovingDoNotPop) {
    const Catenary cable = hanging_cable();
    const WireNodes base = cable_nodes(cable, 16);
    const WireNodes removed = cable_with_removed_node(cable);
    // Without pop-free blend the centripetal curve jumps 6.1 mm (insert on curve) and 47.7 mm (remove node 8);
    // with the blend the largest frame-to-frame jump is 0.04 mm and 0.30 mm.
    for (const NamedSettings& v : spline_variants()) {
        const WireNodes inserted = cable_with_inserted_node(cable, v.settings);
        const struct { const char* name; const WireNodes& from; const WireNodes& to; } events[] = {
            {"insert on curve", base, inserted}, {"remove inserted", inserted, base}, {"remove node 8", base, removed}};
        for (const auto& e : events) {
            const PopNumbers p = measure_pop(v.settings, e.from, e.to);
            const std::string what = v.name + ", " + e.name;
            EXPECT_LT(p.blended_max_m, 1e-3) << what;
            // Never worse than the raw jump, except for changes so small (c2: 0.02 mm) that the morph's sliding
            // along the curve dominates; those stay under 0.1 mm.
            EXPECT_LE(p.blended_max_m, std::max(p.unblended_m, 1e-4)) << what;
            EXPECT_LT(p.final_gap_m, 1e-12) << what;  // the blend ends exactly on the new curve
            EXPECT_LE(p.frames, 241) << what;
            ::testing::Test::RecordProperty(v.name + "_" + e.name + "_no_remedy_m", std::to_string(p.unblended_m));
            ::testing::Test::RecordProperty(v.name + "_" + e.name + "_geomorph_m", std::to_string(p.blended_max_m));
        }
    }
    // The pop-free blend must matter: for the default (centripetal) spline the raw jumps exceed 1 mm and the
    // blend cuts them by the design's 10x (the shortest blend, 15 frames, at smoothstep's peak slope 1.5:
    // 1.5 / 15 of the pop per frame; measured 9.96x for the insertion), asserted with a margin at 8x. (It was
    // 20x while the parameter slide of centripetal's neighbouring segments stretched this 6.1 mm insertion over
    // 2.5 s; the event's length now follows how far the curve moves, not how far its parameters slide.)
    const SplineSettings centripetal{};
    const PopNumbers ins = measure_pop(centripetal, base, cable_with_inserted_node(cable, centripetal));
    const PopNumbers rem = measure_pop(centripetal, base, removed);
    EXPECT_GT(ins.unblended_m, 1e-3);
    EXPECT_GT(rem.unblended_m, 1e-3);
    EXPECT_LT(ins.blended_max_m * 8.0, ins.unblended_m);
    EXPECT_LT(rem.blended_max_m * 8.0, rem.unblended_m);
    // And without the blend the object shows the raw jump.
    PopFreeCurve raw({.enabled = false});
    Curve r0, r1;
    ASSERT_TRUE(raw.update(base, r0).ok());
    ASSERT_TRUE(raw.update(removed, r1).ok());
    EXPECT_NEAR(curve_jump_m(r0, r1), rem.unblended_m, 1e-12);
}

TEST(PopFree, SwitchFrameShowsThePreviousCurveExactly) {
    const Catenary cable = hanging_cable();
    PopFreeCurve m;
    Curve before, at_switch;
    ASSERT_TRUE(m.update(cable_nodes(cable, 16), before).ok());
    ASSERT_TRUE(m.update(cable_with_removed_node(cable), at_switch).ok());
    EXPECT_TRUE(m.blending());
    EXPECT_EQ(at_switch.node_count(), 16u);  // the removed node stays as a ghost while it morphs away
    EXPECT_LT(curve_jump_m(before, at_switch), 1e-12);
    expect_joined(at_switch, "switch");
}

TEST(PopFree, RandomInsertionsAndRemovalsNeverJumpMoreThanAMillimetre) {
    const Catenary cable = hanging_cable();
    for (const SplineSettings& spline : {SplineSettings{}, SplineSettings{.kind = SplineKind::automatic},
                                         SplineSettings{.kind = SplineKind::c2}}) {
        // A refined wire (32 nodes, kept between 24 and 40) whose simulation inserts nodes on the curve and
        // removes interior ones at random, often while earlier morphs still run.
        std::mt19937_64 rng(99);
        WireNodes nodes = cable_nodes(cable, 32);
        PopFreeCurve m({.spline = spline});
        Curve prev, cur;
        ASSERT_TRUE(m.update(nodes, prev).ok());
        uint32_t next_id = 1000;
        double worst = 0.0;
        for (int frame = 0; frame < 400; ++frame) {
            const int action = static_cast<int>(rng() % 6);  // often several events overlap a running blend
            if (action == 0 && nodes.size() < 40) {
                const std::size_t k = 1 + rng() % (nodes.size() - 2);  // insert after node k on the exact curve
                const double u = 0.2 + 0.6 * static_cast<double>(rng() % 1000) / 1000.0;
                nodes.positions.insert(nodes.positions.begin() + static_cast<std::ptrdiff_t>(k + 1), position(m.target().segments[k], u));
                nodes.ids.insert(nodes.ids.begin() + static_cast<std::ptrdiff_t>(k + 1), next_id++);
            } else if (action == 1 && nodes.size() > 24) {
                const std::size_t k = 1 + rng() % (nodes.size() - 2);  // remove an interior node
                nodes.positions.erase(nodes.positions.begin() + static_cast<std::ptrdiff_t>(k));
                nodes.ids.erase(nodes.ids.begin() + static_cast<std::ptrdiff_t>(k));
            }
            ASSERT_TRUE(m.update(nodes, cur).ok());
            expect_joined(cur, "frame " + std::to_string(frame));
            const double jump = curve_jump_m(prev, cur, 32);
            worst = std::max(worst, jump);
            prev = cur;
        }
        for (int frame = 0; frame < 300 && m.blending(); ++frame) {
            ASSERT_TRUE(m.update(nodes, cur).ok());
            worst = std::max(worst, curve_jump_m(prev, cur, 32));
            prev = cur;
        }
        EXPECT_FALSE(m.blending());
        EXPECT_EQ(m.unremedied(), 0u);
        EXPECT_LT(curve_jump_m(cur, m.target()), 1e-12);
        EXPECT_LT(worst, 1e-3) << static_cast<int>(spline.kind);
        ::testing::Test::RecordProperty("random_events_worst_jump_m_kind" + std::to_string(static_cast<int>(spline.kind)), std::to_string(worst));
    }
}

TEST(PopFree, MovingWireFollowsTheNodesWhileMorphing) {
    // All nodes sway by up to 2 mm per frame; a node is inserted mid-sway. Every frame's jump stays within the
    // motion itself plus the blend bound, and the result never lags the target once the morph ends.
    const Catenary cable = hanging_cable();
    WireNodes rest = cable_nodes(cable, 16);
    PopFreeCurve m;
    Curve prev, cur;
    double worst = 0.0;
    for (int frame = 0; frame < 300; ++frame) {
        WireNodes n = frame >= 20 ? cable_with_inserted_node(cable, SplineSettings{}) : rest;
        const double sway = 0.05 * std::sin(frame * 0.04);
        for (dvec3& p : n.positions) p.z += sway * std::sin(p.x / 16.0 * kPi);
        ASSERT_TRUE(m.update(n, cur).ok());
        expect_joined(cur, "sway");
        if (frame > 0) worst = std::max(worst, curve_jump_m(prev, cur, 32));
        prev = cur;
    }
    EXPECT_LT(worst, 2e-3 + 1e-3);
    EXPECT_FALSE(m.blending());
    EXPECT_LT(curve_jump_m(cur, m.target()), 1e-12);
}

TEST(PopFree, BadStatesKeepThePreviousCurve) {
    const WireNodes loop = make_nodes({dvec3(0.0), dvec3(1.0, 0.0, 0.0), dvec3(0.0, 1.0, 0.0), dvec3(-1.0, 0.0, 0.5)});
    PopFreeCurve m({.spline = {.closed = true}});
    Curve c;
    ASSERT_TRUE(m.update(loop, c).ok());
    EXPECT_TRUE(c.closed);
    EXPECT_EQ(c.segment_count(), 4u);
    WireNodes bad = loop;
    bad.positions[1].x = std::nan("");
    const Status st = m.update(bad, c);
    EXPECT_EQ(st.message, "node 1: position.x is NaN");
    EXPECT_EQ(c.segment_count(), 4u);  // the previous frame's curve stays
    // A duplicate id is an error naming the node and the id (the caller prefixes the wire), in the first state too.
    WireNodes dup = make_nodes({dvec3(0.0), dvec3(1.0, 0.0, 0.0), dvec3(2.0, 1.0, 0.0)});
    dup.ids = {5, 6, 5};
    PopFreeCurve d;
    const Status first = d.update(dup, c);
    EXPECT_FALSE(first.ok());
    EXPECT_EQ(first.message, "node 2: id 5 is used twice (also node 0)");
    EXPECT_EQ(first.index, 2);
    dup.ids = {5, 6, 7};
    ASSERT_TRUE(d.update(dup, c).ok());
    dup.ids = {5, 7, 7};
    EXPECT_EQ(d.update(dup, c).message, "node 2: id 7 is used twice (also node 1)");
    EXPECT_EQ(c.segment_count(), 2u);
    // Without ids a node count change renames the nodes: shown at once and counted.
    WireNodes plain = make_nodes({dvec3(0.0), dvec3(1.0, 0.0, 0.0), dvec3(2.0, 1.0, 0.0)});
    PopFreeCurve p;
    ASSERT_TRUE(p.update(plain, c).ok());
    plain.positions.push_back(dvec3(3.0, 1.0, 0.0));
    ASSERT_TRUE(p.update(plain, c).ok());
    EXPECT_FALSE(p.blending());
    EXPECT_EQ(p.unremedied(), 1u);
}

// Issue 17's two-event case: a node inserted on the curve of the 16-node cable, then another node removed, each
// held for at least 60 frames. Every kind ends exactly on the fresh curve within the blend time (at most
// max_blend_frames) and never lags more than the instant pop of the event.
TEST(PopFree, SettlesOnTheFreshCurveWithinTheBlendTime) {
    const Catenary cable = hanging_cable();
    for (const NamedSettings& v : spline_variants()) {
        const WireNodes base = cable_nodes(cable, 16);
        const WireNodes inserted = cable_with_inserted_node(cable, v.settings);
        WireNodes removed = inserted;
        removed.positions.erase(removed.positions.begin() + 4), removed.ids.erase(removed.ids.begin() + 4);
        PopFreeCurve m({.spline = v.settings});
        Curve prev, cur;
        ASSERT_TRUE(m.update(base, prev).ok());
        for (const WireNodes* state : {&inserted, static_cast<const WireNodes*>(&removed)}) {
            const Curve before = m.target();
            ASSERT_TRUE(m.update(*state, cur).ok());
            const double pop = curve_distance_m(before, m.target());
            const int frames = m.last_blend_frames();
            EXPECT_LE(frames, m.max_blend_frames()) << v.name;
            for (int f = 0; f <= std::max(60, frames); ++f) {
                const double lag = curve_distance_m(cur, m.target());
                EXPECT_LE(lag, pop * (1.0 + 1e-9) + 1e-12) << v.name << " frame " << f;
                if (f >= frames) {
                    EXPECT_EQ(lag, 0.0) << v.name << " frame " << f;  // exactly the fresh curve
                }
                if (f > 0) {
                    EXPECT_LE(curve_distance_m(prev, cur), 0.2 * pop + 1e-12) << v.name << " frame " << f;
                }
                prev = cur;
                ASSERT_TRUE(m.update(*state, cur).ok());
            }
        }
        EXPECT_FALSE(m.blending()) << v.name;
    }
}

// A closed loop (a coil of 3 m radius, 12 nodes): a node inserted on its curve in the last segment (across the
// seam), then the seam node itself removed. Both are blended, not popped.
TEST(PopFree, ClosedLoopsAndTheSeamNodeAreRemedied) {
    for (SplineKind kind : {SplineKind::catmull_rom, SplineKind::c2, SplineKind::automatic, SplineKind::linear}) {
        WireNodes loop;
        for (int i = 0; i < 12; ++i) {
            const double th = 2.0 * kPi * i / 12.0;
            loop.positions.emplace_back(3.0 * std::cos(th), 0.4 * std::sin(3.0 * th), 3.0 * std::sin(th));
            loop.ids.push_back(static_cast<uint32_t>(10 + i));
        }
        PopFreeCurve m({.spline = {.kind = kind, .closed = true}});
        Curve prev, cur;
        ASSERT_TRUE(m.update(loop, prev).ok());
        WireNodes inserted = loop;
        inserted.positions.push_back(position(m.target().segments[11], 0.4));
        inserted.ids.push_back(99);
        WireNodes seamless = inserted;
        seamless.positions.erase(seamless.positions.begin()), seamless.ids.erase(seamless.ids.begin());
        for (const WireNodes* state : {static_cast<const WireNodes*>(&inserted), static_cast<const WireNodes*>(&seamless)}) {
            const Curve before = m.target();
            ASSERT_TRUE(m.update(*state, cur).ok());
            const double pop = curve_distance_m(before, m.target());
            EXPECT_LT(curve_distance_m(prev, cur), 1e-12) << int(kind);  // the switch frame shows the old loop
            EXPECT_TRUE(cur.closed);
            EXPECT_EQ(cur.segments.back().b3, cur.segments.front().b0) << int(kind);
            double worst = 0.0;
            for (int f = 0; f <= m.max_blend_frames() && m.blending(); ++f) {
                prev = cur;
                ASSERT_TRUE(m.update(*state, cur).ok());
                worst = std::max(worst, curve_distance_m(prev, cur));
                EXPECT_EQ(cur.segments.back().b3, cur.segments.front().b0) << int(kind);
            }
            if (kind != SplineKind::linear || state == &seamless) {
                EXPECT_GT(pop, 1e-4) << int(kind);
            }
            EXPECT_LE(worst, 0.2 * pop + 1e-12) << int(kind);
            EXPECT_FALSE(m.blending());
            EXPECT_EQ(curve_distance_m(cur, m.target()), 0.0);
            prev = cur;
        }
        EXPECT_EQ(m.unremedied(), 0u);
    }
}

// The physics re-creates an end node under a new id (1 cm from the old one): the wire's ends still correspond,
// so the change is blended like any other.
TEST(PopFree, ReplacedEndNodesAreRemedied) {
    const Catenary cable = hanging_cable();
    for (const NamedSettings& v : spline_variants()) {
        const WireNodes base = cable_nodes(cable, 16);
        WireNodes replaced = base;
        replaced.ids.back() = 4242, replaced.positions.back() += dvec3(0.0, 0.01, 0.0);
        replaced.ids.front() = 4243;
        PopFreeCurve m({.spline = v.settings});
        Curve prev, cur;
        ASSERT_TRUE(m.update(base, prev).ok());
        ASSERT_TRUE(m.update(replaced, cur).ok());
        EXPECT_LT(curve_distance_m(prev, cur), 1e-12) << v.name;
        EXPECT_TRUE(m.blending()) << v.name;
        double worst = 0.0;
        while (m.blending()) {
            prev = cur;
            ASSERT_TRUE(m.update(replaced, cur).ok());
            worst = std::max(worst, curve_distance_m(prev, cur));
        }
        EXPECT_LE(worst, 0.2 * 0.01 + 1e-12) << v.name;
        EXPECT_GT(worst, 0.0) << v.name;
        EXPECT_EQ(curve_distance_m(cur, m.target()), 0.0) << v.name;
        EXPECT_EQ(m.unremedied(), 0u);
    }
}
