// The wire renderer: draws a frame's DrawList (modules/wire/include/wire/draw.hpp) with batched uploads into
// persistently mapped buffers and one multi-draw per (class, material): its commands are bounded by the side
// counts in use, never by the number of wires (issue 29). The only wire code that touches GL.
//
// Upload paths: the nodes path (gpu_nodes, the default where the context has compute) sends the nodes of wires
// whose nodes changed and a 4-byte slot per other visible wire; compute programs build the curve, the LOD, the
// rings and the draw's commands, and the ring vertex shader expands each tube over a static index pattern per
// side count, one instance per chunk of bands (upload_plan.hpp). cpu-mesh (the portable reference and fallback)
// streams every visible wire's vertices, a 4-byte draw index per vertex and its indices (rebased while copying)
// each frame, and draws a material's wires with one command.
//
// Structure: cpu-mesh's frame is (1) the items with geometry sorted by class and material, (2) a "prepare" step
// that writes each item's draw record, the run's commands and its geometry, (3) one submission loop issuing
// glMultiDrawElementsIndirect per run of equal (class, material). The nodes path's frame runs its compute
// stages and submits the commands the GPU wrote (src/node_path.hpp).
//
// \code
//   auto renderer = wire::render::WireRenderer::create();          // needs a current GL 4.5 context
//   engine::gfx::clear({0.1f, 0.1f, 0.12f, 1.0f});
//   wire::render::DrawStats stats = renderer->draw(list, camera);  // list.path picks gpu_nodes or cpu_mesh
// \endcode
#pragma once

#include "wire/draw.hpp"
#include "wire/lod.hpp"
#include "wire/render/node_stream.hpp"
#include "wire/rings.hpp"

#include "engine/gfx/resources.hpp"
#include "engine/gfx/shadow.hpp"
#include "engine/core/expected.hpp"
#include "engine/scene/camera.hpp"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

/// The wire renderer: the one part of the wire module that makes GL calls.
namespace wire::render {

using engine::Error;
using engine::Status;
using engine::Expected;

/// A row of the material table (DrawItem::material indexes it).
struct Material {
    glm::vec3 tint{1.0f};  ///< multiplies the texture (linear RGB)
    uint32_t texture = 0;  ///< index into the renderer's textures; 0 is the built-in weave
    float roughness = 0.5f;  ///< written by the G-buffer output (Output::gbuffer)
};

/// What a draw() writes into the bound framebuffer (always with depth test and depth writes).
enum class Output : uint8_t {
    /// Lit colour: the default shading or RendererDesc::shading_glsl, receiving DrawSettings::shadow.
    color,
    /// Depth only, of the surfaces facing the view: a depth pre-pass (the engine's later passes test against it).
    /// The depth written equals what the colour output writes, value for value (the wire programs compute positions
    /// invariantly); phone-wire lines (wires under a pixel of this view across, drawn translucent) are left out, as
    /// the colour output writes no depth for them. The colour output itself tests with GL_LESS: draw it on a depth
    /// buffer without the wires' pre-pass.
    depth,
    /// Depth only, as a shadow caster: draw from the light's view (engine::scene::directional_light_view,
    /// spot_light_view) into an engine::gfx::ShadowMap. The tube's far side from the light is written (back faces;
    /// strips and lines moved back by the radius): the side a wire shows the light is in front of its own map by
    /// about a diameter, so it never shadows itself (in stripes where the light's LOD or sides differ from the
    /// camera's), and its silhouette, hence its shadow on anything else, is unchanged. Phone-wire lines write depth
    /// over one pixel dithered to their opacity (true width / one pixel): a filtered lookup darkens by the wire's
    /// true width on average, never by a whole texel.
    shadow,
    /// The surface into a G-buffer, for an engine's deferred lights: RendererDesc::gbuffer_glsl, or the default
    /// layout (colour attachment 0: world normal * 0.5 + 0.5, 1: albedo, 2: (roughness, 0, 0, 1)). The normal
    /// and albedo are those the colour output shades.
    gbuffer,
};

/// Views a renderer keeps LOD state for (DrawSettings::view is below it).
inline constexpr uint32_t kMaxViews = 8;

/// Directional light: colour = (albedo * (ambient + (1 - ambient) * max(0, n.l)) + specular *
/// blinn^shininess) * light colour, albedo = texture(u, v) * tint. Both upload paths shade identically.
struct Light {
    glm::vec3 to_light{0.3f, 1.0f, 0.5f};  ///< direction toward the light (normalized by the renderer)
    glm::vec3 color{1.0f};                 ///< light colour (linear RGB)
    float ambient = 0.2f;                  ///< fraction of the albedo seen on the unlit side
    float specular = 0.15f;                ///< Blinn-Phong specular strength
    float shininess = 32.0f;               ///< Blinn-Phong exponent
};

/// Zero means default.
struct RendererDesc {
    uint32_t frames_in_flight = 0;  ///< regions of the stream buffer, each fenced; 0 -> 3
    std::size_t region_bytes = 0;   ///< initial capacity of one region; 0 -> 4 MiB (grows as needed)
    float growth = 0.0f;            ///< growth factor of a region that is too small; 0 -> 2
    int weave_size_px = 0;          ///< built-in weave texture edge; 0 -> 256
    float max_anisotropy = 0.0f;    ///< anisotropic filtering of the weave if the driver has it; 0 -> 8
    /// Optional GLSL `vec3 shade(vec3 albedo, vec3 n, vec3 to_eye)` replacing the default lighting (uniforms
    /// u_to_light, u_light_color, u_ambient, u_specular, u_shininess are declared). A shader that fails to
    /// compile makes create() return the driver's log.
    std::string_view shading_glsl{};
    /// Optional GLSL declaring the G-buffer's outputs and defining `void write_gbuffer(vec3 albedo, vec3 n, vec3
    /// rel_m, float roughness)` (n: unit world normal facing the eye; rel_m: the fragment minus the eye, metres),
    /// used by Output::gbuffer; empty: the default layout (Output::gbuffer). Compiled with the first G-buffer draw;
    /// a failure is that draw's status, with the driver's log.
    std::string_view gbuffer_glsl{};
    /// The nodes path's ring vertex shader: use the instanced chunk-index attribute even when
    /// ARB_shader_draw_parameters is available (tests). cpu-mesh always reads the draw index from its per-vertex
    /// attribute.
    bool force_draw_index_attribute = false;
    /// The nodes path: frames a wire's slot (its nodes, curve and LOD state on the GPU) stays while it is not
    /// drawn (culled or destroyed); 0 -> 180.
    uint32_t retain_frames = 0;
};

/// Per-frame options.
struct DrawSettings {
    Light light{};           ///< the frame's directional light
    bool wireframe = false;  ///< glPolygonMode(GL_LINE) for this frame's wires
    /// What the draw writes (colour, depth only, G-buffer).
    Output output = Output::color;
    /// Which view this draw is, 0 .. kMaxViews - 1: a frame may draw the same list from several views (a camera,
    /// a light's shadow map, a second camera), each with its own culling and LOD. The nodes path keeps each
    /// view's LOD hysteresis and frame state apart and sends nodes once (a later view's draw of an unchanged list
    /// sends a 4-byte slot per wire); give each view of a frame its own number, the same every frame. The CPU
    /// paths draw the rings their list holds (the systems' LOD for their camera); their strips face and their
    /// lines are sized for the view drawn.
    uint32_t view = 0;
    /// Output::color: the shadow map the wires receive (its `light` the view it was drawn from); null: none.
    const engine::gfx::ShadowMap* shadow = nullptr;
};

/// What one draw() did.
struct DrawStats {
    /// Bytes written into mapped buffers. cpu-mesh: draw records (32 B a wire), commands (20 B each), vertices
    /// (32 B) + their draw index (4 B a vertex) + indices (4 B) (streamed_upload_bytes). gpu-nodes: a 64-byte
    /// header and the nodes of each wire whose nodes changed, 4 B a slot when the list of drawn wires changed
    /// (plan_nodes_frame); the node stream's own region is not counted.
    std::size_t bytes_uploaded = 0;
    std::size_t wires_uploaded = 0;  ///< gpu-nodes: wires whose nodes (or curve) were sent this frame
    std::size_t wires_evicted = 0;   ///< gpu-nodes: slots freed (wires not drawn for retain_frames)
    std::size_t wires_skipped = 0;  ///< gpu-nodes: items not drawn (a spline kind the GPU does not build yet)
    /// gpu-nodes: wires whose rings did not fit the ring buffer (sized from a count read back 3 frames late) and
    /// were drawn with one ring a segment from its reserve; reported as read back, 3 frames late.
    std::size_t wires_coarse = 0;
    std::size_t draw_items = 0;      ///< items drawn (items with no geometry are skipped)
    std::size_t vertices = 0;  ///< cpu-mesh: vertices uploaded (the nodes path's are expanded on the GPU: 0)
    /// Triangles drawn; gpu-nodes: as the GPU counted them, read back 3 frames late (0 until then).
    std::size_t triangles = 0;
    /// Draw commands issued (indirect commands of the multi-draws): cpu-mesh one per (class, material) in use
    /// (wire::render::draw_commands); gpu-nodes one per (class, material, side count, chunk kind) slot the GPU
    /// fills. Does not grow with the number of wires.
    std::size_t indirect_commands = 0;
    std::size_t multi_draw_calls = 0;  ///< glMultiDrawElementsIndirect calls: one per (class, material) in use
    /// Success, or the frame's first problem: why it drew nothing (a program that did not build, a buffer that
    /// could not be made), or which item it skipped and why (gpu-nodes: a material out of range, a wire id listed
    /// twice; the rest is drawn). draw() also logs each distinct message once to stderr.
    Status status{};
    bool buffer_grew = false;          ///< the stream buffer was reallocated larger this frame
    bool waited_for_gpu =
        false;  ///< the region's fence had not signalled (more frames in flight than regions)
};

/// One wire's rings as a draw() on the nodes path computed and drew them, read back from the GPU
/// (WireRenderer::read_drawn_rings): what the vertex shader expanded, decoded as it decodes them.
struct DrawnRings {
    uint64_t wire_id = 0;  ///< DrawItem::wire_id
    uint32_t sides = 0;    ///< sides drawn: >= 3 a tube, 2 a camera-facing strip, 1 a line
    bool coarse = false;   ///< drawn with one ring a segment from the reserve (the ring buffer was short)
    /// origin_m: the wire's origin on the GPU (centres are float offsets from it); params: each ring's (segment,
    /// t) from the counts the GPU's LOD chose, placed as place_rings() places them; rings: the float records as
    /// drawn (the frame decoded from its 20-bit quaternion); frames, centre_m, u: the same in double (u of a
    /// closed loop has one more entry: where the loop closes); length_m; closed. arc_length_m, folds and
    /// frame_stats are not read back (left empty).
    RingSet rings;
};

/// The most nodes the GPU computes a wire from (its curve nodes, or its given segments + 1): one GPU invocation
/// walks a whole wire, so its serial work is bounded by this, and llvmpipe ends an invocation's loops after 65,535
/// iterations in all (a longer wire would be cut, not slow). draw() on the nodes path draws a longer item as
/// cpu-mesh does (its curve, LOD, rings and mesh built on the CPU, kept while its nodes_generation holds) in the
/// same frame; read_drawn_rings() lists it, read_draw_order() does not. The node stream refuses a longer write.
inline constexpr std::size_t kNodesPathMaxNodes = 8192;
/// The most rings the nodes path gives one wire: a wire whose LOD asks for more is drawn with one ring a segment
/// from the reserve (counted in DrawStats::wires_coarse), for the same reason.
inline constexpr std::size_t kNodesPathMaxRings = 32768;

/// One instance of a draw() on the nodes path, read back from the GPU (WireRenderer::read_draw_order): a chunk of
/// a wire's bands (upload_plan.hpp's chunk kinds), as the multi-draws meet it.
struct DrawnChunk {
    uint64_t wire_id = 0;      ///< DrawItem::wire_id
    uint32_t material = 0;     ///< DrawItem::material
    uint32_t sides = 0;        ///< sides drawn: >= 3 a tube, 2 a camera-facing strip, 1 a line
    uint32_t kind = 0;         ///< 0 the caps, k >= 1 kChunkBands >> (k - 1) bands
    uint32_t first_band = 0;   ///< the chunk's first band along the wire (0 for the caps)
    bool operator==(const DrawnChunk&) const = default;
};

/// What a renderer holds (WireRenderer::info()).
struct RendererInfo {
    /// The ring vertex shader (nodes path): the chunk index comes from gl_BaseInstanceARB + gl_InstanceID
    /// (ARB_shader_draw_parameters), not from the instanced attribute.
    bool draw_parameters = false;
    std::size_t region_bytes = 0;         ///< capacity of one stream-buffer region now
    std::size_t live_stream_buffers = 0;  ///< stream buffers alive: 1 plus retired ones still waiting for their fences
    std::vector<unsigned> allocated_stream_buffers;  ///< GL names of every stream buffer allocated (the first: initial)
    /// gpu-nodes: GL buffers and programs the nodes path holds (0 before its first frame, which compiles its
    /// programs), and the wires it keeps a slot for.
    std::size_t node_path_buffers = 0, node_path_programs = 0, node_path_wires = 0;
};

/// Draws DrawLists (see the file comment). Owns GL objects: create, use and destroy it with the same context
/// current. Move-only.
class WireRenderer {
public:
    /// Compiles the programs (errors carry the driver's log via engine::gfx::make_program), makes the weave
    /// texture and the stream buffer. Material 0 is the weave with a copper tint. Needs a current GL 4.5
    /// context.
    static Expected<WireRenderer> create(const RendererDesc& desc = {});

    WireRenderer();                                    ///< empty: use create()
    WireRenderer(WireRenderer&&) noexcept;             ///< takes over the GL objects
    WireRenderer& operator=(WireRenderer&&) noexcept;  ///< takes over the GL objects
    ~WireRenderer();                                   ///< deletes the GL objects (context current)

    /// Adds a texture (e.g. engine::gfx::make_texture with Wrap::repeat); returns its index for
    /// Material::texture.
    uint32_t add_texture(engine::gfx::Texture texture);
    /// Adds a material; returns its index for DrawItem::material.
    uint32_t add_material(const Material& material);
    /// Replaces material `index` (< materials().size()).
    void set_material(uint32_t index, const Material& material);
    /// The material table; DrawItem::material indexes it.
    [[nodiscard]] const std::vector<Material>& materials() const;

    /// Uploads and draws `list` into the bound framebuffer with depth test (GL_LESS) and back-face culling (it
    /// does not clear), writing settings.output. All items go into one region of the stream buffer; one glMultiDraw*Indirect per (class,
    /// material); the region is fenced afterwards. An empty list issues no draw. Item rules (asserted): material <
    /// materials(), cpu_mesh items have indices < their vertex count.
    DrawStats draw(const DrawList& list, const engine::scene::Camera& camera,
                    const DrawSettings& settings = {});

    /// The upload path to draw with on this context: gpu_nodes where it has what the nodes path needs (compute
    /// shaders and multi-draw indirect: GL 4.3 or their extensions; the storage block limits its programs use;
    /// programs that build), cpu_mesh otherwise (the portable reference: the same picture). Decided on the first
    /// call (it makes the nodes path), logged once to stderr as one line, "wire: upload path nodes (GL 4.5 compute
    /// on ...)" or "wire: upload path cpu (why)". Runtimes call it once at start and give it to
    /// wire::systems::WireContext::path. WIRE_GL_NO_COMPUTE=1 in the environment forces the fallback.
    [[nodiscard]] UploadPath preferred_path();
    /// Why preferred_path() chose as it did (the logged line's parenthesis).
    [[nodiscard]] const std::string& preferred_path_reason();

    /// gpu-nodes: the rings of every wire the last draw() drew (wires culled on the GPU are absent), in the order
    /// the GPU dispatched them; waits for the GPU. Fails, naming the reason, when the last draw() was on another
    /// path (cpu-mesh builds its rings on the CPU: wire::systems::wire_ring_set has them) or drew
    /// nothing because the nodes path failed.
    Status read_drawn_rings(std::vector<DrawnRings>& out) const;
    /// gpu-nodes: the chunks the last draw() drew, in the order the GPU draws them (per material the tubes' and
    /// strips' multi-draws, then the lines'; in each bucket, the wires in the order they were dispatched, each
    /// wire's chunks along it). The same list and view give the same order on every GPU (the place program
    /// allocates in wire order, not by atomics). Fails as read_drawn_rings() does.
    Status read_draw_order(std::vector<DrawnChunk>& out) const;
    /// The bulk node stream (node_stream.hpp): wires whose nodes a physics engine writes straight into this
    /// renderer's mapped memory, drawn by draw() on the nodes path beside the list's wires. Made (with the nodes
    /// path) on the first call; NodeStream::usable() says why not where the context lacks compute.
    NodeStream& node_stream();

    /// What the renderer holds now (GL buffers, capacities, resident wires): for tests, soak runs and benchmarks.
    [[nodiscard]] RendererInfo info() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace wire::render
