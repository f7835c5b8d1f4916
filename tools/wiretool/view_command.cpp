// `wiretool view`: a wire file through the real runtime (wire entities in the ECS, the installed wire systems and
// the wire renderer in a headless GL context) to pixels, ring records and statistics. A contract:
// docs/wiretool.md.
#include "commands.hpp"
#include "ring_csv.hpp"

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/gfx/mesh.hpp>
#include <engine/gfx/shadow.hpp>
#include <engine/scene/light_view.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <wire/io/wire_json.hpp>
#include <wire/lod.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/spline.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/systems.hpp>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

namespace wiretool {
namespace {

using engine::ecs::Entity;

constexpr double kDefaultFovDeg = 60.0;
/// LodSettings::tolerance_px's documented default (0 -> 0.5 px); reported in the stats when --tolerance-px is not given.
constexpr double kRuntimeDefaultTolerancePx = 0.5;
constexpr double kFrameStepS = 1.0 / 60.0;
/// Reference points per curve segment for the measured screen error (as wire::systems::scene_screen_error).
constexpr int kErrorSamplesPerSegment = 64;
constexpr const char* kPerFrameToken = "%04d";

struct ViewOptions {
    std::string input;
    std::string camera;  ///< "EX,EY,EZ,TX,TY,TZ"
    std::optional<double> fov_deg;
    std::string size = "1280x720";
    std::optional<double> tolerance_px;
    std::optional<std::string> spline;
    std::string path;  ///< auto|cpu|nodes (gpu: retired, nodes); empty: auto
    std::string png_out, csv_out, stats_out;
    std::optional<double> ground_y;  ///< --ground: a horizontal plane at this height
    std::string light;               ///< --light DX,DY,DZ: toward the shadow-casting directional light
};

/// The light the view draws with: toward (0.3, 1, 0.4) unless --light says otherwise.
constexpr glm::dvec3 kDefaultToLight{0.3, 1.0, 0.4};
constexpr int kShadowMapPx = 2048;


/// A bad input or command line: exit 2, nothing written.
struct BadInput {
    std::string message;
};

std::string where(const std::string& file, std::size_t frame, std::size_t frames, std::size_t wire_index) {
    std::string s = file + ": ";
    if (frames > 1) s += "frame " + std::to_string(frame) + ", ";
    return s + "wire " + std::to_string(wire_index);
}

// ---- command-line values ----

bool parse_number(const std::string& text, double& out) {
    std::istringstream in(text);
    in >> out;
    return !in.fail() && in.peek() == std::char_traits<char>::eof() && std::isfinite(out);
}

std::pair<int, int> parse_size(const std::string& text) {
    if (const auto size = parse_size_wxh(text)) return *size;
    throw BadInput{"--size: expected WxH with whole numbers in [1, 16384], got '" + text + "'"};
}

/// The camera in effect for a frame (world metres, double).
struct CameraPose {
    glm::dvec3 eye{}, target{}, up{0, 1, 0};
    bool up_given = false;
    double fov_deg = kDefaultFovDeg;
};

/// `count` comma-separated finite numbers, or nothing.
std::optional<std::vector<double>> parse_numbers(const std::string& text, std::size_t count) {
    std::vector<double> v;
    bool numbers = !text.empty() && text.back() != ',';
    std::stringstream ss(text);
    for (std::string cell; numbers && std::getline(ss, cell, ',');) {
        double d = 0;
        numbers = parse_number(cell, d);
        v.push_back(d);
    }
    if (!numbers || v.size() != count) return std::nullopt;
    return v;
}

CameraPose parse_camera_option(const std::string& text) {
    const std::optional<std::vector<double>> parsed = parse_numbers(text, 6);
    if (!parsed)
        throw BadInput{"--camera: expected EX,EY,EZ,TX,TY,TZ (6 finite numbers), got '" + text + "'"};
    const std::vector<double>& v = *parsed;
    CameraPose c;
    c.eye = {v[0], v[1], v[2]};
    c.target = {v[3], v[4], v[5]};
    if (!(glm::length(c.target - c.eye) > 0.0)) throw BadInput{"--camera: eye and target must differ"};
    return c;
}

glm::dvec3 parse_light_option(const std::string& text) {
    const std::optional<std::vector<double>> v = parse_numbers(text, 3);
    if (!v) throw BadInput{"--light: expected DX,DY,DZ (3 finite numbers), got '" + text + "'"};
    const glm::dvec3 d{(*v)[0], (*v)[1], (*v)[2]};
    if (!(glm::length(d) > 0.0)) throw BadInput{"--light: the direction must not be zero"};
    return glm::normalize(d);
}

/// An up vector for lookAt: the given one, or +y, or (if +y is parallel to the view direction) -z / +z.
glm::dvec3 usable_up(const CameraPose& c) {
    const glm::dvec3 f = glm::normalize(c.target - c.eye);
    if (c.up_given || glm::length(glm::cross(f, c.up)) > 1e-6) return c.up;
    return f.y < 0 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 0, 1);
}

// ---- the scene ----

/// Sphere around a frame's nodes (the centre of their box, half its diagonal plus the largest radius).
struct Bounds {
    glm::dvec3 centre{};
    double radius_m = 0.0;
};

Bounds bounds_of(const wire::io::FrameSpec& frame, const std::vector<wire::systems::Style>& styles) {
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    double thickest = 0.0;
    for (std::size_t w = 0; w < frame.wires.size(); ++w) {
        for (const glm::dvec3& p : frame.wires[w].positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        thickest = std::max(thickest, static_cast<double>(styles[w].radius_m));
        for (float r : frame.wires[w].radius) thickest = std::max(thickest, static_cast<double>(r));
    }
    return {0.5 * (lo + hi), 0.5 * glm::length(hi - lo) + thickest};
}

/// Default camera: looks at the centre of the first frame's bounds from the front-right-above diagonal (+x, +y, +z),
/// far enough that the bounding sphere fits the narrower of the two fields of view.
CameraPose default_camera(const Bounds& b, double fov_deg, double aspect) {
    const double half_y = 0.5 * fov_deg * std::numbers::pi / 180.0;
    const double half_x = std::atan(std::tan(half_y) * aspect);
    const double r = std::max(b.radius_m, 1e-6);
    CameraPose c;
    c.target = b.centre;
    c.eye = b.centre + glm::normalize(glm::dvec3(1, 1, 1)) * (r / std::sin(std::min(half_x, half_y)));
    c.fov_deg = fov_deg;
    return c;
}

/// The runtime's Style for one wire of the file. The spline: --spline, else the file's type, else the runtime's
/// default (wire::SplineSettings{}); the rest of the spline settings from the file (wire_io's resolve_settings).
wire::systems::Style style_of(const wire::io::WireSpec& spec, const std::optional<std::string>& spline_override,
                              const std::string& at) {
    wire::io::SettingsOverrides overrides;
    overrides.spline_type = spline_override;
    wire::PipelineSettings resolved;
    if (engine::Status st = wire::io::resolve_settings(spec, overrides, resolved); !st.ok())
        throw BadInput{at + ": " + st.message};
    wire::systems::Style style;
    style.spline = resolved.spline;
    if (!spline_override && !spec.spline_type) {
        const wire::SplineSettings runtime_default{};
        style.spline.kind = runtime_default.kind;
        style.spline.alpha = runtime_default.kind == wire::SplineKind::catmull_rom && spec.alpha ? *spec.alpha
                                                                                                 : runtime_default.alpha;
    }
    if (spec.radius_m) style.radius_m = static_cast<float>(*spec.radius_m);
    if (spec.sides) style.max_sides = static_cast<uint32_t>(*spec.sides);
    style.closed = spec.closed.value_or(false);
    style.caps = spec.caps.value_or(true);
    return style;
}

bool same_style(const wire::systems::Style& a, const wire::systems::Style& b) {
    const wire::SplineSettings &x = a.spline, &y = b.spline;
    return a.radius_m == b.radius_m && a.max_sides == b.max_sides && a.material == b.material && a.caps == b.caps &&
           a.closed == b.closed && x.kind == y.kind && x.alpha == y.alpha && x.tension == y.tension &&
           x.bias == y.bias && x.continuity == y.continuity && x.curvature_tension == y.curvature_tension;
}

bool same_nodes(const wire::io::WireSpec& a, const wire::io::WireSpec& b) {
    if (a.positions != b.positions || a.ids != b.ids || a.stretch != b.stretch || a.radius != b.radius ||
        a.tcb != b.tcb || a.physics.size() != b.physics.size())
        return false;
    for (std::size_t i = 0; i < a.physics.size(); ++i) {
        const wire::io::NodePhysics &p = a.physics[i], &q = b.physics[i];
        if (p.theta != q.theta || p.Iz != q.Iz || p.L != q.L || p.dL != q.dL || p.A != q.A) return false;
    }
    return true;
}

// ---- outputs: written to temporary names, renamed into place only when everything succeeded ----

class Outputs {
public:
    ~Outputs() { discard(); }

    /// A temporary path beside `final_path` (same directory, so the rename is atomic).
    std::string stage(const std::string& final_path) {
        pending_.push_back({final_path, final_path + ".tmp"});
        return pending_.back().second;
    }
    [[nodiscard]] bool stage_text(const std::string& final_path, const std::string& text, std::string& error) {
        const std::string tmp = stage(final_path);
        std::filesystem::path parent = std::filesystem::path(final_path).parent_path();
        std::error_code ec;
        if (!parent.empty()) std::filesystem::create_directories(parent, ec);
        std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
        file.write(text.data(), static_cast<std::streamsize>(text.size()));
        file.close();
        if (!file) error = final_path + ": cannot write";
        return static_cast<bool>(file);
    }
    /// Renames every staged file into place; on a failure removes what was renamed and what was staged.
    [[nodiscard]] bool commit(std::string& error) {
        std::vector<std::string> done;
        for (const auto& [final_path, tmp] : pending_) {
            if (std::rename(tmp.c_str(), final_path.c_str()) != 0) {
                error = final_path + ": cannot write";
                for (const std::string& d : done) std::remove(d.c_str());
                discard();
                return false;
            }
            done.push_back(final_path);
        }
        pending_.clear();
        return true;
    }
    void discard() {
        for (const auto& p : pending_) std::remove(p.second.c_str());
        pending_.clear();
    }

private:
    std::vector<std::pair<std::string, std::string>> pending_;
};

std::string per_frame_path(const std::string& pattern, std::size_t frame) {
    char number[32];
    std::snprintf(number, sizeof number, "%04zu", frame);
    std::string s = pattern;
    for (std::size_t at = s.find(kPerFrameToken); at != std::string::npos; at = s.find(kPerFrameToken, at))
        s.replace(at, std::string(kPerFrameToken).size(), number);
    return s;
}

// ---- the run ----

struct Failure {
    int status;
    std::string message;
};

int run_view(const ViewOptions& o) try {
    // 1. Everything the command line and the file say, checked before anything runs or is written.
    const auto [width, height] = parse_size(o.size);
    const double aspect = static_cast<double>(width) / height;
    std::optional<CameraPose> cli_camera;
    if (!o.camera.empty()) cli_camera = parse_camera_option(o.camera);
    if (!o.light.empty()) (void)parse_light_option(o.light);  // a bad value is said before anything runs
    const double cli_fov = o.fov_deg.value_or(kDefaultFovDeg);
    // Chosen once the renderer is made: the named path, or (auto) the renderer's preferred_path().
    wire::UploadPath path = wire::UploadPath::cpu_mesh;

    wire::io::SceneSpec scene;
    if (engine::Status st = wire::io::load_wire_json(o.input, scene); !st.ok()) throw BadInput{st.message};
    const std::size_t frames = scene.frames.size();
    const std::size_t wires = scene.frames.front().wires.size();
    std::vector<std::vector<wire::systems::Style>> styles(frames);
    for (std::size_t f = 0; f < frames; ++f) {
        for (std::size_t w = 0; w < wires; ++w) {
            const std::string at = where(o.input, f, frames, w);
            const wire::io::WireSpec& spec = scene.frames[f].wires[w];
            wire::systems::Style style = style_of(spec, o.spline, at);
            style.material = static_cast<uint32_t>(w % 6);
            // The curve stage's own checks (fewer than 2 distinct nodes, ...), so a bad frame late in the file is
            // reported before any frame is drawn.
            wire::SplineSettings spline = style.spline;
            spline.closed = style.closed;
            spline.radius_m = style.radius_m;
            wire::Curve curve;
            if (engine::Status st = wire::build_curve(wire::io::to_wire_nodes(spec), spline, curve); !st.ok())
                throw BadInput{at + ": " + st.message};
            styles[f].push_back(style);
        }
    }
    std::vector<CameraPose> cameras(frames);
    {
        CameraPose current = cli_camera ? *cli_camera : default_camera(bounds_of(scene.frames[0], styles[0]), cli_fov, aspect);
        current.fov_deg = cli_fov;
        for (std::size_t f = 0; f < frames; ++f) {
            if (const auto& c = scene.frames[f].camera) {
                current.eye = c->eye_m;
                current.target = c->target_m;
                current.up = c->up.value_or(glm::dvec3(0, 1, 0));
                current.up_given = c->up.has_value();
                if (c->fov_deg) current.fov_deg = *c->fov_deg;
            }
            cameras[f] = current;
        }
    }

    // 2. The runtime, as a game sets it up: headless GL context, wire renderer, registry, the installed systems.
    auto created = engine::platform::create_headless_context(
        {.backend = engine::platform::Backend::headless, .width = width, .height = height, .quiet = true});
    if (!created) throw Failure{exit_failure, "cannot create a headless GL context: " + created.error().message};
    std::unique_ptr<engine::platform::Context> gl = std::move(created).value();
    auto made = wire::render::WireRenderer::create();
    if (!made) throw Failure{exit_failure, "cannot create the wire renderer: " + made.error().message};
    wire::render::WireRenderer renderer = std::move(made).value();
    if (const std::string_view note = wire::retired_path_note(o.path); !note.empty())
        std::fprintf(stderr, "wiretool view: %s\n", std::string(note).c_str());
    path = o.path.empty() || o.path == "auto" ? renderer.preferred_path()
                                              : *wire::parse_upload_path(o.path);  // CLI11 checked the name
    // Material 0 is the renderer's copper weave; wires cycle through it and five more tints.
    for (const glm::vec3 tint : {glm::vec3(0.25f, 0.55f, 1.0f), glm::vec3(0.95f, 0.80f, 0.15f),
                                 glm::vec3(0.85f, 0.15f, 0.12f), glm::vec3(0.20f, 0.75f, 0.30f),
                                 glm::vec3(0.80f, 0.80f, 0.82f)})
        (void)renderer.add_material({.tint = tint});

    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    wire::systems::WireContext ctx;
    ctx.path = path;
    ctx.viewport_width_px = width;
    ctx.viewport_height_px = height;
    if (o.tolerance_px) ctx.lod.tolerance_px = *o.tolerance_px;
    std::vector<wire::systems::ErrorReport> runtime_errors;
    ctx.on_error = [&](const wire::systems::ErrorReport& e) { runtime_errors.push_back(e); };
    wire::systems::install(schedule, ctx);
    // Shadows (--ground, --light): a map from the directional light fitted to the frame's wires (an orthographic
    // view along the light maps a caster and its shadow to the same texel, so the wires' sphere is enough), drawn
    // each frame from the same list with its own view (view 1: its own LOD on the nodes path).
    const bool shadows = o.ground_y.has_value() || !o.light.empty();
    const glm::dvec3 to_light = o.light.empty() ? glm::normalize(kDefaultToLight) : parse_light_option(o.light);
    std::optional<engine::gfx::ShadowMap> shadow_map;
    std::optional<engine::gfx::LitRenderer> ground_renderer;
    std::optional<engine::gfx::GpuMesh> ground_mesh;
    if (shadows) {
        auto map = engine::gfx::ShadowMap::create(kShadowMapPx);
        if (!map) throw Failure{exit_failure, "cannot create the shadow map: " + map.error().message};
        shadow_map = std::move(*map);
    }
    if (o.ground_y) {
        auto lit = engine::gfx::LitRenderer::create();
        if (!lit) throw Failure{exit_failure, "cannot create the ground renderer: " + lit.error().message};
        ground_renderer = std::move(*lit);
        auto mesh = engine::gfx::upload_mesh(engine::gfx::make_plane_mesh(1.0f), "ground");
        if (!mesh) throw Failure{exit_failure, "cannot upload the ground: " + mesh.error().message};
        ground_mesh = std::move(*mesh);
    }
    Bounds frame_bounds;  // this frame's wires (set before each run)
    wire::render::DrawStats drawn;
    schedule.add("wire.render", [&](engine::ecs::Registry&, const engine::ecs::FrameContext&) {
        wire::render::DrawSettings settings;
        settings.light = {.to_light = glm::vec3(to_light), .ambient = 0.35f, .specular = 0.25f};
        if (shadow_map) {  // its light was set with the frame's bounds, before the systems ran (other_views)
            shadow_map->begin();
            const wire::render::DrawStats cast = renderer.draw(
                ctx.draw_list, shadow_map->light, {.output = wire::render::Output::shadow, .view = 1});
            shadow_map->end();
            if (!cast.status.ok()) throw Failure{exit_failure, "the wire renderer could not draw the shadow map: " + cast.status.message};
            settings.shadow = &*shadow_map;
        }
        if (ground_renderer) {
            // A square under the wires reaching past their shadows, drawn eye-relative (exact far from the origin).
            const engine::scene::Camera& cam = ctx.camera;
            const double drop = std::abs(frame_bounds.centre.y - *o.ground_y);
            const double slant = glm::length(glm::dvec2(to_light.x, to_light.z)) / std::max(std::abs(to_light.y), 0.05);
            const double half = 3.0 * frame_bounds.radius_m + drop * std::min(slant, 20.0);
            const glm::dvec3 centre{frame_bounds.centre.x, *o.ground_y, frame_bounds.centre.z};
            const glm::mat4 model = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(centre - cam.position)),
                                               glm::vec3(static_cast<float>(half)));
            ground_renderer->begin(cam.clip_from_relative(),
                                   {.to_light = glm::vec3(to_light), .color = glm::vec3(1.0f), .ambient = 0.35f},
                                   shadow_map ? &*shadow_map : nullptr, cam.position);
            ground_renderer->draw(*ground_mesh, model, glm::vec3(0.55f, 0.55f, 0.52f));
        }
        drawn = renderer.draw(ctx.draw_list, ctx.camera, settings);
        if (!drawn.status.ok()) throw Failure{exit_failure, "the wire renderer could not draw: " + drawn.status.message};
    });

    std::vector<Entity> entities;
    std::unordered_map<uint64_t, std::size_t> wire_of_entity;
    for (std::size_t w = 0; w < wires; ++w) {
        entities.push_back(wire::systems::spawn_wire(registry, wire::io::to_wire_nodes(scene.frames[0].wires[w]),
                                                     styles[0][w]));
        wire_of_entity[engine::ecs::to_integral(entities.back())] = w;
    }

    // 3. The frames.
    Outputs outputs;
    const bool png_every_frame = o.png_out.find(kPerFrameToken) != std::string::npos;
    std::string csv = std::string(kRingCsvHeader) + ",sides\n";
    wire::RingSet ring_set;  // per wire, for the CSV (reused)
    std::vector<wire::render::DrawnRings> drawn_rings;  // the nodes path's, read back per frame
    wire::Curve gpu_curve;                            // the nodes path: a wire's curve, for its screen error
    nlohmann::ordered_json frame_records = nlohmann::ordered_json::array();
    for (std::size_t f = 0; f < frames; ++f) {
        if (f > 0) {
            for (std::size_t w = 0; w < wires; ++w) {
                if (!same_nodes(scene.frames[f].wires[w], scene.frames[f - 1].wires[w]))
                    wire::systems::set_nodes(registry, entities[w], wire::io::to_wire_nodes(scene.frames[f].wires[w]));
                if (!same_style(styles[f][w], styles[f - 1][w]))
                    wire::systems::set_style(registry, entities[w], styles[f][w]);
            }
        }
        const CameraPose& pose = cameras[f];
        const Bounds b = bounds_of(scene.frames[f], styles[f]);
        // Clip planes around this frame's wires (their curve may bulge a little past the nodes' box): far just past
        // them; near halfway to them, or, from inside or close by, a game-like 5 cm scaled down for small scenes (a
        // tiny near plane would make the LOD refine every segment that crosses it to its maximum count).
        const double reach = 1.25 * b.radius_m;
        const double distance = glm::length(pose.eye - b.centre);
        double far_m = 1.01 * (distance + reach);
        frame_bounds = b;
        if (shadow_map) {
            // The light's view: the systems keep the wires inside it in the list too (nodes path: a wire out of the
            // camera's view still casts its shadow into it).
            shadow_map->light =
                engine::scene::directional_light_view(to_light, b.centre, 1.25 * std::max(b.radius_m, 1e-6));
            ctx.other_views = {shadow_map->light};
        }
        if (o.ground_y) {  // the ground reaches past the wires: so does the far plane
            const double drop = std::abs(b.centre.y - *o.ground_y);
            far_m = std::max(far_m, 1.01 * (distance + drop + 4.0 * reach + 20.0 * drop));
        }
        const double close_near_m = std::max(1e-5 * far_m, std::min(0.05, 0.01 * reach));
        const double near_m = std::max(0.5 * (distance - reach), close_near_m);
        engine::scene::Camera& cam = ctx.camera;
        cam.position = pose.eye;  // double: scenes far from the origin keep their precision
        cam.target = pose.target;
        cam.up = usable_up(pose);
        cam.fov_y_rad = static_cast<float>(pose.fov_deg * std::numbers::pi / 180.0);
        cam.aspect = static_cast<float>(aspect);
        cam.near_m = static_cast<float>(near_m);
        cam.far_m = static_cast<float>(far_m);

        gl->begin_frame();
        engine::gfx::clear({0.10f, 0.10f, 0.12f, 1.0f});
        drawn = {};
        schedule.run(registry, kFrameStepS);
        if (!runtime_errors.empty()) {
            const wire::systems::ErrorReport& e = runtime_errors.front();
            const auto it = wire_of_entity.find(engine::ecs::to_integral(e.entity));
            throw BadInput{where(o.input, f, frames, it == wire_of_entity.end() ? 0 : it->second) + ": " + e.message};
        }

        // What the LOD chose and what it drew, per wire in file order. On the nodes path the rings are the GPU's,
        // read back (what the draw used); the others build them on the CPU.
        std::vector<const wire::DrawItem*> item_of(wires, nullptr);
        for (const wire::DrawItem& item : ctx.draw_list.items) {
            const auto it = wire_of_entity.find(item.wire_id);
            if (it != wire_of_entity.end()) item_of[it->second] = &item;
        }
        std::vector<const wire::render::DrawnRings*> gpu_of(wires, nullptr);
        if (path == wire::UploadPath::gpu_nodes) {
            if (engine::Status st = renderer.read_drawn_rings(drawn_rings); !st)
                throw Failure{exit_failure, "cannot read back the rings the GPU drew: " + st.message};
            for (const wire::render::DrawnRings& d : drawn_rings) {
                const auto it = wire_of_entity.find(d.wire_id);
                if (it != wire_of_entity.end()) gpu_of[it->second] = &d;
            }
        }
        nlohmann::ordered_json wire_records = nlohmann::ordered_json::array();
        double frame_error = 0.0;
        // The frame's totals: the systems' rings and draw()'s counts; on the nodes path what the GPU drew this frame
        // (its read-back rings: draw() reports triangles 3 frames late and no vertices).
        std::size_t frame_rings = ctx.stats.rings, frame_vertices = drawn.vertices, frame_triangles = drawn.triangles;
        if (path == wire::UploadPath::gpu_nodes) frame_rings = frame_vertices = frame_triangles = 0;
        for (std::size_t w = 0; w < wires; ++w) {
            const wire::DrawItem* item = item_of[w];
            double error_px = 0.0;
            std::size_t rings = 0;
            long sides = 0;
            if (path == wire::UploadPath::gpu_nodes) {
                // Culled on the GPU: no rings, 0 sides (as a wire the CPU culls).
                if (const wire::render::DrawnRings* d = gpu_of[w]; d != nullptr) {
                    rings = d->rings.params.size();
                    sides = static_cast<long>(d->sides);
                    const bool closed = d->rings.closed, caps = item == nullptr || item->caps;
                    const std::size_t rows = rings + (closed ? 1 : 0), bands = rows - 1;
                    const std::size_t cap_rows = !closed && caps ? 2 : 0;
                    const std::size_t n = static_cast<std::size_t>(sides);
                    frame_rings += rings;
                    frame_vertices += n <= 2 ? 2 * rows : (rows + cap_rows) * (n + 1);
                    frame_triangles += n <= 2 ? 2 * bands : (2 * bands + cap_rows) * n;
                    if (!o.csv_out.empty()) append_ring_rows(csv, f, w, d->rings, sides);
                    // The screen error of the GPU's rings (its LOD's counts) on the curve through the wire's nodes
                    // (the CPU's build of what the GPU built).
                    wire::SplineSettings spline = styles[f][w].spline;
                    spline.closed = styles[f][w].closed;
                    spline.radius_m = styles[f][w].radius_m;
                    if (wire::build_curve(wire::io::to_wire_nodes(scene.frames[f].wires[w]), spline, gpu_curve).ok() &&
                        !d->rings.params.empty() && d->rings.params.back().segment < gpu_curve.segment_count())
                        error_px = wire::measure_screen_error(gpu_curve, d->rings.params, ctx.view, kErrorSamplesPerSegment)
                                       .max_px;
                }
            } else if (item != nullptr) {
                error_px = wire::systems::wire_screen_error(registry, ctx, entities[w], kErrorSamplesPerSegment).max_px;
                rings = item->rings.size();
                sides = static_cast<long>(item->sides);
                // The systems keep only the float ring records: the CSV's double columns are recomputed.
                if (!o.csv_out.empty() && wire::systems::wire_ring_set(registry, entities[w], ring_set))
                    append_ring_rows(csv, f, w, ring_set, sides);
            }
            frame_error = std::max(frame_error, error_px);
            wire_records.push_back({{"wire", w},
                                    {"visible", item != nullptr},
                                    {"rings", rings},
                                    {"sides", sides},
                                    {"max_screen_error_px", error_px}});
        }
        nlohmann::ordered_json systems_ms = nlohmann::ordered_json::object();
        for (const engine::ecs::SystemStats& s : schedule.stats()) systems_ms[s.name] = s.last_ms;
        frame_records.push_back({{"frame", f},
                                 {"visible_wires", ctx.stats.visible_wires},
                                 {"rings", frame_rings},
                                 {"vertices", frame_vertices},
                                 {"triangles", frame_triangles},
                                 {"bytes_uploaded", drawn.bytes_uploaded},
                                 {"systems_ms", systems_ms},
                                 {"max_screen_error_px", frame_error},
                                 {"wires", wire_records}});

        if (!o.png_out.empty() && (png_every_frame || f + 1 == frames)) {
            const std::string final_path = png_every_frame ? per_frame_path(o.png_out, f) : o.png_out;
            const std::string tmp = outputs.stage(final_path);
            if (auto st = engine::platform::write_png(tmp, engine::platform::read_pixels(*gl)); !st)
                throw Failure{exit_failure, final_path + ": cannot write (" + st.message + ")"};
        }
        gl->end_frame();
    }

    // 4. Text outputs, then everything renamed into place together.
    std::string error;
    if (!o.csv_out.empty() && !outputs.stage_text(o.csv_out, csv, error)) throw Failure{exit_failure, error};
    if (!o.stats_out.empty()) {
        nlohmann::ordered_json stats = {
            {"frames", frame_records},
            {"summary",
             {{"width", width},
              {"height", height},
              {"tolerance_px", o.tolerance_px.value_or(kRuntimeDefaultTolerancePx)},
              {"path", std::string(wire::upload_path_name(path))},
              {"gl_renderer", gl->gl_renderer()}}}};
        if (!outputs.stage_text(o.stats_out, stats.dump(1) + "\n", error)) throw Failure{exit_failure, error};
    }
    if (!outputs.commit(error)) throw Failure{exit_failure, error};
    return exit_ok;
} catch (const BadInput& e) {
    std::cerr << "wiretool view: " << e.message << "\n";
    return exit_bad_input;
} catch (const Failure& e) {
    std::cerr << "wiretool view: " << e.message << "\n";
    return e.status;
}

}  // namespace

Action add_view_command(CLI::App& app) {
    auto o = std::make_shared<ViewOptions>();
    CLI::App* cmd = app.add_subcommand(
        "view",
        "Run wires (JSON) through the real runtime (ECS wire systems, screen-space LOD, wire renderer, headless GL) "
        "and write what it drew: a PNG, one CSV row per drawn ring, per-frame statistics with the measured screen "
        "error. IN.json is what `mesh` reads (one wire, {\"wires\": [...]} or {\"frames\": [{\"wires\": [...]}, ...]}); "
        "a frame may carry \"camera\": {\"eye\": [x,y,z], \"target\": [x,y,z], \"up\": [x,y,z], \"fov_deg\": f} (up "
        "and fov_deg optional), which replaces --camera/--fov from that frame on. Frames step 1/60 s.");
    cmd->add_option("input", o->input, "Wire JSON file")->required();
    cmd->add_option("--camera", o->camera,
                    "EX,EY,EZ,TX,TY,TZ: eye and target in metres (default: the first frame's wires framed from the "
                    "front-right-above diagonal)");
    cmd->add_option("--fov", o->fov_deg, "Vertical field of view in degrees (default 60)")
        ->check(CLI::Range(1e-3, 179.999));
    cmd->add_option("--size", o->size, "Image size WxH in pixels (default 1280x720)");
    cmd->add_option("--tolerance-px", o->tolerance_px, "LOD screen-space tolerance in pixels (default: the runtime's, 0.5)")
        ->check(CLI::Range(1e-6, 1e6));
    cmd->add_option("--spline", o->spline,
                    "uniform|centripetal|chordal|c2|auto (also catmull-rom, linear); default: the file's, else the "
                    "runtime's")
        ->check(CLI::IsMember({"uniform", "centripetal", "chordal", "c2", "auto", "automatic", "catmull-rom", "linear"}));
    cmd->add_option("--path", o->path, "Upload path: auto (default: nodes where the GL context has compute "
                                       "shaders, else cpu; logged on stderr), nodes (nodes only: curve, LOD, frames "
                                       "and rings in compute shaders), cpu (meshes built on the CPU: the portable "
                                       "reference); gpu, retired, draws on nodes")
        ->check(CLI::IsMember({"auto", "cpu", "gpu", "nodes"}));
    cmd->add_option("--png", o->png_out,
                    "Write the last frame as PNG; if OUT contains %04d, every frame (%04d = frame number)");
    cmd->add_option("--csv", o->csv_out, "Write one row per ring of every visible wire and frame (the mesh ring CSV "
                                         "plus the sides the LOD chose)");
    cmd->add_option("--stats", o->stats_out, "Write per-frame statistics (JSON) with the measured screen error");
    cmd->add_option("--ground", o->ground_y,
                    "Y: draw a horizontal ground plane at height Y metres (the environment's shading) that receives "
                    "the wires' shadows; turns shadows on");
    cmd->add_option("--light", o->light,
                    "DX,DY,DZ: direction toward the directional light (default 0.3,1,0.4); it casts shadows (2048 px "
                    "map fitted to the wires) onto the ground and the wires; turns shadows on");
    return [o] { return run_view(*o); };
}

std::optional<std::pair<int, int>> parse_size_wxh(const std::string& text) {
    const std::size_t x = text.find('x');
    double w = 0, h = 0;
    if (x == std::string::npos || !parse_number(text.substr(0, x), w) || !parse_number(text.substr(x + 1), h) ||
        w != std::floor(w) || h != std::floor(h) || w < 1 || h < 1 || w > 16384 || h > 16384)
        return std::nullopt;
    return std::pair<int, int>{static_cast<int>(w), static_cast<int>(h)};
}

}  // namespace wiretool
