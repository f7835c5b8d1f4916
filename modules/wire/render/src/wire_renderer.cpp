// WireRenderer: create(), the material table, the upload path the context allows, the node stream and what the
// renderer holds (renderer_state.hpp has the files of its front end and back ends).
#include "wire/render/wire_renderer.hpp"

#include "renderer_state.hpp"
#include "wire/render/weave.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <cassert>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace wire::render {

namespace gfx = engine::gfx;
using detail::kPatternMinSides;
using detail::kRecordLocation;
using detail::kSectionAlign;
using gfx::StreamBuffer;

WireRenderer::WireRenderer() = default;
WireRenderer::WireRenderer(WireRenderer&&) noexcept = default;
WireRenderer& WireRenderer::operator=(WireRenderer&&) noexcept = default;
WireRenderer::~WireRenderer() = default;

Expected<WireRenderer> WireRenderer::create(const RendererDesc& desc) {
    WireRenderer r;
    r.state_ = std::make_unique<State>();
    State& s = *r.state_;
    s.desc = desc;
    s.draw_parameters = !desc.force_draw_index_attribute &&
                        epoxy_has_gl_extension("GL_ARB_shader_draw_parameters");  // the 450 source's `require`

    const std::string fragment = detail::fragment_source(detail::FragmentOutput::color, desc.shading_glsl, {});
    s.cpu_vertex = detail::vertex_source(true, s.draw_parameters);
    s.rings_vertex = detail::vertex_source(false, s.draw_parameters);
    s.gbuffer_glsl = std::string(desc.gbuffer_glsl);
    s.desc.shading_glsl = {}, s.desc.gbuffer_glsl = {};  // views of the caller's strings: not kept
    const std::string& cpu_vertex = s.cpu_vertex;
    const std::string& rings_vertex = s.rings_vertex;
    Expected<gfx::Program> cpu =
        gfx::make_program({.vertex = cpu_vertex, .fragment = fragment, .label = "wire cpu-mesh"});
    if (!cpu) return cpu.error();
    Expected<gfx::Program> rings =
        gfx::make_program({.vertex = rings_vertex, .fragment = fragment, .label = "wire rings"});
    if (!rings) return rings.error();
    s.cpu_program = std::move(cpu).value();
    s.rings_program = std::move(rings).value();
    // Both vertex shaders read shader storage blocks (the cpu-mesh one its draw records; the rings one the nodes
    // path's draws, rings, chunks and the side table), which GL 4.3 lets a driver refuse in the vertex stage (its
    // minimum of GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS is 0): said by name at create, never a failed draw.
    GLint vertex_blocks = 0;
    glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &vertex_blocks);
    for (const auto& [program, label] :
         {std::pair{&s.cpu_program, "wire cpu-mesh"}, std::pair{&s.rings_program, "wire rings"}}) {
        GLint blocks = 0;
        glGetProgramInterfaceiv(program->id(), GL_SHADER_STORAGE_BLOCK, GL_ACTIVE_RESOURCES, &blocks);
        if (blocks > vertex_blocks) {
            return Error{std::string(label) + ": its vertex shader reads " + std::to_string(blocks) +
                         " shader storage blocks, the driver allows " + std::to_string(vertex_blocks) +
                         " (GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS)"};
        }
    }

    // Vertex arrays: the cpu-mesh one reads TubeVertex at binding 0 and the vertex's draw index at binding 1
    // (both streamed, set per frame); the rings one (the nodes path's) reads the chunk index at binding 1
    // (instanced, from the 0, 1, 2, ... buffer) when the draw-parameters extension is missing.
    s.cpu_vao = gfx::make_vertex_array({.label = "wire cpu-mesh"});
    s.rings_vao = gfx::make_vertex_array({.label = "wire rings"});
    const GLuint cpu_vao = s.cpu_vao.id();
    const struct {
        GLuint location;
        GLint components;
        GLuint offset;
    } attributes[] = {{0, 3, offsetof(TubeVertex, position)},
                      {1, 3, offsetof(TubeVertex, normal)},
                      {2, 2, offsetof(TubeVertex, uv)}};
    for (const auto& a : attributes) {
        glEnableVertexArrayAttrib(cpu_vao, a.location);
        glVertexArrayAttribFormat(cpu_vao, a.location, a.components, GL_FLOAT, GL_FALSE, a.offset);
        glVertexArrayAttribBinding(cpu_vao, a.location, 0);
    }
    glEnableVertexArrayAttrib(cpu_vao, kRecordLocation);
    glVertexArrayAttribIFormat(cpu_vao, kRecordLocation, 1, GL_UNSIGNED_INT, 0);
    glVertexArrayAttribBinding(cpu_vao, kRecordLocation, 1);
    if (!s.draw_parameters) {
        const GLuint rings_vao = s.rings_vao.id();
        glEnableVertexArrayAttrib(rings_vao, kRecordLocation);
        glVertexArrayAttribIFormat(rings_vao, kRecordLocation, 1, GL_UNSIGNED_INT, 0);
        glVertexArrayAttribBinding(rings_vao, kRecordLocation, 1);
        glVertexArrayBindingDivisor(rings_vao, 1, 1);
        if (Status st = s.ensure_draw_index_capacity(1); !st) return st;
    }

    // The built-in weave: mipmapped, repeating, anisotropic where available.
    const int weave_size = desc.weave_size_px > 0 ? desc.weave_size_px : 256;
    const std::vector<uint8_t> weave = make_weave_rgba({.size_px = weave_size});
    Expected<gfx::Texture> texture = gfx::make_texture({.width = weave_size,
                                                        .height = weave_size,
                                                        .rgba = weave,
                                                        .mipmaps = true,
                                                        .wrap = gfx::Wrap::repeat,
                                                        .label = "wire weave"});
    if (!texture) return texture.error();
    if (epoxy_gl_version() >= 46 || epoxy_has_gl_extension("GL_ARB_texture_filter_anisotropic") ||
        epoxy_has_gl_extension("GL_EXT_texture_filter_anisotropic")) {
        GLfloat max_supported = 1.0f;
        glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY_EXT, &max_supported);
        const float wanted = desc.max_anisotropy > 0.0f ? desc.max_anisotropy : 8.0f;
        glTextureParameterf(texture->id(), GL_TEXTURE_MAX_ANISOTROPY_EXT, std::min(wanted, max_supported));
    }
    s.textures.push_back(std::move(texture).value());
    s.materials.push_back({.tint = {0.95f, 0.62f, 0.38f}, .texture = 0});

    Expected<StreamBuffer> stream = StreamBuffer::create(
        {.regions = desc.frames_in_flight,
         .region_bytes = desc.region_bytes != 0 ? desc.region_bytes : std::size_t{4} << 20,
         .growth = desc.growth,
         .alignment = kSectionAlign,
         .label = "wire stream"});
    if (!stream) return stream.error();
    s.stream = std::move(stream).value();
    if (Status st = s.ensure_patterns(kPatternMinSides); !st) return st;
    return r;
}

uint32_t WireRenderer::add_texture(engine::gfx::Texture texture) {
    state_->textures.push_back(std::move(texture));
    return static_cast<uint32_t>(state_->textures.size() - 1);
}

uint32_t WireRenderer::add_material(const Material& material) {
    assert(material.texture < state_->textures.size() && "Material::texture out of range");
    state_->materials.push_back(material);
    return static_cast<uint32_t>(state_->materials.size() - 1);
}

void WireRenderer::set_material(uint32_t index, const Material& material) {
    assert(index < state_->materials.size() && material.texture < state_->textures.size());
    state_->materials[index] = material;
}

const std::vector<Material>& WireRenderer::materials() const {
    return state_->materials;
}
RendererInfo WireRenderer::info() const {
    const State& s = *state_;
    RendererInfo i;
    i.draw_parameters = s.draw_parameters;
    i.region_bytes = s.stream.region_bytes();
    i.live_stream_buffers = s.stream.live_buffers();
    i.allocated_stream_buffers = s.stream.allocated_buffers();
    if (s.nodes) {
        i.node_path_buffers = s.nodes->gl_buffers();
        i.node_path_programs = s.nodes->gl_programs();
        i.node_path_wires = s.nodes->resident_wires();
    }
    return i;
}

UploadPath WireRenderer::preferred_path() {
    State& s = *state_;
    if (!s.preferred) {
        const Status st = s.ensure_nodes();
        s.preferred = st ? UploadPath::gpu_nodes : UploadPath::cpu_mesh;
        if (st) {
            const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
            s.preferred_why = "GL " + std::to_string(epoxy_gl_version() / 10) + "." +
                              std::to_string(epoxy_gl_version() % 10) + " compute on " +
                              (renderer != nullptr ? renderer : "an unnamed renderer");
        } else {
            s.preferred_why = st.message + "; cpu-mesh draws the same picture";
        }
        std::fprintf(stderr, "wire: upload path %s (%s)\n", std::string(upload_path_name(*s.preferred)).c_str(),
                     s.preferred_why.c_str());
    }
    return *s.preferred;
}

const std::string& WireRenderer::preferred_path_reason() {
    (void)preferred_path();
    return state_->preferred_why;
}

NodeStream& WireRenderer::node_stream() {
    State& s = *state_;
    if (!s.node_stream) {
        s.node_stream = std::make_unique<NodeStream>();
        if (Status st = s.ensure_nodes(); st) {
            detail::attach_stream(*s.nodes, *s.node_stream);
        } else {
            detail::detach_stream(*s.node_stream, st);
        }
    }
    return *s.node_stream;
}

Status WireRenderer::read_drawn_rings(std::vector<DrawnRings>& out) const {
    out.clear();
    const State& s = *state_;
    if (!s.drawn_any) return Status::error("read_drawn_rings: nothing has been drawn yet");
    if (s.last_path != UploadPath::gpu_nodes) {
        return Status::error("read_drawn_rings: the last draw was on the '" + std::string(upload_path_name(s.last_path)) +
                             "' path, which builds its rings on the CPU (wire::systems::wire_ring_set has them)");
    }
    if (!s.nodes) return Status::error("read_drawn_rings: " + s.nodes_failed.message);
    if (Status st = s.nodes->read_rings(out); !st) return st;
    for (const auto& [wire_id, wire] : s.long_drawn) {  // drawn from meshes (longer than kNodesPathMaxNodes)
        DrawnRings& drawn = out.emplace_back();
        drawn.wire_id = wire_id;
        drawn.sides = wire->lod.drawn_sides;
        drawn.rings = wire->rings;
    }
    return Status::success();
}

Status WireRenderer::read_draw_order(std::vector<DrawnChunk>& out) const {
    out.clear();
    const State& s = *state_;
    if (!s.drawn_any) return Status::error("read_draw_order: nothing has been drawn yet");
    if (s.last_path != UploadPath::gpu_nodes) {
        return Status::error("read_draw_order: the last draw was on the '" +
                             std::string(upload_path_name(s.last_path)) +
                             "' path, which draws each item in list order (its own draw)");
    }
    if (!s.nodes) return Status::error("read_draw_order: " + s.nodes_failed.message);
    return s.nodes->read_draw_order(out);
}

Status WireRenderer::State::ensure_nodes() {
    if (!nodes_failed.ok()) return nodes_failed;
    if (nodes) return Status::success();
    if (std::string why = missing_compute(); !why.empty()) {
        nodes_failed = Status::error("the nodes path cannot be used: " + why);
        return nodes_failed;
    }
    Expected<std::unique_ptr<detail::NodePath>> made = detail::NodePath::create(desc.retain_frames);
    if (!made) {
        nodes_failed = Status::error("the nodes path cannot be used: " + made.error().message);
        return nodes_failed;
    }
    nodes = std::move(*made);
    return Status::success();
}

std::string WireRenderer::State::missing_compute() {
    if (const char* v = std::getenv("WIRE_GL_NO_COMPUTE"); v != nullptr && std::string_view(v) == "1") {
        return "compute shaders disabled (WIRE_GL_NO_COMPUTE=1)";
    }
    const int version = epoxy_gl_version();
    if (version < 43 && !epoxy_has_gl_extension("GL_ARB_compute_shader")) {
        return "no compute shaders (GL " + std::to_string(version / 10) + "." + std::to_string(version % 10) +
               " without GL_ARB_compute_shader)";
    }
    if (version < 43 && !epoxy_has_gl_extension("GL_ARB_multi_draw_indirect")) {
        return "no multi-draw indirect (GL 4.3 or GL_ARB_multi_draw_indirect)";
    }
    return {};
}

}  // namespace wire::render
