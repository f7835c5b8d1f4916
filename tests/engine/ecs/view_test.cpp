// Tests of views over one, two and three component types: contents, each() forms, range-for, removal
// during iteration.
#include <engine/ecs/registry.hpp>

#include <gtest/gtest.h>

#include "test_print.hpp"

#include <algorithm>
#include <set>
#include <vector>

namespace engine::ecs {
namespace {

struct A {
    int v = 0;
};
struct B {
    int v = 0;
};
struct C {
    int v = 0;
};

// 30 entities: i has A if i%2==0, B if i%3==0, C if i%5==0; component value = i.
struct World {
    Registry r;
    std::vector<Entity> es;
    World() {
        for (int i = 0; i < 30; ++i) {
            const Entity e = r.create();
            es.push_back(e);
            if (i % 2 == 0) r.emplace<A>(e, i);
            if (i % 3 == 0) r.emplace<B>(e, i);
            if (i % 5 == 0) r.emplace<C>(e, i);
        }
    }
    std::set<Entity> expect(bool a, bool b, bool c) const {
        std::set<Entity> out;
        for (int i = 0; i < 30; ++i)
            if ((!a || i % 2 == 0) && (!b || i % 3 == 0) && (!c || i % 5 == 0))
                out.insert(es[static_cast<std::size_t>(i)]);
        return out;
    }
};

TEST(View, OneType) {
    World w;
    std::set<Entity> seen;
    w.r.view<A>().each([&](Entity e, A& a) {
        EXPECT_TRUE(seen.insert(e).second);
        EXPECT_EQ(w.es[static_cast<std::size_t>(a.v)], e);
    });
    EXPECT_EQ(seen, w.expect(true, false, false));
}

TEST(View, TwoTypesAllForms) {
    World w;
    auto view = w.r.view<A, B>();
    std::set<Entity> by_each, by_each_no_entity, by_range, by_tuple;
    view.each([&](Entity e, A& a, B& b) {
        EXPECT_EQ(a.v, b.v);
        by_each.insert(e);
    });
    int count = 0;
    view.each([&](A& a, const B& b) {
        EXPECT_EQ(a.v, b.v);
        ++count;
    });
    for (const Entity e : view) {
        EXPECT_EQ(view.get<A>(e).v, view.get<B>(e).v);
        by_range.insert(e);
    }
    for (auto [e, a, b] : view.each()) {
        EXPECT_EQ(a.v, b.v);
        EXPECT_EQ(w.es[static_cast<std::size_t>(a.v)], e);
        by_tuple.insert(e);
    }
    const std::set<Entity> expect = w.expect(true, true, false);
    EXPECT_EQ(expect.size(), 5u);  // 0, 6, 12, 18, 24
    EXPECT_EQ(by_each, expect);
    EXPECT_EQ(static_cast<std::size_t>(count), expect.size());
    EXPECT_EQ(by_range, expect);
    EXPECT_EQ(by_tuple, expect);
}

TEST(View, ThreeTypesAndConstAccess) {
    World w;
    std::set<Entity> seen;
    w.r.view<const A, B, const C>().each([&](Entity e, const A& a, B& b, const C& c) {
        EXPECT_EQ(a.v, c.v);
        b.v += 1000;
        seen.insert(e);
    });
    EXPECT_EQ(seen, w.expect(true, true, true));  // 0
    EXPECT_EQ(w.r.get<B>(w.es[0]).v, 1000);
    EXPECT_EQ(w.r.get<B>(w.es[3]).v, 3);
}

TEST(View, EmptyStorageGivesEmptyView) {
    World w;
    struct D {};
    int n = 0;
    w.r.view<A, D>().each([&](Entity, A&, D&) { ++n; });
    EXPECT_EQ(n, 0);
    auto empty_view = w.r.view<A, D>();
    EXPECT_TRUE(empty_view.begin() == empty_view.end());
}

TEST(View, RemovingCurrentEntityComponentDuringSingleTypeViewIsSafe) {
    World w;
    std::set<Entity> seen;
    w.r.view<A>().each([&](Entity e, A& a) {
        seen.insert(e);
        if (a.v % 4 == 0) w.r.remove<A>(e);
    });
    EXPECT_EQ(seen, w.expect(true, false, false)) << "every member visited exactly once";
    for (int i = 0; i < 30; i += 2) EXPECT_EQ(w.r.has<A>(w.es[static_cast<std::size_t>(i)]), i % 4 != 0);
}

TEST(View, DestroyingCurrentEntityDuringMultiTypeViewIsSafe) {
    World w;
    std::set<Entity> seen;
    for (const Entity e : w.r.view<A, B>()) {
        seen.insert(e);
        w.r.destroy(e);
    }
    EXPECT_EQ(seen, w.expect(true, true, false));
    EXPECT_EQ(w.r.storage<A>().size(), 15u - 5u);
    EXPECT_EQ(w.r.storage<B>().size(), 10u - 5u);
}

TEST(View, EmplacingDuringIterationDoesNotVisitNewMembers) {
    World w;
    int visits = 0;
    w.r.view<A>().each([&](Entity, A&) {
        ++visits;
        w.r.emplace<A>(w.r.create(), -1);
    });
    EXPECT_EQ(visits, 15);
    EXPECT_EQ(w.r.storage<A>().size(), 30u);
}

}  // namespace
}  // namespace engine::ecs
