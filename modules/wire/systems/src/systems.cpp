// The wire systems: curve -> lod -> rings -> mesh -> draw list, each over a dense array of the wires that need
// work, in parallel with oneTBB; every wire writes only its own components. The stages are in curve_system.cpp
// (the curve's state machine: curve_state.cpp), lod_rings_mesh.cpp (one wire's work: one_wire.cpp) and
// draw_list_system.cpp; here their installation and the read-outs (rings, memory, error).
#include "stages.hpp"

namespace wire::systems {

using namespace detail;

namespace {

template <class T>
std::size_t bytes_of(const std::vector<T>& v) { return v.capacity() * sizeof(T); }

std::size_t bytes_of(const Curve& c) {
    return bytes_of(c.segments) + bytes_of(c.source_node) + bytes_of(c.radius_m) + bytes_of(c.stretch);
}

std::size_t bytes_of(const WireNodes& n) {
    std::size_t bytes = bytes_of(n.positions);
    for_each_node_array([&](const char*, auto member) { bytes += bytes_of(n.*member); });
    return bytes;
}

std::size_t bytes_of(const RingSet& r) {
    return bytes_of(r.params) + bytes_of(r.rings) + bytes_of(r.frames) + bytes_of(r.centre_m) +
           bytes_of(r.arc_length_m) + bytes_of(r.u) + bytes_of(r.tangent_scratch);
}

}  // namespace

void install(engine::ecs::Schedule& schedule, WireContext& context) {
    WireContext* ctx = &context;
    schedule.add(kCurveSystem, [ctx](Registry& r, const engine::ecs::FrameContext& f) {
        curve_system(r, *ctx, f.last_run_tick);
    });
    schedule.add(kLodSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { lod_system(r, *ctx); });
    schedule.add(kRingsSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { rings_system(r, *ctx); });
    schedule.add(kMeshSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { mesh_system(r, *ctx); });
    schedule.add(kDrawListSystem, [ctx](Registry& r, const engine::ecs::FrameContext&) { draw_list_system(r, *ctx); });
}

bool wire_ring_set(Registry& registry, Entity wire, RingSet& out) {
    const WireCurve* curve = registry.try_get<WireCurve>(wire);
    const WireRings* rings = registry.try_get<WireRings>(wire);
    if (curve == nullptr || rings == nullptr || rings->generation == 0 || rings->seen_curve != curve->generation ||
        rings->rings.rings.size() != rings->params.size()) {
        return false;
    }
    build_rings(curve->curve, rings->params, RingSettings{.frames = rings->frame_settings}, out);
    return true;
}

namespace {

/// Adds one wire's memory to `m` (see WireMemory).
void add_wire_memory(Registry& registry, Entity e, const WireCurve& c, WireMemory& m) {
    std::size_t curve =
        sizeof(WireCurve) + bytes_of(c.curve) + bytes_of(c.previous_nodes) + bytes_of(c.lod_bounds.data);
    if (!c.pop_free_stale) {  // live pop-free state: target and rendered curves, one id per node of each
        const Curve& t = c.pop_free.target();
        curve += 2 * (bytes_of(t) + t.node_count() * sizeof(uint32_t));
    }
    std::size_t lod = 0, rings = 0, mesh = 0;
    bool visible = false;
    if (const WireLodState* l = registry.try_get<WireLodState>(e)) {
        lod = sizeof(WireLodState) + bytes_of(l->lod.counts) + bytes_of(l->lod.required);
        visible = l->lod.visible;
    }
    if (const WireRings* r = registry.try_get<WireRings>(e)) {
        rings = sizeof(WireRings) + bytes_of(r->params) + bytes_of(r->rings);
    }
    if (const WireMesh* w = registry.try_get<WireMesh>(e)) {
        mesh = sizeof(WireMesh) + bytes_of(w->mesh.vertices) + bytes_of(w->mesh.indices);
    }
    if (const Nodes* n = registry.try_get<Nodes>(e)) m.nodes_bytes += bytes_of(static_cast<const WireNodes&>(*n));
    m.curve_bytes += curve;
    m.lod_bytes += lod;
    m.rings_bytes += rings;
    m.mesh_bytes += mesh;
    const std::size_t total = curve + lod + rings + mesh;
    if (visible) {
        ++m.visible_wires;
        m.visible_bytes += total;
    } else {
        ++m.culled_wires;
        m.culled_bytes += total;
    }
}

}  // namespace

WireMemory wire_memory(Registry& registry) {
    WireMemory m;
    auto& curves = registry.storage<WireCurve>();
    for (std::size_t i = 0; i < curves.size(); ++i) add_wire_memory(registry, curves.at(i), curves.at_position(i), m);
    return m;
}

WireMemory wire_memory(Registry& registry, Entity wire) {
    WireMemory m;
    if (const WireCurve* c = registry.try_get<WireCurve>(wire)) add_wire_memory(registry, wire, *c, m);
    return m;
}

ScreenError wire_screen_error(Registry& registry, const WireContext& ctx, Entity wire, int samples_per_segment) {
    const WireCurve* curve = registry.try_get<WireCurve>(wire);
    const WireRings* rings = registry.try_get<WireRings>(wire);
    const WireLodState* lod = registry.try_get<WireLodState>(wire);
    if (curve == nullptr || rings == nullptr || lod == nullptr || !lod->lod.visible || rings->params.empty()) return {};
    return measure_screen_error(curve->curve, rings->params, ctx.view, samples_per_segment);
}

ScreenError scene_screen_error(Registry& registry, const WireContext& ctx, int samples_per_segment) {
    ScreenError worst;
    std::size_t samples = 0;
    for (const DrawItem& item : ctx.draw_list.items) {
        const Entity e{static_cast<uint32_t>(item.wire_id)};
        const ScreenError s = wire_screen_error(registry, ctx, e, samples_per_segment);
        samples += s.samples;
        if (s.max_px > worst.max_px) worst = s;
    }
    worst.samples = samples;
    return worst;
}

}  // namespace wire::systems

