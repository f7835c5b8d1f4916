// Tests of the entity sparse set: paged index, swap-remove, handles with versions.
#include <engine/ecs/sparse_set.hpp>

#include <gtest/gtest.h>

#include "test_print.hpp"

#include <vector>

namespace engine::ecs {
namespace {

// SparseSet::push is protected: a thin set that exposes it.
class EntitySet : public SparseSet {
public:
    void insert(Entity e) { push(e); }
};

TEST(EntityHandle, PacksIndexAndVersion) {
    const Entity e = make_entity(12345, 678);
    EXPECT_EQ(to_index(e), 12345u);
    EXPECT_EQ(to_version(e), 678u);
    EXPECT_EQ(to_index(null_entity), entity_index_mask);
    EXPECT_NE(make_entity(1, 0), make_entity(1, 1));
    EXPECT_EQ(to_version(make_entity(0, 4096 + 3)), 3u);  // version masked to 12 bits
}

TEST(SparseSet, InsertContainsRemove) {
    EntitySet s;
    const Entity a = make_entity(3, 0), b = make_entity(70000, 2), c = make_entity(5, 1);
    s.insert(a);
    s.insert(b);
    s.insert(c);
    EXPECT_EQ(s.size(), 3u);
    EXPECT_TRUE(s.contains(a));
    EXPECT_TRUE(s.contains(b));
    EXPECT_FALSE(s.contains(make_entity(70000, 3))) << "other version of a member must not match";
    EXPECT_FALSE(s.contains(make_entity(4, 0)));
    EXPECT_FALSE(s.contains(make_entity(900000, 0))) << "index on a page never allocated";
    EXPECT_FALSE(s.contains(null_entity));

    EXPECT_TRUE(s.remove(a));  // the last member (c) is swapped into position 0
    EXPECT_FALSE(s.remove(a));
    EXPECT_EQ(s.size(), 2u);
    EXPECT_EQ(s.at(0), c);
    EXPECT_EQ(s.index_of(c), 0u);
    EXPECT_EQ(s.index_of(b), 1u);
    EXPECT_FALSE(s.contains(a));
}

TEST(SparseSet, RemoveLastAndClear) {
    EntitySet s;
    std::vector<Entity> es;
    for (std::uint32_t i = 0; i < 10000; i += 7) {
        es.push_back(make_entity(i, i % 5));
        s.insert(es.back());
    }
    EXPECT_TRUE(s.remove(es.back()));
    EXPECT_FALSE(s.contains(es.back()));
    for (std::size_t i = 0; i + 1 < es.size(); ++i) EXPECT_EQ(s.at(s.index_of(es[i])), es[i]);
    s.clear();
    EXPECT_TRUE(s.empty());
    for (const Entity e : es) EXPECT_FALSE(s.contains(e));
}

TEST(SparseSetDeathTest, DoubleInsertAsserts) {
    EntitySet s;
    s.insert(make_entity(1, 0));
    EXPECT_DEATH(s.insert(make_entity(1, 0)), "entity already has this component");
}

}  // namespace
}  // namespace engine::ecs
