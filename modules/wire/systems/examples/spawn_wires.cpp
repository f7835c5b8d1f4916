// Spawning, driving and destroying wire entities: runs the CPU wire systems for a few frames (no window, no GPU)
// and prints what each frame would draw.
#include "wire/systems/api.hpp"
#include "wire/systems/systems.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>

#include <cmath>
#include <cstdio>

namespace {

// A cable hanging between two posts, `n` nodes, sagging by `sag_m`.
wire::WireNodes hanging_cable(int n, double x0, double sag_m) {
    wire::WireNodes nodes;
    for (int i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / (n - 1);
        nodes.positions.emplace_back(x0 + 4.0 * s, 2.0 - 4.0 * sag_m * s * (1.0 - s), -6.0);
    }
    return nodes;
}

}  // namespace

int main() {
    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    wire::systems::WireContext context;  // camera, viewport, LOD tolerance, upload path; the DrawList comes out here
    context.camera.position = {0.0f, 1.5f, 0.0f};
    context.camera.target = {0.0f, 1.5f, -6.0f};
    context.on_error = [](const wire::systems::ErrorReport& e) { std::printf("error: %s\n", e.message.c_str()); };
    wire::systems::install(schedule, context);  // curve -> lod -> rings -> mesh -> draw_list

    // Spawn: nodes + style. Update: set_nodes / edit_nodes / insert_node (marks the wire changed). Destroy: registry.
    const engine::ecs::Entity a = wire::systems::spawn_wire(registry, hanging_cable(16, -4.0, 0.5), {.radius_m = 0.02f});
    const engine::ecs::Entity b = wire::systems::spawn_wire(registry, hanging_cable(16, 0.5, 0.8), {.material = 1});
    wire::WireNodes broken = hanging_cable(8, 0.0, 0.3);
    broken.positions[3].y = std::nan("");
    wire::systems::spawn_wire(registry, broken);  // reported once, skipped; the others keep rendering

    for (int frame = 0; frame < 6; ++frame) {
        if (frame == 2) wire::systems::set_nodes(registry, a, hanging_cable(16, -4.0, 0.7));  // the physics moved it
        if (frame == 3) {  // the simulation refines the wire: a node between nodes 7 and 8 (blended in, no pop)
            const auto& p = registry.get<wire::systems::Nodes>(b).positions;
            wire::systems::insert_node(registry, b, 8, 0.5 * (p[7] + p[8]));
        }
        if (frame == 4) context.camera.position.z -= 3.0f;  // walk toward the wires: more rings
        if (frame == 5) registry.destroy(b);
        schedule.run(registry, 1.0 / 60.0);

        const wire::systems::RunStats& s = context.stats;
        std::printf("frame %d: %zu wires, %zu visible; built %zu curves, %zu lods, %zu rings, %zu meshes; "
                    "draw %zu items, %zu rings, %zu vertices\n",
                    frame, s.wires, s.visible_wires, s.curves_built, s.lod_updates, s.rings_built, s.meshes_built,
                    s.draw_items, s.rings, s.vertices);
    }
    for (const engine::ecs::SystemStats& st : schedule.stats()) {
        std::printf("%-15s mean %.3f ms\n", st.name.c_str(), st.mean_ms);
    }
    return 0;
}
