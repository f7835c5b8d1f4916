// The moving path allocates nothing per wire per frame (issue 18): with every node of every wire moving every
// frame, part of the wires in view and part culled, the allocations of a frame do not grow with the wire count.
// This binary counts every operator new (its own replacement, so only this test executable is affected); the
// systems' per-frame work lists allocate a few times per system and frame whatever the wire count.
#include "wire/systems/api.hpp"
#include "wire/systems/systems.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

namespace {
std::atomic<std::size_t> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace wire::systems {
namespace {

using engine::ecs::Entity;

constexpr int kNodes = 64;

WireNodes hanging(const glm::dvec3& start, double phase) {
    WireNodes w;
    for (int i = 0; i < kNodes; ++i) {
        const double s = static_cast<double>(i) / (kNodes - 1);
        w.positions.push_back(start + glm::dvec3(10.0 * s, -1.6 * s * (1.0 - s), 0.05 * std::sin(phase + 7.0 * s)));
    }
    return w;
}

struct Field {
    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    WireContext ctx;
    std::vector<Entity> wires;
    explicit Field(int count, UploadPath path) {
        ctx.path = path;
        ctx.camera.position = {0.0f, 3.0f, 12.0f};
        ctx.camera.target = {0.0f, 2.0f, 0.0f};
        install(schedule, ctx);
        for (int i = 0; i < count; ++i) {
            // Two wires in three in front of the camera (some near, some far), one behind it.
            const double z = i % 3 == 2 ? 40.0 : -3.0 * static_cast<double>(i / 3 % 40);
            wires.push_back(spawn_wire(registry, hanging({-5.0 + 0.01 * (i % 7), 0.5 * (i % 9), z}, 0.1 * i),
                                       {.radius_m = 0.015f}));
        }
    }
    // Every node but the ends moves (in place: the game's physics writes into the component), the camera too.
    void frame(int f) {
        ctx.camera.position.x = 0.02f * static_cast<float>(std::min(f, 6));  // then still: see the test
        for (std::size_t i = 0; i < wires.size(); ++i) {
            WireNodes& n = edit_nodes(registry, wires[i]);
            for (std::size_t k = 1; k + 1 < n.positions.size(); ++k)
                n.positions[k].z += 0.002 * std::sin(0.1 * f + 0.1 * static_cast<double>(k + i));
        }
        schedule.run(registry, 1.0 / 60.0);
    }
};

// Allocations per frame after warm-up frames (buffers reach their sizes), averaged over the measured frames.
constexpr int kWarmUp = 30;  // frames before counting (every buffer reaches the size it needs)

double allocations_per_frame(int count, UploadPath path) {
    Field field(count, path);
    for (int f = 0; f < kWarmUp; ++f) field.frame(f);
    EXPECT_GT(field.ctx.stats.visible_wires, 0u);
    // The nodes path culls the default (automatic) spline on the GPU: the systems list every wire.
    if (path != UploadPath::gpu_nodes) {
        EXPECT_GT(field.ctx.stats.culled_wires, 0u);
    }
    const std::size_t before = g_allocations.load();
    constexpr int kFrames = 10;
    for (int f = kWarmUp; f < kWarmUp + kFrames; ++f) field.frame(f);
    return static_cast<double>(g_allocations.load() - before) / kFrames;
}

TEST(WireAllocations, MovingWiresAllocateNothingPerWirePerFrame) {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);  // per-thread buffers: one thread
    for (UploadPath path : {UploadPath::cpu_mesh, UploadPath::gpu_nodes}) {
        const double small = allocations_per_frame(30, path);
        const double large = allocations_per_frame(300, path);
        std::printf("%s: %.1f allocations per frame with 30 moving wires, %.1f with 300\n",
                    std::string(upload_path_name(path)).c_str(), small, large);
        // Ten times the wires (200 more in view, 90 more culled; on the nodes path all 270 more listed): not one
        // more allocation per wire and frame.
        EXPECT_LE(large - small, 5.0) << "allocations grow with the wire count";
    }
}

}  // namespace
}  // namespace wire::systems
