// The pop-free blend over random families (issue 17, item 4): >= 500 node events per spline kind on random
// 20-40 m cables, open and closed, nodes inserted exactly on the curve, removed anywhere (the seam node of a
// loop included), end nodes re-created under a new id, often several events running at once. Asserted on every
// frame: the jump is at most 1/5 of the instant pops of the events running and at most 2 mm; the lag (drawn
// against the exact curve of the same nodes) never exceeds those pops; with no event running the drawn curve
// is the exact one (to 1e-6 m; in fact bit for bit), which happens at most max_blend_s after the last event.
#include "wire/pop_free.hpp"
#include "wire/testing/pop_free_family.hpp"
#include "wire/testing/random.hpp"

#include <glm/geometric.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

namespace wire {
namespace {

struct Kind {
    const char* name;
    SplineSettings spline;
};

const Kind kKinds[] = {
    {"centripetal", {.kind = SplineKind::catmull_rom, .alpha = 0.5}},
    {"chordal", {.kind = SplineKind::catmull_rom, .alpha = 1.0}},
    {"uniform", {.kind = SplineKind::catmull_rom, .alpha = 0.0}},
    {"c2", {.kind = SplineKind::c2}},
    {"auto", {.kind = SplineKind::automatic}},
    {"linear", {.kind = SplineKind::linear}},
};

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

class PopFreeFamily : public ::testing::TestWithParam<int> {};

TEST_P(PopFreeFamily, EveryFrameWithinThePopAndSettles) {
    const Kind& kind = kKinds[GetParam()];
    PopFreeFamilySettings s;
    s.spline = kind.spline;
    s.cables = 40;
    s.events_per_cable = 13;  // 520 events
    s.seed = 17 + static_cast<uint64_t>(GetParam());
    const PopFreeFamilyResult r = run_pop_free_family(s);
    ASSERT_TRUE(r.error.empty()) << r.error;
    ASSERT_GE(r.events.size(), 500u);
    std::size_t overlapped = 0, closed = 0, per_type[4] = {0, 0, 0, 0};
    std::vector<double> pop, jump, lag, settle;
    for (const PopFreeEvent& e : r.events) {
        overlapped += e.overlapped, closed += e.closed, ++per_type[e.type];
        pop.push_back(e.pop_m), jump.push_back(e.jump_m), lag.push_back(e.lag_m);
        settle.push_back(e.frames / 60.0);
    }
    // The family is what it claims: open and closed, every event type, many events overlapping others.
    EXPECT_GT(closed, r.events.size() / 3);
    EXPECT_GT(overlapped, r.events.size() / 4);
    for (std::size_t t = 0; t < 4; ++t) EXPECT_GT(per_type[t], 10u) << "event type " << t;

    EXPECT_EQ(r.unremedied, 0u);
    EXPECT_EQ(r.state_mismatch, 0u);
    EXPECT_LE(r.max_jump_ratio, 0.2) << kind.name << ": " << r.worst_jump;
    EXPECT_LE(r.max_jump_m, 2e-3) << kind.name;
    // Every frame within the design's bound (sum over the running events of 1.5 max|D| / N), which is what
    // keeps 2 mm except for changes too large for it within the longest blend (max|D| > 32 cm: counted).
    EXPECT_LE(r.max_jump_over_design, 1.0 + 1e-6) << kind.name;
    EXPECT_LE(r.max_lag_ratio, 1.0 + 1e-6) << kind.name << ": " << r.worst_lag;
    EXPECT_LE(r.max_settled_gap_m, 1e-6) << kind.name;
    EXPECT_LE(r.max_frames, PopFreeCurve().max_blend_frames()) << kind.name;

    std::printf("%-12s events %zu (closed %zu, overlapped %zu) frames %zu | pop mm med %.3g p90 %.3g max %.3g | "
                "jump mm med %.3g p90 %.3g max %.3g | lag mm med %.3g p90 %.3g max %.3g | settle s med %.3g p90 %.3g "
                "max %.3g | worst jump/pop %.3f, lag/pop %.4f, settled gap %.2g m | large %zu, jump/design %.3f\n  worst jump: %s\n  worst lag: %s\n",
                kind.name, r.events.size(), closed, overlapped, r.frames, 1e3 * quantile(pop, 0.5), 1e3 * quantile(pop, 0.9),
                1e3 * quantile(pop, 1.0), 1e3 * quantile(jump, 0.5), 1e3 * quantile(jump, 0.9), 1e3 * quantile(jump, 1.0),
                1e3 * quantile(lag, 0.5), 1e3 * quantile(lag, 0.9), 1e3 * quantile(lag, 1.0), quantile(settle, 0.5),
                quantile(settle, 0.9), quantile(settle, 1.0), r.max_jump_ratio, r.max_lag_ratio, r.max_settled_gap_m,
                r.large_events, r.max_jump_over_design, r.worst_jump.c_str(), r.worst_lag.c_str());
}

// Issue 31: events closer together than one blend (0-3 frames apart, so nearly every event overlaps others),
// on end-dense open cables (1 - cos spacing) and on closed loops (seam removals and insertions across the seam
// among them). Every frame within the stated per-frame bound (1 mm while the running change is under 16 cm,
// design bound 1.5 max|D| / N otherwise: events are folded into one, so the bound is per frame, not per event),
// within the running pops, and exactly on the fresh curve once nothing runs.
class PopFreeOverlap : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(PopFreeOverlap, FoldedEventsKeepTheFrameBound) {
    const Kind& kind = kKinds[std::get<0>(GetParam())];
    const int shapes = std::get<1>(GetParam());  // 1 open end-dense, 2 closed
    PopFreeFamilySettings s;
    s.spline = kind.spline;
    s.cables = 12;
    s.events_per_cable = 13;
    s.max_gap_frames = 3;
    s.shapes = shapes;
    s.open_spacing = 1;
    s.seed = 3100 + static_cast<uint64_t>(std::get<0>(GetParam())) * 10 + static_cast<uint64_t>(shapes);
    const PopFreeFamilyResult r = run_pop_free_family(s);
    ASSERT_TRUE(r.error.empty()) << r.error;
    std::size_t overlapped = 0, seams = 0;
    std::vector<double> pop, jump, lag, settle;
    for (const PopFreeEvent& e : r.events) {
        overlapped += e.overlapped, seams += e.type == PopFreeEvent::seam;
        pop.push_back(e.pop_m), jump.push_back(e.jump_m), lag.push_back(e.lag_m), settle.push_back(e.frames / 60.0);
    }
    EXPECT_GT(overlapped, r.events.size() / 2);
    if (shapes == 2) {
        EXPECT_GT(seams, 3u);
    }
    EXPECT_EQ(r.unremedied, 0u);
    EXPECT_EQ(r.state_mismatch, 0u);
    // Every frame within 1.5 max|D| / N of the running (folded) event: max_step_m (1 mm) up to 16 cm, 2 mm up to
    // 32 cm (the longest blend), and 2 mm in every frame without a larger change.
    EXPECT_LE(r.max_jump_m, 2e-3) << kind.name;
    EXPECT_LE(r.max_jump_over_design, 1.0 + 1e-6) << kind.name << ": " << r.worst_jump;
    if (kind.spline.alpha != 0.0 || kind.spline.kind != SplineKind::catmull_rom) {  // uniform slides (docs)
        EXPECT_LE(r.max_jump_ratio, 0.2) << kind.name << ": " << r.worst_jump;
        EXPECT_LE(r.max_lag_ratio, 1.0 + 1e-6) << kind.name << ": " << r.worst_lag;
    }
    EXPECT_LE(r.max_settled_gap_m, 1e-9) << kind.name;
    EXPECT_LE(r.max_frames, PopFreeCurve().max_blend_frames()) << kind.name;
    std::printf("%-12s %s events %zu (overlapped %zu, seam %zu) frames %zu | pop mm med %.3g p90 %.3g max %.3g | "
                "jump mm med %.3g p90 %.3g max %.3g | lag mm med %.3g p90 %.3g max %.3g | settle s med %.3g p90 %.3g max %.3g | "
                "worst jump/pop %.3f, lag/pop %.4f, jump/design %.3f, settled gap %.2g m, large %zu\n  worst jump: %s\n  worst lag: %s\n",
                kind.name, shapes == 1 ? "end-dense" : "closed   ", r.events.size(), overlapped, seams, r.frames,
                1e3 * quantile(pop, 0.5), 1e3 * quantile(pop, 0.9), 1e3 * quantile(pop, 1.0), 1e3 * quantile(jump, 0.5),
                1e3 * quantile(jump, 0.9), 1e3 * quantile(jump, 1.0), 1e3 * quantile(lag, 0.5), 1e3 * quantile(lag, 0.9),
                1e3 * quantile(lag, 1.0), quantile(settle, 0.5), quantile(settle, 0.9), quantile(settle, 1.0), r.max_jump_ratio,
                r.max_lag_ratio, r.max_jump_over_design, r.max_settled_gap_m, r.large_events, r.worst_jump.c_str(), r.worst_lag.c_str());
}

INSTANTIATE_TEST_SUITE_P(EveryKind, PopFreeOverlap, ::testing::Combine(::testing::Range(0, 5), ::testing::Values(1, 2)),
                         [](const ::testing::TestParamInfo<std::tuple<int, int>>& info) {
                             return std::string(kKinds[std::get<0>(info.param)].name) + (std::get<1>(info.param) == 1 ? "_end_dense" : "_closed");
                         });

// Issue 31's seam scene: a tilted 14-node loop with out-of-plane lobes (the family's loop shape), a node
// inserted exactly on the curve (every segment, the closing one included, appended or prepended), then node 0
// (the seam) removed, then the inserted node removed, 0 or 2 frames apart so the three blends overlap.
// Every frame within 2 mm (1 mm below 16 cm of offset) and 1/5 of the three pops, never further from the fresh curve than their sum, and
// exactly on it once the blend ends.
TEST(PopFreeSeam, InsertRemoveTheSeamThenTheInsertedNode) {
    double worst_ratio = 0.0, worst_jump = 0.0, worst_lag_ratio = 0.0;
    std::string worst;
    int cases = 0;
    for (uint64_t seed = 1; seed <= 2; ++seed) {
        testing::Random rng{seed * 7919};
        const double length = rng.uniform(5.0, 40.0), r = length / (2.0 * std::numbers::pi);
        const double a = r * rng.uniform(1.0, 1.3), b = r * rng.uniform(0.7, 1.0), h = rng.uniform(0.0, 1.0);
        const int lobes = rng.integer(2, 3);
        const glm::dvec3 axis = rng.unit();
        const glm::dvec3 u = glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
        const glm::dvec3 v = glm::cross(axis, u);
        WireNodes loop;
        for (int i = 0; i < 14; ++i) {
            const double th = 2.0 * std::numbers::pi * (i + rng.uniform(-0.3, 0.3)) / 14.0;
            loop.positions.push_back(a * std::cos(th) * u + b * std::sin(th) * v + h * std::sin(lobes * th) * axis);
            loop.ids.push_back(static_cast<uint32_t>(100 + i));
        }
        for (const Kind& kind : kKinds) {
            SplineSettings spline = kind.spline;
            spline.closed = true;
            for (int gap : {0, 2}) {
                for (int seg = 0; seg <= 14; ++seg) {  // 14: in the closing segment, prepended as the new node 0
                    PopFreeCurve m({.spline = spline});
                    WireNodes nodes = loop;
                    Curve prev, cur;
                    ASSERT_TRUE(m.update(nodes, prev).ok());
                    double pops = 0.0, jump = 0.0, lag = 0.0;
                    auto step = [&]() {
                        const Curve before = m.target();
                        ASSERT_TRUE(m.update(nodes, cur).ok());
                        pops += curve_distance_m(before, m.target());
                        jump = std::max(jump, curve_distance_m(prev, cur));
                        lag = std::max(lag, curve_distance_m(cur, m.target()));
                        prev = cur;
                    };
                    auto erase_id = [&](uint32_t id) {
                        const auto it = std::find(nodes.ids.begin(), nodes.ids.end(), id);
                        nodes.positions.erase(nodes.positions.begin() + (it - nodes.ids.begin()));
                        nodes.ids.erase(it);
                    };
                    const std::size_t k = seg == 14 ? 13 : static_cast<std::size_t>(seg);
                    const std::size_t at = seg == 14 ? 0 : k + 1;
                    nodes.positions.insert(nodes.positions.begin() + static_cast<std::ptrdiff_t>(at), position(m.target().segments[k], 0.4));
                    nodes.ids.insert(nodes.ids.begin() + static_cast<std::ptrdiff_t>(at), 99u);
                    step();
                    for (int f = 0; f < gap; ++f) step();
                    erase_id(100);  // the seam
                    step();
                    for (int f = 0; f < gap; ++f) step();
                    erase_id(99);
                    step();
                    for (int f = 0; f <= m.max_blend_frames() && m.blending(); ++f) step();
                    const std::string what = std::string(kind.name) + " seed " + std::to_string(seed) + " segment " +
                                             std::to_string(seg) + " gap " + std::to_string(gap);
                    EXPECT_FALSE(m.blending()) << what;
                    EXPECT_EQ(curve_distance_m(cur, m.target()), 0.0) << what;
                    EXPECT_EQ(m.unremedied(), 0u) << what;
                    EXPECT_LE(jump, 2e-3) << what;  // 1 mm up to max|D| = 16 cm, 2 mm up to 32 cm (pop_free.hpp)
                    EXPECT_LE(jump, 0.2 * pops + 1e-12) << what;
                    EXPECT_LE(lag, pops * (1.0 + 1e-9) + 1e-12) << what;
                    if (pops > 1e-9 && jump / pops > worst_ratio) worst_ratio = jump / pops, worst = what;
                    worst_jump = std::max(worst_jump, jump);
                    ++cases;
                    if (pops > 1e-9) worst_lag_ratio = std::max(worst_lag_ratio, lag / pops);
                }
            }
        }
    }
    std::printf("seam scene: %d cases, largest jump %.3g mm, jump / sum of pops %.3f (%s), lag / sum of pops %.3f\n",
                cases, 1e3 * worst_jump, worst_ratio, worst.c_str(), worst_lag_ratio);
}

INSTANTIATE_TEST_SUITE_P(EveryKind, PopFreeFamily, ::testing::Range(0, 6),
                         [](const ::testing::TestParamInfo<int>& info) { return std::string(kKinds[info.param].name); });

}  // namespace
}  // namespace wire
