// The pop-free remedy over random families (issue 17, item 4): >= 500 node events per spline kind on random
// 20-40 m cables, open and closed, nodes inserted exactly on the curve, removed anywhere (the seam node of a
// loop included), end nodes re-created under a new id, often several events running at once. Asserted on every
// frame: the jump is at most 1/5 of the instant pops of the events running and at most 2 mm; the lag (drawn
// against the exact curve of the same nodes) never exceeds those pops; with no event running the drawn curve
// is the exact one (to 1e-6 m; in fact bit for bit), which happens at most max_blend_s after the last event.
#include "wire/multires.hpp"
#include "wire/testing/remedy_family.hpp"

#include <gtest/gtest.h>

#include <algorithm>
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

class RemedyFamily : public ::testing::TestWithParam<int> {};

TEST_P(RemedyFamily, EveryFrameWithinThePopAndSettles) {
    const Kind& kind = kKinds[GetParam()];
    RemedyFamilySettings s;
    s.spline = kind.spline;
    s.cables = 40;
    s.events_per_cable = 13;  // 520 events
    s.seed = 17 + static_cast<uint64_t>(GetParam());
    const RemedyFamilyResult r = run_remedy_family(s);
    ASSERT_TRUE(r.error.empty()) << r.error;
    ASSERT_GE(r.events.size(), 500u);
    std::size_t overlapped = 0, closed = 0, per_type[4] = {0, 0, 0, 0};
    std::vector<double> pop, jump, lag, settle;
    for (const RemedyEvent& e : r.events) {
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
    // keeps 2 mm except for changes too large for it within the longest geomorph (max|D| > 32 cm: counted).
    EXPECT_LE(r.max_jump_over_design, 1.0 + 1e-6) << kind.name;
    EXPECT_LE(r.max_lag_ratio, 1.0 + 1e-6) << kind.name << ": " << r.worst_lag;
    EXPECT_LE(r.max_settled_gap_m, 1e-6) << kind.name;
    EXPECT_LE(r.max_frames, MultiresCurve().max_blend_frames()) << kind.name;

    std::printf("%-12s events %zu (closed %zu, overlapped %zu) frames %zu | pop mm med %.3g p90 %.3g max %.3g | "
                "jump mm med %.3g p90 %.3g max %.3g | lag mm med %.3g p90 %.3g max %.3g | settle s med %.3g p90 %.3g "
                "max %.3g | worst jump/pop %.3f, lag/pop %.4f, settled gap %.2g m | large %zu, jump/design %.3f\n  worst jump: %s\n  worst lag: %s\n",
                kind.name, r.events.size(), closed, overlapped, r.frames, 1e3 * quantile(pop, 0.5), 1e3 * quantile(pop, 0.9),
                1e3 * quantile(pop, 1.0), 1e3 * quantile(jump, 0.5), 1e3 * quantile(jump, 0.9), 1e3 * quantile(jump, 1.0),
                1e3 * quantile(lag, 0.5), 1e3 * quantile(lag, 0.9), 1e3 * quantile(lag, 1.0), quantile(settle, 0.5),
                quantile(settle, 0.9), quantile(settle, 1.0), r.max_jump_ratio, r.max_lag_ratio, r.max_settled_gap_m,
                r.large_events, r.max_jump_over_design, r.worst_jump.c_str(), r.worst_lag.c_str());
}

// Issue 31: events closer together than one geomorph (0-3 frames apart, so nearly every event overlaps others),
// on end-dense open cables (1 - cos spacing) and on closed loops (seam removals and insertions across the seam
// among them). Every frame within the stated per-frame bound (1 mm while the running change is under 16 cm,
// design bound 1.5 max|D| / N otherwise: events are folded into one, so the bound is per frame, not per event),
// within the running pops, and exactly on the fresh curve once nothing runs.
class RemedyOverlap : public ::testing::TestWithParam<std::tuple<int, int>> {};

TEST_P(RemedyOverlap, FoldedEventsKeepTheFrameBound) {
    const Kind& kind = kKinds[std::get<0>(GetParam())];
    const int shapes = std::get<1>(GetParam());  // 1 open end-dense, 2 closed
    RemedyFamilySettings s;
    s.spline = kind.spline;
    s.cables = 12;
    s.events_per_cable = 13;
    s.max_gap_frames = 3;
    s.shapes = shapes;
    s.open_spacing = 1;
    s.seed = 3100 + static_cast<uint64_t>(std::get<0>(GetParam())) * 10 + static_cast<uint64_t>(shapes);
    const RemedyFamilyResult r = run_remedy_family(s);
    ASSERT_TRUE(r.error.empty()) << r.error;
    std::size_t overlapped = 0, seams = 0;
    std::vector<double> pop, jump, lag, settle;
    for (const RemedyEvent& e : r.events) {
        overlapped += e.overlapped, seams += e.type == RemedyEvent::seam;
        pop.push_back(e.pop_m), jump.push_back(e.jump_m), lag.push_back(e.lag_m), settle.push_back(e.frames / 60.0);
    }
    EXPECT_GT(overlapped, r.events.size() / 2);
    if (shapes == 2) {
        EXPECT_GT(seams, 3u);
    }
    EXPECT_EQ(r.unremedied, 0u);
    EXPECT_EQ(r.state_mismatch, 0u);
    // Every frame within 1.5 max|D| / N of the running (folded) event: max_step_m (1 mm) up to 16 cm, 2 mm up to
    // 32 cm (the longest geomorph), and 2 mm in every frame without a larger change.
    EXPECT_LE(r.max_jump_m, 2e-3) << kind.name;
    EXPECT_LE(r.max_jump_over_design, 1.0 + 1e-6) << kind.name << ": " << r.worst_jump;
    if (kind.spline.alpha != 0.0 || kind.spline.kind != SplineKind::catmull_rom) {  // uniform slides (docs)
        EXPECT_LE(r.max_jump_ratio, 0.2) << kind.name << ": " << r.worst_jump;
        EXPECT_LE(r.max_lag_ratio, 1.0 + 1e-6) << kind.name << ": " << r.worst_lag;
    }
    EXPECT_LE(r.max_settled_gap_m, 1e-9) << kind.name;
    EXPECT_LE(r.max_frames, MultiresCurve().max_blend_frames()) << kind.name;
    std::printf("%-12s %s events %zu (overlapped %zu, seam %zu) frames %zu | pop mm med %.3g p90 %.3g max %.3g | "
                "jump mm med %.3g p90 %.3g max %.3g | lag mm med %.3g p90 %.3g max %.3g | settle s med %.3g p90 %.3g max %.3g | "
                "worst jump/pop %.3f, lag/pop %.4f, jump/design %.3f, settled gap %.2g m, large %zu\n  worst jump: %s\n  worst lag: %s\n",
                kind.name, shapes == 1 ? "end-dense" : "closed   ", r.events.size(), overlapped, seams, r.frames,
                1e3 * quantile(pop, 0.5), 1e3 * quantile(pop, 0.9), 1e3 * quantile(pop, 1.0), 1e3 * quantile(jump, 0.5),
                1e3 * quantile(jump, 0.9), 1e3 * quantile(jump, 1.0), 1e3 * quantile(lag, 0.5), 1e3 * quantile(lag, 0.9),
                1e3 * quantile(lag, 1.0), quantile(settle, 0.5), quantile(settle, 0.9), quantile(settle, 1.0), r.max_jump_ratio,
                r.max_lag_ratio, r.max_jump_over_design, r.max_settled_gap_m, r.large_events, r.worst_jump.c_str(), r.worst_lag.c_str());
}

INSTANTIATE_TEST_SUITE_P(EveryKind, RemedyOverlap, ::testing::Combine(::testing::Range(0, 5), ::testing::Values(1, 2)),
                         [](const ::testing::TestParamInfo<std::tuple<int, int>>& info) {
                             return std::string(kKinds[std::get<0>(info.param)].name) + (std::get<1>(info.param) == 1 ? "_end_dense" : "_closed");
                         });

INSTANTIATE_TEST_SUITE_P(EveryKind, RemedyFamily, ::testing::Range(0, 6),
                         [](const ::testing::TestParamInfo<int>& info) { return std::string(kKinds[info.param].name); });

}  // namespace
}  // namespace wire
