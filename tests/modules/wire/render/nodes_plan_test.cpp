// wire::render::plan_nodes_frame, the nodes path's byte model (what `wiretool bench --gl` checks the renderer
// against), against the bytes the renderer counts as it writes them, frame by frame: over a random family
// driven by the systems (every spline kind, per-node radius, stretch, Kochanek-Bartels arrays, closed loops;
// swaying, still, culled and back, nodes inserted and removed so pop-free blends send CPU-built curves, wires
// destroyed and spawned) and over hand-built lists whose items carry unpacked nodes (the plan packs them as
// the renderer does).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "engine/ecs/registry.hpp"
#include "engine/ecs/schedule.hpp"
#include "engine/platform/context.hpp"
#include "wire/render/upload_plan.hpp"
#include "wire/render/wire_renderer.hpp"
#include "wire/systems/api.hpp"
#include "wire/systems/systems.hpp"

namespace {

namespace platform = engine::platform;

struct PlanWire {
    wire::WireNodes rest;
    wire::SplineSettings spline;
    bool closed = false;
};

// 3-40 nodes over 0.5-4 m, any orientation; every spline kind; some with per-node radius, stretch or
// Kochanek-Bartels arrays; a quarter closed loops.
PlanWire plan_wire(std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    PlanWire w;
    const int n = 3 + static_cast<int>(u(rng) * 38.0);
    w.closed = n >= 4 && u(rng) < 0.25;
    const double size = 0.5 + 3.5 * u(rng);
    const glm::dvec3 centre((u(rng) - 0.5) * 4.0, (u(rng) - 0.5) * 2.0, (u(rng) - 0.5) * 3.0);
    for (int i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / n;
        const double a = 2.0 * std::numbers::pi * s;
        w.rest.positions.push_back(
            w.closed ? centre + 0.5 * size * glm::dvec3(std::cos(a), 0.3 * std::sin(3 * a), std::sin(a))
                     : centre + glm::dvec3(size * (s - 0.5), -0.3 * size * s * (1 - s) + 0.05 * u(rng),
                                           0.1 * u(rng)));
    }
    const wire::SplineKind kinds[] = {wire::SplineKind::automatic, wire::SplineKind::catmull_rom,
                                      wire::SplineKind::c2, wire::SplineKind::linear};
    w.spline.kind = kinds[static_cast<int>(u(rng) * 4.0) % 4];
    if (u(rng) < 0.3) w.rest.radius_m.assign(n, static_cast<float>(0.01 + 0.02 * u(rng)));
    if (u(rng) < 0.3) w.rest.stretch.assign(n, static_cast<float>(0.9 + 0.3 * u(rng)));
    if (w.spline.kind == wire::SplineKind::catmull_rom && u(rng) < 0.5) {
        w.rest.kb_tension.assign(n, static_cast<float>(u(rng) - 0.5));
        w.rest.kb_bias.assign(n, 0.0f);
        w.rest.kb_continuity.assign(n, 0.0f);
    }
    return w;
}

wire::WireNodes swayed(const wire::WireNodes& rest, uint32_t frame, double amplitude) {
    wire::WireNodes n = rest;
    for (std::size_t i = 0; i < n.positions.size(); ++i)
        n.positions[i].y += amplitude * std::sin(0.3 * frame + 0.5 * i);
    return n;
}

TEST(NodesPlan, TheModelCountsTheBytesTheNodesPathWrites) {
    auto made = platform::create_headless_context(
        {.backend = platform::Backend::headless, .width = 320, .height = 180, .quiet = true});
    ASSERT_TRUE(made.ok()) << made.error().message;
    auto renderer = wire::render::WireRenderer::create({.retain_frames = 20});
    ASSERT_TRUE(renderer.ok()) << renderer.error().message;
    if (renderer->preferred_path() != wire::UploadPath::gpu_nodes)
        GTEST_FAIL() << renderer->preferred_path_reason();

    // (1) Driven by the systems.
    std::mt19937 rng(4242);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    wire::systems::WireContext context;
    context.viewport_width_px = 320;
    context.viewport_height_px = 180;
    context.path = wire::UploadPath::gpu_nodes;
    wire::systems::install(schedule, context);
    std::vector<PlanWire> family;
    std::vector<engine::ecs::Entity> wires;
    for (int i = 0; i < 24; ++i) {
        family.push_back(plan_wire(rng));
        wires.push_back(wire::systems::spawn_wire(
            registry, family.back().rest, {.spline = family.back().spline, .closed = family.back().closed}));
    }
    wire::render::NodesPlan plan{.retain_frames = 20};
    std::size_t frames = 0, mismatches = 0, bytes_total = 0, quiet_frames = 0;
    for (uint32_t f = 1; f <= 120; ++f) {
        for (std::size_t i = 0; i < wires.size(); ++i) {
            if (i % 3 == 0)
                wire::systems::set_nodes(registry, wires[i], swayed(family[i].rest, f, 0.05));  // swaying
        }
        if (f % 17 == 0) {  // a node inserted, another removed: blends (CPU-built curves on the nodes path)
            const std::size_t i = static_cast<std::size_t>(u(rng) * wires.size()) % wires.size();
            if (registry.valid(wires[i]) && family[i].rest.size() > 4) {
                wire::systems::insert_node(registry, wires[i], 2,
                                           family[i].rest.positions[2] + glm::dvec3(0, 0.01, 0));
                wire::systems::remove_node(registry, wires[i], 1);
            }
        }
        if (f % 29 == 0) {  // a wire destroyed, a new one spawned
            const std::size_t i = static_cast<std::size_t>(u(rng) * wires.size()) % wires.size();
            registry.destroy(wires[i]);
            family[i] = plan_wire(rng);
            wires[i] = wire::systems::spawn_wire(registry, family[i].rest,
                                                 {.spline = family[i].spline, .closed = family[i].closed});
        }
        // The camera looks away for frames 40-69 (every wire culled; evicted after 20), then back.
        const bool away = f >= 40 && f < 70;
        context.camera.position = {0.3 * std::sin(0.05 * f), 0.0, 5.0};
        context.camera.target = away ? glm::dvec3(0.0, 0.0, 10.0) : glm::dvec3(0.0);
        schedule.run(registry, 1.0 / 60.0);
        const std::size_t planned = wire::render::plan_nodes_frame(context.draw_list, plan);
        const wire::render::DrawStats st = renderer->draw(context.draw_list, context.camera);
        EXPECT_TRUE(st.status.ok()) << st.status.message;
        ++frames;
        bytes_total += st.bytes_uploaded;
        quiet_frames += st.bytes_uploaded == 0 ? 1 : 0;
        if (st.bytes_uploaded != planned) {
            ++mismatches;
            ADD_FAILURE() << "frame " << f << ": the renderer wrote " << st.bytes_uploaded
                          << " bytes, the plan says " << planned;
        }
    }
    // (2) Hand-built lists of unpacked nodes (the plan packs them with wire::pack_nodes, as the renderer
    // does).
    std::vector<PlanWire> hand;
    for (int i = 0; i < 16; ++i) hand.push_back(plan_wire(rng));
    std::vector<wire::WireNodes> nodes(hand.size());
    for (uint32_t f = 1; f <= 10; ++f) {
        wire::DrawList list{.path = wire::UploadPath::gpu_nodes, .items = {}};
        for (std::size_t i = 0; i < hand.size(); ++i) {
            if (f == 1 || i % 2 == 0) nodes[i] = swayed(hand[i].rest, f, 0.02);
            wire::DrawItem item;
            item.wire_id = 1000 + i;
            item.nodes = &nodes[i];
            item.spline = hand[i].spline;
            item.spline.closed = hand[i].closed;
            item.nodes_generation = (f == 1 || i % 2 == 0) ? f : 1;
            item.sides = 8;
            list.items.push_back(item);
        }
        list.lod = {};
        const std::size_t planned = wire::render::plan_nodes_frame(list, plan);
        const wire::render::DrawStats st = renderer->draw(list, context.camera, {.view = 1});
        EXPECT_TRUE(st.status.ok()) << st.status.message;
        ++frames;
        EXPECT_EQ(st.bytes_uploaded, planned) << "hand-built frame " << f;
        mismatches += st.bytes_uploaded != planned ? 1 : 0;
    }
    std::printf(
        "nodes plan: %zu frames, %zu mismatches, %zu bytes written in all, %zu frames that sent nothing\n",
        frames, mismatches, bytes_total, quiet_frames);
    EXPECT_GT(bytes_total, 0u);
}

}  // namespace
