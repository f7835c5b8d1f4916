// The wire systems on a registry: spawn/update/destroy, only the work a scene needs (counters and generations),
// bad wires reported once while the rest renders, deterministic DrawList for 1 and 2 threads, both upload paths,
// pop-free node insertion and the carried-over first frame.
#include "wire/systems/api.hpp"
#include "wire/systems/systems.hpp"

#include "draw_bytes.hpp"

#include "wire/pop_free.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>

#include <glm/gtc/quaternion.hpp>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace wire::systems {
namespace {

using engine::ecs::Entity;
using engine::ecs::Registry;
using engine::ecs::Schedule;

WireNodes cable(int n, const glm::dvec3& start, double length_m, double sag_m, double phase = 0.0) {
    WireNodes w;
    for (int i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / (n - 1);
        w.positions.push_back(start + glm::dvec3(length_m * s, -4.0 * sag_m * s * (1.0 - s) + 0.05 * std::sin(phase + 6 * s),
                                                 0.1 * std::sin(phase + 3 * s)));
    }
    return w;
}

struct World {
    Registry registry;
    Schedule schedule;
    WireContext ctx;
    World() {
        ctx.camera.position = {0.0f, 0.0f, 5.0f};
        ctx.camera.target = {0.0f, 0.0f, 0.0f};
        install(schedule, ctx);
    }
    void run() { schedule.run(registry, 1.0 / 60.0); }
};

TEST(WireSystems, InstallsFiveSystemsInOrder) {
    World w;
    ASSERT_EQ(w.schedule.size(), 5u);
    const char* names[] = {kCurveSystem, kLodSystem, kRingsSystem, kMeshSystem, kDrawListSystem};
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(w.schedule.stats()[i].name, names[i]);
}

TEST(WireSystems, SpawnUpdateDestroy) {
    World w;
    const Entity a = spawn_wire(w.registry, cable(12, {-2, 0, 0}, 4.0, 0.5), {.radius_m = 0.02f, .material = 3});
    w.run();
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    const DrawItem& item = w.ctx.draw_list.items[0];
    EXPECT_EQ(item.wire_id, engine::ecs::to_integral(a));
    EXPECT_EQ(item.material, 3u);
    EXPECT_FALSE(item.vertices.empty());
    EXPECT_FALSE(item.indices.empty());
    EXPECT_FALSE(item.rings.empty());
    EXPECT_GE(item.sides, 3u);
    EXPECT_EQ(w.ctx.stats.curves_built, 1u);

    set_nodes(w.registry, a, cable(12, {-2, 0, 0}, 4.0, 0.8));
    w.run();
    EXPECT_EQ(w.ctx.stats.curves_built, 1u);
    EXPECT_EQ(w.ctx.stats.rings_built, 1u);

    edit_nodes(w.registry, a).positions[5].z += 0.1;
    w.run();
    EXPECT_EQ(w.ctx.stats.curves_built, 1u);

    w.registry.destroy(a);
    w.run();
    EXPECT_TRUE(w.ctx.draw_list.items.empty());
    EXPECT_EQ(w.ctx.stats.wires, 0u);
}

TEST(WireSystems, UnchangedWireAndCameraAreNotRegenerated) {
    World w;
    std::vector<Entity> wires;
    for (int i = 0; i < 8; ++i) wires.push_back(spawn_wire(w.registry, cable(16, {-2, 0.3 * i - 1, -i}, 4.0, 0.4, i)));
    w.run();
    EXPECT_EQ(w.ctx.stats.curves_built, 8u);
    EXPECT_EQ(w.ctx.stats.lod_updates, 8u);
    std::vector<uint64_t> ring_gen, mesh_gen;
    for (Entity e : wires) {
        ring_gen.push_back(w.registry.get<WireRings>(e).generation);
        mesh_gen.push_back(w.registry.get<WireMesh>(e).generation);
    }
    for (int frame = 0; frame < 3; ++frame) {
        w.run();
        EXPECT_EQ(w.ctx.stats.curves_built, 0u);
        EXPECT_EQ(w.ctx.stats.lod_updates, 0u);
        EXPECT_EQ(w.ctx.stats.rings_built, 0u);
        EXPECT_EQ(w.ctx.stats.meshes_built, 0u);
        EXPECT_EQ(w.ctx.draw_list.items.size(), 8u);
    }
    for (std::size_t i = 0; i < wires.size(); ++i) {
        EXPECT_EQ(w.registry.get<WireRings>(wires[i]).generation, ring_gen[i]);
        EXPECT_EQ(w.registry.get<WireMesh>(wires[i]).generation, mesh_gen[i]);
        EXPECT_EQ(w.registry.get<WireCurve>(wires[i]).builds, 1u);
    }
    // One wire moves: only it is rebuilt.
    edit_nodes(w.registry, wires[3]).positions[4].y += 0.05;
    w.run();
    EXPECT_EQ(w.ctx.stats.curves_built, 1u);
    EXPECT_EQ(w.ctx.stats.lod_updates, 1u);
    EXPECT_EQ(w.ctx.stats.rings_built, 1u);
    EXPECT_EQ(w.ctx.stats.meshes_built, 1u);
    // The camera moves: every wire's LOD is re-evaluated (rings only where counts changed).
    w.ctx.camera.position.x += 0.01f;
    w.run();
    EXPECT_EQ(w.ctx.stats.curves_built, 0u);
    EXPECT_EQ(w.ctx.stats.lod_updates, 8u);
}

TEST(WireSystems, OffscreenWireCostsOnlyTheHullTest) {
    World w;
    const Entity on = spawn_wire(w.registry, cable(16, {-2, 0, 0}, 4.0, 0.5));
    const Entity off = spawn_wire(w.registry, cable(16, {-2, 0, 20}, 4.0, 0.5));  // behind the camera
    for (int frame = 0; frame < 4; ++frame) {
        w.ctx.camera.position.x = 0.01f * frame;  // a moving camera: every frame re-runs the LOD
        if (frame == 2) edit_nodes(w.registry, off).positions[3].y += 0.1;  // it moves, still off screen
        w.run();
        ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
        EXPECT_EQ(w.ctx.draw_list.items[0].wire_id, engine::ecs::to_integral(on));
    }
    const WireLodState& lod = w.registry.get<WireLodState>(off);
    EXPECT_FALSE(lod.lod.visible);
    EXPECT_EQ(lod.updates, 4u);  // the hull test ran each frame ...
    EXPECT_TRUE(lod.lod.counts.empty());
    EXPECT_EQ(w.registry.get<WireRings>(off).generation, 0u);  // ... and nothing else
    EXPECT_TRUE(w.registry.get<WireRings>(off).params.empty());
    EXPECT_EQ(w.registry.get<WireMesh>(off).generation, 0u);
    EXPECT_TRUE(w.registry.get<WireMesh>(off).mesh.vertices.empty());
    EXPECT_EQ(w.ctx.stats.culled_wires, 1u);
    EXPECT_EQ(w.ctx.stats.visible_wires, 1u);

    // Turning around brings it into view: now it gets rings and a mesh.
    w.ctx.camera.target = {0.0f, 0.0f, 20.0f};
    w.run();
    EXPECT_EQ(w.ctx.draw_list.items.size(), 1u);
    EXPECT_EQ(w.ctx.draw_list.items[0].wire_id, engine::ecs::to_integral(off));
    EXPECT_GT(w.registry.get<WireRings>(off).generation, 0u);
}

TEST(WireSystems, BadWireIsReportedOnceAndTheRestRenders) {
    World w;
    std::vector<ErrorReport> reported;
    w.ctx.on_error = [&](const ErrorReport& r) { reported.push_back(r); };
    const Entity good = spawn_wire(w.registry, cable(10, {-2, 0, 0}, 4.0, 0.5));
    WireNodes nan_nodes = cable(10, {-2, 1, 0}, 4.0, 0.5);
    nan_nodes.positions[3].y = std::numeric_limits<double>::quiet_NaN();
    const Entity bad = spawn_wire(w.registry, nan_nodes);
    WireNodes one;
    one.positions.push_back({0, 0, 0});
    const Entity single = spawn_wire(w.registry, one);
    const Entity empty = spawn_wire(w.registry, WireNodes{});
    for (int frame = 0; frame < 5; ++frame) {
        w.ctx.camera.position.y = 0.01f * frame;
        w.run();
        ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
        EXPECT_EQ(w.ctx.draw_list.items[0].wire_id, engine::ecs::to_integral(good));
        EXPECT_EQ(w.ctx.stats.errors, 3u);
    }
    ASSERT_EQ(reported.size(), 3u);  // once, not every frame
    EXPECT_EQ(reported[0].entity, bad);
    EXPECT_NE(reported[0].message.find(describe_entity(bad)), std::string::npos) << reported[0].message;
    EXPECT_NE(reported[0].message.find("node 3: position.y is NaN"), std::string::npos) << reported[0].message;
    EXPECT_EQ(reported[1].entity, single);
    EXPECT_NE(reported[1].message.find("at least 2"), std::string::npos) << reported[1].message;
    EXPECT_EQ(reported[2].entity, empty);
    ASSERT_NE(wire_error(w.registry, bad), nullptr);
    EXPECT_EQ(wire_error(w.registry, bad)->node, 3);
    EXPECT_EQ(wire_error(w.registry, good), nullptr);

    // The game touches the bad wire again with the same fault: still not reported again.
    edit_nodes(w.registry, bad).positions[5].x += 0.1;
    w.run();
    EXPECT_EQ(reported.size(), 3u);
    EXPECT_TRUE(w.ctx.new_errors.empty());
    // A different fault is a new report.
    edit_nodes(w.registry, bad).positions[7].z = std::numeric_limits<double>::infinity();
    edit_nodes(w.registry, bad).positions[3].y = 0.0;
    w.run();
    ASSERT_EQ(reported.size(), 4u);
    EXPECT_NE(reported[3].message.find("node 7: position.z"), std::string::npos) << reported[3].message;
    // Fixed: the error goes away and the wire is drawn.
    set_nodes(w.registry, bad, cable(10, {-2, 1, 0}, 4.0, 0.5));
    w.run();
    EXPECT_EQ(wire_error(w.registry, bad), nullptr);
    EXPECT_EQ(w.ctx.draw_list.items.size(), 2u);
    EXPECT_EQ(w.ctx.stats.errors, 2u);
}

TEST(WireSystems, BadUpdateKeepsDrawingTheLastValidCurve) {
    World w;
    const Entity e = spawn_wire(w.registry, cable(10, {-2, 0, 0}, 4.0, 0.5));
    w.run();
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    edit_nodes(w.registry, e).positions[2].x = std::numeric_limits<double>::quiet_NaN();
    w.run();
    EXPECT_NE(wire_error(w.registry, e), nullptr);
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    for (const TubeVertex& v : w.ctx.draw_list.items[0].vertices) {
        ASSERT_TRUE(std::isfinite(v.position.x) && std::isfinite(v.position.y) && std::isfinite(v.position.z));
    }
}

// Flattens a DrawList into bytes (spans by content, not by address).
std::vector<unsigned char> bytes_of(const DrawList& list) {
    std::vector<unsigned char> out;
    out.insert(out.end(), reinterpret_cast<const unsigned char*>(&list.path),
               reinterpret_cast<const unsigned char*>(&list.path) + sizeof(list.path));
    for (const DrawItem& it : list.items) test::append_item_bytes(it, true, out);
    return out;
}

std::vector<std::vector<unsigned char>> run_scene(int threads, UploadPath path, bool fused = true,
                                                  std::vector<RunStats>* stats = nullptr, bool turn_away = false) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    World w;
    w.ctx.path = path;
    w.ctx.fused_stages = fused;
    std::vector<Entity> wires;
    for (int i = 0; i < 150; ++i) {
        wires.push_back(spawn_wire(w.registry, cable(24, {-3.0 + 0.02 * i, 0.05 * (i % 40) - 1, -0.3 * i}, 6.0, 0.6, i),
                                   {.radius_m = 0.01f + 0.0001f * i, .material = static_cast<uint32_t>(i % 3),
                                    .closed = (i % 17 == 0)}));
    }
    std::vector<std::vector<unsigned char>> frames;
    for (int frame = 0; frame < 12; ++frame) {
        w.ctx.camera.position = {0.3f * std::sin(0.2f * frame), 0.1f * frame, 5.0f - 0.5f * frame};
        for (std::size_t i = frame % 3; i < wires.size(); i += 3) {
            if (w.registry.valid(wires[i])) edit_nodes(w.registry, wires[i]).positions[5].y += 0.01;
        }
        if (frame == 4) insert_node(w.registry, wires[10], 6, glm::dvec3(0.0, 0.0, -3.0));
        if (frame == 6) w.registry.destroy(wires[20]);
        if (frame == 7) spawn_wire(w.registry, cable(8, {0, 0, -2}, 1.0, 0.2));  // reuses slot 20
        // Turned away: moving wires culled (their curves released), and back: restored.
        if (turn_away && frame == 9) w.ctx.camera.target = {0.0f, 0.0f, 20.0f};
        if (turn_away && frame == 10) w.ctx.camera.target = {0.0f, 0.0f, 0.0f};
        w.run();
        frames.push_back(bytes_of(w.ctx.draw_list));
        if (stats) stats->push_back(w.ctx.stats);
    }
    return frames;
}

TEST(WireSystems, DrawListIsByteEqualForOneAndTwoThreads) {
    for (UploadPath path : {UploadPath::cpu_mesh, UploadPath::gpu_nodes}) {
        const auto one = run_scene(1, path);
        const auto two = run_scene(2, path);
        ASSERT_EQ(one.size(), two.size());
        for (std::size_t f = 0; f < one.size(); ++f) {
            EXPECT_GT(one[f].size(), 1000u);
            EXPECT_TRUE(one[f] == two[f]) << "frame " << f << " path " << static_cast<int>(path);
        }
    }
}

// A wire whose curve changed goes on through lod, rings and mesh right after its curve (WireContext::fused_stages):
// the same draw lists, bit for bit, as stage by stage, on both thread counts, with moving, inserted, destroyed,
// culled and restored wires; the same work counted (each wire's lod, rings and mesh once). cpu-mesh only: the
// nodes path has no CPU lod, rings or mesh to fuse.
TEST(WireSystems, FusedStagesGiveTheSameDrawListsAsStageByStage) {
    for (UploadPath path : {UploadPath::cpu_mesh}) {
        for (int threads : {1, 2}) {
            std::vector<RunStats> fused_stats, staged_stats;
            const auto fused = run_scene(threads, path, true, &fused_stats, true);
            const auto staged = run_scene(threads, path, false, &staged_stats, true);
            ASSERT_EQ(fused.size(), staged.size());
            for (std::size_t f = 0; f < fused.size(); ++f) {
                EXPECT_TRUE(fused[f] == staged[f]) << "frame " << f << " path " << static_cast<int>(path);
                const RunStats &a = fused_stats[f], &b = staged_stats[f];
                EXPECT_EQ(a.lod_updates, b.lod_updates) << "frame " << f;
                EXPECT_EQ(a.rings_built, b.rings_built) << "frame " << f;
                EXPECT_EQ(a.meshes_built, b.meshes_built) << "frame " << f;
                EXPECT_EQ(a.curves_released, b.curves_released) << "frame " << f;
                EXPECT_EQ(a.curves_restored, b.curves_restored) << "frame " << f;
                EXPECT_EQ(a.visible_wires, b.visible_wires) << "frame " << f;
            }
            EXPECT_EQ(fused[9].size(), sizeof(UploadPath)) << "turned away: nothing drawn";
            EXPECT_GT(fused_stats[9].curves_released + fused_stats[10].curves_restored, 0u);
        }
    }
}

TEST(WireSystems, DrawListIsInEntityOrder) {
    World w;
    std::vector<Entity> wires;
    for (int i = 0; i < 6; ++i) wires.push_back(spawn_wire(w.registry, cable(8, {-2, 0.3 * i - 1, 0}, 4.0, 0.3)));
    w.registry.destroy(wires[1]);
    w.registry.destroy(wires[4]);
    spawn_wire(w.registry, cable(8, {-2, 1.5, 0}, 4.0, 0.3));  // reuses slot 4 (last freed)
    w.run();
    ASSERT_EQ(w.ctx.draw_list.items.size(), 5u);
    for (std::size_t i = 1; i < w.ctx.draw_list.items.size(); ++i) {
        EXPECT_LT(engine::ecs::to_index(Entity{static_cast<uint32_t>(w.ctx.draw_list.items[i - 1].wire_id)}),
                  engine::ecs::to_index(Entity{static_cast<uint32_t>(w.ctx.draw_list.items[i].wire_id)}));
    }
}

// The nodes path builds no curve, rings or meshes on the CPU (it sends packed nodes); switching to cpu-mesh builds
// the meshes on demand, and switching back sends packed nodes again.
TEST(WireSystems, NodesPathBuildsNoMeshesAndSwitchingPathsRebuilds) {
    World w;
    w.ctx.path = UploadPath::gpu_nodes;
    const Entity e = spawn_wire(w.registry, cable(16, {-2, 0, 0}, 4.0, 0.5), {.closed = true});
    w.run();
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    {
        const DrawItem& item = w.ctx.draw_list.items[0];
        EXPECT_EQ(w.ctx.draw_list.path, UploadPath::gpu_nodes);
        EXPECT_TRUE(item.vertices.empty());
        EXPECT_TRUE(item.rings.empty());
        ASSERT_NE(item.packed_nodes, nullptr);
        EXPECT_EQ(item.packed_nodes->node_count, 16u);
        EXPECT_TRUE(item.spline.closed);
        EXPECT_EQ(w.ctx.stats.meshes_built, 0u);
        EXPECT_EQ(w.ctx.stats.rings_built, 0u);
        EXPECT_EQ(w.registry.get<WireMesh>(e).generation, 0u);
    }
    w.ctx.path = UploadPath::cpu_mesh;
    w.run();
    EXPECT_EQ(w.ctx.stats.meshes_built, 1u);
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    {
        const DrawItem& item = w.ctx.draw_list.items[0];
        EXPECT_FALSE(item.vertices.empty());
        EXPECT_FALSE(item.rings.empty());
        EXPECT_TRUE(item.closed);
        EXPECT_FALSE(item.caps);
        EXPECT_GT(item.u_close, 0.0f);
        EXPECT_EQ(item.packed_nodes, nullptr);
    }
    w.ctx.path = UploadPath::gpu_nodes;
    w.run();
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    EXPECT_NE(w.ctx.draw_list.items[0].packed_nodes, nullptr);
    EXPECT_TRUE(w.ctx.draw_list.items[0].vertices.empty());
}

// A wire whose nodes go bad on the nodes path (which keeps no curve on the CPU) and a switch to cpu-mesh: the wire
// draws its last valid curve there, rebuilt from its last valid nodes, and the rings and mesh stages never see an
// empty curve (fuzz_wire_systems found build_rings reading past one: regression_nodes_path_back_to_cpu_bad_nodes).
TEST(WireSystems, BadNodesOnTheNodesPathThenCpuMeshDrawTheLastValidCurve) {
    World w;
    w.ctx.path = UploadPath::gpu_nodes;
    const WireNodes good = cable(12, {-2, 0, 0}, 4.0, 0.5);
    const Entity e = spawn_wire(w.registry, good);
    w.run();
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    EXPECT_TRUE(w.registry.get<WireCurve>(e).curve.segments.empty()) << "the nodes path keeps no curve";
    WireNodes bad = good;
    bad.positions[5].y = std::nan("");
    set_nodes(w.registry, e, bad);
    w.run();
    ASSERT_NE(wire_error(w.registry, e), nullptr);
    w.ctx.path = UploadPath::cpu_mesh;
    for (int frame = 0; frame < 2; ++frame) {
        w.run();
        ASSERT_EQ(w.ctx.draw_list.items.size(), 1u) << "frame " << frame;
        const DrawItem& item = w.ctx.draw_list.items[0];
        EXPECT_FALSE(item.vertices.empty());
        const wire::Curve& curve = w.registry.get<WireCurve>(e).curve;
        ASSERT_EQ(curve.segments.size(), good.size() - 1);
        // Through the last valid nodes (node 5 is NaN in the current ones).
        EXPECT_EQ(curve.segments[5].b0, good.positions[5]);
        EXPECT_EQ(curve.segments.back().b3, good.positions.back());
    }
}

// The other way: a wire moved on cpu-mesh after the nodes path packed it, then its nodes go bad, then the nodes path
// again: it draws its last valid nodes, packed on the systems' threads (not older packed ones, not unpacked).
TEST(WireSystems, BadNodesOnCpuMeshThenTheNodesPathDrawTheLastValidNodesPacked) {
    World w;
    w.ctx.path = UploadPath::gpu_nodes;
    const Entity e = spawn_wire(w.registry, cable(12, {-2, 0, 0}, 4.0, 0.5));
    w.run();
    w.ctx.path = UploadPath::cpu_mesh;
    const WireNodes moved = cable(12, {-2, 0.3, 0}, 4.0, 0.5);
    set_nodes(w.registry, e, moved);
    w.run();
    WireNodes bad = moved;
    bad.positions[5].y = std::nan("");
    set_nodes(w.registry, e, bad);
    w.run();
    ASSERT_NE(wire_error(w.registry, e), nullptr);
    w.ctx.path = UploadPath::gpu_nodes;
    w.run();
    ASSERT_EQ(w.ctx.draw_list.items.size(), 1u);
    const DrawItem& item = w.ctx.draw_list.items[0];
    ASSERT_EQ(item.curve, nullptr);
    ASSERT_NE(item.packed_nodes, nullptr);
    ASSERT_EQ(item.packed_nodes->node_count, moved.size());
    for (std::size_t j = 0; j < moved.size(); ++j) {
        const glm::dvec3 p = item.packed_nodes->origin_m + glm::dvec3(glm::vec3(item.packed_nodes->node(j)));
        EXPECT_LT(glm::length(p - moved.positions[j]), 1e-4) << "node " << j;
    }
}

TEST(WireSystems, TessellationMeetsTheScreenTolerance) {
    World w;
    for (int i = 0; i < 20; ++i) spawn_wire(w.registry, cable(32, {-3, 0.2 * i - 2, -0.5 * i}, 6.0, 0.8, i));
    for (double tol : {0.5, 0.1, 2.0}) {
        w.ctx.lod.tolerance_px = tol;
        w.ctx.lod.max_rings_per_segment = 4096;
        w.run();
        const ScreenError e = scene_screen_error(w.registry, w.ctx, 128);
        EXPECT_GT(e.samples, 1000u);
        EXPECT_LE(e.max_px, tol * (1 + 1e-9));
        if (tol < 1.0) {
            EXPECT_GT(e.max_px, tol * 0.2);  // (at 2 px these gentle wires need 1 ring a segment)
        }
    }
}

TEST(WireSystems, InsertedNodeIsBlendedInWithoutAPop) {
    World w;
    const Entity e = spawn_wire(w.registry, cable(12, {-2, 0, 0}, 4.0, 0.6));
    w.run();
    Curve before = w.registry.get<WireCurve>(e).curve;
    // The simulation refines: a node in the middle of segment 5 (near the curve, not on it).
    const auto& p = w.registry.get<Nodes>(e).positions;
    insert_node(w.registry, e, 6, 0.5 * (p[5] + p[6]) + glm::dvec3(0, 0.02, 0));
    double worst_jump = 0.0;
    int blend_frames = 0;
    for (int frame = 0; frame < 300; ++frame) {
        w.run();
        const Curve& now = w.registry.get<WireCurve>(e).curve;
        worst_jump = std::max(worst_jump, rendered_jump_m(before, now));
        before = now;
        if (w.ctx.stats.curves_built == 0) break;
        ++blend_frames;
    }
    EXPECT_GT(blend_frames, 1);  // blended over several frames ...
    EXPECT_LT(blend_frames, 300);  // ... and then the wire rests (no work)
    EXPECT_LE(worst_jump, 1e-3);

    // With the pop-free blend off the same change pops at once.
    World raw;
    raw.ctx.pop_free = false;
    const Entity r = spawn_wire(raw.registry, cable(12, {-2, 0, 0}, 4.0, 0.6));
    raw.run();
    const Curve raw_before = raw.registry.get<WireCurve>(r).curve;
    const auto& q = raw.registry.get<Nodes>(r).positions;
    insert_node(raw.registry, r, 6, 0.5 * (q[5] + q[6]) + glm::dvec3(0, 0.02, 0));
    raw.run();
    EXPECT_GT(rendered_jump_m(raw_before, raw.registry.get<WireCurve>(r).curve), 2.0 * worst_jump);
}

// A state with a node id used twice is an error naming the wire entity, the node and the id, with or without the
// pop-free blend; the wire keeps drawing its last valid curve.
TEST(WireSystems, DuplicateNodeIdIsAnErrorNamingWireAndId) {
    for (bool pop_free : {true, false}) {
        World w;
        w.ctx.pop_free = pop_free;
        std::vector<ErrorReport> reported;
        w.ctx.on_error = [&](const ErrorReport& r) { reported.push_back(r); };
        WireNodes nodes = cable(8, {-2, 0, 0}, 4.0, 0.5);
        nodes.ids = {10, 11, 12, 13, 14, 15, 16, 17};
        const Entity e = spawn_wire(w.registry, nodes);
        w.run();
        const Curve good = w.registry.get<WireCurve>(e).curve;
        WireNodes dup = w.registry.get<Nodes>(e);
        dup.ids[5] = dup.ids[2];
        set_nodes(w.registry, e, dup);
        w.run();
        ASSERT_EQ(reported.size(), 1u) << pop_free;
        EXPECT_EQ(reported[0].message, describe_entity(e) + ": node 5: id " + std::to_string(dup.ids[2]) +
                                           " is used twice (also node 2)");
        EXPECT_EQ(wire_error(w.registry, e)->node, 5);
        EXPECT_EQ(w.registry.get<WireCurve>(e).curve.segments.size(), good.segments.size());
    }
}

// Style::blend_s sets the blend length per wire: a small change on a wire with 1 s blends for 60 frames,
// the same change on a default wire for 15 (0.25 s at the 60 Hz frame).
TEST(WireSystems, BlendTimeIsSetPerWire) {
    World w;
    // Catmull-Rom: a node inserted 2 mm off the sag is a small change for it. The automatic spline (the default)
    // reads that node as a concentrated turn and re-parameterises the neighbouring spans, which the pop-free blend then
    // spreads over a longer blend to keep every frame under its 1 mm step (that case is in the pop-free blend families).
    const SplineSettings cr{.kind = SplineKind::catmull_rom};
    const Entity quick = spawn_wire(w.registry, cable(12, {-2, 0, 0}, 4.0, 0.6), {.spline = cr});
    const Entity slow = spawn_wire(w.registry, cable(12, {-2, 0, 0}, 4.0, 0.6), {.spline = cr, .blend_s = 1.0f});
    w.run();
    for (const Entity e : {quick, slow}) {
        const auto& p = w.registry.get<Nodes>(e).positions;
        insert_node(w.registry, e, 6, 0.5 * (p[5] + p[6]) + glm::dvec3(0, 0.002, 0));
    }
    int frames[2] = {0, 0};
    for (int frame = 0; frame < 200; ++frame) {
        w.run();
        if (w.registry.get<WireCurve>(quick).blending) ++frames[0];
        if (w.registry.get<WireCurve>(slow).blending) ++frames[1];
    }
    EXPECT_EQ(frames[0], 15);
    EXPECT_EQ(frames[1], 60);
}

// Regression (churn_soak under ASan): wires destroyed while blending stay on the blend list for one frame; new
// wires that reuse their slots (same index, newer version) were sorted by index only among them, so the same new
// wire could come out twice around its stale handle, be built by two threads at once (use after free in
// place_rings) and be counted twice. Every valid wire is worked on exactly once.
TEST(WireSystems, WiresReusingTheSlotsOfBlendingWiresAreBuiltOnce) {
    World w;
    constexpr int kWires = 300;
    std::vector<Entity> old;
    for (int i = 0; i < kWires; ++i) old.push_back(spawn_wire(w.registry, cable(8, {-2, 0.003 * i, 0}, 4.0, 0.5)));
    w.run();
    for (const Entity e : old) {
        const auto& p = w.registry.get<Nodes>(e).positions;
        insert_node(w.registry, e, 4, 0.5 * (p[3] + p[4]) + glm::dvec3(0, 0.02, 0));
    }
    w.run();
    std::size_t blending = 0;
    for (const Entity e : old) blending += w.registry.get<WireCurve>(e).blending ? 1 : 0;
    ASSERT_EQ(blending, static_cast<std::size_t>(kWires));
    for (const Entity e : old) w.registry.destroy(e);
    std::size_t reused_slots = 0;
    for (int i = 0; i < kWires; ++i) {
        const Entity e = spawn_wire(w.registry, cable(8, {-2, 0.003 * i, 1}, 4.0, 0.4));
        for (const Entity o : old) reused_slots += engine::ecs::to_index(o) == engine::ecs::to_index(e) ? 1 : 0;
    }
    ASSERT_EQ(reused_slots, static_cast<std::size_t>(kWires));
    for (int repeat = 0; repeat < 2; ++repeat) {
        w.run();
        EXPECT_EQ(w.ctx.stats.curves_built, repeat == 0 ? static_cast<std::size_t>(kWires) : 0u);
        EXPECT_EQ(w.ctx.stats.errors, 0u);
    }
    EXPECT_EQ(w.ctx.draw_list.items.size(), static_cast<std::size_t>(kWires));
}

TEST(WireSystems, InsertAndRemoveNodeKeepArraysAndIds) {
    World w;
    WireNodes n = cable(6, {-1, 0, 0}, 2.0, 0.2);
    n.stretch.assign(6, 1.0f);
    n.radius_m = {0.01f, 0.02f, 0.03f, 0.04f, 0.05f, 0.06f};
    const Entity e = spawn_wire(w.registry, n);
    w.run();
    const uint32_t id = insert_node(w.registry, e, 2, glm::dvec3(-0.4, -0.1, 0.0));
    EXPECT_EQ(id, 6u);  // ids were implicit (0..5): made explicit, the new one is max + 1
    const WireNodes& now = w.registry.get<Nodes>(e);
    ASSERT_EQ(now.positions.size(), 7u);
    EXPECT_EQ(now.ids, (std::vector<uint32_t>{0, 1, 6, 2, 3, 4, 5}));
    EXPECT_EQ(now.stretch.size(), 7u);
    EXPECT_EQ(now.radius_m.size(), 7u);
    EXPECT_EQ(now.radius_m[2], 0.03f);
    EXPECT_TRUE(now.kb_tension.empty());
    w.run();
    EXPECT_EQ(w.ctx.stats.curves_built, 1u);
    EXPECT_EQ(wire_error(w.registry, e), nullptr);
    remove_node(w.registry, e, 4);  // id 3
    EXPECT_EQ(w.registry.get<Nodes>(e).ids, (std::vector<uint32_t>{0, 1, 6, 2, 4, 5}));
    EXPECT_EQ(w.registry.get<Nodes>(e).radius_m.size(), 6u);
    w.run();
    EXPECT_EQ(wire_error(w.registry, e), nullptr);
    EXPECT_EQ(w.ctx.draw_list.items.size(), 1u);
}

// Found by fuzz_wire_systems (tests/fuzz/corpus/fuzz_wire_systems/regression_insert_short_array.bin): a wire
// whose stretch array is one short (reported as a WireError) got insert_node at the end: the array was written
// past its end (vector::insert beyond end(), ASan negative-size-param). Now the array stays one short, the error
// stays reported with the new count, and the wire recovers once the array is fixed.
TEST(WireSystems, InsertAndRemoveNodeOnAWireWithAShortArray) {
    World w;
    WireNodes n = cable(6, {-1, 0, 0}, 2.0, 0.2);
    n.stretch.assign(5, 1.0f);  // one short
    const Entity e = spawn_wire(w.registry, n);
    w.run();
    ASSERT_NE(wire_error(w.registry, e), nullptr);
    EXPECT_EQ(wire_error(w.registry, e)->message,
              describe_entity(e) + ": stretch has 5 entries for 6 nodes (must be empty or one per node)");
    (void)insert_node(w.registry, e, 6, glm::dvec3(1.2, 0.0, 0.0));  // append: past the stretch array's end
    (void)insert_node(w.registry, e, 0, glm::dvec3(-1.2, 0.0, 0.0));
    EXPECT_EQ(w.registry.get<Nodes>(e).positions.size(), 8u);
    EXPECT_EQ(w.registry.get<Nodes>(e).stretch.size(), 7u);
    w.run();
    ASSERT_EQ(w.ctx.new_errors.size(), 1u);  // the message changed: reported again, once
    EXPECT_EQ(w.ctx.new_errors[0].message,
              describe_entity(e) + ": stretch has 7 entries for 8 nodes (must be empty or one per node)");
    remove_node(w.registry, e, 7);  // past the stretch array's end: nothing to erase there, lengths now agree
    EXPECT_EQ(w.registry.get<Nodes>(e).stretch.size(), 7u);
    w.run();
    EXPECT_EQ(wire_error(w.registry, e), nullptr);
    EXPECT_EQ(w.ctx.draw_list.items.size(), 1u);
}

TEST(WireSystems, FirstFrameIsCarriedOver) {
    // The wire's first tangent sweeps through the world axes while it turns slowly: a re-seeded first normal
    // would jump; the carried one turns as little as the tangent does.
    World w;
    auto turned = [](double a) {
        WireNodes n;
        for (int i = 0; i < 8; ++i) {
            n.positions.emplace_back(0.3 * i * std::cos(a), 0.3 * i * std::sin(a), 0.02 * std::sin(i));
        }
        return n;
    };
    const Entity e = spawn_wire(w.registry, turned(0.0));
    w.run();
    glm::dvec3 last = w.registry.get<WireRings>(e).rings.frames.front().r;
    for (int frame = 1; frame <= 90; ++frame) {
        set_nodes(w.registry, e, turned(frame * 0.02));  // 1.15 degrees a frame
        w.run();
        const glm::dvec3 r = w.registry.get<WireRings>(e).rings.frames.front().r;
        EXPECT_GT(glm::dot(r, last), std::cos(0.03)) << "frame " << frame;
        last = r;
    }
}

}  // namespace
}  // namespace wire::systems

namespace wire::systems {
namespace {

// The nodes path (issue 30): the systems send packed nodes (no curve, rings or mesh on the CPU), the blended curve
// while a pop-free blend lasts (then packed nodes again), and keep drawing the last valid nodes after a bad
// update, reported once; automatic wires too (their weights packed with the nodes). A wire far behind the camera
// is culled by the sphere from its nodes.
TEST(WireSystems, NodesPathSendsPackedNodesBlendsAndLastValidNodes) {
    World w;
    w.ctx.path = UploadPath::gpu_nodes;
    const Entity e = spawn_wire(w.registry, cable(12, {-2, 0, 0}, 4.0, 0.6), {.spline = {.kind = SplineKind::catmull_rom}});
    const Entity a = spawn_wire(w.registry, cable(9, {-2, 1, 0}, 4.0, 0.3));  // automatic (Style's default)
    const Entity behind = spawn_wire(w.registry, cable(9, {-2, 0, 50}, 4.0, 0.3), {.spline = {.kind = SplineKind::c2}});
    const Entity far_away = spawn_wire(w.registry, cable(9, {-2, 0, 5000}, 4.0, 0.3), {.spline = {.kind = SplineKind::catmull_rom}});
    w.run();
    const auto item_of = [&](Entity x) -> const DrawItem* {
        for (const DrawItem& it : w.ctx.draw_list.items)
            if (it.wire_id == engine::ecs::to_integral(x)) return &it;
        return nullptr;
    };
    ASSERT_NE(item_of(e), nullptr);
    EXPECT_NE(item_of(e)->packed_nodes, nullptr);
    EXPECT_EQ(item_of(e)->curve, nullptr);
    EXPECT_EQ(item_of(e)->packed_nodes->node_count, 12u);
    EXPECT_EQ(w.ctx.stats.rings_built, 0u);
    EXPECT_EQ(w.ctx.stats.meshes_built, 0u);
    EXPECT_TRUE(w.registry.get<WireCurve>(e).curve.segments.empty());  // built on the GPU, not kept here
    ASSERT_NE(item_of(a), nullptr);
    EXPECT_NE(item_of(a)->packed_nodes, nullptr);  // automatic: built on the GPU too (weights from the CPU)
    EXPECT_NE(item_of(behind), nullptr);    // c2: no sphere from nodes, culled on the GPU
    EXPECT_EQ(item_of(far_away), nullptr);  // behind the camera: culled by the sphere from its nodes
    const uint64_t generation = item_of(e)->nodes_generation;
    w.run();
    EXPECT_EQ(item_of(e)->nodes_generation, generation);  // unchanged: the renderer sends nothing for it

    // A node inserted: the blended curve is sent while the blend lasts (and, unchanged, its last state after it),
    // then packed nodes again from the next change.
    const auto& p = w.registry.get<Nodes>(e).positions;
    insert_node(w.registry, e, 6, 0.5 * (p[5] + p[6]) + glm::dvec3(0, 0.02, 0));
    int blend_frames = 0;
    for (int frame = 0; frame < 300; ++frame) {
        w.run();
        ASSERT_NE(item_of(e), nullptr);
        EXPECT_NE(item_of(e)->curve, nullptr);
        if (!w.registry.get<WireCurve>(e).blending) break;
        ++blend_frames;
    }
    EXPECT_GT(blend_frames, 1);
    EXPECT_LT(blend_frames, 300);
    edit_nodes(w.registry, e).positions[0].y += 0.01;  // the next change takes the fast path: packed nodes
    w.run();
    ASSERT_NE(item_of(e)->packed_nodes, nullptr);
    EXPECT_EQ(item_of(e)->packed_nodes->node_count, 13u);

    // A bad update: reported once, the last valid nodes keep drawing.
    const std::vector<glm::uvec2> last_valid = item_of(e)->packed_nodes->records;
    edit_nodes(w.registry, e).positions[2].x = std::numeric_limits<double>::quiet_NaN();
    w.run();
    EXPECT_NE(wire_error(w.registry, e), nullptr);
    EXPECT_EQ(w.ctx.new_errors.size(), 1u);
    ASSERT_NE(item_of(e), nullptr);
    ASSERT_NE(item_of(e)->packed_nodes, nullptr);
    EXPECT_EQ(item_of(e)->packed_nodes->records, last_valid);
    w.run();
    EXPECT_TRUE(w.ctx.new_errors.empty());  // once
}

// The nodes path carries the first frame with the wire's motion. Each draw item whose nodes changed says how: the
// GPU fits it (fit_motion: packed nodes, none merged, the ids at the reference's nodes where they were when the
// renderer last got the wire: matching by index is matching by id), or the CPU did (an id event, a blended
// curve: `motion`, carried_rotation's vector part of the fit from the nodes sent last). A frame without a change
// sends nothing; a wire turned while culled is fitted across the gap (the GPU keeps the last upload's reference).
TEST(WireSystems, NodesPathSendsTheWiresMotion) {
    World w;
    w.ctx.path = UploadPath::gpu_nodes;
    WireNodes nodes = cable(12, {-2, 0, 0}, 4.0, 0.6);
    for (uint32_t i = 0; i < 12; ++i) nodes.ids.push_back(100 + 10 * i);
    const Entity e = spawn_wire(w.registry, nodes, {.spline = {.kind = SplineKind::catmull_rom}});
    const auto item_of = [&](Entity x) -> const DrawItem* {
        for (const DrawItem& it : w.ctx.draw_list.items)
            if (it.wire_id == engine::ecs::to_integral(x)) return &it;
        return nullptr;
    };
    w.run();
    ASSERT_NE(item_of(e), nullptr);
    EXPECT_EQ(item_of(e)->motion, glm::vec3(0.0f));  // the first nodes: nothing to carry from
    EXPECT_FALSE(item_of(e)->fit_motion);
    const glm::dvec3 pivot(-2.0, 0.0, 0.0);
    const auto turn = [&](const glm::dquat& q, const glm::dvec3& about) {
        for (glm::dvec3& p : edit_nodes(w.registry, e).positions) p = about + q * (p - about);
    };
    const glm::dquat q = glm::angleAxis(0.05, glm::normalize(glm::dvec3(1.0, 2.0, 0.5)));
    turn(q, pivot);
    w.run();
    ASSERT_NE(item_of(e), nullptr);
    EXPECT_TRUE(item_of(e)->fit_motion);  // the common case: on the GPU
    EXPECT_EQ(item_of(e)->motion, glm::vec3(0.0f));
    // Taken far behind the camera, turned there, brought back: the GPU fits across the gap.
    const auto shift = [&](double dz) {
        for (glm::dvec3& p : edit_nodes(w.registry, e).positions) p.z += dz;
    };
    shift(5000.0);
    w.run();
    EXPECT_EQ(item_of(e), nullptr);  // culled
    turn(q, pivot + glm::dvec3(0.0, 0.0, 5000.0));
    w.run();
    shift(-5000.0);
    w.run();
    ASSERT_NE(item_of(e), nullptr);
    EXPECT_TRUE(item_of(e)->fit_motion);
    // A node inserted while the wire turns: the ids moved, so the CPU fits (from the nodes sent last, by id).
    const auto& p = w.registry.get<Nodes>(e).positions;
    insert_node(w.registry, e, 6, 0.5 * (p[5] + p[6]) + glm::dvec3(0, 0.02, 0));
    turn(q, pivot);
    w.run();
    ASSERT_NE(item_of(e), nullptr);
    EXPECT_FALSE(item_of(e)->fit_motion);
    const glm::vec3 m = item_of(e)->motion;
    EXPECT_NEAR(m.x, q.x, 1e-6);
    EXPECT_NEAR(m.y, q.y, 1e-6);
    EXPECT_NEAR(m.z, q.z, 1e-6);
}

}  // namespace
}  // namespace wire::systems
