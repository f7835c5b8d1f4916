// Randomized model check: 100,000 random create/destroy/emplace/remove/patch/mark-changed operations
// (fixed seeds), with now and then a view walk that removes components of, or destroys, the current entity.
// Every 1000 operations all queries are compared with a std::map model: validity, has/get, storage sizes,
// views for every combination of types, and the changed-since sets of two systems that run at different
// rates.
#include <engine/ecs/registry.hpp>

#include <gtest/gtest.h>

#include "test_print.hpp"

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <type_traits>
#include <utility>
#include <vector>

namespace engine::ecs {
namespace {

template <int I>
struct Comp {
    int v = 0;
};

constexpr int kTypes = 3;
constexpr int kSystems = 2;

// Calls fn(std::integral_constant<int, t>) for a runtime type number t.
template <class Fn>
void with_type(int t, Fn&& fn) {
    switch (t) {
        case 0:
            fn(std::integral_constant<int, 0>{});
            break;
        case 1:
            fn(std::integral_constant<int, 1>{});
            break;
        default:
            fn(std::integral_constant<int, 2>{});
            break;
    }
}

struct ModelEntity {
    std::array<std::optional<int>, kTypes> comp;
    // dirty[s][t]: component t was emplaced/replaced/patched/marked since system s last ran.
    std::array<std::array<bool, kTypes>, kSystems> dirty{};
};

class RandomOps : public ::testing::TestWithParam<std::uint32_t> {
protected:
    Registry reg;
    std::map<Entity, ModelEntity> model;
    std::vector<Entity> live;  // same members as model, for O(1) random picks
    std::vector<Entity> stale;
    std::array<std::uint64_t, kSystems> last_run{};
    std::mt19937 rng{GetParam()};
    int checks = 0;
    std::size_t sweep_visits = 0;

    int rand_int(int lo, int hi) { return std::uniform_int_distribution<int>{lo, hi}(rng); }
    Entity pick() { return live[static_cast<std::size_t>(rand_int(0, static_cast<int>(live.size()) - 1))]; }
    void stamp(ModelEntity& m, int t) {
        for (auto& d : m.dirty) d[static_cast<std::size_t>(t)] = true;
    }

    void destroy_entity(Entity e) {
        reg.destroy(e);
        model.erase(e);
        live.erase(std::find(live.begin(), live.end(), e));
        stale.push_back(e);
    }
    void remove_component(Entity e, int t) {
        bool removed = false;
        with_type(t, [&](auto tc) { removed = reg.remove<Comp<decltype(tc)::value>>(e); });
        ModelEntity& m = model.at(e);
        auto& slot = m.comp[static_cast<std::size_t>(t)];
        ASSERT_EQ(removed, slot.has_value());
        slot.reset();
        for (auto& d : m.dirty) d[static_cast<std::size_t>(t)] = false;
    }

    // Walks view<Comp<0>, Comp<1>> and removes components of, or destroys, the current entity at random:
    // every member at the start must be visited exactly once.
    void sweep() {
        const std::set<Entity> expect = expected_view(0b011);
        std::set<Entity> seen;
        reg.view<Comp<0>, Comp<1>>().each([&](Entity e, Comp<0>& a, Comp<1>& b) {
            EXPECT_TRUE(seen.insert(e).second) << "sweep visited an entity twice";
            ++sweep_visits;
            const ModelEntity& m = model.at(e);
            EXPECT_EQ(a.v, *m.comp[0]);
            EXPECT_EQ(b.v, *m.comp[1]);
            const int r = rand_int(0, 9);
            if (r == 0) {
                destroy_entity(e);
            } else if (r < 4) {
                remove_component(e, rand_int(0, kTypes - 1));
            }
        });
        ASSERT_EQ(seen, expect);
    }

    void step() {
        if (rand_int(0, 999) < 3) {
            sweep();
            return;
        }
        const int op = rand_int(0, 99);
        if (live.empty() || op < 12) {
            if (live.size() < 3000) {
                const Entity e = reg.create();
                ASSERT_FALSE(model.contains(e));
                model[e] = ModelEntity{};
                live.push_back(e);
                return;
            }
        }
        const Entity e = pick();
        ModelEntity& m = model.at(e);
        const int t = rand_int(0, kTypes - 1);
        auto& slot = m.comp[static_cast<std::size_t>(t)];
        if (op < 22) {  // destroy
            destroy_entity(e);
        } else if (op < 52) {  // emplace or replace
            const int v = rand_int(-1000000, 1000000);
            with_type(t, [&](auto tc) {
                using T = Comp<decltype(tc)::value>;
                if (rand_int(0, 1) == 0) {
                    reg.emplace_or_replace<T>(e, v);
                } else if (slot) {
                    reg.replace<T>(e, v);
                } else {
                    reg.emplace<T>(e, v);
                }
            });
            slot = v;
            stamp(m, t);
        } else if (op < 70) {  // remove
            remove_component(e, t);
        } else if (op < 88) {  // patch
            if (!slot) return;
            const int delta = rand_int(1, 100);
            with_type(t, [&](auto tc) {
                using T = Comp<decltype(tc)::value>;
                if (rand_int(0, 1) == 0) {
                    reg.patch<T>(e).v += delta;
                } else {
                    reg.patch<T>(e, [delta](T& c) { c.v += delta; });
                }
            });
            *slot += delta;
            stamp(m, t);
        } else {  // mark changed without writing
            if (!slot) return;
            with_type(t, [&](auto tc) { reg.mark_changed<Comp<decltype(tc)::value>>(e); });
            stamp(m, t);
        }
    }

    void check_entities() {
        ASSERT_EQ(reg.alive(), model.size());
        std::array<std::size_t, kTypes> counts{};
        for (const auto& entry : model) {
            const Entity e = entry.first;  // a named copy: lambdas below capture it
            const ModelEntity& m = entry.second;
            ASSERT_TRUE(reg.valid(e));
            for (int t = 0; t < kTypes; ++t) {
                const auto& slot = m.comp[static_cast<std::size_t>(t)];
                with_type(t, [&](auto tc) {
                    using T = Comp<decltype(tc)::value>;
                    ASSERT_EQ(reg.has<T>(e), slot.has_value());
                    const T* p = reg.try_get<T>(e);
                    ASSERT_EQ(p != nullptr, slot.has_value());
                    if (slot) {
                        ASSERT_EQ(reg.get<T>(e).v, *slot);
                        ASSERT_EQ(p->v, *slot);
                    }
                });
                counts[static_cast<std::size_t>(t)] += slot ? 1 : 0;
            }
        }
        ASSERT_EQ(reg.storage<Comp<0>>().size(), counts[0]);
        ASSERT_EQ(reg.storage<Comp<1>>().size(), counts[1]);
        ASSERT_EQ(reg.storage<Comp<2>>().size(), counts[2]);
        for (const Entity s : stale) {
            ASSERT_FALSE(reg.valid(s));
            ASSERT_FALSE(reg.has<Comp<0>>(s));
            ASSERT_EQ(reg.try_get<Comp<1>>(s), nullptr);
        }
    }

    // Expected members of the view over the types in `mask` (bit t = Comp<t>).
    std::set<Entity> expected_view(unsigned mask) const {
        std::set<Entity> out;
        for (const auto& [e, m] : model) {
            bool all = true;
            for (int t = 0; t < kTypes; ++t)
                if ((mask >> t) & 1u) all = all && m.comp[static_cast<std::size_t>(t)].has_value();
            if (all) out.insert(e);
        }
        return out;
    }

    template <class... Ts>
    void check_view(unsigned mask) {
        std::set<Entity> seen;
        reg.view<Ts...>().each([&](Entity e, Ts&... cs) {
            EXPECT_TRUE(seen.insert(e).second) << "entity visited twice";
            const ModelEntity& m = model.at(e);
            const std::array<int, sizeof...(Ts)> got{cs.v...};
            const std::array<int, sizeof...(Ts)> want{*m.comp[static_cast<std::size_t>(type_of<Ts>())]...};
            EXPECT_EQ(got, want) << "component values of a view member";
        });
        ASSERT_EQ(seen, expected_view(mask)) << "view mask " << mask;
        std::set<Entity> by_range;
        for (const Entity e : reg.view<Ts...>()) by_range.insert(e);
        ASSERT_EQ(by_range, seen);
    }
    template <class T>
    static constexpr int type_of() {
        if constexpr (std::is_same_v<T, Comp<0>>) return 0;
        if constexpr (std::is_same_v<T, Comp<1>>) return 1;
        return 2;
    }

    void check_views() {
        check_view<Comp<0>>(1);
        check_view<Comp<1>>(2);
        check_view<Comp<2>>(4);
        check_view<Comp<0>, Comp<1>>(3);
        check_view<Comp<0>, Comp<2>>(5);
        check_view<Comp<2>, Comp<1>>(6);
        check_view<Comp<0>, Comp<1>, Comp<2>>(7);
    }

    // System s runs: it must see exactly the components stamped since its last run.
    void run_system(int s) {
        for (int t = 0; t < kTypes; ++t) {
            std::set<Entity> seen;
            with_type(t, [&](auto tc) {
                for (const Entity e :
                     reg.changed<Comp<decltype(tc)::value>>(last_run[static_cast<std::size_t>(s)]))
                    EXPECT_TRUE(seen.insert(e).second) << "changed<> listed an entity twice";
            });
            std::set<Entity> expect;
            for (auto& [e, m] : model)
                if (m.dirty[static_cast<std::size_t>(s)][static_cast<std::size_t>(t)]) expect.insert(e);
            ASSERT_EQ(seen, expect) << "system " << s << " type " << t << " check " << checks;
        }
        for (auto& [e, m] : model) m.dirty[static_cast<std::size_t>(s)] = {};
        last_run[static_cast<std::size_t>(s)] = reg.tick();
    }

    void check_all() {
        ++checks;
        check_entities();
        check_views();
        run_system(0);                       // every batch
        if (checks % 3 == 0) run_system(1);  // every third batch: sees three batches of changes
    }
};

TEST_P(RandomOps, HundredThousandOpsMatchModel) {
    constexpr int kOps = 100000;
    for (int i = 1; i <= kOps; ++i) {
        ASSERT_NO_FATAL_FAILURE(step()) << "op " << i;
        if (i % 1000 == 0) {
            ASSERT_NO_FATAL_FAILURE(check_all()) << "after op " << i;
        }
    }
    run_system(1);
    EXPECT_EQ(checks, kOps / 1000);
    EXPECT_GT(reg.alive(), 0u);
    EXPECT_GT(stale.size(), 1000u) << "the mix must exercise destroy";
    EXPECT_GT(sweep_visits, 1000u) << "the mix must exercise removal during view walks";
    // Change logs stay bounded by their live sizes no matter how many stamps happened.
    EXPECT_LE(reg.storage<Comp<0>>().change_log_size(), 2 * reg.storage<Comp<0>>().size() + 64);
}

INSTANTIATE_TEST_SUITE_P(Seeds, RandomOps, ::testing::Values(1u, 20261121u, 777u));

}  // namespace
}  // namespace engine::ecs
