// Tests of component storage: packed components, swap-remove, and change ticks / the change log.
#include <engine/ecs/storage.hpp>

#include <gtest/gtest.h>

#include "test_print.hpp"

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

namespace engine::ecs {
namespace {

struct Position {
    float x, y;
};

template <class T>
std::vector<Entity> collect(const ChangedRange<T>& r) {
    std::vector<Entity> out;
    for (const Entity e : r) out.push_back(e);
    return out;
}

std::vector<Entity> sorted(std::vector<Entity> v) {
    std::sort(v.begin(), v.end());
    return v;
}

TEST(Storage, EmplaceGetTryGet) {
    Storage<Position> s;
    const Entity a = make_entity(0, 0), b = make_entity(1, 0);
    Position& pa = s.emplace(a, 1.0f, 2.0f);
    EXPECT_EQ(pa.x, 1.0f);
    s.emplace(b, 3.0f, 4.0f);
    EXPECT_EQ(s.get(a).y, 2.0f);
    EXPECT_EQ(s.get(b).x, 3.0f);
    EXPECT_EQ(s.try_get(make_entity(0, 1)), nullptr) << "stale version";
    EXPECT_EQ(s.try_get(make_entity(2, 0)), nullptr);
    ASSERT_NE(s.try_get(b), nullptr);
    EXPECT_EQ(s.try_get(b)->y, 4.0f);
}

TEST(Storage, NonAggregateAndMoveOnlyComponents) {
    Storage<std::string> names;
    names.emplace(make_entity(0, 0), 3, 'x');
    EXPECT_EQ(names.get(make_entity(0, 0)), "xxx");
    Storage<std::unique_ptr<int>> owned;
    owned.emplace(make_entity(0, 0), std::make_unique<int>(7));
    owned.emplace(make_entity(1, 0), std::make_unique<int>(8));
    owned.remove(make_entity(0, 0));
    EXPECT_EQ(*owned.get(make_entity(1, 0)), 8);
}

TEST(Storage, SwapRemoveKeepsOtherComponents) {
    Storage<int> s;
    std::vector<Entity> es;
    for (std::uint32_t i = 0; i < 100; ++i) {
        es.push_back(make_entity(i * 13, i % 3));
        s.emplace(es.back(), static_cast<int>(i) * 10);
    }
    // Remove every third entity, from the front, so the last one is swapped in each time.
    for (std::uint32_t i = 0; i < 100; i += 3) EXPECT_TRUE(s.remove(es[i]));
    for (std::uint32_t i = 0; i < 100; ++i) {
        if (i % 3 == 0) {
            EXPECT_FALSE(s.contains(es[i]));
        } else {
            ASSERT_TRUE(s.contains(es[i]));
            EXPECT_EQ(s.get(es[i]), static_cast<int>(i) * 10) << "entity " << i;
        }
    }
    EXPECT_EQ(s.size(), 66u);
    EXPECT_EQ(s.components().size(), s.entities().size());
}

TEST(StorageChanges, EmplacePatchMarkAreChanges) {
    Storage<int> s;
    const Entity a = make_entity(0, 0), b = make_entity(1, 0), c = make_entity(2, 0);
    s.emplace(a, 1);
    s.emplace(b, 2);
    const std::uint64_t t0 = s.clock();
    EXPECT_EQ(sorted(collect(s.changed(0))), sorted({a, b}));
    EXPECT_TRUE(collect(s.changed(t0)).empty());

    s.emplace(c, 3);
    s.patch(a) = 10;
    EXPECT_EQ(collect(s.changed(t0)), (std::vector<Entity>{c, a})) << "stamp order";
    const std::uint64_t t1 = s.clock();
    s.mark_changed(b);
    s.patch(c, [](int& v) { v += 1; });
    EXPECT_EQ(collect(s.changed(t1)), (std::vector<Entity>{b, c}));
    EXPECT_EQ(s.get(c), 4);
    EXPECT_GT(s.changed_tick(c), s.changed_tick(b));
    EXPECT_EQ(collect(s.changed(t0)), (std::vector<Entity>{a, b, c})) << "each entity once, by latest stamp";
}

TEST(StorageChanges, TwoSystemsSeeAllChangesSinceTheirOwnRun) {
    Storage<int> s;
    std::vector<Entity> es;
    for (std::uint32_t i = 0; i < 10; ++i) {
        es.push_back(make_entity(i, 0));
        s.emplace(es.back(), 0);
    }
    std::uint64_t last_a = 0, last_b = 0;
    EXPECT_EQ(collect(s.changed(last_a)).size(), 10u);
    last_a = s.clock();  // system A ran; B has not
    s.patch(es[3]) = 1;
    s.patch(es[5]) = 1;
    EXPECT_EQ(sorted(collect(s.changed(last_a))), sorted({es[3], es[5]}));
    last_a = s.clock();
    s.patch(es[7]) = 1;
    s.patch(es[3]) = 2;
    EXPECT_EQ(sorted(collect(s.changed(last_a))), sorted({es[3], es[7]}));
    EXPECT_EQ(collect(s.changed(last_b)).size(), 10u) << "B never ran: it still sees every change";
    last_b = s.clock();
    EXPECT_TRUE(collect(s.changed(last_b)).empty());
    EXPECT_EQ(sorted(collect(s.changed(last_a))), sorted({es[3], es[7]}))
        << "B's run consumed nothing of A's";
}

TEST(StorageChanges, RemovedComponentsAreNotListed) {
    Storage<int> s;
    const Entity a = make_entity(0, 0), b = make_entity(1, 0);
    s.emplace(a, 1);
    s.emplace(b, 2);
    s.remove(a);
    EXPECT_EQ(collect(s.changed(0)), (std::vector<Entity>{b}));
    s.emplace(a, 5);  // re-added: a change again
    EXPECT_EQ(collect(s.changed(0)), (std::vector<Entity>{b, a}));
    const Entity a2 = make_entity(0, 1);  // same slot, new version: the old handle's entry must not match
    s.remove(a);
    s.emplace(a2, 6);
    EXPECT_EQ(collect(s.changed(0)), (std::vector<Entity>{b, a2}));
}

TEST(StorageChanges, LogStaysBoundedAndCorrectAcrossCompaction) {
    Storage<int> s;
    std::vector<Entity> es;
    for (std::uint32_t i = 0; i < 50; ++i) {
        es.push_back(make_entity(i, 0));
        s.emplace(es.back(), 0);
    }
    const std::uint64_t mid = s.clock();
    for (int round = 0; round < 1000; ++round) s.mark_changed(es[static_cast<std::size_t>(round * 7) % 50]);
    EXPECT_LE(s.change_log_size(), 2 * s.size() + 64);
    // round*7 mod 50 covers every entity (gcd(7,50)=1), so all were stamped after `mid`.
    EXPECT_EQ(sorted(collect(s.changed(mid))), sorted(es));
    EXPECT_EQ(collect(s.changed(s.clock())).size(), 0u);
}

TEST(StorageChanges, StampingWhileWalkingVisitsEachOnceAndDefersNewStamps) {
    Storage<int> s;
    std::vector<Entity> es;
    for (std::uint32_t i = 0; i < 200; ++i) {
        es.push_back(make_entity(i, 0));
        s.emplace(es.back(), 0);
    }
    // Patching every visited entity (and restamping es[0] in between, which defeats the back-to-back
    // dedupe) appends to the log and compacts it while we walk.
    std::vector<Entity> seen;
    const std::size_t log_before = s.change_log_size();
    for (const Entity e : s.changed(0)) {
        seen.push_back(e);
        s.patch(e) += 1;
        s.mark_changed(es[0]);
    }
    EXPECT_EQ(log_before, 200u);
    EXPECT_LT(s.change_log_size(), 200u + 2 * 200u) << "the log must have been compacted during the walk";
    EXPECT_EQ(sorted(seen), sorted(es));
    const std::uint64_t after = s.clock();
    EXPECT_TRUE(collect(s.changed(after)).empty());
    for (const Entity e : es) EXPECT_EQ(s.get(e), 1);
}

struct Scratch {
    int v = 0;
};

}  // namespace

template <>
inline constexpr bool track_changes_v<Scratch> = false;

namespace {

TEST(StorageChanges, UntrackedTypeStampsNothingButWorks) {
    std::uint64_t clock = 0;
    Storage<Scratch> s{&clock};
    std::vector<Entity> es;
    for (std::uint32_t i = 0; i < 10; ++i) {
        es.push_back(make_entity(i, 0));
        s.emplace(es.back(), static_cast<int>(i));
    }
    s.patch(es[3]).v = 30;
    s.mark_changed(es[4]);
    s.remove(es[0]);
    EXPECT_EQ(clock, 0u) << "no stamps for an untracked type";
    EXPECT_EQ(s.change_log_size(), 0u);
    EXPECT_EQ(s.get(es[3]).v, 30);
    EXPECT_EQ(s.get(es[9]).v, 9) << "swap-remove still moves components";
    EXPECT_EQ(s.size(), 9u);
}

}  // namespace
}  // namespace engine::ecs
