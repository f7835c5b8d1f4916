// The tunnel level (see level.hpp): creation in named steps, the frame's systems in order, accessors. The
// steps and systems live in the files named after their concepts:
//   piece_meshes.cpp    load, group, refine and upload the pieces; the contact shapes
//   level_animation.cpp the chain's bends and the fly camera (tunnel.animate)
//   level_cables.cpp    the fixed wall cables and their clips; all cables' wire nodes (tunnel.cables)
//   rope_driving.cpp    the hanging cables: spawned, settled, stepped (tunnel.ropes)
//   rope_contact.cpp    the contact geometry the ropes collide with
//   rope_metrics.cpp    turns, penetration and camera distances of the ropes
//   piece_lod.cpp       the subdivision level of each visible piece
//   level_render.cpp    the renderers; pieces and wires drawn and timed (tunnel.pieces, wire.render)
#include "tunnel/level.hpp"

#include "tunnel/level_state.hpp"

#include <engine/assets/subdivide.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#ifndef TUNNEL_ASSET_DIR
#define TUNNEL_ASSET_DIR "assets/tunnel"
#endif

namespace tunnel {

namespace {

// The settings with zero fields replaced by their defaults (see LevelSettings).
LevelSettings with_defaults(const LevelSettings& settings_in) {
    LevelSettings settings = settings_in;
    if (settings.pieces <= 0) settings.pieces = 16;
    if (settings.seed == 0) settings.seed = 1;
    if (settings.bend_scale == 0.0) settings.bend_scale = 1.0;
    if (settings.asset_dir.empty()) settings.asset_dir = TUNNEL_ASSET_DIR;
    if (settings.max_subdivision_level < 0) settings.max_subdivision_level = kDefaultMaxSubdivisionLevel;
    settings.max_subdivision_level =
        std::min(settings.max_subdivision_level, engine::assets::kMaxSubdivisionLevel);
    if (settings.prewarm_s == 0.0) settings.prewarm_s = 3.0;
    return settings;
}

// The 8 cable anchors of a piece (unbent, piece space) from anchors.json.
engine::Status read_anchors(const std::string& path, std::vector<glm::dvec3>& anchors) {
    std::ifstream in(path);
    if (!in) return Error{path + ": cannot open"};
    std::stringstream text;
    text << in.rdbuf();
    const nlohmann::json doc = nlohmann::json::parse(text.str(), nullptr, false);
    if (doc.is_discarded() || !doc.contains("anchors") || !doc["anchors"].is_array())
        return Error{path + ": expected {\"anchors\": [...]}"};
    for (const auto& a : doc["anchors"]) {
        const auto& p = a.at("position");
        anchors.emplace_back(p.at(0).get<double>(), p.at(1).get<double>(), p.at(2).get<double>());
    }
    if (anchors.size() != 8) return Error{path + ": expected 8 anchors (4 per wall)"};
    return {};
}

}  // namespace

Level::Level() : state_(std::make_unique<State>()) {}
Level::~Level() = default;

Expected<std::unique_ptr<Level>> Level::create(const LevelSettings& settings) {
    std::unique_ptr<Level> level(new Level());
    State& s = *level->state_;
    s.settings = with_defaults(settings);
    if (auto st = level->load_pieces(); !st) return st;
    if (auto st = read_anchors(s.settings.asset_dir + "/anchors.json", s.anchors); !st) return st;
    level->build_chain();
    level->animate(0.0);
    if (auto st = level->create_wire_renderer(); !st) return st;
    if (auto st = level->spawn_fixed_cables(); !st) return st;
    level->spawn_ropes();
    level->settle();
    level->install_systems();
    return level;
}

Status Level::load_pieces() {
    State& s = *state_;
    auto pieces = PieceRenderer::create();
    if (!pieces) return pieces.error();
    s.pieces = std::move(pieces).value();
    s.groups = make_groups();
    if (auto st = load_piece_meshes(s.settings.asset_dir, s.groups); !st) return st;
    for (std::size_t gi = 0; gi + 1 < kGroups; ++gi) {  // the clips come with the wall cables
        Group& g = s.groups[gi];
        if (g.controls.empty()) return Error{s.settings.asset_dir + ": no mesh for the tunnel " + g.name};
        if (auto st = refine_group(g, s.settings.max_subdivision_level, s.pieces); !st.ok())
            return Error{st.message};
    }
    s.shapes = measure_shapes(s.groups);
    return {};
}

// Settles the ropes (fixed step, so every run starts from the same state), then sets the cables' nodes and
// the options.
void Level::settle() {
    State& s = *state_;
    const double prewarm_dt = 1.0 / 30.0;
    options_.gusts = false;
    for (double t = 0.0; t < s.settings.prewarm_s; t += prewarm_dt) update_ropes(prewarm_dt);
    options_.gusts = true;
    s.rope_time_s = 0.0;
    update_cables();
    applied_ = options_;
    applied_.spline = wire::SplineKind::catmull_rom;
    apply_options();
}

// The frame's systems, in order.
void Level::install_systems() {
    State& s = *state_;
    Level* self = this;
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
    schedule.add("tunnel.shadows",
                 [self](engine::ecs::Registry&, const engine::ecs::FrameContext&) { self->draw_shadow_map(); });
    schedule.add("tunnel.pieces",
                 [self](engine::ecs::Registry&, const engine::ecs::FrameContext&) { self->draw_pieces(); });
    schedule.add("wire.render",
                 [self](engine::ecs::Registry&, const engine::ecs::FrameContext&) { self->draw_wires(); });
    schedule_ = std::move(schedule);
}

void Level::set_viewport(int width_px, int height_px) {
    State& s = *state_;
    s.width_px = std::max(1, width_px);
    s.height_px = std::max(1, height_px);
    // The predicted error of a piece on screen grows with the focal length in pixels (the viewport's height), and
    // each subdivision level divides it by about 4 (Catmull-Clark: the error falls as h^2): the cache holds
    // ceil(log4(height / 720)) levels more than at 720 p (4, where the default run stays within 0.5 px), so the
    // tolerance holds at any screen size (1080 p and 2160 p: 5). The per-frame clamp follows unless it was lowered.
    const double ratio = static_cast<double>(s.height_px) / 720.0;
    const int extra = ratio > 1.0 ? static_cast<int>(std::ceil(std::log(ratio) / std::log(4.0) - 1e-12)) : 0;
    const int need = std::min(engine::assets::kMaxSubdivisionLevel, kDefaultMaxSubdivisionLevel + extra);
    const int cached = s.settings.max_subdivision_level;
    if (need <= cached) return;
    for (Group& g : s.groups)
        if (auto st = extend_group(g, need, s.pieces); !st.ok()) {
            std::fprintf(stderr, "tunnel: cannot refine the pieces to level %d for %dx%d: %s\n", need, s.width_px,
                         s.height_px, st.message.c_str());
            return;  // the level keeps its cache; piece_max_error_px reports what that costs
        }
    s.settings.max_subdivision_level = need;
    if (options_.max_subdivision_level >= cached) options_.max_subdivision_level = need;
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

void Level::frame(double dt_s) {
    schedule_.run(state_->registry, dt_s);
    stats_.frame = schedule_.frames() - 1;
    stats_.time_s = state_->time_s;
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
const LevelShapes& Level::shapes() const {
    return state_->shapes;
}
const engine::assets::MeshData& Level::refined_mesh(std::size_t group) const {
    return state_->groups[group].top;
}

const wire::WireNodes& Level::cable_nodes(std::size_t cable) const {
    return state_->registry.get<wire::systems::Nodes>(cables_[cable].entity);
}

const wire::Curve& Level::cable_curve(std::size_t cable) const {
    return state_->registry.get<wire::systems::WireCurve>(cables_[cable].entity).curve;
}

glm::dvec3 Level::anchor_world(int piece, std::size_t anchor) const {
    glm::dvec3 p = state_->anchors[anchor];
    p.z += kPieceLength * piece;
    return chain_.transform_point(p);
}

}  // namespace tunnel
