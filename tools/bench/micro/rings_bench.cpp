// Ring stage throughput: frames + rings + tube mesh (vertices and indices) for many wires into one arena, against
// memset of the same bytes (the memory-bandwidth bound). Reports items = vertices and bytes = vertex + index bytes.
#include "wire/rings.hpp"
#include "wire/tessellate.hpp"
#include "wire/tube.hpp"

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace {

constexpr int kWires = 1000;
constexpr int kSegments = 64;
constexpr uint32_t kRingsPerSegment = 8;
constexpr uint32_t kSides = 12;

/// 1,000 random smooth wires (uniform Catmull-Rom through a random walk, 0.1 m node spacing), built by hand.
struct Scene {
    std::vector<wire::Curve> curves;
    std::vector<std::vector<wire::RingParam>> params;
    std::vector<wire::RingSet> ring_sets;      // per wire: carries the first frame to the next evaluation
    std::vector<wire::TubeVertex> vertices;    // the frame's arena
    std::vector<uint32_t> indices;
    std::vector<std::size_t> vertex_offset, index_offset;
    wire::TubeSettings tube_settings{.sides = kSides};

    Scene() {
        std::mt19937 rng(3);
        std::normal_distribution<double> jitter(0.0, 0.3);
        curves.resize(kWires);
        params.resize(kWires);
        ring_sets.resize(kWires);
        std::size_t nv = 0, ni = 0;
        for (int w = 0; w < kWires; ++w) {
            std::vector<glm::dvec3> p(kSegments + 3);
            glm::dvec3 dir(1, 0, 0);
            p[0] = glm::dvec3(w % 32, w / 32, 0.0);
            for (std::size_t i = 1; i < p.size(); ++i) {
                dir = glm::normalize(dir + glm::dvec3(jitter(rng), jitter(rng), jitter(rng)));
                p[i] = p[i - 1] + 0.1 * dir;
            }
            wire::Curve& c = curves[w];
            for (int i = 1; i <= kSegments; ++i) {
                const glm::dvec3 m0 = 0.5 * (p[i + 1] - p[i - 1]);
                const glm::dvec3 m1 = 0.5 * (p[i + 2] - p[i]);
                c.segments.push_back(wire::CubicBezier{p[i], p[i] + m0 / 3.0, p[i + 1] - m1 / 3.0, p[i + 1]});
            }
            for (int i = 0; i <= kSegments; ++i) {
                c.source_node.push_back(static_cast<uint32_t>(i));
                c.radius_m.push_back(0.01f + 0.002f * static_cast<float>(i % 3));
            }
            c.stretch.assign(kSegments, 1.0f);
            const std::vector<uint32_t> counts(kSegments, kRingsPerSegment);
            wire::place_rings(c, counts, params[w]);
            wire::build_rings(c, params[w], {}, ring_sets[w]);
            const wire::TubeCounts tc = wire::tube_counts(params[w].size(), false, tube_settings);
            vertex_offset.push_back(nv);
            index_offset.push_back(ni);
            nv += tc.vertices;
            ni += tc.indices;
        }
        vertex_offset.push_back(nv);
        index_offset.push_back(ni);
        vertices.resize(nv);
        indices.resize(ni);
    }
    [[nodiscard]] std::size_t vertex_count() const { return vertices.size(); }
    [[nodiscard]] std::size_t bytes() const {
        return vertices.size() * sizeof(wire::TubeVertex) + indices.size() * sizeof(uint32_t);
    }

    void rings(int w) {
        wire::RingSettings s;
        s.frames.has_previous_normal = true;  // temporal coherence, as the system runs it
        s.frames.previous_normal = ring_sets[w].frames[0].r;
        wire::build_rings(curves[w], params[w], s, ring_sets[w]);
    }
    void tube(int w) {
        const std::size_t v0 = vertex_offset[w], i0 = index_offset[w];
        wire::write_tube(ring_sets[w].rings, false, 0.0f, tube_settings,
                         std::span(vertices).subspan(v0, vertex_offset[w + 1] - v0),
                         std::span(indices).subspan(i0, index_offset[w + 1] - i0), static_cast<uint32_t>(v0));
    }
};

Scene& scene() {
    static Scene s;
    return s;
}

void report(benchmark::State& state, const Scene& s) {
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(s.vertex_count()));
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(s.bytes()));
    state.counters["vertices"] = static_cast<double>(s.vertex_count());
    state.counters["MB"] = static_cast<double>(s.bytes()) / 1e6;
    double split = 0.0;
    for (const wire::RingSet& r : s.ring_sets) split += r.frame_stats.subdivided_steps;
    state.counters["split_steps"] = split;
}

/// The whole ring stage: frames + ring records + tube vertices and indices, 1,000 wires x 64 segments x 8 rings.
void BM_RingsAndTube(benchmark::State& state) {
    Scene& s = scene();
    for (auto _ : state) {
        for (int w = 0; w < kWires; ++w) {
            s.rings(w);
            s.tube(w);
        }
        benchmark::DoNotOptimize(s.vertices.data());
        benchmark::DoNotOptimize(s.indices.data());
        benchmark::ClobberMemory();
    }
    report(state, s);
}

/// The same on the first 16 wires only (~6 MB of output, mostly cache-resident): the compute-bound rate.
void BM_RingsAndTubeCacheResident(benchmark::State& state) {
    Scene& s = scene();
    constexpr int kFew = 16;
    for (auto _ : state) {
        for (int w = 0; w < kFew; ++w) {
            s.rings(w);
            s.tube(w);
        }
        benchmark::DoNotOptimize(s.vertices.data());
        benchmark::ClobberMemory();
    }
    const auto vertices = static_cast<int64_t>(s.vertex_offset[kFew]);
    const auto bytes = vertices * static_cast<int64_t>(sizeof(wire::TubeVertex)) +
                       static_cast<int64_t>(s.index_offset[kFew] * sizeof(uint32_t));
    state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) * vertices);
    state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * bytes);
}

/// The same with non-temporal vertex stores (TubeSettings::streaming_stores), as for a mapped GPU arena.
void BM_RingsAndTubeStreaming(benchmark::State& state) {
    Scene& s = scene();
    s.tube_settings.streaming_stores = true;
    for (auto _ : state) {
        for (int w = 0; w < kWires; ++w) {
            s.rings(w);
            s.tube(w);
        }
        benchmark::DoNotOptimize(s.vertices.data());
        benchmark::DoNotOptimize(s.indices.data());
        benchmark::ClobberMemory();
    }
    s.tube_settings.streaming_stores = false;
    report(state, s);
}

/// Frames + ring records only (what the GPU path does on the CPU).
void BM_RingsOnly(benchmark::State& state) {
    Scene& s = scene();
    for (auto _ : state) {
        for (int w = 0; w < kWires; ++w) s.rings(w);
        benchmark::ClobberMemory();
    }
    report(state, s);
}

/// Tube vertices and indices from prepared rings only.
void BM_TubeOnly(benchmark::State& state) {
    Scene& s = scene();
    s.tube_settings.streaming_stores = state.range(0) != 0;
    for (auto _ : state) {
        for (int w = 0; w < kWires; ++w) s.tube(w);
        benchmark::DoNotOptimize(s.vertices.data());
        benchmark::ClobberMemory();
    }
    s.tube_settings.streaming_stores = false;
    report(state, s);
}

/// memset of the same bytes into the same arena: the bandwidth bound the mesh path is compared with.
void BM_MemsetSameBytes(benchmark::State& state) {
    Scene& s = scene();
    int value = 0;
    for (auto _ : state) {
        std::memset(static_cast<void*>(s.vertices.data()), ++value & 0xff, s.vertices.size() * sizeof(wire::TubeVertex));
        std::memset(s.indices.data(), value & 0xff, s.indices.size() * sizeof(uint32_t));
        benchmark::DoNotOptimize(s.vertices.data());
        benchmark::ClobberMemory();
    }
    report(state, s);
}

BENCHMARK(BM_RingsAndTube)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RingsAndTubeCacheResident)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RingsAndTubeStreaming)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RingsOnly)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TubeOnly)->ArgName("streaming")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MemsetSameBytes)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
