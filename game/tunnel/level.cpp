// The tunnel level: see level.hpp.
#include "tunnel/level.hpp"

#include "tunnel/piece_renderer.hpp"

#include <curved_space/gpu.hpp>
#include <engine/assets/gltf.hpp>
#include <engine/assets/subdivide.hpp>
#include <engine/ecs/registry.hpp>
#include <engine/gfx/gpu_timer.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/scene/frustum.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#ifndef TUNNEL_ASSET_DIR
#define TUNNEL_ASSET_DIR "assets/tunnel"
#endif

namespace tunnel {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kPieceLength = 4.0;  // the assets' length along +z
constexpr double kWallRadius = 2.5;
constexpr int kLevelSlots = 8;

// Wire materials (indices into the WireRenderer's table; 0 is its copper weave).
enum WireMaterial : uint32_t { copper = 0, rubber, orange, yellow, blue, red };

struct Group {
    std::string name;
    Surface surface = Surface::concrete;
    glm::vec3 albedo{1.0f};
    std::vector<engine::assets::ControlMesh> controls{};
    engine::assets::RefinementErrorModel model{};
    std::vector<PieceRenderer::MeshHandle> meshes{};  // per level
    std::vector<std::size_t> vertices{};              // per level
};

struct SegmentAnimation {
    double base_angle = 0.0;
    double angle_amp = 0.0;
    double angle_freq = 0.0;
    double angle_phase = 0.0;
    double dir_amp = 0.0;
    double dir_freq = 0.0;
    double dir_phase = 0.0;
};

struct FixedCable {
    double x = 0.0, y = 0.0;  // unbent cross-section position
    std::size_t cable = 0;
};

struct RopeEnds {
    int piece_a = 0;
    std::size_t anchor_a = 0;
    int piece_b = 0;
    std::size_t anchor_b = 0;
    std::size_t cable = 0;
    glm::dmat4 world_from_piece{1.0};  // the piece's frame when the rope was last moved with it
    double inset_m = 0.0;              // ends moved this far from the hook toward the axis (festoons)
};

// Deterministic [0, 1) from an integer (no library distribution: the same phases everywhere).
double hash01(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return static_cast<double>(x) / 4294967296.0;
}

void append(engine::assets::MeshData& dst, const engine::assets::MeshData& src) {
    const auto base = static_cast<uint32_t>(dst.vertex_count());
    for (std::size_t v = 0; v < src.vertex_count(); ++v) {
        const glm::dvec3 p =
            src.origin + glm::dvec3(src.positions[3 * v], src.positions[3 * v + 1], src.positions[3 * v + 2]);
        dst.positions.insert(dst.positions.end(),
                             {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)});
        dst.normals.insert(dst.normals.end(),
                           {src.normals[3 * v], src.normals[3 * v + 1], src.normals[3 * v + 2]});
        if (src.uvs.size() == 2 * src.vertex_count()) {
            dst.uvs.insert(dst.uvs.end(), {src.uvs[2 * v], src.uvs[2 * v + 1]});
        } else {
            dst.uvs.insert(dst.uvs.end(), {0.0f, 0.0f});
        }
    }
    for (uint32_t i : src.indices) dst.indices.push_back(base + i);
}

engine::assets::RefinementErrorModel merge(const engine::assets::RefinementErrorModel& a,
                                           const engine::assets::RefinementErrorModel& b) {
    return {std::max(a.shape_error_m, b.shape_error_m), std::max(a.max_axial_extent_m, b.max_axial_extent_m),
            std::max(a.max_radius_m, b.max_radius_m)};
}

}  // namespace

struct Level::State {
    LevelSettings settings;
    engine::ecs::Registry registry;
    wire::systems::WireContext context;
    wire::render::WireRenderer wires;
    PieceRenderer pieces;
    std::vector<Group> groups;
    std::vector<glm::dvec3> anchors;  // unbent, in piece space
    std::vector<SegmentAnimation> animation;
    std::vector<curved_space::Segment> segments;
    std::vector<FixedCable> fixed;
    std::vector<RopeEnds> rope_ends;
    wire::WireNodes scratch;
    int width_px = 1280;
    int height_px = 720;
    double time_s = 0.0;
    double fly_distance_m = 0.0;
    double rope_time_s = 0.0;
    double flight_z_m = 0.0;  // simulated rope time since frame 0 (drives the gusts)
    wire::render::FrameStats wire_stats{};
    std::vector<float> bucket;
    engine::gfx::GpuTimer pieces_timer, wires_timer;  // GPU ms per pass, read back a few frames later
    std::map<uint64_t, std::pair<double, double>> gpu_results;  // frame -> (pieces, wires) ms, -1 = not yet
};

Level::Level() : state_(std::make_unique<State>()) {}
Level::~Level() = default;

glm::dvec3 Level::rope_end(int piece, std::size_t anchor, double inset_m) const {
    glm::dvec3 p = state_->anchors[anchor];
    p.x -= p.x < 0.0 ? -inset_m : inset_m;
    p.y += inset_m > 0.0 ? 0.03 : 0.0;
    p.z += kPieceLength * piece;
    return chain_.transform_point(p);
}

double Level::flight_z_m() const {
    return state_->flight_z_m;
}

int Level::piece_count() const {
    return static_cast<int>(state_->segments.size());
}
double Level::piece_length_m() const {
    return kPieceLength;
}
double Level::wall_radius_m() const {
    return kWallRadius;
}

const wire::WireNodes& Level::cable_nodes(std::size_t cable) const {
    return state_->registry.get<wire::systems::Nodes>(cables_[cable].entity);
}

glm::dvec3 Level::anchor_world(int piece, std::size_t anchor) const {
    glm::dvec3 p = state_->anchors[anchor];
    p.z += kPieceLength * piece;
    return chain_.transform_point(p);
}

Expected<std::unique_ptr<Level>> Level::create(const LevelSettings& settings_in) {
    LevelSettings settings = settings_in;
    if (settings.pieces <= 0) settings.pieces = 16;
    if (settings.seed == 0) settings.seed = 1;
    if (settings.bend_scale == 0.0) settings.bend_scale = 1.0;
    if (settings.asset_dir.empty()) settings.asset_dir = TUNNEL_ASSET_DIR;
    if (settings.max_subdivision_level < 0) settings.max_subdivision_level = 3;
    settings.max_subdivision_level =
        std::min(settings.max_subdivision_level, engine::assets::kMaxSubdivisionLevel);
    if (settings.prewarm_s == 0.0) settings.prewarm_s = 3.0;

    std::unique_ptr<Level> level(new Level());
    State& s = *level->state_;
    s.settings = settings;

    // ---- pieces: load, group, refine every cached level once, upload ----
    auto pieces = PieceRenderer::create();
    if (!pieces) return pieces.error();
    s.pieces = std::move(pieces).value();

    std::vector<engine::assets::MeshData> meshes;
    for (const char* file : {"straight_section.glb", "wall_details.glb", "cable_hooks.glb"}) {
        const std::string path = settings.asset_dir + "/" + file;
        std::vector<engine::assets::MeshData> file_meshes;  // read_gltf replaces its output
        if (auto st = engine::assets::read_gltf(path, file_meshes); !st.ok()) return Error{st.message};
        for (auto& m : file_meshes) meshes.push_back(std::move(m));
    }
    s.groups = {{.name = "wall", .surface = Surface::concrete, .albedo = {0.62f, 0.60f, 0.56f}},
                {.name = "ribs", .surface = Surface::steel, .albedo = {0.26f, 0.28f, 0.31f}},
                {.name = "walkway", .surface = Surface::grating, .albedo = {0.55f, 0.50f, 0.42f}},
                {.name = "hooks", .surface = Surface::steel, .albedo = {0.90f, 0.72f, 0.12f}}};
    for (const engine::assets::MeshData& m : meshes) {
        Group* g = m.name == "tunnel_wall"           ? &s.groups[0]
                   : m.name.rfind("rib_", 0) == 0    ? &s.groups[1]
                   : m.name == "walkway"             ? &s.groups[2]
                   : m.name.rfind("anchor_", 0) == 0 ? &s.groups[3]
                                                     : nullptr;
        if (g == nullptr) continue;
        engine::assets::ControlMesh control;
        if (auto st = engine::assets::make_control_mesh(m, control); !st.ok()) return Error{st.message};
        g->model = merge(g->model, engine::assets::refinement_error_model(control));
        g->controls.push_back(std::move(control));
    }
    for (Group& g : s.groups) {
        if (g.controls.empty()) return Error{settings.asset_dir + ": no mesh for the tunnel " + g.name};
        for (int lvl = 0; lvl <= settings.max_subdivision_level; ++lvl) {
            engine::assets::MeshData combined;
            combined.name = g.name;
            for (const engine::assets::ControlMesh& c : g.controls) {
                engine::assets::MeshData refined;
                if (auto st = engine::assets::subdivide(c, lvl, refined); !st.ok()) return Error{st.message};
                append(combined, refined);
            }
            auto handle = s.pieces.add_mesh(combined, g.name + " level " + std::to_string(lvl));
            if (!handle) return handle.error();
            g.meshes.push_back(handle.value());
            g.vertices.push_back(combined.vertex_count());
        }
    }

    // ---- anchors ----
    {
        const std::string path = settings.asset_dir + "/anchors.json";
        std::ifstream in(path);
        if (!in) return Error{path + ": cannot open"};
        std::stringstream text;
        text << in.rdbuf();
        const nlohmann::json doc = nlohmann::json::parse(text.str(), nullptr, false);
        if (doc.is_discarded() || !doc.contains("anchors") || !doc["anchors"].is_array())
            return Error{path + ": expected {\"anchors\": [...]}"};
        for (const auto& a : doc["anchors"]) {
            const auto& p = a.at("position");
            s.anchors.emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
        }
        if (s.anchors.size() != 8) return Error{path + ": expected 8 anchors (4 per wall)"};
    }

    // ---- the chain: an S-shaped run of bends, each wobbling slowly in angle and direction ----
    for (int i = 0; i < settings.pieces; ++i) {
        const auto u = static_cast<uint32_t>(i) * 8u + settings.seed * 7919u;
        SegmentAnimation a;
        // Straight-ish first piece (the camera starts there), then an S: left, right, left...
        a.base_angle = settings.bend_scale * 0.30 * std::sin(0.9 + 0.45 * i) * std::min(1.0, 0.4 * i);
        a.angle_amp = 0.05 + 0.03 * hash01(u + 1);
        a.angle_freq = 0.5 + 0.4 * hash01(u + 2);
        a.angle_phase = 2.0 * kPi * hash01(u + 3);
        a.dir_amp = 0.25 + 0.15 * hash01(u + 4);
        a.dir_freq = 0.25 + 0.2 * hash01(u + 5);
        a.dir_phase = 2.0 * kPi * hash01(u + 6);
        s.animation.push_back(a);
        s.segments.push_back({.length_m = kPieceLength, .angle_rad = a.base_angle, .direction_rad = 0.0});
    }
    level->animate(0.0);

    // ---- wire renderer and materials ----
    auto renderer = wire::render::WireRenderer::create();
    if (!renderer) return renderer.error();
    s.wires = std::move(renderer).value();
    s.pieces_timer = engine::gfx::GpuTimer::create();
    s.wires_timer = engine::gfx::GpuTimer::create();
    s.wires.add_material({.tint = {0.16f, 0.16f, 0.17f}});  // rubber
    s.wires.add_material({.tint = {1.00f, 0.45f, 0.12f}});  // orange
    s.wires.add_material({.tint = {0.95f, 0.80f, 0.15f}});  // yellow
    s.wires.add_material({.tint = {0.20f, 0.40f, 0.95f}});  // blue
    s.wires.add_material({.tint = {0.85f, 0.15f, 0.12f}});  // red

    // ---- cables fixed along the walls: through the hooks, above them, and high on each wall ----
    const double total = kPieceLength * settings.pieces;
    const glm::dvec3 hook = s.anchors[0];
    struct FixedSpec {
        double x, y;
        uint32_t material;
        float radius;
    };
    const FixedSpec fixed_specs[] = {{hook.x, hook.y, rubber, 0.035f},
                                     {-hook.x, hook.y, blue, 0.03f},
                                     {hook.x + 0.02, hook.y + 0.075, copper, 0.022f},
                                     {-hook.x - 0.02, hook.y + 0.075, red, 0.022f},
                                     {-2.02, 1.05, yellow, 0.025f},
                                     {2.02, 1.05, rubber, 0.03f}};
    for (const FixedSpec& f : fixed_specs) {
        wire::WireNodes nodes;
        for (double z = 0.0; z <= total + 1e-9; z += 0.5)
            nodes.positions.push_back(level->chain_.transform_point({f.x, f.y, z}));
        const auto e = wire::systems::spawn_wire(s.registry, std::move(nodes),
                                                 {.radius_m = f.radius, .material = f.material});
        s.fixed.push_back({f.x, f.y, level->cables_.size()});
        level->cables_.push_back(
            {.entity = e, .hanging = false, .material = f.material, .radius_m = f.radius});
    }

    // ---- hanging cables: festoons between the hooks of each wall, and a few across the tunnel ----
    auto add_rope = [&](int pa, std::size_t aa, int pb, std::size_t ab, double inset, double slack,
                        uint32_t material, float radius) {
        const glm::dvec3 a = level->rope_end(pa, aa, inset);
        const glm::dvec3 b = level->rope_end(pb, ab, inset);
        const double length = glm::length(b - a) * slack;
        level->ropes_.emplace_back(a, b, length, 8);
        wire::WireNodes nodes;
        level->ropes_.back().write_nodes(nodes);
        const auto e = wire::systems::spawn_wire(s.registry, std::move(nodes),
                                                 {.radius_m = radius, .material = material});
        s.rope_ends.push_back({pa, aa, pb, ab, level->cables_.size(),
                               level->chain_.world_from_segment(static_cast<std::size_t>(pa)), inset});
        level->cables_.push_back({.entity = e,
                                  .hanging = true,
                                  .across = (aa < 4) != (ab < 4),
                                  .rope = static_cast<int>(level->ropes_.size() - 1),
                                  .material = material,
                                  .radius_m = radius});
    };
    for (int k = 0; k < settings.pieces; ++k) {
        // Festoons hang from the hook lips, shallow enough to stay clear of the ribs (inner radius ~2.2 m).
        add_rope(k, 0, k, 3, 0.1, 1.03 + 0.02 * hash01(static_cast<uint32_t>(k) + 101u),
                 k % 2 == 0 ? orange : rubber, 0.02f);
        add_rope(k, 4, k, 7, 0.1, 1.03 + 0.02 * hash01(static_cast<uint32_t>(k) + 202u),
                 k % 2 == 0 ? rubber : red, 0.02f);
        // Cables across the tunnel (every other piece), and a diagonal one now and then.
        if (k % 2 == 1)
            add_rope(k, 1 + static_cast<std::size_t>(k % 4 == 1), k, 5 + static_cast<std::size_t>(k % 4 == 1),
                     0.0, 1.10, k % 4 == 1 ? yellow : orange, 0.025f);
        if (k % 4 == 2) add_rope(k, 0, k, 7, 0.0, 1.06, blue, 0.02f);
    }

    // Settle the ropes (fixed step, so every run starts from the same state).
    const double prewarm_dt = 1.0 / 60.0;
    level->options_.gusts = false;
    for (double t = 0.0; t < settings.prewarm_s; t += prewarm_dt) level->update_ropes(prewarm_dt);
    level->options_.gusts = true;
    s.rope_time_s = 0.0;
    level->update_cables();
    level->applied_ = level->options_;
    level->applied_.spline = wire::SplineKind::catmull_rom;
    level->apply_options();

    // ---- the frame's systems, in order ----
    Level* self = level.get();
    engine::ecs::Schedule schedule;
    schedule.add("tunnel.animate", [self](engine::ecs::Registry&, const engine::ecs::FrameContext& ctx) {
        self->apply_options();
        self->animate(ctx.dt_s);
    });
    schedule.add("tunnel.ropes", [self](engine::ecs::Registry&, const engine::ecs::FrameContext& ctx) {
        self->update_ropes(ctx.dt_s);
    });
    schedule.add("tunnel.cables",
                 [self](engine::ecs::Registry&, const engine::ecs::FrameContext&) { self->update_cables(); });
    wire::systems::install(schedule, s.context);
    schedule.add("tunnel.pieces",
                 [self](engine::ecs::Registry&, const engine::ecs::FrameContext&) { self->draw_pieces(); });
    schedule.add("wire.render",
                 [self](engine::ecs::Registry&, const engine::ecs::FrameContext&) { self->draw_wires(); });
    level->schedule_ = std::move(schedule);
    return level;
}

void Level::set_viewport(int width_px, int height_px) {
    state_->width_px = std::max(1, width_px);
    state_->height_px = std::max(1, height_px);
}

void Level::apply_options() {
    State& s = *state_;
    s.context.lod.tolerance_px = options_.lod_tolerance_px;
    s.context.path = options_.upload_path;
    s.context.pop_free = options_.pop_free;
    if (options_.spline != applied_.spline) {
        for (const CableInfo& c : cables_) {
            wire::systems::Style style = s.registry.get<wire::systems::Style>(c.entity);
            style.spline.kind = options_.spline;
            wire::systems::set_style(s.registry, c.entity, style);
        }
    }
    applied_ = options_;
}

void Level::animate(double dt_s) {
    State& s = *state_;
    if (options_.animate_bends) s.time_s += dt_s;
    const double t = s.time_s;
    for (std::size_t i = 0; i < s.segments.size(); ++i) {
        const SegmentAnimation& a = s.animation[i];
        s.segments[i].angle_rad = a.base_angle + a.angle_amp * std::sin(a.angle_freq * t + a.angle_phase);
        s.segments[i].direction_rad = a.dir_amp * std::sin(a.dir_freq * t + a.dir_phase);
    }
    (void)curved_space::make_chain(s.segments, chain_);  // finite lengths and angles by construction

    // Fly along the bent centre line, looking ahead; loop before the end.
    const double total = chain_.total_length_m();
    s.fly_distance_m += options_.flight_speed_mps * dt_s;
    const double span = std::max(1.0, total - 18.0);
    const double z = 3.0 + std::fmod(s.fly_distance_m, span);
    s.flight_z_m = z;
    camera_.aspect = static_cast<float>(s.width_px) / static_cast<float>(s.height_px);
    camera_.fov_y_rad = glm::radians(70.0f);
    camera_.near_m = 0.05f;
    camera_.far_m = 200.0f;
    if (options_.camera_mode == CameraMode::fly) {
        const curved_space::BentVertex eye = chain_.transform({0.0, 0.35, z}, {0.0, 1.0, 0.0});
        camera_.position = glm::vec3(eye.position);
        camera_.target = glm::vec3(chain_.transform_point({0.0, 0.05, z + 7.0}));
        camera_.up = glm::vec3(eye.normal);
    }
    s.context.camera = camera_;
    s.context.viewport_width_px = s.width_px;
    s.context.viewport_height_px = s.height_px;
}

void Level::update_ropes(double dt_s) {
    State& s = *state_;
    stats_.nodes_inserted = 0;
    stats_.nodes_removed = 0;
    stats_.rope_nodes = 0;
    wire::SplineSettings spline;
    spline.kind = options_.spline;
    // A gust front travels down the tunnel at kGustSpeed, one every period; ropes it passes are pushed toward
    // the tunnel axis (festoons) or along the tunnel (cross cables), bend, refine, straighten and coarsen.
    constexpr double kGustSpeed = 6.0;
    constexpr double kGustAccel = 15.0;
    constexpr double kGustWidth = 1.4;
    const double period = (chain_.total_length_m() + 16.0) / kGustSpeed;
    const double gust_z = -6.0 + kGustSpeed * std::fmod(s.rope_time_s, period);
    const bool gusting = options_.gusts && options_.simulate_ropes && s.rope_time_s > 0.0;
    if (options_.simulate_ropes) s.rope_time_s += dt_s;
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
        RopeEnds& e = s.rope_ends[r];
        // Carry the rope with its piece as the tunnel bends (the simulation sees only the motion relative to
        // the piece: a rope at the far end of a 64 m chain would otherwise be whipped around by metres).
        const glm::dmat4& now = chain_.world_from_segment(static_cast<std::size_t>(e.piece_a));
        ropes_[r].transform(now * glm::inverse(e.world_from_piece));
        e.world_from_piece = now;
        const glm::dvec3 a = rope_end(e.piece_a, e.anchor_a, e.inset_m);
        const glm::dvec3 b = rope_end(e.piece_b, e.anchor_b, e.inset_m);
        ropes_[r].set_ends(a, b);
        if (options_.simulate_ropes) {
            Rope::AccelerationField field;
            const double z0 = kPieceLength * e.piece_a;
            if (gusting && std::abs(z0 + 2.0 - gust_z) < 2.0 + 4.0 * kGustWidth) {
                const glm::dmat4 piece_from_world = glm::inverse(now);
                const glm::dvec3 anchor = s.anchors[e.anchor_a];
                const bool across = e.anchor_b >= 4 && e.anchor_a < 4;  // from one wall to the other
                const glm::dvec3 local_dir = glm::normalize(
                    across ? glm::dvec3(0.0, 0.25, 1.0) : glm::dvec3(anchor.x < 0.0 ? 1.0 : -1.0, 0.6, 0.0));
                const glm::dvec3 dir = glm::dmat3(now) * local_dir;
                field = [piece_from_world, dir, z0, gust_z](const glm::dvec3& p) {
                    const double z = z0 + (piece_from_world * glm::dvec4(p, 1.0)).z;
                    const double u = (z - gust_z) / kGustWidth;
                    return dir * (kGustAccel * std::exp(-u * u));
                };
            }
            ropes_[r].step(dt_s, field);
        }
        if (options_.adapt_ropes) {
            const AdaptResult changed = ropes_[r].adapt(spline);
            stats_.nodes_inserted += changed.inserted;
            stats_.nodes_removed += changed.removed;
        }
        stats_.rope_nodes += ropes_[r].size();
    }
}

void Level::update_cables() {
    State& s = *state_;
    for (const FixedCable& f : s.fixed) {
        wire::WireNodes& nodes = wire::systems::edit_nodes(s.registry, cables_[f.cable].entity);
        for (std::size_t i = 0; i < nodes.positions.size(); ++i)
            nodes.positions[i] = chain_.transform_point({f.x, f.y, 0.5 * static_cast<double>(i)});
    }
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
        ropes_[r].write_nodes(s.scratch);
        wire::systems::set_nodes(s.registry, cables_[s.rope_ends[r].cable].entity, s.scratch);
    }
}

namespace {
/// GPU time of one pass: begin() now, end() when the scope closes (early returns included).
struct GpuPass {
    engine::gfx::GpuTimer& timer;
    explicit GpuPass(engine::gfx::GpuTimer& t) : timer(t) { timer.begin(); }
    ~GpuPass() { timer.end(); }
    GpuPass(const GpuPass&) = delete;
    GpuPass& operator=(const GpuPass&) = delete;
};
}  // namespace

void Level::draw_pieces() {
    State& s = *state_;
    const GpuPass gpu_pass(s.pieces_timer);
    engine::gfx::clear({0.02f, 0.025f, 0.035f, 1.0f});
    stats_.piece_levels.fill(0);
    stats_.piece_triangles = 0;
    stats_.piece_vertices = 0;
    if (!options_.draw_pieces) return;

    const glm::dvec3 eye(camera_.position);
    const std::vector<curved_space::GpuSegment> records = curved_space::gpu_segments(chain_, eye);
    const glm::mat4 view_rel = glm::lookAt(glm::vec3(0.0f), camera_.target - camera_.position, camera_.up);
    PieceFrame frame{.clip_from_rel = camera_.projection() * view_rel,
                     .segments = records,
                     .to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.4f)),
                     .wireframe = options_.wireframe};
    stats_.segment_bytes_uploaded = s.pieces.begin(frame);

    // Per piece: visible? and the level its bend and its distance on screen need (the caches hold every
    // level).
    const engine::scene::Frustum frustum =
        engine::scene::Frustum::from_view_projection(camera_.view_projection());
    const double focal_px = camera_.focal_px(static_cast<float>(s.height_px));
    const int max_level = std::clamp(options_.max_subdivision_level, 0, s.settings.max_subdivision_level);
    const int n = piece_count();
    std::vector<std::array<int, 4>> levels(static_cast<std::size_t>(n), {-1, -1, -1, -1});
    for (int k = 0; k < n; ++k) {
        const double z0 = kPieceLength * k;
        const curved_space::Aabb box = chain_.bounds({{-2.7, -2.7, z0}, {2.7, 2.7, z0 + kPieceLength}});
        if (!frustum.intersects_aabb(glm::vec3(box.min), glm::vec3(box.max))) continue;
        // Distance from the eye to the wall of this piece: sample the bent centre line, measure along the
        // tangent and radially from it.
        double distance = 1e30;
        constexpr int kSamples = 8;
        for (int j = 0; j <= kSamples; ++j) {
            const double z = z0 + kPieceLength * j / kSamples;
            const glm::dvec3 c = chain_.transform_point({0.0, 0.0, z});
            const glm::dvec3 t = glm::normalize(chain_.transform_point({0.0, 0.0, z + 0.01}) - c);
            const glm::dvec3 v = eye - c;
            const double along = std::max(0.0, std::abs(glm::dot(v, t)) - 0.5 * kPieceLength / kSamples);
            const double radial = glm::length(v - glm::dot(v, t) * t);
            distance = std::min(distance,
                                std::sqrt(along * along + (kWallRadius - radial) * (kWallRadius - radial)));
        }
        const double curvature =
            std::abs(chain_.segment(static_cast<std::size_t>(k)).angle_rad) / kPieceLength;
        for (std::size_t g = 0; g < s.groups.size(); ++g) {
            levels[static_cast<std::size_t>(k)][g] = engine::assets::choose_subdivision_level(
                s.groups[g].model, {.curvature_per_m = curvature,
                                    .distance_m = distance,
                                    .focal_px = focal_px,
                                    .tolerance_px = options_.subdivision_tolerance_px,
                                    .max_level = max_level});
        }
        ++stats_.piece_levels[static_cast<std::size_t>(levels[static_cast<std::size_t>(k)][0])];
    }
    // Front to back for early depth rejection (llvmpipe shades only what survives): details in front of the
    // wall first, the wall last; near pieces (high levels) before far ones, instances in chain order.
    for (std::size_t g : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{0}}) {
        const Group& group = s.groups[g];
        for (int lvl = max_level; lvl >= 0; --lvl) {
            s.bucket.clear();
            for (int k = 0; k < n; ++k)
                if (levels[static_cast<std::size_t>(k)][g] == lvl)
                    s.bucket.push_back(static_cast<float>(kPieceLength * k));
            if (s.bucket.empty()) continue;
            const PieceRenderer::MeshHandle mesh = group.meshes[static_cast<std::size_t>(lvl)];
            s.pieces.draw(mesh, group.surface, group.albedo, s.bucket);
            stats_.piece_triangles += s.pieces.triangle_count(mesh) * s.bucket.size();
            stats_.piece_vertices += group.vertices[static_cast<std::size_t>(lvl)] * s.bucket.size();
        }
    }
    s.pieces.end();
}

void Level::draw_wires() {
    State& s = *state_;
    {
        const GpuPass gpu_pass(s.wires_timer);
        s.wire_stats = {};
        if (options_.draw_wires) {
            wire::render::FrameSettings settings;
            settings.light = {.to_light = {0.3f, 1.0f, 0.4f}, .ambient = 0.35f, .specular = 0.25f};
            settings.wireframe = options_.wireframe;
            s.wire_stats = s.wires.draw(s.context.draw_list, camera_, settings);
        }
    }
    // GPU ms of both passes: the newest frame whose two results are available, never waited for.
    for (const auto& m : s.pieces_timer.poll()) s.gpu_results.try_emplace(m.frame, -1.0, -1.0).first->second.first = m.ms;
    for (const auto& m : s.wires_timer.poll()) s.gpu_results.try_emplace(m.frame, -1.0, -1.0).first->second.second = m.ms;
    for (auto it = s.gpu_results.rbegin(); it != s.gpu_results.rend(); ++it) {
        if (it->second.first < 0.0 || it->second.second < 0.0) continue;
        stats_.gpu_ms_frame = static_cast<int64_t>(it->first);
        stats_.pieces_gpu_ms = it->second.first;
        stats_.wires_gpu_ms = it->second.second;
        s.gpu_results.erase(s.gpu_results.begin(), it.base());  // this frame and older
        break;
    }
    while (s.gpu_results.size() > 16) s.gpu_results.erase(s.gpu_results.begin());  // rejected results
    const wire::systems::FrameStats& ws = s.context.stats;
    stats_.wires = ws.wires;
    stats_.curves_built = ws.curves_built;
    stats_.rings = ws.rings;
    stats_.wires_drawn = s.wire_stats.draw_items;
    stats_.wire_vertices = s.wire_stats.vertices;
    stats_.wire_triangles = s.wire_stats.triangles;
    stats_.wire_bytes_uploaded = s.wire_stats.bytes_uploaded;
    stats_.wire_waited_for_gpu = s.wire_stats.waited_for_gpu;
}

void Level::frame(double dt_s) {
    schedule_.run(state_->registry, dt_s);
    stats_.frame = schedule_.frames() - 1;
    stats_.time_s = state_->time_s;
}

void Level::render() {
    draw_pieces();
    draw_wires();
}

}  // namespace tunnel
