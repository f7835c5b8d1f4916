// libFuzzer target: the wire ECS systems (install(): curve -> lod -> rings -> mesh -> draw list) driven over
// frames by arbitrary operations: spawn_wire, set_nodes (node arrays whose stable ids are kept, vanish, appear,
// repeat, come back, change order, or are implicit), insert_node, remove_node, edit_nodes, set_style,
// registry.destroy, camera moves, pop_free and upload-path switches, and runs of frames.
// Properties, every frame: no crash or UB (ASan+UBSan); every drawn vertex, ring and rendered curve control
// point finite, indices in range; errors reported once per wire (a report only when a wire's error appears or
// its message changes, naming the wire's entity, equal to its WireError, and through on_error exactly once).
// At the end of the input, frames run with no further change: every blend ends (no wire blending) within
// kSettleFrames, and then every valid wire's rendered curve equals a fresh build_curve of its nodes and style.
// WIRE_FUZZ_DUMP=1 prints the decoded operations.
#include "fuzz_checks.hpp"

#include <wire/packed_nodes.hpp>
#include <wire/spline.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>

#include <fuzzer/FuzzedDataProvider.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace {

using engine::ecs::Entity;
using engine::ecs::Registry;
namespace ws = wire::systems;

constexpr double kDt = 1.0 / 60.0;
// Frames run after the last operation until no wire blends. A blend lasts Style::blend_s (0 -> 0.25 s) and at
// most PopFreeSettings::max_blend_s (4 s, 240 frames at 60 Hz): 600 frames of 1/60 s (10 s) is beyond that, and
// the property reads only the public WireContext::blending / WireCurve::blending.
constexpr int kSettleFrames = 600;
constexpr std::size_t kMaxWires = 6;
constexpr std::size_t kMaxNodes = 40;

bool want_dump() {
    static const bool dump = std::getenv("WIRE_FUZZ_DUMP") != nullptr;
    return dump;
}

double special_or_raw(FuzzedDataProvider& in) {
    static constexpr double kSpecial[] = {0.0, -0.0, 1.0, -1.0, 1e-9, 1e-6, 1e6, 1e12, 2e12, 1e300, 5e-324,
                                          std::numeric_limits<double>::infinity(),
                                          std::numeric_limits<double>::quiet_NaN()};
    return wire_fuzz::special_or_raw(in, kSpecial);
}

/// A sane position in a 10 m box (most nodes) or a special one (NaN, Inf, huge, denormal: an error or a limit).
glm::dvec3 position(FuzzedDataProvider& in) {
    if (in.ConsumeIntegral<uint8_t>() < 224)
        return {in.ConsumeFloatingPointInRange<double>(-5.0, 5.0), in.ConsumeFloatingPointInRange<double>(-5.0, 5.0),
                in.ConsumeFloatingPointInRange<double>(-5.0, 5.0)};
    return {special_or_raw(in), special_or_raw(in), special_or_raw(in)};
}

/// Per-wire generator state: ids handed out so far, ids that vanished (for reuse).
struct WireModel {
    Entity entity = engine::ecs::null_entity;
    uint32_t next_id = 0;
    std::vector<uint32_t> vanished;
};

wire::WireNodes fresh_nodes(FuzzedDataProvider& in, WireModel& model) {
    wire::WireNodes n;
    const std::size_t count = in.ConsumeIntegralInRange<std::size_t>(0, 16);
    glm::dvec3 p = position(in);
    for (std::size_t i = 0; i < count && in.remaining_bytes() > 0; ++i) {
        n.positions.push_back(p);
        p += glm::dvec3(in.ConsumeFloatingPointInRange<double>(-1.0, 1.0), in.ConsumeFloatingPointInRange<double>(-1.0, 1.0),
                        in.ConsumeFloatingPointInRange<double>(-1.0, 1.0));
        if (in.ConsumeIntegral<uint8_t>() >= 250) p = position(in);
    }
    if (in.ConsumeBool()) {  // explicit ids 0..n-1, or implicit (ids empty: nodes are named by index)
        for (std::size_t i = 0; i < n.positions.size(); ++i) n.ids.push_back(static_cast<uint32_t>(i));
        model.next_id = static_cast<uint32_t>(n.positions.size());
    }
    return n;
}

/// The next state of a wire's nodes: per node keep (maybe moved), drop (its id vanishes), repeat its id, insert a
/// new id or a vanished one before it, swap with the next; optional arrays sometimes added, dropped or corrupted.
wire::WireNodes next_nodes(FuzzedDataProvider& in, const wire::WireNodes& old, WireModel& model) {
    wire::WireNodes n;
    const bool ids = !old.ids.empty() || in.ConsumeIntegral<uint8_t>() < 32;
    const double move = in.ConsumeBool() ? 0.0 : in.ConsumeFloatingPointInRange<double>(0.0, 0.5);
    for (std::size_t i = 0; i < old.positions.size() && n.positions.size() < kMaxNodes; ++i) {
        const uint32_t id = old.ids.empty() ? static_cast<uint32_t>(i) : old.ids[i];
        const uint8_t op = in.ConsumeIntegral<uint8_t>();
        glm::dvec3 p = old.positions[i] + move * glm::dvec3(in.ConsumeFloatingPointInRange<double>(-1.0, 1.0),
                                                            in.ConsumeFloatingPointInRange<double>(-1.0, 1.0),
                                                            in.ConsumeFloatingPointInRange<double>(-1.0, 1.0));
        if (op < 150) {  // keep
            n.positions.push_back(p);
            n.ids.push_back(id);
        } else if (op < 180) {  // vanish
            model.vanished.push_back(id);
        } else if (op < 200) {  // a new node before it, then it
            const glm::dvec3 before = i > 0 ? 0.5 * (old.positions[i - 1] + p) : p - glm::dvec3(0.3, 0.0, 0.0);
            n.positions.push_back(before);
            n.ids.push_back(model.next_id++);
            n.positions.push_back(p);
            n.ids.push_back(id);
        } else if (op < 212 && !model.vanished.empty()) {  // a vanished id comes back, then it
            const std::size_t k = in.ConsumeIntegralInRange<std::size_t>(0, model.vanished.size() - 1);
            n.positions.push_back(p + glm::dvec3(0.0, 0.2, 0.0));
            n.ids.push_back(model.vanished[k]);
            model.vanished.erase(model.vanished.begin() + static_cast<std::ptrdiff_t>(k));
            n.positions.push_back(p);
            n.ids.push_back(id);
        } else if (op < 222) {  // repeated id
            n.positions.push_back(p);
            n.ids.push_back(id);
            n.positions.push_back(p + glm::dvec3(0.1, 0.0, 0.0));
            n.ids.push_back(id);
        } else if (op < 232 && i + 1 < old.positions.size()) {  // order swap
            n.positions.push_back(old.positions[i + 1]);
            n.ids.push_back(old.ids.empty() ? static_cast<uint32_t>(i + 1) : old.ids[i + 1]);
            n.positions.push_back(p);
            n.ids.push_back(id);
            ++i;
        } else if (op < 240) {  // an arbitrary id (maybe huge, maybe an existing one)
            n.positions.push_back(p);
            n.ids.push_back(in.ConsumeBool() ? in.ConsumeIntegral<uint32_t>() : std::numeric_limits<uint32_t>::max());
        } else {  // a special position (error or limit)
            n.positions.push_back(position(in));
            n.ids.push_back(id);
        }
    }
    if (in.ConsumeIntegral<uint8_t>() < 40) n.positions.push_back(position(in)), n.ids.push_back(model.next_id++);
    if (!ids) n.ids.clear();
    const uint8_t extras = in.ConsumeIntegral<uint8_t>();
    const std::size_t size = n.positions.size();
    if (extras & 1) n.radius_m.assign(size, in.ConsumeBool() ? 0.0f : 0.02f);
    if (extras & 2) n.stretch.assign(size, in.ConsumeBool() ? 1.0f : 1.5f);
    if ((extras & 4) && size > 0 && !n.radius_m.empty())
        n.radius_m[in.ConsumeIntegralInRange<std::size_t>(0, size - 1)] = static_cast<float>(special_or_raw(in));
    if ((extras & 8) && !n.stretch.empty()) n.stretch.pop_back();  // wrong-length array: an error
    if (extras & 16) {
        for (std::size_t i = 0; i < size; ++i) {
            n.kb_tension.push_back(in.ConsumeFloatingPointInRange<float>(-1.0f, 1.0f));
            n.kb_bias.push_back(in.ConsumeFloatingPointInRange<float>(-1.0f, 1.0f));
            n.kb_continuity.push_back(in.ConsumeFloatingPointInRange<float>(-1.0f, 1.0f));
        }
    }
    return n;
}

ws::Style read_style(FuzzedDataProvider& in) {
    ws::Style s;
    const uint8_t pick = in.ConsumeIntegral<uint8_t>();
    s.radius_m = pick < 200 ? in.ConsumeFloatingPointInRange<float>(0.0f, 0.1f) : static_cast<float>(special_or_raw(in));
    s.max_sides = in.ConsumeIntegralInRange<uint32_t>(0, 40);
    s.spline.kind = static_cast<wire::SplineKind>(in.ConsumeIntegralInRange<int>(0, 3));
    s.spline.alpha = in.ConsumeFloatingPointInRange<double>(0.0, 1.0);
    if (in.ConsumeBool()) s.spline.tension = in.ConsumeFloatingPointInRange<double>(-1.0, 1.0);
    s.spline.curvature_tension = in.ConsumeBool();
    s.material = in.ConsumeIntegral<uint8_t>();
    s.caps = in.ConsumeBool();
    s.closed = in.ConsumeIntegral<uint8_t>() < 48;
    return s;
}

void set_camera(FuzzedDataProvider& in, ws::WireContext& ctx) {
    if (in.ConsumeBool()) {  // a camera that sees the 10 m box
        ctx.camera.position = {in.ConsumeFloatingPointInRange<float>(-3.0f, 3.0f), in.ConsumeFloatingPointInRange<float>(-3.0f, 3.0f),
                               in.ConsumeFloatingPointInRange<float>(8.0f, 20.0f)};
        ctx.camera.target = {0.0f, 0.0f, 0.0f};
    } else {  // anywhere, looking anywhere (inside wires, behind them)
        ctx.camera.position = {in.ConsumeFloatingPointInRange<float>(-10.0f, 10.0f), in.ConsumeFloatingPointInRange<float>(-10.0f, 10.0f),
                               in.ConsumeFloatingPointInRange<float>(-10.0f, 10.0f)};
        ctx.camera.target = ctx.camera.position + glm::dvec3(in.ConsumeFloatingPointInRange<float>(-1.0f, 1.0f),
                                                            in.ConsumeFloatingPointInRange<float>(-1.0f, 1.0f), -1.0f);
    }
    ctx.lod.tolerance_px = in.ConsumeBool() ? 0.0 : in.ConsumeFloatingPointInRange<double>(0.05, 20.0);
    ctx.lod.max_rings_per_segment = in.ConsumeIntegralInRange<uint32_t>(0, 64);
}

/// The curve settings the curve system derives from a Style (closed and radius from the Style; 0 -> 1 cm).
wire::SplineSettings spline_of(const ws::Style& style) {
    wire::SplineSettings s = style.spline;
    s.closed = style.closed;
    s.radius_m = style.radius_m > 0.0f ? style.radius_m : 0.01f;
    return s;
}

void check_curve(const wire::Curve& c) {
    for (const wire::CubicBezier& b : c.segments)
        wire_fuzz::require(wire_fuzz::finite_vec(b.b0) && wire_fuzz::finite_vec(b.b1) && wire_fuzz::finite_vec(b.b2) &&
                               wire_fuzz::finite_vec(b.b3),
                           "rendered curve control point not finite");
    for (float r : c.radius_m) wire_fuzz::require(std::isfinite(r) && r > 0.0f, "rendered curve radius not finite and positive");
}

struct Harness {
    Registry registry;
    engine::ecs::Schedule schedule;
    ws::WireContext ctx;
    std::vector<WireModel> wires;
    std::vector<ws::ErrorReport> callback_reports;
    std::size_t frames = 0;

    Harness() {
        ctx.camera.position = {0.0f, 0.0f, 12.0f};
        ctx.camera.target = {0.0f, 0.0f, 0.0f};
        ctx.on_error = [this](const ws::ErrorReport& r) { callback_reports.push_back(r); };
        ws::install(schedule, ctx);
    }

    /// One frame and the per-frame properties.
    void frame() {
        std::map<uint32_t, std::string> before;  // entity -> error message before the frame
        for (const WireModel& w : wires)
            if (const ws::WireError* e = ws::wire_error(registry, w.entity)) before[engine::ecs::to_integral(w.entity)] = e->message;
        callback_reports.clear();
        schedule.run(registry, kDt);
        ++frames;

        // Errors: reported once, when they appear or change; the callback saw exactly the same reports.
        wire_fuzz::require(callback_reports.size() == ctx.new_errors.size(), "on_error calls differ from new_errors");
        std::map<uint32_t, int> reported;
        for (std::size_t i = 0; i < ctx.new_errors.size(); ++i) {
            const ws::ErrorReport& r = ctx.new_errors[i];
            const uint32_t key = engine::ecs::to_integral(r.entity);
            wire_fuzz::require(callback_reports[i].entity == r.entity && callback_reports[i].message == r.message,
                               "on_error report differs from new_errors");
            wire_fuzz::require(++reported[key] == 1, "a wire's error reported twice in one frame");
            wire_fuzz::require(registry.valid(r.entity), "error reported for a destroyed wire");
            const ws::WireError* now = ws::wire_error(registry, r.entity);
            wire_fuzz::require(now != nullptr && now->message == r.message, "reported error is not the wire's WireError");
            wire_fuzz::require(r.message.rfind(ws::describe_entity(r.entity) + ": ", 0) == 0, "error does not name the wire");
            wire_fuzz::require(r.message.size() > ws::describe_entity(r.entity).size() + 2, "error without a message");
            const auto old = before.find(key);
            wire_fuzz::require(old == before.end() || old->second != r.message, "unchanged error reported again");
        }
        for (const WireModel& w : wires) {
            const ws::WireError* e = ws::wire_error(registry, w.entity);
            const uint32_t key = engine::ecs::to_integral(w.entity);
            if (e == nullptr || reported.count(key)) continue;
            const auto old = before.find(key);
            wire_fuzz::require(old != before.end() && old->second == e->message, "a wire's error appeared or changed unreported");
        }

        // Finite output.
        for (const WireModel& w : wires)
            if (const ws::WireCurve* c = registry.try_get<ws::WireCurve>(w.entity)) check_curve(c->curve);
        for (const wire::DrawItem& item : ctx.draw_list.items) {
            wire_fuzz::require(wire_fuzz::finite_vec(item.origin_m), "draw item origin not finite");
            wire_fuzz::require(item.sides >= 1, "draw item with no sides (1 = AA line, 2 = strip, >= 3 = tube)");
            for (const wire::Ring& r : item.rings)
                wire_fuzz::require(wire_fuzz::finite_vec(r.centre_m) && wire_fuzz::finite_vec(r.normal) &&
                                       wire_fuzz::finite_vec(r.binormal) && std::isfinite(r.radius_m) && std::isfinite(r.u),
                                   "ring not finite");
            for (const wire::TubeVertex& v : item.vertices)
                wire_fuzz::require(wire_fuzz::finite_vec(v.position) && wire_fuzz::finite_vec(v.normal) && wire_fuzz::finite_vec(v.uv),
                                   "mesh vertex not finite");
            for (uint32_t i : item.indices) wire_fuzz::require(i < item.vertices.size(), "mesh index out of range");
            if (item.packed_nodes != nullptr) {  // the nodes path: what the GPU reads
                const wire::PackedNodes& p = *item.packed_nodes;
                wire_fuzz::require(p.node_count >= 2, "fewer than 2 packed nodes");
                wire_fuzz::require(p.records.size() == (p.quantised ? p.node_count + 1 : 2 * p.node_count),
                                   "packed node records do not match the node count");
                for (std::size_t j = 0; j < p.node_count; ++j) {
                    const glm::vec4 n = p.node(j);
                    wire_fuzz::require(std::isfinite(n.x + n.y + n.z + n.w) && n.w > 0.0f, "packed node not finite");
                }
            }
            if (ctx.draw_list.path == wire::UploadPath::gpu_nodes) {
                // Packed nodes (the last valid ones, also for a wire whose nodes are bad when the path changes), a
                // CPU-built curve, or nodes the systems could not pack (a style change the last valid nodes do not
                // fit: the renderer tries them and reports them).
                const bool nodes = item.nodes != nullptr && item.nodes->size() >= 2;
                wire_fuzz::require(item.packed_nodes != nullptr || item.curve != nullptr || nodes,
                                   "nodes-path item with neither nodes, packed nodes nor a curve");
                wire::PackedNodes again;  // the packed nodes are the item's (last valid) nodes, not older ones
                if (item.packed_nodes != nullptr && item.nodes != nullptr &&
                    wire::pack_nodes(*item.nodes, item.spline, again).ok()) {
                    wire_fuzz::require(again.records == item.packed_nodes->records,
                                       "packed nodes are not the item's nodes");
                }
            }
        }
        wire_fuzz::require(ctx.stats.visible_wires + ctx.stats.culled_wires == registry.storage<ws::WireLodState>().size(),
                           "visible + culled differs from the wire count");
    }

    WireModel* pick(FuzzedDataProvider& in) {
        if (wires.empty()) return nullptr;
        return &wires[in.ConsumeIntegralInRange<std::size_t>(0, wires.size() - 1)];
    }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    static tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);  // deterministic
    FuzzedDataProvider in(data, size);
    Harness h;
    h.ctx.pop_free = in.ConsumeIntegral<uint8_t>() < 224;
    h.ctx.path = in.ConsumeBool() ? wire::UploadPath::cpu_mesh : wire::UploadPath::gpu_nodes;
    const bool dump = want_dump();

    for (int step = 0; step < 96 && in.remaining_bytes() > 0; ++step) {
        const uint8_t op = in.ConsumeIntegralInRange<uint8_t>(0, 11);
        WireModel* w = op == 0 ? nullptr : h.pick(in);
        if (op == 0 || w == nullptr) {
            if (h.wires.size() >= kMaxWires) continue;
            WireModel model;
            wire::WireNodes nodes = fresh_nodes(in, model);
            const ws::Style style = read_style(in);
            if (dump) std::fprintf(stderr, "spawn: %zu nodes, radius %g, kind %d, closed %d\n", nodes.size(),
                                   double(style.radius_m), int(style.spline.kind), int(style.closed));
            model.entity = ws::spawn_wire(h.registry, std::move(nodes), style);
            h.wires.push_back(model);
            continue;
        }
        const wire::WireNodes& current = h.registry.get<ws::Nodes>(w->entity);
        switch (op) {
            case 1:
            case 2:
            case 3: {
                wire::WireNodes next = next_nodes(in, current, *w);
                if (dump) {
                    std::fprintf(stderr, "set_nodes %u:", engine::ecs::to_integral(w->entity));
                    for (std::size_t i = 0; i < next.size(); ++i)
                        std::fprintf(stderr, " %u", next.ids.empty() ? static_cast<uint32_t>(i) : next.ids[i]);
                    std::fprintf(stderr, "\n");
                }
                ws::set_nodes(h.registry, w->entity, std::move(next));
                break;
            }
            case 4: {
                const std::size_t at = in.ConsumeIntegralInRange<std::size_t>(0, current.size());
                if (current.size() >= kMaxNodes) break;
                glm::dvec3 p = current.positions.empty() ? glm::dvec3(0.0) : current.positions[std::min(at, current.size() - 1)];
                p += glm::dvec3(in.ConsumeFloatingPointInRange<double>(-0.5, 0.5), in.ConsumeFloatingPointInRange<double>(-0.5, 0.5), 0.0);
                if (dump) std::fprintf(stderr, "insert_node %u at %zu\n", engine::ecs::to_integral(w->entity), at);
                (void)ws::insert_node(h.registry, w->entity, at, p);
                break;
            }
            case 5: {
                if (current.size() == 0) break;
                const std::size_t at = in.ConsumeIntegralInRange<std::size_t>(0, current.size() - 1);
                if (dump) std::fprintf(stderr, "remove_node %u at %zu\n", engine::ecs::to_integral(w->entity), at);
                ws::remove_node(h.registry, w->entity, at);
                break;
            }
            case 6: {
                if (current.size() == 0) break;
                const std::size_t at = in.ConsumeIntegralInRange<std::size_t>(0, current.size() - 1);
                const glm::dvec3 p = position(in);
                if (dump) std::fprintf(stderr, "edit_nodes %u node %zu\n", engine::ecs::to_integral(w->entity), at);
                ws::edit_nodes(h.registry, w->entity).positions[at] = p;
                break;
            }
            case 7: {
                const ws::Style style = read_style(in);
                if (dump) std::fprintf(stderr, "set_style %u\n", engine::ecs::to_integral(w->entity));
                ws::set_style(h.registry, w->entity, style);
                break;
            }
            case 8: {
                if (dump) std::fprintf(stderr, "destroy %u\n", engine::ecs::to_integral(w->entity));
                h.registry.destroy(w->entity);
                h.wires.erase(h.wires.begin() + (w - h.wires.data()));
                break;
            }
            case 9:
                set_camera(in, h.ctx);
                if (dump) std::fprintf(stderr, "camera\n");
                break;
            case 10:
                if (in.ConsumeBool()) h.ctx.pop_free = !h.ctx.pop_free;
                else
                    h.ctx.path = h.ctx.path == wire::UploadPath::cpu_mesh ? wire::UploadPath::gpu_nodes
                                                                          : wire::UploadPath::cpu_mesh;
                if (dump) std::fprintf(stderr, "pop_free %d path %d\n", int(h.ctx.pop_free), int(h.ctx.path));
                break;
            default: {
                const int n = in.ConsumeIntegralInRange<int>(1, 4);
                if (dump) std::fprintf(stderr, "run %d frame(s)\n", n);
                for (int k = 0; k < n; ++k) h.frame();
                break;
            }
        }
    }
    h.frame();

    // Settle: with no further change every blend ends, and each valid wire then shows its exact curve.
    int settle = 0;
    while (!h.ctx.blending.empty() && settle < kSettleFrames) {
        h.frame();
        ++settle;
    }
    if (dump) std::fprintf(stderr, "settled after %d frame(s)\n", settle);
    wire_fuzz::require(h.ctx.blending.empty(), "a geomorph did not end within kSettleFrames");
    for (const WireModel& w : h.wires) {
        const ws::WireCurve& c = h.registry.get<ws::WireCurve>(w.entity);
        wire_fuzz::require(!c.blending, "a wire still blends after settling");
        if (ws::wire_error(h.registry, w.entity) != nullptr || c.generation == 0) continue;  // shows its last valid curve
        if (h.ctx.path == wire::UploadPath::gpu_nodes && c.curve.segments.empty()) {
            // The nodes path keeps the nodes packed for the GPU, not a curve: a fresh packing of the same nodes.
            wire::PackedNodes packed;
            const engine::Status st = wire::pack_nodes(h.registry.get<ws::Nodes>(w.entity),
                                                       spline_of(h.registry.get<ws::Style>(w.entity)), packed);
            wire_fuzz::require(st.ok(), "a wire without WireError has nodes pack_nodes rejects");
            wire_fuzz::require(packed.node_count == c.packed.node_count && packed.records == c.packed.records &&
                                   packed.extras == c.packed.extras,
                               "settled packed nodes differ from a fresh packing");
            continue;
        }
        if (c.released) {  // culled while moving: its curve comes back when the view turns to it (WireCurve)
            wire_fuzz::require(!h.registry.get<ws::WireLodState>(w.entity).lod.visible && c.curve.segments.empty(),
                               "a released curve on a visible wire");
            continue;
        }
        wire::Curve fresh;
        const engine::Status st = wire::build_curve(h.registry.get<ws::Nodes>(w.entity), spline_of(h.registry.get<ws::Style>(w.entity)), fresh);
        wire_fuzz::require(st.ok(), "a wire without WireError has nodes build_curve rejects");
        wire_fuzz::require(fresh.segments.size() == c.curve.segments.size(), "settled curve has another segment count than a fresh one");
        double scale = 1.0;
        for (const wire::CubicBezier& b : fresh.segments)
            for (const glm::dvec3& p : {b.b0, b.b1, b.b2, b.b3}) scale = std::max({scale, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        for (std::size_t i = 0; i < fresh.segments.size(); ++i) {
            const wire::CubicBezier& a = fresh.segments[i];
            const wire::CubicBezier& b = c.curve.segments[i];
            const double d = std::max({glm::length(a.b0 - b.b0), glm::length(a.b1 - b.b1), glm::length(a.b2 - b.b2),
                                       glm::length(a.b3 - b.b3)});
            if (!(d <= 1e-9 * scale)) {
                std::fprintf(stderr, "wire %u segment %zu differs from the fresh curve by %.3g m\n",
                             engine::ecs::to_integral(w.entity), i, d);
                wire_fuzz::fail("settled curve differs from a fresh build_curve of its nodes");
            }
        }
    }
    return 0;
}
