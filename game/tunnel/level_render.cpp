// Drawing the level: the wire renderer and its materials, the bent pieces (system tunnel.pieces) and the
// wires (system wire.render), each pass timed on the GPU without stalling.
#include "tunnel/level_state.hpp"

#include <curved_space/gpu.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/gfx/shadow.hpp>
#include <engine/scene/light_view.hpp>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace tunnel {

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

Status Level::create_wire_renderer() {
    State& s = *state_;
    auto renderer = wire::render::WireRenderer::create();
    if (!renderer) return renderer.error();
    s.wires = std::move(renderer).value();
    options_.upload_path = s.wires.preferred_path();  // the nodes path where the context has compute
    s.pieces_timer = engine::gfx::GpuTimer::create();
    s.wires_timer = engine::gfx::GpuTimer::create();
    s.wires.add_material({.tint = {0.16f, 0.16f, 0.17f}});  // rubber
    s.wires.add_material({.tint = {1.00f, 0.45f, 0.12f}});  // orange
    s.wires.add_material({.tint = {0.95f, 0.80f, 0.15f}});  // yellow
    s.wires.add_material({.tint = {0.20f, 0.40f, 0.95f}});  // blue
    s.wires.add_material({.tint = {0.85f, 0.15f, 0.12f}});  // red
    return {};
}

namespace {
constexpr int kHeadLampMapPx = 1024;  // a texel is 4.5 mm at 2 m: cables are 4 or more across
constexpr float kHeadLampHalfAngle = 0.8f;  // radians
constexpr float kHeadLampRange_m = 40.0f;
}  // namespace

engine::scene::Camera head_lamp_view(const engine::scene::Camera& camera) {
    const glm::dvec3 forward = camera.forward();
    const glm::dvec3 right = glm::normalize(glm::cross(forward, camera.up));
    const glm::dvec3 up = glm::cross(right, forward);
    return engine::scene::spot_light_view(camera.position + 0.9 * up + 0.6 * right, forward, kHeadLampHalfAngle,
                                          kHeadLampRange_m, 0.1f);
}

void Level::draw_shadow_map() {
    State& s = *state_;
    if (!options_.shadows) return;
    if (!s.head_lamp) {
        auto map = engine::gfx::ShadowMap::create(kHeadLampMapPx);
        if (!map) {
            options_.shadows = false;  // said once, the level draws on unshadowed
            std::fprintf(stderr, "tunnel: no head lamp shadows: %s\n", map.error().message.c_str());
            return;
        }
        s.head_lamp = std::move(*map);
    }
    engine::gfx::ShadowMap& map = *s.head_lamp;
    map.light = head_lamp_view(camera_);
    map.begin();
    if (options_.draw_pieces) {  // the pieces' coarsest level: the lamp sees their shapes, not their detail
        const glm::dvec3 eye = camera_.position;
        const std::vector<curved_space::GpuSegment> records = curved_space::gpu_segments(chain_, eye);
        s.pieces.begin({.clip_from_rel = engine::gfx::shadow_from_relative(map.light, eye),
                        .segments = records,
                        .depth_only = true});
        s.bucket.clear();
        for (int k = 0; k < piece_count(); ++k) s.bucket.push_back(static_cast<float>(kPieceLength * k));
        for (const Group& group : s.groups) s.pieces.draw(group.meshes[0], group.surface, group.albedo, s.bucket);
        s.pieces.end();
    }
    if (options_.draw_wires) {
        const wire::render::DrawStats cast = s.wires.draw(
            s.context.draw_list, map.light, {.output = wire::render::Output::shadow, .view = 1});
        (void)cast;  // a failure is logged by the renderer; the camera's draw says it again in the stats
    }
    map.end();
}

void Level::draw_pieces() {
    State& s = *state_;
    const GpuPass gpu_pass(s.pieces_timer);
    engine::gfx::clear({0.02f, 0.025f, 0.035f, 1.0f});
    stats_.piece_triangles = 0;
    stats_.piece_vertices = 0;
    choose_piece_levels();
    if (!options_.draw_pieces) return;

    const glm::dvec3 eye = camera_.position;
    const std::vector<curved_space::GpuSegment> records = curved_space::gpu_segments(chain_, eye);
    PieceFrame frame{.clip_from_rel = camera_.clip_from_relative(),
                     .segments = records,
                     .to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.4f)),
                     .wireframe = options_.wireframe};
    const engine::scene::Camera lamp = head_lamp_view(camera_);
    frame.head_rel_m = glm::vec3(lamp.position - eye);
    frame.head_dir = glm::vec3(lamp.forward());
    frame.head_cos_cone = std::cos(kHeadLampHalfAngle);
    frame.head_shadow = options_.shadows && s.head_lamp ? &*s.head_lamp : nullptr;
    frame.eye_m = eye;
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
            wire::render::DrawSettings settings;
            settings.light = {.to_light = {0.3f, 1.0f, 0.4f}, .ambient = 0.35f, .specular = 0.25f};
            settings.wireframe = options_.wireframe;
            if (options_.shadows && s.head_lamp) {
                // Lit by the head lamp (from where it shines on the view's middle distance), in its shadows.
                const engine::scene::Camera& lamp = s.head_lamp->light;
                settings.light.to_light = glm::vec3(glm::normalize(lamp.position - (camera_.position + 3.0 * camera_.forward())));
                settings.shadow = &*s.head_lamp;
            }
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
    const wire::systems::RunStats& ws = s.context.stats;
    stats_.wires = ws.wires;
    stats_.curves_built = ws.curves_built;
    stats_.rings = ws.rings;
    stats_.wires_drawn = s.wire_stats.draw_items;
    stats_.wire_vertices = s.wire_stats.vertices;
    stats_.wire_triangles = s.wire_stats.triangles;
    stats_.wire_bytes_uploaded = s.wire_stats.bytes_uploaded;
    stats_.wire_waited_for_gpu = s.wire_stats.waited_for_gpu;
}

void Level::render() {
    draw_shadow_map();
    draw_pieces();
    draw_wires();
}

}  // namespace tunnel
