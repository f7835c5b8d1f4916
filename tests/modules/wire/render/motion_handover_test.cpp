// The nodes path carries each wire's first frame with the wire's motion, and the renderer keeps what that needs:
// per slot, the motion reference of the nodes it last sent. Each wire whose nodes changed is fitted on the GPU where
// matching by index is matching by id (packed, none merged, now and the last time, the ids at the reference's
// samples where they sat), else on the CPU by id (an id event, merged nodes, a blended curve); a frame without a
// change sends nothing; a wire turned while culled is fitted across the gap.
#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include "engine/ecs/registry.hpp"
#include "engine/ecs/schedule.hpp"
#include "engine/platform/context.hpp"
#include "gpu_wire_data.hpp"
#include "wire/motion.hpp"
#include "wire/render/install.hpp"
#include "wire/systems/api.hpp"
#include "wire/systems/systems.hpp"

namespace {

namespace platform = engine::platform;
using wire::WireNodes;

WireNodes cable(int n, const glm::dvec3& start, double length_m, double sag_m) {
    WireNodes w;
    for (int i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / (n - 1);
        w.positions.push_back(start + glm::dvec3(length_m * s, -4.0 * sag_m * s * (1.0 - s) + 0.05 * std::sin(6 * s),
                                                 0.1 * std::sin(3 * s)));
    }
    return w;
}

// Through the systems and the installed render step: the renderer's own counts of who fitted each sent wire.
TEST(NodesPathMotion, TheRendererFitsEachSentWiresMotionFromTheNodesItLastSent) {
    auto made = platform::create_headless_context(
        {.backend = platform::Backend::headless, .width = 320, .height = 180, .quiet = true});
    ASSERT_TRUE(made.ok()) << made.error().message;
    auto renderer = wire::render::WireRenderer::create();
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    wire::systems::WireContext context;
    context.viewport_width_px = 320;
    context.viewport_height_px = 180;
    context.camera.position = {0.0f, 0.0f, 5.0f};
    context.camera.target = {0.0f, 0.0f, 0.0f};
    context.path = wire::UploadPath::gpu_nodes;
    wire::systems::install(schedule, context);
    const std::shared_ptr<wire::render::RenderStep> step = wire::render::install(schedule, *renderer, context);
    const auto run = [&] { schedule.run(registry, 1.0 / 60.0); };

    WireNodes nodes = cable(12, {-2, 0, 0}, 4.0, 0.6);
    for (uint32_t i = 0; i < 12; ++i) nodes.ids.push_back(100 + 10 * i);
    const auto e = wire::systems::spawn_wire(registry, nodes, {.spline = {.kind = wire::SplineKind::catmull_rom}});
    run();
    EXPECT_TRUE(step->stats.status.ok()) << step->stats.status.message;
    EXPECT_EQ(step->stats.draw_items, 1u);
    EXPECT_EQ(step->stats.motion_fitted_gpu, 0u);  // the first nodes: nothing to carry from
    EXPECT_EQ(step->stats.motion_fitted_cpu, 0u);
    const glm::dvec3 pivot(-2.0, 0.0, 0.0);
    const glm::dquat q = glm::angleAxis(0.05, glm::normalize(glm::dvec3(1.0, 2.0, 0.5)));
    const auto turn = [&](const glm::dvec3& about) {
        for (glm::dvec3& p : wire::systems::edit_nodes(registry, e).positions) p = about + q * (p - about);
    };
    turn(pivot);
    run();
    EXPECT_EQ(step->stats.motion_fitted_gpu, 1u);  // the common case: on the GPU
    EXPECT_EQ(step->stats.motion_fitted_cpu, 0u);
    run();  // no change: nothing sent, nothing fitted
    EXPECT_EQ(step->stats.motion_fitted_gpu + step->stats.motion_fitted_cpu, 0u);
    // Taken far behind the camera, turned there, brought back: the GPU fits across the gap.
    const auto shift = [&](double dz) {
        for (glm::dvec3& p : wire::systems::edit_nodes(registry, e).positions) p.z += dz;
    };
    shift(5000.0);
    run();
    EXPECT_TRUE(context.draw_list.items.empty());  // culled
    EXPECT_EQ(step->stats.motion_fitted_gpu + step->stats.motion_fitted_cpu, 0u);
    turn(pivot + glm::dvec3(0.0, 0.0, 5000.0));
    run();
    shift(-5000.0);
    run();
    EXPECT_EQ(step->stats.motion_fitted_gpu, 1u);
    EXPECT_EQ(step->stats.motion_fitted_cpu, 0u);
    // A node inserted while the wire turns: the ids moved (and the wire blends), so the CPU fits, by id.
    const auto& p = registry.get<wire::systems::Nodes>(e).positions;
    wire::systems::insert_node(registry, e, 6, 0.5 * (p[5] + p[6]) + glm::dvec3(0, 0.02, 0));
    turn(pivot);
    run();
    EXPECT_EQ(step->stats.motion_fitted_gpu, 0u);
    EXPECT_EQ(step->stats.motion_fitted_cpu, 1u);
    EXPECT_TRUE(step->stats.status.ok()) << step->stats.status.message;
}

// The rule itself over a random family: sagging cables of 4-64 nodes (uniform, end-dense or jittered spacing, with
// or without ids, 0.5-40 m), each moved rigidly (any axis, up to 0.3 rad, any shift) a few times with events
// between: none the first time; on the GPU while index is id; on the CPU, by id, after an id event or with merged
// nodes, where the fit is the rigid motion's rotation (the vector part of q) wherever the nodes fix it fully.
TEST(NodesPathMotion, MotionSinceFitsOnTheGpuWhenIndexIsIdAndOnTheCpuOtherwise) {
    using wire::render::detail::motion_since;
    using wire::render::detail::SentMotion;
    std::mt19937 rng(20261206);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<double> errors;
    int cpu_fits = 0, gpu_fits = 0, full_confidence = 0;
    for (int c = 0; c < 200; ++c) {
        const int n = 4 + static_cast<int>(u(rng) * 61.0);
        const double span = 0.5 + 39.5 * u(rng), sag = (0.05 + 0.3 * u(rng)) * span;
        const bool ids = u(rng) < 0.5;
        const int spacing = static_cast<int>(u(rng) * 3.0);
        WireNodes w;
        for (int i = 0; i < n; ++i) {
            double s = static_cast<double>(i) / (n - 1);
            if (spacing == 1) s = 0.5 - 0.5 * std::cos(std::numbers::pi * s);
            if (spacing == 2 && i > 0 && i < n - 1) s += (u(rng) - 0.5) * 0.6 / (n - 1);
            w.positions.push_back(glm::dvec3(span * s, -4.0 * sag * s * (1.0 - s), 0.02 * span * std::sin(5 * s)));
            if (ids) w.ids.push_back(static_cast<uint32_t>(7 + 3 * i));
        }
        const auto rigid = [&](WireNodes& x, glm::dquat& q) {
            const glm::dvec3 axis = glm::normalize(glm::dvec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) +
                                                   glm::dvec3(1e-6));
            q = glm::angleAxis(0.3 * u(rng), axis);
            const glm::dvec3 shift(100.0 * (u(rng) - 0.5), 10.0 * (u(rng) - 0.5), 1e3 * (u(rng) - 0.5));
            for (glm::dvec3& p : x.positions) p = q * p + shift;
        };
        SentMotion sent;
        const wire::render::detail::WireMotion first = motion_since(sent, &w, true);
        EXPECT_FALSE(first.fit);
        EXPECT_EQ(first.rotation, glm::vec3(0.0f)) << "case " << c << ": nothing to carry from";
        glm::dquat q;
        // Moved, same nodes: on the GPU.
        rigid(w, q);
        const wire::render::detail::WireMotion same = motion_since(sent, &w, true);
        EXPECT_TRUE(same.fit) << "case " << c;
        EXPECT_EQ(same.rotation, glm::vec3(0.0f));
        gpu_fits += same.fit ? 1 : 0;
        // Moved with a node inserted (ids: a fresh id; no ids: matched by index no longer holds), or sent merged:
        // on the CPU, by id where there are ids.
        const bool insert = ids;
        const wire::MotionReference before = sent.reference;
        rigid(w, q);
        if (insert) {
            const std::size_t at = 1 + static_cast<std::size_t>(u(rng) * (n - 2));
            w.positions.insert(w.positions.begin() + static_cast<std::ptrdiff_t>(at),
                               0.5 * (w.positions[at - 1] + w.positions[at]));
            w.ids.insert(w.ids.begin() + static_cast<std::ptrdiff_t>(at), 1000u);
        }
        const wire::render::detail::WireMotion moved = motion_since(sent, &w, insert);
        EXPECT_FALSE(moved.fit) << "case " << c << (insert ? ": an id event" : ": merged nodes");
        ++cpu_fits;
        wire::MotionReference weighed = before;
        wire::weigh_reference(weighed);
        if (weighed.determinacy >= 1e-3f) {  // the nodes fix the rotation fully (confidence 1)
            ++full_confidence;
            const glm::dvec3 want = q.w >= 0.0 ? glm::dvec3(q.x, q.y, q.z) : -glm::dvec3(q.x, q.y, q.z);
            errors.push_back(glm::length(glm::dvec3(moved.rotation) - want));
            EXPECT_LT(errors.back(), 1e-6) << "case " << c << ": the CPU's fit is the rigid rotation";
        }
        // No nodes: the slot forgets; the next nodes start afresh.
        EXPECT_EQ(motion_since(sent, nullptr, true).rotation, glm::vec3(0.0f));
        const wire::render::detail::WireMotion fresh = motion_since(sent, &w, true);
        EXPECT_FALSE(fresh.fit);
        EXPECT_EQ(fresh.rotation, glm::vec3(0.0f));
    }
    std::sort(errors.begin(), errors.end());
    ASSERT_FALSE(errors.empty());
    EXPECT_GE(full_confidence, 150) << "the family should mostly fix its rotation";
    std::printf("motion_since: %d GPU fits, %d CPU fits, %d at full confidence: rotation error median %.2e p90 %.2e "
                "max %.2e\n",
                gpu_fits, cpu_fits, full_confidence, errors[errors.size() / 2], errors[errors.size() * 9 / 10],
                errors.back());
}

}  // namespace
