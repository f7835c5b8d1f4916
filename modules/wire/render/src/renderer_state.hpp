// Internal: WireRenderer's state, shared by its front end and its back ends.
//
//   wire_renderer.cpp  create(), the material table, preferred_path(), the node stream, the info
//   draw.cpp           the front end of draw(): items sorted into runs, the programs, GL state, the stream
//   region's
//                      begin and end, the one submission loop (a multi-draw per run); the nodes path's frame
//   mesh_path.cpp      cpu-mesh's back end: its commands, the vertices and rebased indices it streams, its
//                      bindings
//   patterns.cpp       the ring expansion's index patterns, side table and chunk-index buffer (the nodes path)
//   node_path*.cpp     the nodes path (node_path.hpp)
// cpu-mesh's back end prepares a frame (ListFrame) into the region the front end begins and binds what its
// program reads; the front end submits it.
#pragma once

#include "wire/render/wire_renderer.hpp"

#include "node_path.hpp"
#include "shaders.hpp"
#include "wire/curve.hpp"
#include "wire/render/upload_plan.hpp"
#include "wire/rings.hpp"
#include "wire/tube.hpp"

#include "engine/gfx/stream_buffer.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace wire::render::detail {

namespace gfx = engine::gfx;

struct DrawElementsIndirectCommand {
    uint32_t count;
    uint32_t instance_count;
    uint32_t first_index;
    int32_t base_vertex;
    uint32_t base_instance;
};
static_assert(sizeof(DrawElementsIndirectCommand) == kCommandBytes);
static_assert(sizeof(GpuDraw) == kDrawRecordBytes);

/// cpu-mesh: the vertex's draw index; the rings (nodes path) without draw parameters: the chunk index.
inline constexpr unsigned kRecordLocation = 3;
/// The ring patterns are built for 3 .. max(this, the largest side count seen).
inline constexpr uint32_t kPatternMinSides = 16;

/// Phone-wire lines (sides 1) are drawn blended, after the opaque tubes and strips.
inline bool blended(const DrawItem& item) {
    return item.sides == 1;
}
/// Items `a` and `b` of `list` go in one multi-draw: the same class (opaque or blended) and material.
inline bool same_run(const DrawList& list, uint32_t a, uint32_t b) {
    const DrawItem& x = list.items[a];
    const DrawItem& y = list.items[b];
    return blended(x) == blended(y) && x.material == y.material;
}

/// One cpu-mesh frame: what the back end's prepare wrote into the stream region, read by its bind and by the
/// front end's submission. Region layout: draw records | commands | vertices | the vertices' draw indices |
/// indices.
struct ListFrame {
    gfx::StreamRegion region{};
    std::size_t draws_bytes = 0;
    std::size_t command_offset = 0;
    std::size_t geometry_offset = 0, geometry_bytes = 0;
    std::size_t record_offset = 0;  ///< the vertices' draw indices

    /// Lays the sections out for `n` draw records, `command_bytes`, geometry_bytes and `record_bytes` of vertex
    /// draw indices; returns the index section's offset (the region's size is that plus the indices).
    std::size_t lay_out(std::size_t n, std::size_t command_bytes, std::size_t record_bytes) {
        draws_bytes = n * sizeof(GpuDraw);
        command_offset = align_up(draws_bytes);
        geometry_offset = align_up(command_offset + command_bytes);
        record_offset = align_up(geometry_offset + geometry_bytes);
        return align_up(record_offset + record_bytes);
    }
};

}  // namespace wire::render::detail

namespace wire::render {

struct WireRenderer::State {
    RendererDesc desc;
    detail::gfx::Program cpu_program;    ///< colour output
    detail::gfx::Program rings_program;  ///< colour output (the nodes path draws with it too)
    /// Depth and G-buffer outputs, [0] cpu-mesh, [1] rings: compiled with their first draw.
    std::array<detail::gfx::Program, 2> depth_programs, gbuffer_programs;
    std::string cpu_vertex, rings_vertex, gbuffer_glsl;  ///< kept for those compiles
    detail::gfx::VertexArray cpu_vao;
    detail::gfx::VertexArray rings_vao;
    detail::gfx::Buffer
        draw_index_buffer;  ///< 0, 1, 2, ... for the instanced chunk-index attribute (fallback only)
    std::size_t draw_index_capacity = 0;
    bool draw_parameters = false;
    detail::gfx::StreamBuffer stream;
    detail::gfx::Buffer pattern;          ///< static index patterns of the ring expansion, one per side count
    detail::gfx::Buffer circle;           ///< cos, sin of 2 pi j / n per side count n (the shader's circle[])
    std::vector<uint32_t> pattern_first;  ///< first index of side count n's pattern (index n)
    uint32_t pattern_max_sides = 0;
    std::vector<detail::gfx::Texture> textures;
    std::vector<Material> materials;
    // Per-frame scratch, reused.
    std::vector<uint32_t> order;  ///< cpu-mesh: items with geometry, sorted by class and material
    std::vector<uint32_t>
        run_first;  ///< per run of (class, material): first order position (+ one past the end)
    std::vector<uint32_t> run_command;  ///< per run: its first command (plus one past the end)
    std::vector<detail::DrawElementsIndirectCommand> commands;
    std::unique_ptr<detail::NodePath> nodes;  ///< gpu-nodes: made on its first frame
    std::unique_ptr<NodeStream> node_stream;  ///< made on the first node_stream() call
    Status nodes_failed{};                    ///< why the nodes path could not be made (not retried)
    std::optional<UploadPath> preferred;      ///< preferred_path()'s choice, made once
    std::string preferred_why;
    std::vector<std::string> logged;  ///< failures draw() has logged (each once)
    UploadPath last_path = UploadPath::cpu_mesh;
    bool drawn_any = false;  ///< a draw() has run

    // ---- wire_renderer.cpp ----
    /// Makes the nodes path once (a failure is kept: not retried).
    Status ensure_nodes();
    /// What the context lacks of what the nodes path needs (empty: nothing): compute shaders and multi-draw
    /// indirect (GL 4.3 or their extensions); WIRE_GL_NO_COMPUTE=1 in the environment pretends compute is
    /// missing (the fallback's test).
    static std::string missing_compute();

    // ---- draw.cpp: the front end ----
    /// `stats` with the failure recorded, logged to stderr the first time this message is seen.
    DrawStats& failed(DrawStats& stats, const Status& why);
    /// The program of `output` for cpu-mesh or the rings (compiled on first use); null: it did not build
    /// (why).
    const detail::gfx::Program* program_for(bool cpu, Output output, Status& why);
    /// The camera a draw places positions and projects with, and the LOD's view of it.
    struct View {
        engine::scene::Camera camera;  ///< at the eye positions are relative to
        LodView lod;
    };
    /// `camera` over the bound viewport: positions are relative to its eye (offsets computed in double, sent
    /// as float, projected with Camera::clip_from_relative(): wires far from the world origin keep their
    /// precision); an orthographic camera is moved back to the eye of LodView::orthographic() with its clip
    /// box unchanged.
    static View view_of(const engine::scene::Camera& camera);
    /// The frame's GL state and the wire program's per-frame uniforms (every path).
    void begin_wires(const detail::gfx::Program& program, const engine::scene::Camera& camera,
                     const DrawSettings& settings);
    /// The gpu-nodes frame (node_path.hpp).
    DrawStats draw_nodes(const DrawList& list, const engine::scene::Camera& camera,
                         const DrawSettings& settings);
    /// The cpu-mesh frame of `list`'s items with geometry, into `stats`.
    DrawStats draw_mesh(const DrawList& list, const engine::scene::Camera& camera, const DrawSettings& settings,
                        DrawStats stats);

    // ---- long_wires.cpp ----
    /// A nodes-path item longer than kNodesPathMaxNodes, drawn as cpu-mesh from what is built here: its curve
    /// (rebuilt when its nodes_generation changes, or every frame at 0), its LOD in this view (hysteresis
    /// kept), its rings (the first normal carried from the last build) and mesh (rebuilt when the counts or
    /// sides change).
    struct LongWire {
        uint64_t generation = 0;
        bool has_curve = false, has_mesh = false;
        Curve curve;
        WireLod lod;
        std::vector<RingParam> params;
        RingSet rings;
        TubeMesh mesh;
        std::vector<uint32_t> mesh_counts;
        uint32_t mesh_sides = 0;
        uint64_t last_frame = 0;
    };
    std::unordered_map<uint64_t, LongWire> long_wires;  ///< by wire_id
    uint64_t long_frame = 0;
    std::vector<std::pair<uint64_t, const LongWire*>> long_drawn;  ///< the last draw()'s long wires (read back)
    /// A nodes-path list with long items: those drawn from meshes (cpu-mesh), then the rest on the nodes path.
    DrawStats draw_with_long_wires(const DrawList& list, const engine::scene::Camera& camera,
                                   const DrawSettings& settings);

    // ---- mesh_path.cpp: cpu-mesh ----
    /// `order`'s items (at least one) into a region it begins: runs, one command a run over its indices
    /// (rebased while copying), draw records, vertices and their draw indices. Fails (nothing begun) without
    /// a region.
    Status prepare_mesh(const DrawList& list, const glm::dvec3& eye, detail::ListFrame& frame,
                        DrawStats& stats);
    /// Binds the vertex array and the region's vertices, draw indices and indices.
    void bind_mesh(const detail::ListFrame& frame);

    // ---- patterns.cpp ----
    /// The ring expansion's index patterns and side table cover 3 .. max_sides sides.
    Status ensure_patterns(uint32_t max_sides);
    /// The 0, 1, 2, ... buffer of the chunk-index attribute holds at least `n` (draw parameters: nothing to
    /// do).
    Status ensure_draw_index_capacity(std::size_t n);
};

}  // namespace wire::render
