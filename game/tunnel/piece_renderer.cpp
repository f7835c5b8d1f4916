// PieceRenderer: bent, instanced tunnel pieces (see piece_renderer.hpp).
#include "tunnel/piece_renderer.hpp"

#include <engine/gfx/draw.hpp>
#include <engine/gfx/resources.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace tunnel {

namespace gfx = engine::gfx;

namespace {

constexpr int kMaxInstances = 64;  // u_piece_z[] length: larger draws are split

constexpr const char* kVertexHead = R"(#version 450 core
#define CS_SEGMENT_BINDING 3
)";

constexpr const char* kVertexBody = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
uniform mat4 u_clip_from_rel;
uniform float u_piece_z[64];
out vec3 v_rel;
out vec3 v_normal;
out vec3 v_unbent;
out vec3 v_unbent_normal;
void main() {
    vec3 p = a_position;
    p.z += u_piece_z[gl_InstanceID];
    vec3 p_bent;
    vec3 n_bent;
    bool folded;
    cs_bend(p, a_normal, p_bent, n_bent, folded);
    v_rel = p_bent;
    v_normal = n_bent;
    v_unbent = p;
    v_unbent_normal = a_normal;
    gl_Position = u_clip_from_rel * vec4(p_bent, 1.0);
}
)";

constexpr const char* kFragmentHead = R"(#version 450 core
in vec3 v_rel;
in vec3 v_normal;
in vec3 v_unbent;
in vec3 v_unbent_normal;
uniform vec3 u_albedo;
uniform int u_surface;
uniform vec3 u_to_light;
uniform vec3 u_fog_color;
uniform float u_fog_m;
uniform float u_lamp_spacing_m;
uniform float u_lamp_y_m;
uniform vec3 u_head_rel;
uniform vec3 u_head_dir;
uniform float u_head_cos;
out vec4 o_color;
)";

constexpr const char* kFragment = R"(

float hash12(vec2 p) {
    vec3 p3 = fract(vec3(p.xyx) * 0.1031);
    p3 += dot(p3, p3.yzx + 33.33);
    return fract((p3.x + p3.y) * p3.z);
}

float value_noise(vec2 p) {
    vec2 i = floor(p);
    vec2 f = fract(p);
    vec2 u = f * f * (3.0 - 2.0 * f);
    return mix(mix(hash12(i), hash12(i + vec2(1, 0)), u.x), mix(hash12(i + vec2(0, 1)), hash12(i + vec2(1, 1)), u.x), u.y);
}

void main() {
    vec3 n = normalize(v_normal);
    vec3 to_eye = normalize(-v_rel);
    vec3 albedo = u_albedo;
    float shininess = 16.0;
    float spec_k = 0.05;
    if (u_surface == 0) {
        // Concrete panels: 1 m along, 30 degrees around; seams, per-panel tone, fine grain.
        float around = (atan(v_unbent.y, v_unbent.x) + 3.14159265) / 6.2831853 * 12.0;
        vec2 panel = vec2(around, v_unbent.z);
        vec2 f = abs(fract(panel) - 0.5);
        float seam = smoothstep(0.47, 0.495, max(f.x, f.y * 1.0));
        float tone = 0.88 + 0.2 * hash12(floor(panel) + 17.0);
        float grain = 0.85 + 0.3 * value_noise(vec2(around * 9.0, v_unbent.z * 9.0));
        float stain = 0.8 + 0.2 * smoothstep(-2.4, -0.8, v_unbent.y);
        albedo *= tone * grain * stain * (1.0 - 0.55 * seam);
    } else if (u_surface == 2) {
        // Walkway grating: slats across the tunnel every 12.5 cm.
        // Antialiased by the slat frequency on screen: far away the slats blend to their mean.
        float zs = v_unbent.z * 8.0;
        float w = fwidth(zs);
        float slat = abs(fract(zs) - 0.5);
        float stripes = mix(0.45, 1.0, smoothstep(0.23 - w, 0.23 + w, slat));
        stripes = mix(stripes, 0.72, smoothstep(0.25, 0.6, w));
        albedo *= v_unbent_normal.y > 0.5 ? stripes : 0.7;
        spec_k = 0.12;
        shininess = 24.0;
    } else {
        spec_k = 0.35;
        shininess = 40.0;
    }

    // Sun-like fill from the light direction, a head lamp at the eye, warm ceiling lamps every few metres.
    float ambient = 0.16;
    float sun = 0.25 * max(dot(n, normalize(u_to_light)), 0.0);
    float d = length(v_rel);
    // The head lamp, beside the eye, in its cone, shadowed by its map.
    vec3 to_head = u_head_rel - v_rel;
    float dh = length(to_head);
    to_head /= max(dh, 1e-6);
    float cone = smoothstep(u_head_cos, mix(u_head_cos, 1.0, 0.2), dot(-to_head, u_head_dir));
    float head = 0.9 * max(dot(n, to_head), 0.0) * cone / (1.0 + dh * dh / 90.0);
    if (head > 0.0) head *= shadow_visibility(v_rel, n);
    vec3 lamp_light = vec3(0.0);
    float k0 = floor(v_unbent.z / u_lamp_spacing_m);
    for (int k = 0; k < 2; ++k) {
        float lz = (k0 + float(k) + 0.5) * u_lamp_spacing_m;
        vec3 to_lamp = vec3(0.0, u_lamp_y_m, lz) - v_unbent;
        float dist2 = dot(to_lamp, to_lamp);
        float lambert = max(dot(normalize(v_unbent_normal), to_lamp * inversesqrt(dist2)), 0.0);
        lamp_light += vec3(1.0, 0.82, 0.6) * (1.6 * lambert / (1.0 + dist2 * 0.35));
    }
    vec3 h = normalize(to_eye + normalize(u_to_light));
    float spec = spec_k * pow(max(dot(n, h), 0.0), shininess);
    vec3 c = albedo * (vec3(ambient + sun + head) + lamp_light) + vec3(spec);
    float fog = 1.0 - exp(-d / u_fog_m);
    o_color = vec4(mix(c, u_fog_color, fog * fog), 1.0);
}
)";

struct GpuPieceMesh {
    gfx::Buffer vertices;
    gfx::Buffer indices;
    gfx::VertexArray vao;
    std::size_t index_count = 0;
};

}  // namespace

struct PieceRenderer::State {
    gfx::Program program;
    gfx::Program depth_program;  ///< the same vertex shader, an empty fragment shader
    gfx::Program* current = nullptr;
    int loc_depth_piece_z = -1;
    std::vector<GpuPieceMesh> meshes;
    gfx::Buffer segments;
    int loc_piece_z = -1;
    bool wireframe = false;
};

PieceRenderer::PieceRenderer() = default;
PieceRenderer::PieceRenderer(PieceRenderer&&) noexcept = default;
PieceRenderer& PieceRenderer::operator=(PieceRenderer&&) noexcept = default;
PieceRenderer::~PieceRenderer() = default;

Expected<PieceRenderer> PieceRenderer::create() {
    const std::string vertex =
        std::string(kVertexHead) + std::string(curved_space::glsl_bend_source()) + kVertexBody;
    Expected<gfx::Program> program =
        gfx::make_program({.vertex = vertex,
                           .fragment = std::string(kFragmentHead) + std::string(gfx::shadow_glsl()) + kFragment,
                           .label = "tunnel pieces"});
    if (!program) return program.error();
    PieceRenderer r;
    r.state_ = std::make_unique<State>();
    r.state_->program = std::move(program).value();
    r.state_->loc_piece_z = r.state_->program.uniform_location("u_piece_z");
    Expected<gfx::Program> depth = gfx::make_program(
        {.vertex = vertex, .fragment = "#version 450 core\nvoid main() {}\n", .label = "tunnel pieces depth"});
    if (!depth) return depth.error();
    r.state_->depth_program = std::move(depth).value();
    r.state_->loc_depth_piece_z = r.state_->depth_program.uniform_location("u_piece_z");
    return r;
}

Expected<PieceRenderer::MeshHandle> PieceRenderer::add_mesh(const engine::assets::MeshData& mesh,
                                                            std::string_view label) {
    const std::size_t n = mesh.vertex_count();
    std::vector<float> interleaved;
    interleaved.reserve(n * 8);
    for (std::size_t v = 0; v < n; ++v) {
        const glm::dvec3 p = mesh.origin + glm::dvec3(mesh.positions[3 * v], mesh.positions[3 * v + 1],
                                                      mesh.positions[3 * v + 2]);
        interleaved.insert(interleaved.end(),
                           {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z),
                            mesh.normals[3 * v], mesh.normals[3 * v + 1], mesh.normals[3 * v + 2]});
        if (mesh.uvs.size() == 2 * n) {
            interleaved.insert(interleaved.end(), {mesh.uvs[2 * v], mesh.uvs[2 * v + 1]});
        } else {
            interleaved.insert(interleaved.end(), {0.0f, 0.0f});
        }
    }
    GpuPieceMesh gpu;
    auto vb = gfx::make_buffer(std::span<const float>(interleaved), label);
    if (!vb) return vb.error();
    auto ib = gfx::make_buffer(std::span<const uint32_t>(mesh.indices), label);
    if (!ib) return ib.error();
    gpu.vertices = std::move(vb).value();
    gpu.indices = std::move(ib).value();
    gpu.vao = gfx::make_vertex_array({.vertex_buffer = &gpu.vertices,
                                      .stride_bytes = 8 * sizeof(float),
                                      .attributes = {{.location = 0, .components = 3, .offset_bytes = 0},
                                                     {.location = 1, .components = 3, .offset_bytes = 12},
                                                     {.location = 2, .components = 2, .offset_bytes = 24}},
                                      .index_buffer = &gpu.indices,
                                      .label = label});
    gpu.index_count = mesh.indices.size();
    state_->meshes.push_back(std::move(gpu));
    return static_cast<MeshHandle>(state_->meshes.size() - 1);
}

std::size_t PieceRenderer::triangle_count(MeshHandle mesh) const {
    return state_->meshes[mesh].index_count / 3;
}

std::size_t PieceRenderer::begin(const PieceFrame& frame) {
    State& s = *state_;
    const std::size_t bytes = frame.segments.size_bytes();
    if (!s.segments || s.segments.size_bytes() < bytes) {
        auto buffer = gfx::make_buffer({.size_bytes = std::max<std::size_t>(bytes, 96 * 64),
                                        .dynamic = true,
                                        .label = "tunnel segments"});
        if (buffer) s.segments = std::move(buffer).value();
    }
    if (s.segments && bytes > 0) s.segments.update(0, std::as_bytes(frame.segments));
    // Bind exactly the records of this frame: the shader's binary search uses the array's length().
    gfx::bind_storage_range(curved_space::segment_buffer_binding, s.segments, 0, bytes);
    gfx::set_opaque_state();
    s.wireframe = frame.wireframe;
    if (frame.wireframe) gfx::set_wireframe(true);
    if (frame.depth_only) {
        s.current = &s.depth_program;
        s.depth_program.use();
        s.depth_program.set("u_clip_from_rel", frame.clip_from_rel);
        return bytes;
    }
    s.current = &s.program;
    s.program.use();
    s.program.set("u_clip_from_rel", frame.clip_from_rel);
    s.program.set("u_to_light", frame.to_light);
    s.program.set("u_fog_color", frame.fog_color);
    s.program.set("u_fog_m", frame.fog_distance_m);
    s.program.set("u_lamp_spacing_m", frame.lamp_spacing_m);
    s.program.set("u_lamp_y_m", frame.lamp_y_m);
    s.program.set("u_head_rel", frame.head_rel_m);
    s.program.set("u_head_dir", frame.head_dir);
    s.program.set("u_head_cos", frame.head_cos_cone);
    gfx::set_shadow_uniforms(s.program, frame.head_shadow, frame.eye_m);
    return bytes;
}

void PieceRenderer::draw(MeshHandle mesh, Surface surface, const glm::vec3& albedo,
                         std::span<const float> piece_z_m) {
    State& s = *state_;
    const GpuPieceMesh& m = s.meshes[mesh];
    const bool depth = s.current == &s.depth_program;
    const gfx::Program& program = depth ? s.depth_program : s.program;
    if (!depth) {
        program.set("u_albedo", albedo);
        program.set("u_surface", static_cast<int>(surface));
    }
    for (std::size_t first = 0; first < piece_z_m.size(); first += kMaxInstances) {
        const std::size_t count = std::min<std::size_t>(kMaxInstances, piece_z_m.size() - first);
        program.set(depth ? s.loc_depth_piece_z : s.loc_piece_z, piece_z_m.subspan(first, count));
        gfx::draw_instanced(m.vao, m.index_count, count);
    }
}

void PieceRenderer::end() {
    if (state_->wireframe) gfx::set_wireframe(false);
    gfx::unbind_vertex_array();
}

}  // namespace tunnel
