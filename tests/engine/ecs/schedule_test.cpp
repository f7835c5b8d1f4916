// Tests of the schedule: run order, per-system timing, frame context and per-system change ticks.
#include <engine/ecs/schedule.hpp>

#include <gtest/gtest.h>

#include "test_print.hpp"

#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace engine::ecs {
namespace {

struct Value {
    int v = 0;
};

TEST(Schedule, RunsSystemsInTheOrderAdded) {
    Registry r;
    Schedule s;
    std::vector<std::string> order;
    s.add("physics", [&](Registry&, const FrameContext&) { order.push_back("physics"); })
        .add("curve", [&](Registry&, const FrameContext&) { order.push_back("curve"); })
        .add("lod", [&](Registry&, const FrameContext&) { order.push_back("lod"); });
    s.run(r, 1.0 / 60.0);
    s.run(r, 1.0 / 60.0);
    EXPECT_EQ(order, (std::vector<std::string>{"physics", "curve", "lod", "physics", "curve", "lod"}));
    EXPECT_EQ(s.size(), 3u);
    EXPECT_EQ(s.frames(), 2u);
    ASSERT_EQ(s.stats().size(), 3u);
    EXPECT_EQ(s.stats()[1].name, "curve");
}

TEST(Schedule, RecordsLastAndMeanTimePerSystem) {
    Registry r;
    Schedule s;
    int frame = 0;
    // 2 ms on frame 0, 6 ms on frame 1: last 6, mean 4 (sleep overshoots, so allow slack above).
    s.add("sleepy", [&](Registry&, const FrameContext&) {
        std::this_thread::sleep_for(std::chrono::milliseconds(frame == 0 ? 2 : 6));
    });
    s.add("quick", [](Registry&, const FrameContext&) {});
    s.run(r, 0.016);
    const double first_ms = s.find("sleepy")->last_ms;
    ++frame;
    s.run(r, 0.016);
    const SystemStats* sleepy = s.find("sleepy");
    ASSERT_NE(sleepy, nullptr);
    EXPECT_EQ(sleepy->runs, 2u);
    EXPECT_GE(first_ms, 2.0);
    EXPECT_GE(sleepy->last_ms, 6.0);
    EXPECT_LT(sleepy->last_ms, 200.0);
    EXPECT_NEAR(sleepy->mean_ms, (first_ms + sleepy->last_ms) / 2.0, 1e-9);
    EXPECT_EQ(sleepy->max_ms, std::max(first_ms, sleepy->last_ms));
    const SystemStats* quick = s.find("quick");
    ASSERT_NE(quick, nullptr);
    EXPECT_LT(quick->last_ms, sleepy->last_ms);
    EXPECT_GE(s.last_frame_ms(), sleepy->last_ms);
    EXPECT_EQ(s.find("missing"), nullptr);
}

TEST(Schedule, FrameContextCarriesFrameDataAndUserPointer) {
    Registry r;
    Schedule s;
    std::vector<FrameContext> got;
    s.add("record", [&](Registry&, const FrameContext& ctx) { got.push_back(ctx); });
    int user = 42;
    s.run(r, 0.5, &user);
    s.run(r, 0.25, &user);
    ASSERT_EQ(got.size(), 2u);
    EXPECT_EQ(got[0].frame_index, 0u);
    EXPECT_EQ(got[1].frame_index, 1u);
    EXPECT_EQ(got[1].dt_s, 0.25);
    EXPECT_EQ(got[1].time_s, 0.75);
    EXPECT_EQ(*static_cast<int*>(got[1].user), 42);
}

TEST(Schedule, EachSystemSeesChangesSinceItsOwnLastRun) {
    Registry r;
    Schedule s;
    std::vector<Entity> es;
    for (int i = 0; i < 4; ++i) es.push_back(r.create());
    int frame = 0;
    std::vector<std::size_t> seen_every, seen_odd;
    // "writer" patches entity (frame % 4); "every" reads each frame; "odd" reads only on odd frames.
    s.add("writer", [&](Registry& reg, const FrameContext&) {
        const Entity e = es[static_cast<std::size_t>(frame % 4)];
        if (reg.has<Value>(e)) {
            reg.patch<Value>(e).v += 1;
        } else {
            reg.emplace<Value>(e, 1);
        }
    });
    s.add("every", [&](Registry& reg, const FrameContext& ctx) {
        std::size_t n = 0;
        for (const Entity e : reg.changed<Value>(ctx.last_run_tick)) n += e != null_entity ? 1 : 0;
        seen_every.push_back(n);
    });
    s.add("odd", [&](Registry& reg, const FrameContext& ctx) {
        if (frame % 2 == 0) return;  // skipped frames still advance its tick: it chose to ignore them
        std::size_t n = 0;
        for (const Entity e : reg.changed<Value>(ctx.last_run_tick)) n += e != null_entity ? 1 : 0;
        seen_odd.push_back(n);
    });
    for (frame = 0; frame < 6; ++frame) s.run(r, 0.016);
    EXPECT_EQ(seen_every, (std::vector<std::size_t>{1, 1, 1, 1, 1, 1}));
    // odd frames see only that frame's change, because "odd" also ran (and returned) on even frames.
    EXPECT_EQ(seen_odd, (std::vector<std::size_t>{1, 1, 1}));
}

TEST(Schedule, SystemThatRunsRarelySeesEverythingSinceItsLastRun) {
    Registry r;
    std::vector<Entity> es;
    for (int i = 0; i < 10; ++i) {
        es.push_back(r.create());
        r.emplace<Value>(es.back());
    }
    Schedule fast, slow;
    std::size_t fast_seen = 0, slow_seen = 0;
    fast.add("fast", [&](Registry& reg, const FrameContext& ctx) {
        for ([[maybe_unused]] const Entity e : reg.changed<Value>(ctx.last_run_tick)) ++fast_seen;
    });
    slow.add("slow", [&](Registry& reg, const FrameContext& ctx) {
        for ([[maybe_unused]] const Entity e : reg.changed<Value>(ctx.last_run_tick)) ++slow_seen;
    });
    fast.run(r, 0.0);
    slow.run(r, 0.0);
    EXPECT_EQ(fast_seen, 10u);
    EXPECT_EQ(slow_seen, 10u);
    fast_seen = slow_seen = 0;
    for (int f = 0; f < 5; ++f) {
        r.patch<Value>(es[static_cast<std::size_t>(f)]);
        fast.run(r, 0.0);
    }
    EXPECT_EQ(fast_seen, 5u);
    slow.run(r, 0.0);
    EXPECT_EQ(slow_seen, 5u) << "five distinct entities changed since slow last ran";
}

TEST(ScheduleDeathTest, DuplicateNamesAssert) {
    Schedule s;
    s.add("a", [](Registry&, const FrameContext&) {});
    EXPECT_DEATH(s.add("a", [](Registry&, const FrameContext&) {}), "already added");
}

}  // namespace
}  // namespace engine::ecs
