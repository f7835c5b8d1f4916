// Tests of the registry: entity lifetime, stale handles, version exhaustion, component operations.
#include <engine/ecs/registry.hpp>

#include <gtest/gtest.h>

#include "test_print.hpp"

#include <set>
#include <vector>

namespace engine::ecs {
namespace {

struct Position {
    float x = 0, y = 0;
};
struct Velocity {
    float dx = 0, dy = 0;
};
struct Tag {};

TEST(Registry, CreateGivesDistinctValidEntities) {
    Registry r;
    std::set<Entity> seen;
    for (int i = 0; i < 1000; ++i) {
        const Entity e = r.create();
        EXPECT_TRUE(r.valid(e));
        EXPECT_TRUE(seen.insert(e).second);
    }
    EXPECT_EQ(r.alive(), 1000u);
    EXPECT_FALSE(r.valid(null_entity));
    EXPECT_FALSE(r.valid(make_entity(5000, 0))) << "never created";
}

TEST(Registry, DestroyMakesHandleStaleAndSlotIsReusedWithNewVersion) {
    Registry r;
    const Entity a = r.create();
    const Entity b = r.create();
    r.destroy(a);
    EXPECT_FALSE(r.valid(a));
    EXPECT_TRUE(r.valid(b));
    EXPECT_EQ(r.alive(), 1u);
    const Entity c = r.create();
    EXPECT_EQ(to_index(c), to_index(a)) << "the freed slot is reused";
    EXPECT_EQ(to_version(c), to_version(a) + 1);
    EXPECT_TRUE(r.valid(c));
    EXPECT_FALSE(r.valid(a)) << "the old handle stays stale after reuse";
}

TEST(Registry, StaleHandleSeesNoComponents) {
    Registry r;
    const Entity a = r.create();
    r.emplace<Position>(a, 1.0f, 2.0f);
    r.destroy(a);
    const Entity c = r.create();  // same slot
    r.emplace<Position>(c, 5.0f, 6.0f);
    EXPECT_FALSE(r.has<Position>(a));
    EXPECT_EQ(r.try_get<Position>(a), nullptr);
    EXPECT_EQ(r.get<Position>(c).x, 5.0f);
}

TEST(RegistryDeathTest, OperationsOnStaleHandlesAssert) {
    Registry r;
    const Entity a = r.create();
    r.emplace<Position>(a);
    r.destroy(a);
    const Entity c = r.create();
    r.emplace<Position>(c);
    EXPECT_DEATH((void)r.get<Position>(a), "get: stale or null entity handle");
    EXPECT_DEATH(r.emplace<Velocity>(a), "emplace: stale or null entity handle");
    EXPECT_DEATH(r.remove<Position>(a), "remove: stale or null entity handle");
    EXPECT_DEATH(r.patch<Position>(a), "patch: stale or null entity handle");
    EXPECT_DEATH(r.destroy(a), "destroy: stale or null entity handle");
    EXPECT_DEATH((void)r.get<Velocity>(c), "no such component");
    EXPECT_DEATH(r.emplace<Position>(c), "already has this component");
}

TEST(Registry, VersionExhaustionRetiresTheSlot) {
    Registry r;
    std::vector<Entity> old;
    Entity e = r.create();
    const std::uint32_t index = to_index(e);
    for (std::uint32_t v = 0; v < entity_version_mask; ++v) {
        old.push_back(e);
        r.destroy(e);
        e = r.create();
        ASSERT_EQ(to_index(e), index);
        ASSERT_EQ(to_version(e), v + 1);
    }
    EXPECT_EQ(to_version(e), entity_version_mask);
    r.destroy(e);
    old.push_back(e);
    EXPECT_EQ(r.retired(), 1u);
    const Entity fresh = r.create();
    EXPECT_NE(to_index(fresh), index) << "a slot at the last version is never handed out again";
    for (const Entity s : old) ASSERT_FALSE(r.valid(s));
    EXPECT_FALSE(r.valid(make_entity(index, 0))) << "no wrap-around to version 0";
}

TEST(Registry, EmplaceGetHasRemoveReplace) {
    Registry r;
    const Entity e = r.create();
    EXPECT_FALSE(r.has<Position>(e));
    r.emplace<Position>(e, 1.0f, 2.0f);
    r.emplace<Tag>(e);
    EXPECT_TRUE(r.has<Position>(e));
    EXPECT_TRUE((r.has<Position, Tag>(e)));
    EXPECT_FALSE((r.has<Position, Velocity>(e)));
    EXPECT_EQ(r.get<Position>(e).y, 2.0f);
    r.replace<Position>(e, 7.0f, 8.0f);
    EXPECT_EQ(r.get<Position>(e).x, 7.0f);
    r.emplace_or_replace<Velocity>(e, 1.0f, 1.0f);
    r.emplace_or_replace<Velocity>(e, 2.0f, 3.0f);
    EXPECT_EQ(r.get<Velocity>(e).dy, 3.0f);
    EXPECT_TRUE(r.remove<Position>(e));
    EXPECT_FALSE(r.remove<Position>(e));
    EXPECT_FALSE(r.has<Position>(e));
    EXPECT_EQ(r.try_get<Position>(e), nullptr);
    const Registry& cr = r;
    EXPECT_EQ(cr.get<Velocity>(e).dx, 2.0f);
    EXPECT_EQ(cr.try_get<Position>(e), nullptr);
}

TEST(Registry, DestroyRemovesAllComponents) {
    Registry r;
    const Entity a = r.create(), b = r.create();
    r.emplace<Position>(a, 1.0f, 1.0f);
    r.emplace<Velocity>(a);
    r.emplace<Position>(b, 2.0f, 2.0f);
    r.destroy(a);
    EXPECT_EQ(r.storage<Position>().size(), 1u);
    EXPECT_EQ(r.storage<Velocity>().size(), 0u);
    EXPECT_EQ(r.get<Position>(b).x, 2.0f);
}

TEST(Registry, SwapRemoveKeepsOtherEntitiesComponents) {
    Registry r;
    std::vector<Entity> es;
    for (int i = 0; i < 64; ++i) {
        es.push_back(r.create());
        r.emplace<Position>(es.back(), static_cast<float>(i), static_cast<float>(-i));
    }
    for (int i = 0; i < 64; i += 2) r.remove<Position>(es[static_cast<std::size_t>(i)]);
    for (int i = 1; i < 64; i += 2) {
        const Position& p = r.get<Position>(es[static_cast<std::size_t>(i)]);
        EXPECT_EQ(p.x, static_cast<float>(i));
        EXPECT_EQ(p.y, static_cast<float>(-i));
    }
}

TEST(Registry, ChangeTrackingSharesOneClockAcrossTypes) {
    Registry r;
    const Entity a = r.create(), b = r.create();
    r.emplace<Position>(a);
    r.emplace<Velocity>(b);
    const std::uint64_t since = r.tick();
    r.patch<Velocity>(b).dx = 1.0f;
    r.mark_changed<Position>(a);
    std::vector<Entity> pos, vel;
    for (const Entity e : r.changed<Position>(since)) pos.push_back(e);
    for (const Entity e : r.changed<Velocity>(since)) vel.push_back(e);
    EXPECT_EQ(pos, std::vector<Entity>{a});
    EXPECT_EQ(vel, std::vector<Entity>{b});
    EXPECT_EQ(r.tick(), since + 2);
    r.patch<Position>(a, [](Position& p) { p.x = 3.0f; });
    EXPECT_EQ(r.get<Position>(a).x, 3.0f);
    r.destroy(a);
    EXPECT_TRUE(r.changed<Position>(since).begin() == r.changed<Position>(since).end());
}

TEST(Registry, MoveKeepsStoragesAndClock) {
    Registry r;
    const Entity a = r.create();
    r.emplace<Position>(a, 4.0f, 4.0f);
    Registry moved = std::move(r);
    const std::uint64_t t = moved.tick();
    moved.patch<Position>(a);
    EXPECT_EQ(moved.tick(), t + 1);
    EXPECT_EQ(moved.get<Position>(a).x, 4.0f);
}

TEST(Registry, EachEntityVisitsLiveOnes) {
    Registry r;
    std::vector<Entity> es;
    for (int i = 0; i < 10; ++i) es.push_back(r.create());
    r.destroy(es[2]);
    r.destroy(es[7]);
    std::vector<Entity> seen;
    r.each_entity([&](Entity e) { seen.push_back(e); });
    EXPECT_EQ(seen.size(), 8u);
    for (const Entity e : seen) EXPECT_TRUE(r.valid(e));
}

}  // namespace
}  // namespace engine::ecs
