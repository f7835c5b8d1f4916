// Benchmarks of the ECS core on 1M entities: creation with two components, two-component view iteration,
// random add/remove churn, and walking the changed-since list. Run:
//   build-ecs/bin/bench_ecs --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <engine/ecs/registry.hpp>

#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <vector>

namespace {

using engine::ecs::Entity;
using engine::ecs::Registry;

struct Position {
    float x = 0, y = 0, z = 0;
};
struct Velocity {
    float x = 0, y = 0, z = 0;
};

// Same data as Velocity, with change tracking turned off (see track_changes_v).
struct UntrackedVelocity {
    float x = 0, y = 0, z = 0;
};

}  // namespace

template <>
inline constexpr bool engine::ecs::track_changes_v<UntrackedVelocity> = false;

namespace {

constexpr std::int64_t kEntities = 1'000'000;

// Create 1M entities, each with a Position and a Velocity, into a fresh registry (destruction untimed).
void BM_Create1MWithTwoComponents(benchmark::State& state) {
    for (auto _ : state) {
        auto* r = new Registry;
        for (std::int64_t i = 0; i < kEntities; ++i) {
            const Entity e = r->create();
            r->emplace<Position>(e, static_cast<float>(i), 0.0f, 0.0f);
            r->emplace<Velocity>(e, 1.0f, 0.0f, 0.0f);
        }
        benchmark::DoNotOptimize(r);
        state.PauseTiming();
        delete r;
        state.ResumeTiming();
    }
    state.SetItemsProcessed(state.iterations() * kEntities);
}
BENCHMARK(BM_Create1MWithTwoComponents)->Unit(benchmark::kMillisecond);

// Iterate view<Position, const Velocity> over 1M entities that have both, integrating positions.
void BM_IterateTwoComponentView1M(benchmark::State& state) {
    Registry r;
    for (std::int64_t i = 0; i < kEntities; ++i) {
        const Entity e = r.create();
        r.emplace<Position>(e);
        r.emplace<Velocity>(e, 1.0f, 2.0f, 3.0f);
    }
    auto view = r.view<Position, const Velocity>();
    for (auto _ : state) {
        view.each([](Position& p, const Velocity& v) {
            p.x += v.x * 0.016f;
            p.y += v.y * 0.016f;
            p.z += v.z * 0.016f;
        });
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * kEntities);
}
BENCHMARK(BM_IterateTwoComponentView1M)->Unit(benchmark::kMillisecond);

// The same loop through range-for over (entity, components) tuples.
void BM_IterateTwoComponentView1MRangeFor(benchmark::State& state) {
    Registry r;
    for (std::int64_t i = 0; i < kEntities; ++i) {
        const Entity e = r.create();
        r.emplace<Position>(e);
        r.emplace<Velocity>(e, 1.0f, 2.0f, 3.0f);
    }
    auto view = r.view<Position, const Velocity>();
    for (auto _ : state) {
        for (auto [e, p, v] : view.each()) {
            p.x += v.x * 0.016f;
            p.y += v.y * 0.016f;
            p.z += v.z * 0.016f;
        }
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations() * kEntities);
}
BENCHMARK(BM_IterateTwoComponentView1MRangeFor)->Unit(benchmark::kMillisecond);

// 1M random toggles of V (remove if present, else emplace) over 1M entities that all have Position.
template <class V>
void BM_RandomAddRemove1M(benchmark::State& state) {
    Registry r;
    std::vector<Entity> es;
    es.reserve(kEntities);
    for (std::int64_t i = 0; i < kEntities; ++i) {
        es.push_back(r.create());
        r.emplace<Position>(es.back());
        if (i % 2 == 0) r.emplace<V>(es.back());
    }
    std::mt19937 rng{42};
    std::uniform_int_distribution<std::size_t> pick{0, es.size() - 1};
    std::vector<Entity> order(static_cast<std::size_t>(kEntities));
    for (Entity& e : order) e = es[pick(rng)];
    auto& vel = r.storage<V>();
    for (auto _ : state) {
        for (const Entity e : order) {
            if (!r.remove<V>(e)) r.emplace<V>(e, 1.0f, 1.0f, 1.0f);
        }
        benchmark::DoNotOptimize(vel.size());
    }
    state.SetItemsProcessed(state.iterations() * kEntities);
}
BENCHMARK(BM_RandomAddRemove1M<Velocity>)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RandomAddRemove1M<UntrackedVelocity>)->Unit(benchmark::kMillisecond);

// 1M entities with Position; 10k random ones are patched per frame; a system walks changed<Position>(since).
void BM_ChangedSince10kOf1M(benchmark::State& state) {
    Registry r;
    std::vector<Entity> es;
    for (std::int64_t i = 0; i < kEntities; ++i) {
        es.push_back(r.create());
        r.emplace<Position>(es.back());
    }
    std::mt19937 rng{7};
    std::uniform_int_distribution<std::size_t> pick{0, es.size() - 1};
    std::uint64_t since = r.tick();
    for (auto _ : state) {
        for (int i = 0; i < 10'000; ++i) r.patch<Position>(es[pick(rng)]).x += 1.0f;
        float sum = 0.0f;
        for (const Entity e : r.changed<Position>(since)) sum += r.get<Position>(e).x;
        since = r.tick();
        benchmark::DoNotOptimize(sum);
    }
    state.SetItemsProcessed(state.iterations() * 10'000);
}
BENCHMARK(BM_ChangedSince10kOf1M)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
