// WireRenderer: one stream-buffer region per frame holding per-draw records, chunk records (gpu-rings), indirect
// commands and streamed geometry (tube vertices, their draw indices and rebased indices, or packed rings when not
// retained); retained ring records in a RetainedBuffer; a static index pattern per side count for the ring
// expansion; one glMultiDrawElementsIndirect per run of (class, material) with a bounded number of commands.
#include "wire/render/wire_renderer.hpp"

#include "node_path.hpp"
#include "shaders.hpp"
#include "wire/render/upload_plan.hpp"
#include "wire/render/weave.hpp"

#include "engine/gfx/retained_buffer.hpp"
#include "engine/gfx/stream_buffer.hpp"

#include <epoxy/gl.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <string>
#include <numeric>
#include <optional>
#include <string_view>

namespace wire::render {
namespace {

namespace gfx = engine::gfx;
using gfx::StreamBuffer;
using gfx::StreamRegion;

struct DrawElementsIndirectCommand {
    uint32_t count;
    uint32_t instance_count;
    uint32_t first_index;
    int32_t base_vertex;
    uint32_t base_instance;
};
static_assert(sizeof(DrawElementsIndirectCommand) == kCommandBytes);
static_assert(sizeof(detail::GpuDraw) == kDrawRecordBytes);

constexpr std::size_t kSectionAlign =
    256;  // >= GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT on every driver we know
constexpr GLuint kRecordLocation = 3;  // cpu-mesh: the vertex's draw index; gpu-rings fallback: the chunk index
constexpr uint32_t kPatternMinSides = 16;  // patterns are built for 3..max(this, largest side count seen)

std::size_t align_up(std::size_t v) {
    return (v + kSectionAlign - 1) / kSectionAlign * kSectionAlign;
}

/// Indices of the ring-expansion pattern for `n` sides (upload_plan.hpp): start cap, end cap, kChunkBands
/// bands, in write_tube's winding.
void append_pattern(uint32_t n, std::vector<uint32_t>& out) {
    for (uint32_t cap = 0; cap < 2; ++cap) {
        const uint32_t centre = kCapVertexBase + cap * (n + 1);
        for (uint32_t j = 0; j < n; ++j) {
            const uint32_t rim_j = centre + 1 + j, rim_k = centre + 1 + (j + 1) % n;
            // Start cap faces -t: (centre, rim_k, rim_j); end cap faces +t: (centre, rim_j, rim_k).
            out.insert(out.end(), {centre, cap == 0 ? rim_k : rim_j, cap == 0 ? rim_j : rim_k});
        }
    }
    for (uint32_t b = 0; b < kChunkBands; ++b) {
        for (uint32_t j = 0; j < n; ++j) {
            const uint32_t a = b * (n + 1) + j, c = (b + 1) * (n + 1) + j;
            out.insert(out.end(), {a, a + 1, c, a + 1, c + 1, c});
        }
    }
}

}  // namespace

struct WireRenderer::State {
    RendererDesc desc;
    gfx::Program cpu_program;    ///< colour output
    gfx::Program rings_program;  ///< colour output (the nodes path draws with it too)
    /// Depth and G-buffer outputs, [0] cpu-mesh, [1] rings: compiled with their first draw.
    std::array<gfx::Program, 2> depth_programs, gbuffer_programs;
    std::string cpu_vertex, rings_vertex, gbuffer_glsl;  ///< kept for those compiles
    gfx::VertexArray cpu_vao;
    gfx::VertexArray rings_vao;
    gfx::Buffer draw_index_buffer;  ///< 0, 1, 2, ... for the instanced chunk-index attribute (fallback only)
    std::size_t draw_index_capacity = 0;
    bool draw_parameters = false;
    StreamBuffer stream;
    gfx::RetainedBuffer ring_storage;  ///< retained packed rings (gpu-rings, retain_rings)
    RingResidency residency{180};
    gfx::Buffer pattern;                 ///< static index patterns of the ring expansion, one per side count
    gfx::Buffer circle;                  ///< cos, sin of 2 pi j / n per side count n (the shader's circle[])
    std::vector<uint32_t> pattern_first; ///< first index of side count n's pattern (index n)
    uint32_t pattern_max_sides = 0;
    std::vector<gfx::Texture> textures;
    std::vector<Material> materials;
    // Per-frame scratch, reused.
    std::vector<uint32_t> order;          ///< items with geometry, sorted by class, material (and side count)
    std::vector<uint32_t> ring_word;      ///< per order position: first word of its rings (retained)
    std::vector<uint32_t> run_first;      ///< per run of (class, material): first order position (+ one past the end)
    std::vector<uint32_t> run_command;    ///< per run: its first command (plus one past the end)
    std::vector<DrawElementsIndirectCommand> commands;
    std::vector<uint32_t> chunks;         ///< gpu-rings: (draw index, first band) per chunk, in command order
    std::vector<PackedRing> packed;
    std::vector<uint8_t> streamed;     ///< retained path, per drawn item (order): rings streamed this frame
    std::size_t retained_ring_bytes = 0;  ///< retained path: bytes written into the ring storage this frame
    std::unique_ptr<detail::NodePath> nodes;  ///< gpu-nodes: made on its first frame
    std::unique_ptr<NodeStream> node_stream;  ///< made on the first node_stream() call
    Status nodes_failed{};                    ///< why the nodes path could not be made (not retried)
    std::optional<UploadPath> preferred;      ///< preferred_path()'s choice, made once
    std::string preferred_why;

    /// Makes the nodes path once (a failure is kept: not retried).
    Status ensure_nodes() {
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
    /// What the context lacks of what the nodes path needs (empty: nothing): compute shaders and multi-draw
    /// indirect (GL 4.3 or their extensions); WIRE_GL_NO_COMPUTE=1 in the environment pretends compute is missing
    /// (the fallback's test).
    static std::string missing_compute() {
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
    std::vector<std::string> logged;          ///< failures draw() has logged (each once)
    UploadPath last_path = UploadPath::cpu_mesh;
    bool drawn_any = false;                   ///< a draw() has run

    /// `stats` with the failure recorded, logged to stderr the first time this message is seen.
    DrawStats& failed(DrawStats& stats, const Status& why) {
        stats.status = why;
        if (std::find(logged.begin(), logged.end(), why.message) == logged.end()) {
            logged.push_back(why.message);
            std::fprintf(stderr, "wire renderer: %s\n", why.message.c_str());
        }
        return stats;
    }

    /// The program of `output` for cpu-mesh or the rings (compiled on first use); null: it did not build (why).
    const gfx::Program* program_for(bool cpu, Output output, Status& why) {
        if (output == Output::color) return cpu ? &cpu_program : &rings_program;
        const bool depth = output == Output::depth || output == Output::shadow;
        gfx::Program& program = (depth ? depth_programs : gbuffer_programs)[cpu ? 0 : 1];
        if (program.id() != 0) return &program;
        const std::string fragment = detail::fragment_source(
            depth ? detail::FragmentOutput::depth : detail::FragmentOutput::gbuffer, {}, gbuffer_glsl);
        const std::string label = std::string(cpu ? "wire cpu-mesh" : "wire gpu-rings") + (depth ? " depth" : " gbuffer");
        Expected<gfx::Program> made =
            gfx::make_program({.vertex = cpu ? cpu_vertex : rings_vertex, .fragment = fragment, .label = label});
        if (!made) {
            why = Status::error(label + ": " + made.error().message);
            return nullptr;
        }
        program = std::move(made).value();
        return &program;
    }

    /// The camera a draw places positions and projects with, and the LOD's view of it.
    struct View {
        engine::scene::Camera camera;  ///< at the eye positions are relative to
        LodView lod;
    };
    /// `camera` over the bound viewport: positions are relative to its eye (offsets computed in double, sent as
    /// float, projected with Camera::clip_from_relative(): wires far from the world origin keep their precision); an
    /// orthographic camera is moved back to the eye of LodView::orthographic() with its clip box unchanged.
    static View view_of(const engine::scene::Camera& camera) {
        GLint viewport[4] = {0, 0, 1, 1};
        glGetIntegerv(GL_VIEWPORT, viewport);
        const double w = std::max(viewport[2], 1), h = std::max(viewport[3], 1);
        View v{camera, {}};
        const engine::scene::Camera& c = v.camera;
        if (!c.orthographic()) {
            v.lod = LodView::perspective(c.position, c.target, c.up, c.fov_y_rad, w, h, c.near_m, c.far_m);
            return v;
        }
        v.lod = LodView::orthographic(c.position, c.target, c.up, c.ortho_half_height_m, w, h, c.near_m, c.far_m);
        const double back = LodView::orthographic_back_m(c.ortho_half_height_m, c.near_m, c.far_m);
        v.camera.target += v.lod.eye_m - v.camera.position;
        v.camera.position = v.lod.eye_m;
        v.camera.near_m = static_cast<float>(back + c.near_m);
        v.camera.far_m = static_cast<float>(back + c.far_m);
        return v;
    }

    /// The frame's GL state and the wire program's per-frame uniforms (both paths that draw rings, and cpu-mesh).
    void begin_wires(const gfx::Program& program, const engine::scene::Camera& camera, const DrawSettings& settings) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glEnable(GL_CULL_FACE);
        glCullFace(GL_BACK);
        glFrontFace(GL_CCW);
        if (settings.wireframe) glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);  // front faces only: culling stays on
        program.use();
        // Camera-relative: the view is the camera's rotation only; positions arrive as offsets from the eye.
        program.set("u_clip_from_rel", camera.clip_from_relative());
        program.set("u_to_light", glm::normalize(settings.light.to_light));
        program.set("u_light_color", settings.light.color);
        program.set("u_ambient", settings.light.ambient);
        program.set("u_specular", settings.light.specular);
        program.set("u_shininess", settings.light.shininess);
        GLint viewport[4] = {0, 0, 1, 1};
        glGetIntegerv(GL_VIEWPORT, viewport);
        program.set("u_viewport_px", glm::vec2(static_cast<float>(std::max(viewport[2], 1)),
                                               static_cast<float>(std::max(viewport[3], 1))));
        program.set("u_focal_px", camera.focal_px(static_cast<float>(std::max(viewport[3], 1))));
        program.set("u_push_back", settings.output == Output::shadow ? 1 : 0);
        if (settings.output == Output::shadow) glCullFace(GL_FRONT);  // the far side (end_wires() restores)
        if (settings.output == Output::color) gfx::set_shadow_uniforms(program, settings.shadow, camera.position);
    }

    /// The gpu-nodes frame (node_path.hpp).
    DrawStats draw_nodes(const DrawList& list, const engine::scene::Camera& camera, const DrawSettings& settings) {
        DrawStats stats;
        if (Status st = ensure_nodes(); !st) return failed(stats, st);
        nodes->set_lod(list.lod);  // the systems' LOD, evaluated on the GPU
        if (Status st = ensure_patterns(nodes->max_sides()); !st) return failed(stats, st);
        const std::size_t bytes = nodes->upload_bytes(list);
        Expected<StreamRegion> begun = stream.begin(bytes);
        if (!begun) return failed(stats, begun.error());
        stats.buffer_grew = begun->grew;
        stats.waited_for_gpu = begun->waited;
        Status no_program;
        const gfx::Program* program = program_for(false, settings.output, no_program);
        if (program == nullptr) {
            stream.end();
            return failed(stats, no_program);
        }
        const detail::NodeDrawContext ctx{*program, rings_vao, circle.id(), pattern_first, materials, textures,
                                          draw_parameters};
        const View view = view_of(camera);
        const bool drawn = nodes->prepare(list, view.lod, std::min(settings.view, kMaxViews - 1), *begun, ctx, stats);
        const bool streamed = node_stream && detail::stream_active(*node_stream);
        if (!stats.status.ok()) failed(stats, stats.status);
        Status index_capacity = drawn ? ensure_draw_index_capacity(nodes->chunk_capacity()) : Status::success();
        if (!index_capacity) failed(stats, index_capacity);
        if (drawn && index_capacity) {
            begin_wires(*program, view.camera, settings);
            using Lines = detail::NodePath::Lines;
            nodes->submit(ctx, stats,
                          settings.output == Output::color   ? Lines::blended
                          : settings.output == Output::depth ? Lines::skipped
                                                             : Lines::opaque);
            glBindVertexArray(0);
            glCullFace(GL_BACK);
            if (settings.wireframe) glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
        }
        stream.end();
        if (streamed) detail::end_stream_frame(*node_stream);  // after the dispatches that read its region
        return stats;
    }

    /// The item's rings in GPU form at `out`: the rings system's packed records when the item has them (one
    /// memcpy), else packed here.
    void copy_packed(const DrawItem& item, std::byte* out) {
        if (item.packed.size() == item.rings.size()) {
            std::memcpy(out, item.packed.data(), item.packed.size_bytes());
            return;
        }
        packed.resize(item.rings.size());
        pack_rings(item.rings, packed.data());
        std::memcpy(out, packed.data(), packed.size() * sizeof(PackedRing));
    }

    Status ensure_patterns(uint32_t max_sides) {
        if (max_sides <= pattern_max_sides) return {};
        const uint32_t top = std::max(max_sides, std::max(kPatternMinSides, 2 * pattern_max_sides));
        std::vector<uint32_t> indices;
        std::vector<uint32_t> first(top + 1, 0);
        // Strip and line pattern first (first[1] = first[2] = 0): wire::write_strip's band triangles.
        for (uint32_t b = 0; b < kChunkBands; ++b) {
            const uint32_t a = 2 * b;
            indices.insert(indices.end(), {a + 1, a + 3, a + 2, a + 1, a + 2, a});
        }
        for (uint32_t n = 3; n <= top; ++n) {
            first[n] = static_cast<uint32_t>(indices.size());
            append_pattern(n, indices);
        }
        Expected<gfx::Buffer> made = gfx::make_buffer(std::span<const uint32_t>(indices), "wire ring pattern");
        if (!made) return made.error();
        // Side table as wire::write_tube computes it: entry (n, j) at n (n + 1) / 2 - 6 + j.
        std::vector<float> table;
        for (uint32_t n = 3; n <= top; ++n) {
            for (uint32_t j = 0; j <= n; ++j) {
                const double phi = 2.0 * std::numbers::pi * (j == n ? 0 : j) / n;
                table.push_back(static_cast<float>(std::cos(phi)));
                table.push_back(static_cast<float>(std::sin(phi)));
            }
        }
        Expected<gfx::Buffer> circle_made = gfx::make_buffer(std::span<const float>(table), "wire ring circle");
        if (!circle_made) return circle_made.error();
        circle = std::move(circle_made).value();
        pattern = std::move(made).value();  // draws in flight keep the old one alive (GL deletes it later)
        pattern_first = std::move(first);
        pattern_max_sides = top;
        glVertexArrayElementBuffer(rings_vao.id(), pattern.id());
        return {};
    }

    /// Retained path: makes every drawn item's rings resident (uploading new or changed ones) and records the
    /// first word of each; evicts wires not drawn for a while. Items whose rings could not be stored are
    /// dropped from `order` (the rest of the frame draws).
    void retain(const DrawList& list, DrawStats& stats) {
        ring_storage.begin_frame();
        residency.begin_frame();
        ring_word.clear();
        streamed.clear();
        retained_ring_bytes = 0;
        std::size_t kept = 0;
        for (std::size_t k = 0; k < order.size(); ++k) {
            const DrawItem& item = list.items[order[k]];
            RingResidency::Touch t = residency.touch(item);
            if (t.replaced && t.replaced->size_bytes > 0)
                ring_storage.free({.offset_bytes = t.replaced->offset_bytes, .size_bytes = t.replaced->size_bytes});
            if (t.upload) {
                const std::size_t bytes = item.rings.size() * sizeof(PackedRing);
                Expected<gfx::RetainedRange> range = ring_storage.allocate(bytes);
                if (!range) {
                    residency.forget(item.wire_id);
                    continue;
                }
                copy_packed(item, static_cast<std::byte*>(range->data));  // write-only mapped memory
                t.entry->offset_bytes = range->offset_bytes;
                t.entry->size_bytes = bytes;
                retained_ring_bytes += bytes;
                stats.ring_bytes_uploaded += bytes;
                ++stats.wires_uploaded;
                stats.buffer_grew = stats.buffer_grew || range->grew;
            }
            if (t.stream) ++stats.wires_streamed;  // written into the frame's region by draw()
            streamed.push_back(t.stream ? 1 : 0);
            ring_word.push_back(static_cast<uint32_t>(t.entry->offset_bytes / 4));
            order[kept++] = order[k];
        }
        order.resize(kept);
        for (const Residency& gone : residency.evict()) {
            if (gone.size_bytes > 0)
                ring_storage.free({.offset_bytes = gone.offset_bytes, .size_bytes = gone.size_bytes});
            ++stats.wires_evicted;
        }
    }

    Status ensure_draw_index_capacity(std::size_t n) {
        if (draw_parameters || n <= draw_index_capacity) return {};
        const std::size_t capacity =
            std::max<std::size_t>(n, std::max<std::size_t>(1024, 2 * draw_index_capacity));
        std::vector<uint32_t> iota(capacity);
        std::iota(iota.begin(), iota.end(), 0u);
        Expected<gfx::Buffer> made = gfx::make_buffer(std::span<const uint32_t>(iota), "wire draw index");
        if (!made) return made.error();
        draw_index_buffer = std::move(made).value();
        draw_index_capacity = capacity;
        glVertexArrayVertexBuffer(rings_vao.id(), 1, draw_index_buffer.id(), 0, sizeof(uint32_t));
        return {};
    }
};

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
        gfx::make_program({.vertex = rings_vertex, .fragment = fragment, .label = "wire gpu-rings"});
    if (!rings) return rings.error();
    s.cpu_program = std::move(cpu).value();
    s.rings_program = std::move(rings).value();
    // Both vertex shaders read shader storage blocks (the cpu-mesh one its draw records; the rings one draws,
    // rings, chunks and the side table), which GL 4.3 lets a driver refuse in the vertex stage (its minimum of
    // GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS is 0): said by name at create, never a failed draw.
    GLint vertex_blocks = 0;
    glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &vertex_blocks);
    for (const auto& [program, label] : {std::pair{&s.cpu_program, "wire cpu-mesh"}, std::pair{&s.rings_program, "wire gpu-rings"}}) {
        GLint blocks = 0;
        glGetProgramInterfaceiv(program->id(), GL_SHADER_STORAGE_BLOCK, GL_ACTIVE_RESOURCES, &blocks);
        if (blocks > vertex_blocks) {
            return Error{std::string(label) + ": its vertex shader reads " + std::to_string(blocks) +
                         " shader storage blocks, the driver allows " + std::to_string(vertex_blocks) +
                         " (GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS)"};
        }
    }

    // Vertex arrays: the cpu-mesh one reads TubeVertex at binding 0 and the vertex's draw index at binding 1
    // (both streamed, set per frame); the gpu-rings one reads the chunk index at binding 1 (instanced, from the
    // 0, 1, 2, ... buffer) when the draw-parameters extension is missing.
    s.cpu_vao = gfx::make_vertex_array({.label = "wire cpu-mesh"});
    s.rings_vao = gfx::make_vertex_array({.label = "wire gpu-rings"});
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
    Expected<gfx::RetainedBuffer> storage = gfx::RetainedBuffer::create(
        {.initial_bytes = desc.ring_storage_bytes != 0 ? desc.ring_storage_bytes : std::size_t{4} << 20,
         .growth = desc.growth,
         .alignment = 16,
         .label = "wire ring storage"});
    if (!storage) return storage.error();
    s.ring_storage = std::move(storage).value();
    s.residency = RingResidency(desc.retain_frames != 0 ? desc.retain_frames : 180);
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
bool WireRenderer::uses_draw_parameters() const {
    return state_->draw_parameters;
}
std::size_t WireRenderer::live_stream_buffers() const {
    return state_->stream.live_buffers();
}
const std::vector<unsigned>& WireRenderer::allocated_stream_buffers() const {
    return state_->stream.allocated_buffers();
}
std::size_t WireRenderer::region_bytes() const {
    return state_->stream.region_bytes();
}
std::size_t WireRenderer::resident_wires() const {
    return state_->residency.resident_wires();
}
std::size_t WireRenderer::ring_storage_live_bytes() const {
    return state_->ring_storage.live_bytes();
}
std::size_t WireRenderer::ring_storage_capacity() const {
    return state_->ring_storage.capacity_bytes();
}
std::size_t WireRenderer::live_ring_buffers() const {
    return state_->ring_storage.live_buffers();
}
const std::vector<unsigned>& WireRenderer::allocated_ring_buffers() const {
    return state_->ring_storage.allocated_buffers();
}

std::size_t WireRenderer::node_path_buffers() const { return state_->nodes ? state_->nodes->gl_buffers() : 0; }
std::size_t WireRenderer::node_path_programs() const { return state_->nodes ? 2 : 0; }
std::size_t WireRenderer::node_path_wires() const { return state_->nodes ? state_->nodes->resident_wires() : 0; }

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
    return s.nodes->read_rings(out);
}

DrawStats WireRenderer::draw(const DrawList& list, const engine::scene::Camera& camera,
                              const DrawSettings& settings) {
    State& s = *state_;
    s.last_path = list.path;
    s.drawn_any = true;
    if (list.path == UploadPath::gpu_nodes) return s.draw_nodes(list, camera, settings);
    DrawStats stats;
    if (s.node_stream && detail::stream_active(*s.node_stream)) {
        // The stream's wires are computed by the nodes path only: said, not dropped in silence; the list draws.
        detail::end_stream_frame(*s.node_stream);
        s.failed(stats, Status::error("the node stream's wires draw on the nodes path; this draw list is on '" +
                                      std::string(upload_path_name(list.path)) + "': they were not drawn"));
    }
    const bool cpu = list.path == UploadPath::cpu_mesh;
    const bool retained = !cpu && s.desc.retain_rings;

    // (1) Items with geometry, grouped by material (stable: equal materials keep the list's order).
    s.order.clear();
    uint32_t max_sides = 0;
    for (uint32_t i = 0; i < list.items.size(); ++i) {
        const DrawItem& item = list.items[i];
        assert(item.material < s.materials.size() && "DrawItem::material out of range");
        assert((cpu || item.sides >= 1) && "DrawItem::sides must be >= 1");
        if (!has_geometry(item, list.path)) continue;
        s.order.push_back(i);
        max_sides = std::max(max_sides, item.sides);
    }
    // Opaque items (tubes, strips) first, then the blended phone-wire lines (sides 1), each by material; on
    // gpu-rings by side count within a material (one index pattern per side count).
    auto blended = [&](uint32_t i) { return list.items[i].sides == 1; };
    std::stable_sort(s.order.begin(), s.order.end(), [&](uint32_t a, uint32_t b) {
        if (blended(a) != blended(b)) return blended(b);
        const DrawItem& x = list.items[a];
        const DrawItem& y = list.items[b];
        if (x.material != y.material) return x.material < y.material;
        return !cpu && x.sides < y.sides;
    });
    if (retained) {
        s.retain(list, stats);  // also on an empty list: culled and destroyed wires age out
    }
    if (s.order.empty()) {  // nothing to draw: no draw call
        if (retained) s.ring_storage.end_frame();
        return stats;
    }
    const std::size_t n = s.order.size();
    if (!cpu) {
        if (Status st = s.ensure_patterns(max_sides); !st) return s.failed(stats, st);
    }

    // (2) Prepare: runs of equal (class, material), one multi-draw each, and their commands. cpu-mesh: one
    // command over the run's indices (rebased while copying, so no base vertex is needed). gpu-rings: one
    // instanced command per (side count, chunk kind) over the side count's pattern, one instance per chunk record
    // (upload_plan.hpp). The count never depends on the number of wires.
    auto same_run = [&](uint32_t a, uint32_t b) {
        return blended(a) == blended(b) && list.items[a].material == list.items[b].material;
    };
    s.run_first.clear();
    s.run_command.clear();
    s.commands.clear();
    s.chunks.clear();
    std::size_t geometry_bytes = 0;
    std::size_t vertex_total = 0;
    std::size_t index_total = 0;
    for (std::size_t r0 = 0; r0 < n;) {
        const DrawItem& head = list.items[s.order[r0]];
        if (r0 == 0 || !same_run(s.order[r0 - 1], s.order[r0])) {
            s.run_first.push_back(static_cast<uint32_t>(r0));
            s.run_command.push_back(static_cast<uint32_t>(s.commands.size()));
            if (cpu) s.commands.push_back({0, 1, static_cast<uint32_t>(index_total), 0, 0});  // first index: relative
        }
        if (cpu) {
            geometry_bytes += head.vertices.size_bytes();
            vertex_total += head.vertices.size();
            index_total += head.indices.size();
            s.commands.back().count += static_cast<uint32_t>(head.indices.size());
            ++r0;
            continue;
        }
        // gpu-rings: the items of one side count in this run.
        std::size_t r1 = r0 + 1;
        while (r1 < n && same_run(s.order[r0], s.order[r1]) && list.items[s.order[r1]].sides == head.sides) ++r1;
        std::array<uint32_t, kChunkKinds> counts{};
        for (std::size_t k = r0; k < r1; ++k) {
            const DrawItem& item = list.items[s.order[k]];
            const std::array<uint32_t, kChunkKinds> c = chunk_counts(item);
            for (uint32_t kind = 0; kind < kChunkKinds; ++kind) counts[kind] += c[kind];
            if (!retained || s.streamed[k]) geometry_bytes += item.rings.size() * sizeof(PackedRing);
        }
        const uint32_t sides = head.sides;
        const uint32_t pattern = s.pattern_first[sides];
        const uint32_t band_indices = sides > 2 ? 6 * sides : 6;  // strips and lines: 2 triangles a band
        std::array<uint32_t, kChunkKinds> next{};  // per kind: the next chunk record to write
        auto cursor = static_cast<uint32_t>(s.chunks.size() / 2);
        for (uint32_t kind = 0; kind < kChunkKinds; ++kind) {
            if (counts[kind] == 0) continue;
            next[kind] = cursor;
            // Caps: [start cap 3n][end cap 3n] at the pattern's start; bands follow them (tubes only).
            const uint32_t count = kind == 0 ? 6 * sides : chunk_kind_bands(kind) * band_indices;
            const uint32_t first = kind == 0 || sides <= 2 ? pattern : pattern + 6 * sides;
            s.commands.push_back({count, counts[kind], first, 0, cursor});
            cursor += counts[kind];
        }
        s.chunks.resize(2 * std::size_t{cursor});
        auto put = [&](uint32_t kind, std::size_t k, uint32_t first_band) {
            const uint32_t at = next[kind]++;
            s.chunks[2 * at] = static_cast<uint32_t>(k);
            s.chunks[2 * at + 1] = first_band;
        };
        for (std::size_t k = r0; k < r1; ++k) {
            const std::array<uint32_t, kChunkKinds> c = chunk_counts(list.items[s.order[k]]);
            if (c[0] != 0) put(0, k, 0);
            uint32_t band = 0;
            for (uint32_t i = 0; i < c[1]; ++i, band += kChunkBands) put(1, k, band);
            for (uint32_t kind = 2; kind < kChunkKinds; ++kind) {
                if (c[kind] == 0) continue;
                put(kind, k, band);
                band += chunk_kind_bands(kind);
            }
        }
        r0 = r1;
    }
    s.run_first.push_back(static_cast<uint32_t>(n));
    s.run_command.push_back(static_cast<uint32_t>(s.commands.size()));
    const std::size_t chunk_count_total = s.chunks.size() / 2;
    if (Status st = s.ensure_draw_index_capacity(chunk_count_total); !st) return stats;

    // Region layout: draw records | chunk records | commands | streamed geometry (vertices, or packed rings) |
    // the vertices' draw indices (cpu-mesh) | indices (cpu-mesh).
    const std::size_t draws_bytes = n * sizeof(detail::GpuDraw);
    const std::size_t chunk_bytes = s.chunks.size() * sizeof(uint32_t);
    const std::size_t command_bytes = s.commands.size() * sizeof(DrawElementsIndirectCommand);
    const std::size_t record_bytes = vertex_total * kVertexDrawIndexBytes;
    const std::size_t index_bytes = index_total * sizeof(uint32_t);
    const std::size_t chunk_offset = align_up(draws_bytes);
    const std::size_t command_offset = align_up(chunk_offset + chunk_bytes);
    const std::size_t geometry_offset = align_up(command_offset + command_bytes);
    const std::size_t record_offset = align_up(geometry_offset + geometry_bytes);
    const std::size_t index_offset = align_up(record_offset + record_bytes);
    const std::size_t total = index_offset + index_bytes;

    Expected<StreamRegion> begun = s.stream.begin(total);
    if (!begun) {  // allocation failed: skip the frame's wires, the rest of the frame goes on
        if (retained) s.ring_storage.end_frame();
        return stats;
    }
    const StreamRegion region = *begun;
    stats.buffer_grew = stats.buffer_grew || region.grew;
    stats.waited_for_gpu = region.waited;

    // Fill the region with sequential writes only (write-combined memory: never read it back).
    const State::View view = State::view_of(camera);
    const glm::dvec3 eye = view.camera.position;
    std::byte* base = region.data;
    const auto first_index_base = static_cast<uint32_t>((region.offset_bytes + index_offset) / sizeof(uint32_t));
    if (cpu) {
        for (DrawElementsIndirectCommand& c : s.commands) c.first_index += first_index_base;
    }
    if (chunk_bytes > 0) std::memcpy(base + chunk_offset, s.chunks.data(), chunk_bytes);
    std::memcpy(base + command_offset, s.commands.data(), command_bytes);
    std::size_t geometry_cursor = 0;  // bytes into the geometry section
    std::size_t index_cursor = 0;     // indices into the index section
    uint32_t vertex_cursor = 0;       // vertices into the vertex section
    auto* const vertex_records = reinterpret_cast<uint32_t*>(base + record_offset);
    auto* const indices = reinterpret_cast<uint32_t*>(base + index_offset);
    for (std::size_t k = 0; k < n; ++k) {
        const DrawItem& item = list.items[s.order[k]];
        const glm::vec3 offset(item.origin_m - eye);  // difference in double, then float
        detail::GpuDraw draw{{offset.x, offset.y, offset.z}, 0, 0, 0, 0, 0.0f};
        const uint32_t strip_flags =
            item.sides == 2 ? detail::kStrip : item.sides == 1 ? detail::kLine : 0u;  // both paths
        draw.flags = strip_flags;
        if (cpu) {
            const auto vertex_count = static_cast<uint32_t>(item.vertices.size());
            const std::size_t index_count = item.indices.size();
            std::memcpy(base + geometry_offset + geometry_cursor, item.vertices.data(),
                        item.vertices.size_bytes());
            std::fill_n(vertex_records + vertex_cursor, vertex_count, static_cast<uint32_t>(k));
            // Rebased while copying: one draw covers every wire of the run without a base vertex per wire.
            const uint32_t* src = item.indices.data();
            uint32_t* dst = indices + index_cursor;
            for (std::size_t i = 0; i < index_count; ++i) dst[i] = src[i] + vertex_cursor;
            geometry_cursor += item.vertices.size_bytes();
            index_cursor += index_count;
            vertex_cursor += vertex_count;
            stats.vertices += vertex_count;
            stats.triangles += index_count / 3;
        } else {
            const auto ring_count = static_cast<uint32_t>(item.rings.size());
            const bool stream = !retained || s.streamed[k];
            if (stream) {  // into this frame's region (binding 4); the retained path's moving wires too
                s.copy_packed(item, base + geometry_offset + geometry_cursor);
                draw.ring_first = static_cast<uint32_t>(geometry_cursor / 4);
                geometry_cursor += ring_count * sizeof(PackedRing);
                stats.ring_bytes_uploaded += ring_count * sizeof(PackedRing);
                ++stats.wires_uploaded;
            } else {
                draw.ring_first = s.ring_word[k];
            }
            draw.ring_count = ring_count;
            draw.sides = item.sides;
            // Normals tilt by the radius slope as write_tube's default does; a wire of constant radius has
            // slope 0 everywhere, so the shader skips the neighbour fetches per vertex for it.
            const float r0 = item.rings.front().radius_m;
            const bool varying = item.radius_varies ? *item.radius_varies
                                                    : std::any_of(item.rings.begin(), item.rings.end(),
                                                                  [r0](const Ring& r) { return r.radius_m != r0; });
            draw.flags = (item.closed ? detail::kClosed : 0u) | (item.caps ? detail::kCaps : 0u) |
                         (varying ? detail::kTilt : 0u) | (stream && retained ? detail::kStreamedRings : 0u) |
                         strip_flags;
            draw.u_close = item.u_close;
            stats.vertices += expanded_vertices(item);
            stats.triangles += expanded_triangles(item);
        }
        std::memcpy(base + k * sizeof(detail::GpuDraw), &draw, sizeof(draw));
    }
    stats.bytes_uploaded = draws_bytes + chunk_bytes + command_bytes + geometry_bytes + record_bytes + index_bytes +
                           (retained ? s.retained_ring_bytes : 0);
    stats.draw_items = n;
    stats.chunks = chunk_count_total;
    stats.indirect_commands = s.commands.size();

    // (3) Submit: GL state for the wires, the mode's program and vertex array, one multi-draw per run.
    Status no_program;
    const gfx::Program* chosen = s.program_for(cpu, settings.output, no_program);
    if (chosen == nullptr) {
        s.stream.end();
        if (retained) s.ring_storage.end_frame();
        return s.failed(stats, no_program);
    }
    const gfx::Program& program = *chosen;
    s.begin_wires(program, view.camera, settings);

    const GLuint buffer = region.buffer;
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, buffer, static_cast<GLintptr>(region.offset_bytes),
                      static_cast<GLsizeiptr>(draws_bytes));
    if (cpu) {
        glVertexArrayVertexBuffer(s.cpu_vao.id(), 0, buffer,
                                  static_cast<GLintptr>(region.offset_bytes + geometry_offset),
                                  sizeof(TubeVertex));
        glVertexArrayVertexBuffer(s.cpu_vao.id(), 1, buffer,
                                  static_cast<GLintptr>(region.offset_bytes + record_offset), sizeof(uint32_t));
        glVertexArrayElementBuffer(s.cpu_vao.id(), buffer);
        s.cpu_vao.bind();
    } else {
        // Binding 1: the rings a draw record addresses by default (retained storage, or the frame's region);
        // binding 4: the frame's region, for retained-path wires streamed this frame (kStreamedRings).
        const GLintptr geometry_at = static_cast<GLintptr>(region.offset_bytes + geometry_offset);
        const auto geometry_size = static_cast<GLsizeiptr>(std::max<std::size_t>(geometry_bytes, 4));
        if (retained) {
            glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, s.ring_storage.buffer(), 0,
                              static_cast<GLsizeiptr>(s.ring_storage.capacity_bytes()));
        } else {
            glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 1, buffer, geometry_at, geometry_size);
        }
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 4, buffer, geometry_at, geometry_size);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, s.circle.id());
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 3, buffer,
                          static_cast<GLintptr>(region.offset_bytes + chunk_offset),
                          static_cast<GLsizeiptr>(std::max<std::size_t>(chunk_bytes, 8)));
        s.rings_vao.bind();  // its element buffer is the pattern
    }
    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, buffer);

    bool blending = false;
    for (std::size_t run = 0; run + 1 < s.run_first.size(); ++run) {
        const DrawItem& head = list.items[s.order[s.run_first[run]]];
        const bool line = head.sides == 1;
        if (line && settings.output == Output::depth) break;  // translucent: no depth in a pre-pass (lines run last)
        // Phone-wire lines: opacity = true width / drawn width, over the opaque wires (colour output only).
        if (line && !blending && settings.output == Output::color) {
            glEnable(GL_BLEND);
            glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
            glDepthMask(GL_FALSE);
            blending = true;
        }
        const Material& material = s.materials[head.material];
        program.set("u_tint", material.tint);
        program.set("u_roughness", material.roughness);
        s.textures[material.texture].bind(0);
        const auto* indirect = reinterpret_cast<const void*>(
            region.offset_bytes + command_offset + s.run_command[run] * sizeof(DrawElementsIndirectCommand));
        const auto count = static_cast<GLsizei>(s.run_command[run + 1] - s.run_command[run]);
        glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, indirect, count, 0);
        ++stats.multi_draw_calls;
    }
    if (blending) {
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
    }
    s.stream.end();
    if (retained) s.ring_storage.end_frame();

    glBindBuffer(GL_DRAW_INDIRECT_BUFFER, 0);
    glBindVertexArray(0);
    glCullFace(GL_BACK);
    if (settings.wireframe) glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    return stats;
}

}  // namespace wire::render
