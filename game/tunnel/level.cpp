// The tunnel level: see level.hpp.
#include "tunnel/level.hpp"

#include "tunnel/piece_renderer.hpp"

#include <curved_space/gpu.hpp>
#include <engine/assets/gltf.hpp>
#include <engine/assets/mesh_building.hpp>
#include <engine/assets/subdivide.hpp>
#include <engine/ecs/registry.hpp>
#include <engine/gfx/gpu_timer.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/scene/frustum.hpp>
#include <wire/curve.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/spline.hpp>
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
constexpr std::size_t kGroups = 5;  // wall, ribs, walkway, hooks, clips
constexpr glm::dvec2 kCloseUpEye{1.70,
                                 -0.20};  // unbent (x, y) of the eye at the closest point of the close-up

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
    engine::assets::MeshData top{};                   // refined at the highest cached level
    double inner_radius_m = 0.0;                      // smallest distance of `top` from the axis
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

// ---- contact geometry in the unbent tunnel space (see LevelShapes) ----

// Signed distance from q to the box [lo, hi] in 2D (negative inside) and the outward normal there.
double box_distance_2d(const glm::dvec2& q, const glm::dvec2& lo, const glm::dvec2& hi, glm::dvec2& normal) {
    const glm::dvec2 c = 0.5 * (lo + hi);
    const glm::dvec2 half = 0.5 * (hi - lo);
    const glm::dvec2 d = glm::abs(q - c) - half;
    const glm::dvec2 sign(q.x < c.x ? -1.0 : 1.0, q.y < c.y ? -1.0 : 1.0);
    if (d.x > 0.0 || d.y > 0.0) {
        const glm::dvec2 out(std::max(d.x, 0.0), std::max(d.y, 0.0));
        const double len = glm::length(out);
        normal = out * sign / len;
        return len;
    }
    if (d.x > d.y) {
        normal = {sign.x, 0.0};
        return d.x;
    }
    normal = {0.0, sign.y};
    return d.y;
}

// Closest points of segments p0-p1 and q0-q1: parameters s, t in [0, 1].
void closest_segments(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& q0, const glm::dvec3& q1,
                      double& s, double& t) {
    const glm::dvec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
    if (a <= 1e-18 && e <= 1e-18) {
        s = t = 0.0;
        return;
    }
    if (a <= 1e-18) {
        s = 0.0;
        t = std::clamp(f / e, 0.0, 1.0);
        return;
    }
    const double c = glm::dot(d1, r);
    if (e <= 1e-18) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
        return;
    }
    const double b = glm::dot(d1, d2);
    const double denom = a * e - b * b;
    s = denom > 1e-18 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    t = (b * s + f) / e;
    if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
}

// Length, in the bent space, of a unit step along the unbent direction n where the bend stretches z by
// z_scale (the cross-section is carried rigidly): a tube of radius r needs r / metric unbent clearance.
double bent_metric(const glm::dvec3& n, double z_scale) {
    return std::sqrt(n.x * n.x + n.y * n.y + z_scale * z_scale * n.z * n.z);
}

// Which shapes a query looks at (element_contact narrows them down per element).
struct Near {
    bool wall = true;
    bool ribs = true;
    bool walkway = true;
    uint32_t cables = ~0u;  // bit per wall cable
};

// The deepest contact of a point with the level geometry: signed distance (negative inside) and outward
// normal, unbent. Returns false when nothing is within `reach` of the point.
bool point_contact(const LevelShapes& g, double total_z, const glm::dvec3& p, double reach, double& distance,
                   glm::dvec3& normal, const Near& near = {}) {
    distance = 1e30;
    const double rho = std::sqrt(p.x * p.x + p.y * p.y);
    const glm::dvec3 radial = rho > 1e-12 ? glm::dvec3(p.x / rho, p.y / rho, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    // Wall: inside the cylinder.
    if (near.wall && g.wall_radius_m - rho < reach) {
        distance = g.wall_radius_m - rho;
        normal = -radial;
    }
    // Ribs: in (rho, z) the rectangle [rib_inner, wall] x [z0, z1] of every piece.
    if (near.ribs && rho > g.rib_inner_radius_m - reach) {
        const double zp = std::floor(p.z / kPieceLength) * kPieceLength;
        for (double base : {zp - kPieceLength, zp, zp + kPieceLength}) {
            if (base < -1e-9 || base > total_z - 1e-9) continue;
            for (const glm::dvec2& z : g.rib_z_m) {
                if (p.z < base + z.x - reach || p.z > base + z.y + reach) continue;
                glm::dvec2 n2;
                const double d = box_distance_2d({rho, p.z}, {g.rib_inner_radius_m, base + z.x},
                                                 {g.wall_radius_m + 1.0, base + z.y}, n2);
                if (d < distance) {
                    distance = d;
                    normal = n2.x * radial + glm::dvec3(0.0, 0.0, n2.y);
                }
            }
        }
    }
    // Walkway: a box in (x, y) along the whole tunnel.
    if (near.walkway) {
        glm::dvec2 n2;
        const double d = box_distance_2d({p.x, p.y}, g.walkway_min_m, g.walkway_max_m, n2);
        if (d < distance) {
            distance = d;
            normal = {n2.x, n2.y, 0.0};
        }
    }
    // Wall cables: cylinders along z.
    for (std::size_t i = 0; i < g.cables.size(); ++i) {
        if ((near.cables & (1u << i)) == 0) continue;
        const LevelShapes::Cable& c = g.cables[i];
        const glm::dvec2 v = glm::dvec2(p.x, p.y) - c.section_m;
        const double len = glm::length(v);
        const double d = len - c.radius_m;
        if (d < distance) {
            distance = d;
            normal = len > 1e-12 ? glm::dvec3(v.x / len, v.y / len, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
        }
    }
    return distance < reach;
}

// The deepest contact of the element a-b (a tube of radius r) with the level geometry. Candidate points
// along the element: its ends, quarter points, and the points closest to the shapes' corners (ribs in
// (rho, z), walkway in (x, y)) and to the wall cables' axes, where the deepest point of a straight element
// lies; `z_scale` is the bend's stretch of z (bent_metric).
bool element_contact(const LevelShapes& g, double total_z, const glm::dvec3& a, const glm::dvec3& b, double r,
                     double z_scale, tunnel::ElementContact& out) {
    constexpr double kReach = 0.04;
    const double m = r * 1.3 + kReach;  // r / bent_metric <= r / z_scale; z_scale >= 0.8 in this level
    const glm::dvec3 lo = glm::min(a, b) - m;
    const glm::dvec3 hi = glm::max(a, b) + m;
    // rho is convex along a segment: its largest value is at an end.
    const double rho_a = std::sqrt(a.x * a.x + a.y * a.y), rho_b = std::sqrt(b.x * b.x + b.y * b.y);
    Near near;
    near.wall = std::max(rho_a, rho_b) > g.wall_radius_m - m;
    near.ribs = std::max(rho_a, rho_b) > g.rib_inner_radius_m - m;
    near.walkway = lo.y < g.walkway_max_m.y && hi.y > g.walkway_min_m.y && lo.x < g.walkway_max_m.x &&
                   hi.x > g.walkway_min_m.x;
    near.cables = 0;
    for (std::size_t i = 0; i < g.cables.size(); ++i) {
        const LevelShapes::Cable& c = g.cables[i];
        if (lo.x < c.section_m.x + c.radius_m && hi.x > c.section_m.x - c.radius_m &&
            lo.y < c.section_m.y + c.radius_m && hi.y > c.section_m.y - c.radius_m)
            near.cables |= 1u << i;
    }
    if (!near.wall && !near.ribs && !near.walkway && near.cables == 0) return false;

    double ts[32];
    int nt = 0;
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) ts[nt++] = t;
    const glm::dvec3 d = b - a;
    auto closest_t_2d = [&](const glm::dvec2& p0, const glm::dvec2& p1, const glm::dvec2& q) {
        const glm::dvec2 e = p1 - p0;
        const double ee = glm::dot(e, e);
        return ee > 1e-18 ? std::clamp(glm::dot(q - p0, e) / ee, 0.0, 1.0) : 0.0;
    };
    // Walkway corners and cable axes in (x, y): the element projects to a straight segment there.
    const glm::dvec2 a2(a.x, a.y), b2(b.x, b.y);
    if (near.walkway)
        for (const glm::dvec2& c :
             {g.walkway_min_m, g.walkway_max_m, glm::dvec2(g.walkway_min_m.x, g.walkway_max_m.y),
              glm::dvec2(g.walkway_max_m.x, g.walkway_min_m.y)})
            ts[nt++] = closest_t_2d(a2, b2, c);
    for (std::size_t i = 0; i < g.cables.size(); ++i)
        if ((near.cables & (1u << i)) != 0 && nt < 32) ts[nt++] = closest_t_2d(a2, b2, g.cables[i].section_m);
    // Rib corners in (rho, z): rho is nearly linear along a short element.
    if (near.ribs) {
        const glm::dvec2 ra(rho_a, a.z), rb(rho_b, b.z);
        for (double base = std::floor((lo.z - 1.0) / kPieceLength) * kPieceLength; base <= hi.z + 1.0;
             base += kPieceLength)
            for (const glm::dvec2& z : g.rib_z_m)
                for (double zc : {base + z.x, base + z.y})
                    if (zc > lo.z && zc < hi.z && nt < 32)
                        ts[nt++] = closest_t_2d(ra, rb, {g.rib_inner_radius_m, zc});
    }
    bool found = false;
    for (int i = 0; i < nt; ++i) {
        const glm::dvec3 p = a + ts[i] * d;
        double dist = 0.0;
        glm::dvec3 n;
        if (!point_contact(g, total_z, p, m, dist, n, near)) continue;
        const double depth = r / bent_metric(n, z_scale) - dist;
        if (depth > 0.0 && (!found || depth > out.depth_m)) {
            out = {ts[i], n, depth};
            found = true;
        }
    }
    return found;
}

struct RopeEnds {
    int piece_a = 0;
    std::size_t anchor_a = 0;
    int piece_b = 0;
    std::size_t anchor_b = 0;
    std::size_t cable = 0;
    glm::dmat4 world_from_piece{1.0};  // the piece's frame when the rope was last moved with it
    double inset_m = 0.0;              // ends moved this far from the hook toward the axis (festoons)
    double lift_m = 0.0;               // ends raised this far (the cable rests on the hook)
    double z_scale = 1.0;              // smallest stretch of z by the bend over the rope's piece (this frame)
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
    LevelShapes shapes;
    std::vector<std::array<int, kGroups>> levels;  // per piece and group, -1: not visible
};

Level::Level() : state_(std::make_unique<State>()) {}
Level::~Level() = default;

glm::dvec3 Level::rope_end(int piece, std::size_t anchor, double inset_m, double lift_m) const {
    // Unbent: the ropes are simulated in the unbent tunnel space.
    glm::dvec3 p = state_->anchors[anchor];
    p.x -= p.x < 0.0 ? -inset_m : inset_m;
    p.y += inset_m > 0.0 ? 0.03 : lift_m;
    p.z += kPieceLength * piece;
    return p;
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

Expected<std::unique_ptr<Level>> Level::create(const LevelSettings& settings_in) {
    LevelSettings settings = settings_in;
    if (settings.pieces <= 0) settings.pieces = 16;
    if (settings.seed == 0) settings.seed = 1;
    if (settings.bend_scale == 0.0) settings.bend_scale = 1.0;
    if (settings.asset_dir.empty()) settings.asset_dir = TUNNEL_ASSET_DIR;
    if (settings.max_subdivision_level < 0) settings.max_subdivision_level = 4;
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
                {.name = "hooks", .surface = Surface::steel, .albedo = {0.90f, 0.72f, 0.12f}},
                {.name = "clips", .surface = Surface::steel, .albedo = {0.42f, 0.44f, 0.47f}}};
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
    auto refine = [&](Group& g) -> engine::assets::Status {
        for (int lvl = 0; lvl <= settings.max_subdivision_level; ++lvl) {
            engine::assets::MeshData combined;
            combined.name = g.name;
            for (const engine::assets::ControlMesh& c : g.controls) {
                engine::assets::MeshData refined;
                if (auto st = engine::assets::subdivide(c, lvl, refined); !st.ok()) return st;
                append(combined, refined);
            }
            auto handle = s.pieces.add_mesh(combined, g.name + " level " + std::to_string(lvl));
            if (!handle) return engine::assets::Status::failure(handle.error().message);
            g.meshes.push_back(handle.value());
            g.vertices.push_back(combined.vertex_count());
            if (lvl == settings.max_subdivision_level) {
                g.inner_radius_m = 1e30;
                for (std::size_t v = 0; v < combined.vertex_count(); ++v)
                    g.inner_radius_m = std::min<double>(
                        g.inner_radius_m,
                        std::hypot(combined.positions[3 * v], combined.positions[3 * v + 1]));
                g.top = std::move(combined);
            }
        }
        return {};
    };
    for (std::size_t gi = 0; gi + 1 < kGroups; ++gi) {
        Group& g = s.groups[gi];
        if (g.controls.empty()) return Error{settings.asset_dir + ": no mesh for the tunnel " + g.name};
        if (auto st = refine(g); !st.ok()) return Error{st.message};
    }
    // What the ropes collide with, measured on the refined meshes (within a fraction of a millimetre of the
    // limit surfaces at level 4; the wall's and ribs' refined polygons lie inside their limit circles).
    LevelShapes& shapes = s.shapes;
    shapes.wall_radius_m = s.groups[0].inner_radius_m;
    shapes.rib_inner_radius_m = s.groups[1].inner_radius_m;
    for (const engine::assets::ControlMesh& c : s.groups[1].controls) {
        double z0 = 1e30, z1 = -1e30;
        for (std::size_t v = 2; v < c.positions.size(); v += 3) {
            z0 = std::min(z0, c.origin.z + c.positions[v]);
            z1 = std::max(z1, c.origin.z + c.positions[v]);
        }
        shapes.rib_z_m.emplace_back(z0, z1);
    }
    {
        const engine::assets::MeshData& w = s.groups[2].top;
        shapes.walkway_min_m = glm::dvec2(1e30);
        shapes.walkway_max_m = glm::dvec2(-1e30);
        for (std::size_t v = 0; v < w.vertex_count(); ++v) {
            const glm::dvec2 q(w.origin.x + w.positions[3 * v], w.origin.y + w.positions[3 * v + 1]);
            shapes.walkway_min_m = glm::min(shapes.walkway_min_m, q);
            shapes.walkway_max_m = glm::max(shapes.walkway_max_m, q);
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

    // ---- cables fixed along the walls, on clips on the ribs' inner faces: just above the hooks, and high on
    // each wall. A clip holds its cable kClipGap clear of the rib (no cable touches a rib); the clips are a
    // fifth piece group, refined like the others.
    const double total = kPieceLength * settings.pieces;
    struct FixedSpec {
        double side, y;  // side -1 left, +1 right; height of the cable's axis
        uint32_t material;
        float radius;
    };
    const FixedSpec fixed_specs[] = {{-1.0, -0.06, rubber, 0.035f}, {1.0, -0.06, blue, 0.03f},
                                     {-1.0, 0.06, copper, 0.022f},  {1.0, 0.05, red, 0.022f},
                                     {-1.0, 1.05, yellow, 0.025f},  {1.0, 1.05, rubber, 0.03f}};
    constexpr double kClipGap = 0.012;
    engine::assets::MeshData clips;
    clips.name = "clips";
    for (const FixedSpec& f : fixed_specs) {
        const double rho = shapes.rib_inner_radius_m - f.radius - kClipGap;
        const double x = f.side * std::sqrt(rho * rho - f.y * f.y);
        const glm::dvec3 u = glm::normalize(glm::dvec3(x, f.y, 0.0));  // radial
        const glm::dvec3 w(0.0, 0.0, 1.0);
        const glm::dvec3 v = glm::cross(w, u);
        // Saddle from the cable's axis into the rib; as wide as the cable plus 8 mm, 8 cm along the tunnel.
        const double r0 = rho - 0.3 * f.radius;
        const double r1 = shapes.rib_inner_radius_m + 0.02;
        for (const glm::dvec2& rz : shapes.rib_z_m)
            engine::assets::add_box(clips, glm::dvec3(0.0, 0.0, 0.5 * (rz.x + rz.y)) + u * (0.5 * (r0 + r1)), u, v, w,
                    {0.5 * (r1 - r0), f.radius + 0.008, 0.04});
        wire::WireNodes nodes;
        for (double z = 0.0; z <= total + 1e-9; z += 0.5)
            nodes.positions.push_back(level->chain_.transform_point({x, f.y, z}));
        const auto e = wire::systems::spawn_wire(s.registry, std::move(nodes),
                                                 {.radius_m = f.radius, .material = f.material});
        s.fixed.push_back({x, f.y, level->cables_.size()});
        shapes.cables.push_back({{x, f.y}, f.radius});
        level->cables_.push_back({.entity = e,
                                  .hanging = false,
                                  .material = f.material,
                                  .radius_m = f.radius,
                                  .section_m = {x, f.y}});
    }
    {
        Group& g = s.groups[4];
        engine::assets::ControlMesh control;
        if (auto st = engine::assets::make_control_mesh(clips, control); !st.ok()) return Error{st.message};
        g.model = engine::assets::refinement_error_model(control);
        g.controls.push_back(std::move(control));
        if (auto st = refine(g); !st.ok()) return Error{st.message};
    }

    // ---- hanging cables: festoons between the hooks of each wall, and a few across the tunnel ----
    auto add_rope = [&](int pa, std::size_t aa, int pb, std::size_t ab, double inset, double slack,
                        uint32_t material, float radius) {
        const double lift = inset > 0.0 ? 0.0 : radius;  // resting on the hook's arm
        const glm::dvec3 a = level->rope_end(pa, aa, inset, lift);
        const glm::dvec3 b = level->rope_end(pb, ab, inset, lift);
        const double length = glm::length(b - a) * slack;
        level->ropes_.emplace_back(a, b, length, 8, RopeSettings{.radius_m = radius});
        wire::WireNodes nodes;
        level->ropes_.back().write_nodes(nodes);
        for (glm::dvec3& p : nodes.positions) p = level->chain_.transform_point(p);
        const auto e = wire::systems::spawn_wire(s.registry, std::move(nodes),
                                                 {.radius_m = radius, .material = material});
        s.rope_ends.push_back({pa, aa, pb, ab, level->cables_.size(),
                               level->chain_.world_from_segment(static_cast<std::size_t>(pa)), inset, lift});
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
    const double prewarm_dt = 1.0 / 30.0;
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
        // Close-up (unbent z 7.5..14, frames ~55..130 of the default run): the camera glides to the right
        // wall, past the festoon of piece 2 and the wall cables, looking at them, then back to the axis.
        auto smooth = [](double e0, double e1, double x) {
            const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
            return t * t * (3.0 - 2.0 * t);
        };
        const double u = options_.close_up ? smooth(7.5, 9.5, z) * (1.0 - smooth(12.5, 14.0, z)) : 0.0;
        const glm::dvec3 eye_unbent(kCloseUpEye.x * u, 0.35 + (kCloseUpEye.y - 0.35) * u, z);
        const glm::dvec3 look =
            glm::mix(glm::dvec3(0.0, 0.05, z + 7.0), glm::dvec3(2.2, -0.45, z + 2.0), 0.8 * u);
        const curved_space::BentVertex eye = chain_.transform(eye_unbent, {0.0, 1.0, 0.0});
        camera_.position = glm::vec3(eye.position);
        camera_.target = glm::vec3(chain_.transform_point(look));
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
    const double total_z = chain_.total_length_m();
    const std::size_t n = ropes_.size();

    // The ropes live in the unbent tunnel space: their ends stay on the hooks, the level geometry is made of
    // simple shapes. What the bend changes: the direction of gravity (the piece tilts) and the stretch of z.
    std::vector<Rope::AccelerationField> fields(n);
    std::vector<Collider> colliders(n);
    for (std::size_t r = 0; r < n; ++r) {
        RopeEnds& e = s.rope_ends[r];
        ropes_[r].set_ends(rope_end(e.piece_a, e.anchor_a, e.inset_m, e.lift_m),
                           rope_end(e.piece_b, e.anchor_b, e.inset_m, e.lift_m));
        const double zc = kPieceLength * (e.piece_a + 0.5);
        const glm::dvec3 c = chain_.transform_point({0.0, 0.0, zc});
        constexpr double kEps = 1e-3;
        glm::dmat3 jacobian;
        for (int k = 0; k < 3; ++k) {
            glm::dvec3 d(0.0);
            d[k] = kEps;
            jacobian[k] = (chain_.transform_point(glm::dvec3(0.0, 0.0, zc) + d) - c) / kEps;
        }
        e.z_scale = 1.0;
        for (const glm::dvec2& q : {glm::dvec2(2.4, 0.0), {-2.4, 0.0}, {0.0, 2.4}, {0.0, -2.4}})
            for (double z : {kPieceLength * e.piece_a, zc, kPieceLength * (e.piece_a + 1)}) {
                const glm::dvec3 p(q, z);
                e.z_scale =
                    std::min(e.z_scale, glm::length(chain_.transform_point(p + glm::dvec3(0, 0, kEps)) -
                                                    chain_.transform_point(p)) /
                                            kEps);
            }
        // Gravity (world -y) seen in the unbent space at the rope's piece, minus the -y the rope applies.
        const double g = ropes_[r].settings().gravity_mps2;
        const glm::dvec3 gravity = glm::inverse(jacobian) * glm::dvec3(0.0, -g, 0.0);
        const glm::dvec3 correction = gravity - glm::dvec3(0.0, -g, 0.0);
        const double z0 = kPieceLength * e.piece_a;
        if (gusting && std::abs(z0 + 2.0 - gust_z) < 2.0 + 4.0 * kGustWidth) {
            const glm::dvec3 anchor = s.anchors[e.anchor_a];
            const bool across = e.anchor_b >= 4 && e.anchor_a < 4;  // from one wall to the other
            const glm::dvec3 dir = glm::normalize(across ? glm::dvec3(0.0, 0.25, 1.0)
                                                         : glm::dvec3(anchor.x < 0.0 ? 1.0 : -1.0, 0.6, 0.0));
            fields[r] = [dir, gust_z, correction](const glm::dvec3& p) {
                const double u = (p.z - gust_z) / kGustWidth;
                return correction + dir * (kGustAccel * std::exp(-u * u));
            };
        } else {
            fields[r] = [correction](const glm::dvec3&) { return correction; };
        }
        const LevelShapes* shapes = &s.shapes;
        const double z_scale = e.z_scale;
        colliders[r] = [shapes, total_z, z_scale](const glm::dvec3& a, const glm::dvec3& b, double radius,
                                                  ElementContact& out) {
            return element_contact(*shapes, total_z, a, b, radius, z_scale, out);
        };
    }

    if (options_.simulate_ropes && dt_s > 0.0 && n > 0) {
        const RopeSettings& rs = ropes_[0].settings();
        // At most 1/30 s per step: a slow window frame (llvmpipe, up to 0.1 s) takes several, so the ropes
        // behave the same at any frame rate.
        const int steps = static_cast<int>(std::ceil(dt_s * 30.0 - 1e-9));
        const double h = dt_s / (steps * rs.substeps);
        // Rope pairs whose boxes come within reach of each other (checked per substep for their elements).
        struct Pair {
            std::size_t a, b, ea, eb;
        };
        std::vector<Pair> pairs;
        std::vector<glm::dvec3> lo(n), hi(n);
        for (int sub = 0; sub < rs.substeps * steps; ++sub) {
            for (std::size_t r = 0; r < n; ++r) ropes_[r].begin_substep(h, fields[r]);
            pairs.clear();
            constexpr double kReach = 0.08;
            for (std::size_t r = 0; r < n; ++r) {
                lo[r] = glm::dvec3(1e30);
                hi[r] = glm::dvec3(-1e30);
                for (const glm::dvec3& p : ropes_[r].positions()) {
                    lo[r] = glm::min(lo[r], p);
                    hi[r] = glm::max(hi[r], p);
                }
            }
            for (std::size_t a = 0; a < n; ++a)
                for (std::size_t b = a + 1; b < n; ++b) {
                    if (glm::any(glm::greaterThan(lo[a] - kReach, hi[b])) ||
                        glm::any(glm::greaterThan(lo[b] - kReach, hi[a])))
                        continue;
                    const auto& pa = ropes_[a].positions();
                    const auto& pb = ropes_[b].positions();
                    for (std::size_t i = 0; i + 1 < pa.size(); ++i) {
                        const glm::dvec3 al = glm::min(pa[i], pa[i + 1]) - kReach;
                        const glm::dvec3 ah = glm::max(pa[i], pa[i + 1]) + kReach;
                        for (std::size_t j = 0; j + 1 < pb.size(); ++j) {
                            const glm::dvec3 bl = glm::min(pb[j], pb[j + 1]);
                            const glm::dvec3 bh = glm::max(pb[j], pb[j + 1]);
                            if (glm::any(glm::greaterThan(al, bh)) || glm::any(glm::greaterThan(bl, ah)))
                                continue;
                            pairs.push_back({a, b, i, j});
                        }
                    }
                }
            for (int it = 0; it < rs.iterations; ++it) {
                for (std::size_t r = 0; r < n; ++r) ropes_[r].solve(it, colliders[r]);
                for (const Pair& q : pairs) {
                    const auto& pa = ropes_[q.a].positions();
                    const auto& pb = ropes_[q.b].positions();
                    double sa = 0.0, sb = 0.0;
                    closest_segments(pa[q.ea], pa[q.ea + 1], pb[q.eb], pb[q.eb + 1], sa, sb);
                    const glm::dvec3 d = (pa[q.ea] + sa * (pa[q.ea + 1] - pa[q.ea])) -
                                         (pb[q.eb] + sb * (pb[q.eb + 1] - pb[q.eb]));
                    const double len = glm::length(d);
                    if (len < 1e-9) continue;
                    const glm::dvec3 nrm = d / len;
                    const double clear =
                        (ropes_[q.a].settings().radius_m + ropes_[q.b].settings().radius_m) /
                        bent_metric(nrm, std::min(s.rope_ends[q.a].z_scale, s.rope_ends[q.b].z_scale));
                    if (len < clear)
                        Rope::separate(ropes_[q.a], q.ea, sa, ropes_[q.b], q.eb, sb, nrm, clear - len);
                }
            }
            for (std::size_t r = 0; r < n; ++r) ropes_[r].end_substep();
        }
    }
    for (std::size_t r = 0; r < n; ++r) {
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
    // Turns, on the bent nodes the wire systems draw.
    stats_.rope_max_turn_deg = 0.0;
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
        ropes_[r].write_nodes(s.scratch);
        auto& x = s.scratch.positions;
        for (glm::dvec3& p : x) p = chain_.transform_point(p);
        for (std::size_t i = 1; i + 1 < x.size(); ++i) {
            const glm::dvec3 a = x[i] - x[i - 1];
            const glm::dvec3 b = x[i + 1] - x[i];
            const double la = glm::length(a), lb = glm::length(b);
            if (la < 1e-12 || lb < 1e-12) continue;
            const double turn = std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0)) * 180.0 / kPi;
            stats_.rope_max_turn_deg = std::max(stats_.rope_max_turn_deg, turn);
        }
        wire::systems::set_nodes(s.registry, cables_[s.rope_ends[r].cable].entity, s.scratch);
    }
    measure_ropes();
}

void Level::measure_ropes() {
    State& s = *state_;
    const double total_z = chain_.total_length_m();
    wire::SplineSettings spline;
    spline.kind = options_.spline;
    // Penetration of the rendered tube: the curve the wire systems build through the nodes (built here in the
    // unbent space, 8 samples per segment), distances to the shapes measured between bent points.
    std::vector<std::vector<glm::dvec3>> samples(ropes_.size());
    double deepest = 0.0;
    wire::WireNodes nodes;
    wire::Curve curve;
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
        ropes_[r].write_nodes(nodes);
        if (!wire::build_curve(nodes, spline, curve).ok) continue;
        for (const wire::CubicBezier& seg : curve.segments)
            for (int k = 0; k < 8; ++k) samples[r].push_back(wire::position(seg, k / 8.0));
        samples[r].push_back(nodes.positions.back());
        const double radius = ropes_[r].settings().radius_m;
        // The pinned ends rest on their hooks: skip the samples within 2 radii of an end.
        const glm::dvec3 ea = nodes.positions.front(), eb = nodes.positions.back();
        for (const glm::dvec3& p : samples[r]) {
            if (glm::length(p - ea) < 2.0 * radius || glm::length(p - eb) < 2.0 * radius) continue;
            double d = 0.0;
            glm::dvec3 nrm;
            if (!point_contact(s.shapes, total_z, p, 2.0 * radius, d, nrm)) continue;
            const double bent = glm::length(chain_.transform_point(p) - chain_.transform_point(p - d * nrm));
            const double pen = radius - (d >= 0.0 ? bent : -bent);
            deepest = std::max(deepest, pen);
        }
    }
    std::vector<glm::dvec3> lo(ropes_.size(), glm::dvec3(1e30)), hi(ropes_.size(), glm::dvec3(-1e30));
    for (std::size_t r = 0; r < ropes_.size(); ++r)
        for (const glm::dvec3& p : samples[r]) {
            lo[r] = glm::min(lo[r], p);
            hi[r] = glm::max(hi[r], p);
        }
    for (std::size_t a = 0; a < ropes_.size(); ++a)
        for (std::size_t b = a + 1; b < ropes_.size(); ++b) {
            const auto& pa = samples[a];
            const auto& pb = samples[b];
            if (pa.size() < 2 || pb.size() < 2) continue;
            const double clear = ropes_[a].settings().radius_m + ropes_[b].settings().radius_m;
            if (glm::any(glm::greaterThan(lo[a] - clear, hi[b])) ||
                glm::any(glm::greaterThan(lo[b] - clear, hi[a])))
                continue;
            for (std::size_t i = 0; i + 1 < pa.size(); ++i)
                for (std::size_t j = 0; j + 1 < pb.size(); ++j) {
                    const glm::dvec3 al = glm::min(pa[i], pa[i + 1]) - clear,
                                     ah = glm::max(pa[i], pa[i + 1]) + clear;
                    const glm::dvec3 bl = glm::min(pb[j], pb[j + 1]), bh = glm::max(pb[j], pb[j + 1]);
                    if (glm::any(glm::greaterThan(al, bh)) || glm::any(glm::greaterThan(bl, ah))) continue;
                    double sa = 0.0, sb = 0.0;
                    closest_segments(pa[i], pa[i + 1], pb[j], pb[j + 1], sa, sb);
                    const glm::dvec3 p = pa[i] + sa * (pa[i + 1] - pa[i]);
                    const glm::dvec3 q = pb[j] + sb * (pb[j + 1] - pb[j]);
                    const double pen =
                        clear - glm::length(chain_.transform_point(p) - chain_.transform_point(q));
                    deepest = std::max(deepest, pen);
                }
        }
    stats_.rope_penetration_m = deepest;
    // Close-up distances: eye to the nearest rope and wall cable centre lines.
    const glm::dvec3 eye(camera_.position);
    stats_.camera_rope_m = 1e30;
    for (std::size_t r = 0; r < ropes_.size(); ++r)
        for (const glm::dvec3& p : samples[r])
            stats_.camera_rope_m =
                std::min(stats_.camera_rope_m, glm::length(chain_.transform_point(p) - eye));
    stats_.camera_cable_m = 1e30;
    const double z_eye = s.flight_z_m;
    for (const FixedCable& f : s.fixed)
        for (double z = z_eye - 1.0; z <= z_eye + 1.0; z += 0.02)
            stats_.camera_cable_m =
                std::min(stats_.camera_cable_m, glm::length(chain_.transform_point({f.x, f.y, z}) - eye));
}

void Level::choose_piece_levels() {
    State& s = *state_;
    stats_.piece_levels.fill(0);
    stats_.piece_max_error_px = 0.0;
    const glm::dvec3 eye(camera_.position);
    // Per piece: visible? and the level its bend and its distance on screen need, per group (the caches
    // hold every level up to the cap). The distance of a group: along the bent centre line to the piece, and
    // radially from the eye to the group's innermost surface (the wall's, the ribs' inner faces, ...).
    const engine::scene::Frustum frustum =
        engine::scene::Frustum::from_view_projection(camera_.view_projection());
    const double focal_px = camera_.focal_px(static_cast<float>(s.height_px));
    const int max_level = std::clamp(options_.max_subdivision_level, 0, s.settings.max_subdivision_level);
    const int n = piece_count();
    s.levels.assign(static_cast<std::size_t>(n), {-1, -1, -1, -1, -1});
    for (int k = 0; k < n; ++k) {
        const double z0 = kPieceLength * k;
        const curved_space::Aabb box = chain_.bounds({{-2.7, -2.7, z0}, {2.7, 2.7, z0 + kPieceLength}});
        if (!frustum.intersects_aabb(glm::vec3(box.min), glm::vec3(box.max))) continue;
        std::array<double, kGroups> distance;
        distance.fill(1e30);
        constexpr int kSamples = 8;
        for (int j = 0; j <= kSamples; ++j) {
            const double z = z0 + kPieceLength * j / kSamples;
            const glm::dvec3 c = chain_.transform_point({0.0, 0.0, z});
            const glm::dvec3 t = glm::normalize(chain_.transform_point({0.0, 0.0, z + 0.01}) - c);
            const glm::dvec3 v = eye - c;
            const double along = std::max(0.0, std::abs(glm::dot(v, t)) - 0.5 * kPieceLength / kSamples);
            const double radial = glm::length(v - glm::dot(v, t) * t);
            for (std::size_t g = 0; g < kGroups; ++g) {
                const double gap = std::max(0.0, s.groups[g].inner_radius_m - radial);
                distance[g] = std::min(distance[g], std::sqrt(along * along + gap * gap));
            }
        }
        const double curvature =
            std::abs(chain_.segment(static_cast<std::size_t>(k)).angle_rad) / kPieceLength;
        for (std::size_t g = 0; g < kGroups; ++g) {
            const int level = engine::assets::choose_subdivision_level(
                s.groups[g].model, {.curvature_per_m = curvature,
                                    .distance_m = distance[g],
                                    .focal_px = focal_px,
                                    .tolerance_px = options_.subdivision_tolerance_px,
                                    .max_level = max_level});
            s.levels[static_cast<std::size_t>(k)][g] = level;
            const double error_px = engine::assets::predicted_error_m(s.groups[g].model, curvature, level) *
                                    focal_px / std::max(distance[g], 0.01);
            stats_.piece_max_error_px = std::max(stats_.piece_max_error_px, error_px);
        }
        ++stats_.piece_levels[static_cast<std::size_t>(s.levels[static_cast<std::size_t>(k)][0])];
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
    stats_.piece_triangles = 0;
    stats_.piece_vertices = 0;
    choose_piece_levels();
    if (!options_.draw_pieces) return;

    const glm::dvec3 eye(camera_.position);
    const std::vector<curved_space::GpuSegment> records = curved_space::gpu_segments(chain_, eye);
    const glm::mat4 view_rel = glm::lookAt(glm::vec3(0.0f), camera_.target - camera_.position, camera_.up);
    PieceFrame frame{.clip_from_rel = camera_.projection() * view_rel,
                     .segments = records,
                     .to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.4f)),
                     .wireframe = options_.wireframe};
    stats_.segment_bytes_uploaded = s.pieces.begin(frame);
    const int max_level = std::clamp(options_.max_subdivision_level, 0, s.settings.max_subdivision_level);
    const int n = piece_count();
    // Front to back for early depth rejection (llvmpipe shades only what survives): details in front of the
    // wall first, the wall last; near pieces (high levels) before far ones, instances in chain order.
    for (std::size_t g : {std::size_t{1}, std::size_t{4}, std::size_t{2}, std::size_t{3}, std::size_t{0}}) {
        const Group& group = s.groups[g];
        for (int lvl = max_level; lvl >= 0; --lvl) {
            s.bucket.clear();
            for (int k = 0; k < n; ++k)
                if (s.levels[static_cast<std::size_t>(k)][g] == lvl)
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
    for (const auto& m : s.pieces_timer.poll())
        s.gpu_results.try_emplace(m.frame, -1.0, -1.0).first->second.first = m.ms;
    for (const auto& m : s.wires_timer.poll())
        s.gpu_results.try_emplace(m.frame, -1.0, -1.0).first->second.second = m.ms;
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
