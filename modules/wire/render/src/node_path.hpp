// Internal: the renderer's nodes path (UploadPath::gpu_nodes, issue 30). Per frame the CPU sends, for the visible
// wires whose nodes changed, their curve nodes and a 64-byte header (into the renderer's fenced stream region),
// plus a 4-byte slot per other visible wire (the curve passes list the changed ones); the node stream's wires
// (node_stream.hpp) arrive with their headers and nodes in the stream's own region, and get a curve pass of their
// own. Everything after that runs in compute dispatches: the curve (into persistent per-wire segments), the LOD
// (below the node resolution unless the settings keep it; hysteresis state per wire kept on the GPU), the ring
// ranges and chunk records (in wire order), the indirect commands, the rings with their frames and u, the draw
// records; then the ring vertex shader draws them with one multi-draw per (class, material), reading commands
// the GPU wrote.
#pragma once

#include "wire/curve.hpp"
#include "wire/draw.hpp"
#include "wire/lod.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/packed_ring.hpp"
#include "wire/render/node_stream.hpp"
#include "wire/render/wire_renderer.hpp"

#include "engine/gfx/range_allocator.hpp"
#include "engine/gfx/resources.hpp"
#include "engine/gfx/stream_buffer.hpp"
#include "engine/scene/camera.hpp"

#include <epoxy/gl.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

namespace wire::render::detail {

/// Alignment of the sections of a stream region: >= GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT on every driver.
inline constexpr std::size_t kSectionAlign = 256;
inline std::size_t align_up(std::size_t v) { return (v + kSectionAlign - 1) / kSectionAlign * kSectionAlign; }
/// Frames between the ring pass's counts and their read on the CPU (the ring buffer's size).
inline constexpr uint32_t kReadbackSlots = 3;
/// The ring pass's Counter: rings, wires that did not fit, reserve rings, triangles.
inline constexpr std::size_t kCounterBytes = 16;
/// The nodes path's GPU records (gpu_wire_data.hpp has their C++ mirrors): a job, a slot's state, a segment, a draw.
inline constexpr std::size_t kJobBytes = 64, kSlotStateBytes = 32, kSegmentBytes = 64, kDrawBytes = 32;
/// A nodes-path item's nodes: its packed nodes', its given curve's segments + 1 (open), or its nodes'.
inline std::size_t node_count(const DrawItem& item) {
    if (item.packed_nodes != nullptr && item.packed_nodes->node_count >= 2) return item.packed_nodes->node_count;
    if (item.curve != nullptr && !item.curve->segments.empty())
        return item.curve->segments.size() + (item.spline.closed ? 0 : 1);
    return item.nodes != nullptr ? item.nodes->size() : 0;
}

/// Zeroes `bytes` of `buffer` from `offset` (a multiple of 4).
void clear_range(const engine::gfx::Buffer& buffer, std::size_t offset, std::size_t bytes);

struct StreamState;
struct WireUpload;

/// What the nodes path borrows from the renderer to draw.
struct NodeDrawContext {
    const engine::gfx::Program& program;  ///< the ring vertex shader's program
    const engine::gfx::VertexArray& vao;  ///< its vertex array (element buffer: the patterns)
    unsigned circle = 0;                  ///< the side table buffer
    const std::vector<uint32_t>& pattern_first;
    const std::vector<Material>& materials;
    const std::vector<engine::gfx::Texture>& textures;
    bool draw_parameters = true;
};

class NodePath {
public:
    static Expected<std::unique_ptr<NodePath>> create(uint32_t retain_frames);
    NodePath() = default;
    NodePath(const NodePath&) = delete;
    NodePath& operator=(const NodePath&) = delete;
    ~NodePath();  ///< deletes its fences (context current)
    /// The LOD of the next frames (max_sides clamped to 3 .. 256).
    void set_lod(const LodSettings& lod);

    /// Uploads and computes the frame (see the file comment) into `region` (begun by the caller with at least
    /// upload_bytes(list) bytes) as seen by `lod_view` (positions relative to its eye), with view `view`'s LOD and
    /// frame state (< kMaxViews; each view keeps its own hysteresis); returns false (nothing to draw) when no item
    /// draws. The patterns in `ctx` must cover max_sides().
    bool prepare(const DrawList& list, const LodView& lod_view, uint32_t view, const engine::gfx::StreamRegion& region,
                 const NodeDrawContext& ctx, DrawStats& stats);
    /// How submit() draws the phone-wire lines: blended over the rest without depth writes (colour), not at all
    /// (a depth pre-pass: they are translucent), or opaque with depth (a shadow caster; the shader dithers them).
    enum class Lines { blended, skipped, opaque };
    /// Issues the draws prepare() set up.
    void submit(const NodeDrawContext& ctx, DrawStats& stats, Lines lines = Lines::blended);
    /// Bytes prepare() writes into the region for `list` (an upper bound; computed per frame).
    std::size_t upload_bytes(const DrawList& list);
    /// The rings the last prepare() computed and submit() drew (WireRenderer::read_drawn_rings); waits for the GPU.
    Status read_rings(std::vector<DrawnRings>& out) const;
    /// The chunks the last prepare() placed, in the order submit() draws them (WireRenderer::read_draw_order).
    Status read_draw_order(std::vector<DrawnChunk>& out) const;
    /// The most sides the frame's LOD can give (the patterns must cover it).
    [[nodiscard]] uint32_t max_sides() const { return max_sides_; }

    [[nodiscard]] std::size_t resident_wires() const { return slots_.size(); }
    /// GL buffers it holds now (its persistent and per-frame buffers; a grown one replaces the old).
    [[nodiscard]] std::size_t gl_buffers() const;
    /// GL programs it holds (the curve program and the ring pass's four).
    [[nodiscard]] std::size_t gl_programs() const;
    /// Chunk records the frame may draw (the instanced chunk-index attribute must cover them).
    [[nodiscard]] std::size_t chunk_capacity() const { return chunk_bytes_ / 8; }

    /// The node stream whose wires the frames draw beside the list's (node_stream.cpp); null: none.
    void attach(StreamState* stream) { stream_ = stream; }
    /// A slot for a new wire (its LOD and frame state and motion reference cleared); nullopt if it cannot grow.
    std::optional<uint32_t> acquire_slot();
    /// Gives a wire's slot and segments back.
    void release_slot(uint32_t index, uint32_t segment_first, uint32_t segments);

private:
    struct Slot {
        uint32_t index = 0;
        uint32_t segment_first = 0, segments = 0;
        uint64_t generation = 0;
        uint64_t last_frame = 0;
        bool built = false;  ///< its curve is on the GPU
    };
    Status grow_slots(std::size_t slots);
    /// View `view`'s LOD and frame state (view 0: slot_state_), made (cleared) on first use; null if it cannot be.
    const engine::gfx::Buffer* view_state(uint32_t view);
    /// Clears `bytes` of slot `index`'s state in every view's buffer (16: the LOD only, kSlotStateBytes: all).
    void clear_slot_state(uint32_t index, std::size_t bytes);
    Status grow_segments(std::size_t segments);
    Status ensure(engine::gfx::Buffer& buffer, std::size_t& capacity, std::size_t bytes, const char* label,
                  bool keep_contents);
    bool allocate_segments(uint32_t count, uint32_t& first);
    void free_segments(uint32_t first, uint32_t count);
    // The stream's part of a frame (node_stream.cpp): its written wires' headers into its region (returns how
    // many), the others listed; what to bind; the nodes written; on a failed frame, its wires marked unbuilt.
    std::size_t emit_stream(std::size_t materials, std::size_t& segments_visible, DrawStats& stats);
    struct StreamLayout {
        unsigned buffer = 0;
        std::size_t header_at = 0, header_bytes = 0, node_at = 0, node_bytes = 0;
    };
    [[nodiscard]] StreamLayout stream_layout() const;
    [[nodiscard]] std::size_t stream_nodes() const;
    [[nodiscard]] std::size_t stream_wires() const;  ///< the stream's wire records (live or not)
    void unbuild_stream();
    // The frame's CPU side (node_path_gather.cpp).
    /// The ring pass's counts of kReadbackSlots frames ago, once the fence after their copy has signalled: the ring
    /// buffer's size, and the coarse wires and triangles they report.
    void read_counts(DrawStats& stats);
    /// What gather() found: 8-byte units and vec4s for the region's node and extra arrays, segments of the visible wires.
    struct Gathered {
        std::size_t node_total = 0, extra_total = 0, segments_visible = 0;
    };
    /// The list's items into slots (new, changed, unchanged): the changed wires' headers into `up` and their nodes
    /// as pieces to copy, the unchanged ones listed; slots not drawn for a while evicted. Skipped items are counted
    /// in `stats` (a material out of range, an id listed twice: its status says which).
    Gathered gather(const DrawList& list, std::size_t materials, WireUpload& up, DrawStats& stats);

    engine::gfx::Program curve_program_;
    /// The ring pass's stages (shaders.hpp): LOD, place (ring ranges), indirect commands, place (chunk records), rings.
    engine::gfx::Program ring_lod_program_, ring_place_program_, ring_commands_program_, ring_build_program_;
    LodSettings lod_{};
    uint32_t retain_frames_ = 180, max_sides_ = 32;
    uint64_t frame_ = 0;
    std::unordered_map<uint64_t, Slot> slots_;
    std::vector<uint32_t> free_slots_;
    uint32_t slot_count_ = 0;  ///< slots made (the list's wires and the stream's)
    StreamState* stream_ = nullptr;
    engine::gfx::RangeAllocator segment_ranges_{0, 1};  ///< the segment storage's ranges, in segments
    // Persistent (GPU only).
    engine::gfx::Buffer slot_headers_, slot_state_, motion_refs_, segments_, counts_;
    std::vector<engine::gfx::Buffer> view_states_;  ///< views 1 ..: their slot state (same size as slot_state_)
    std::size_t slot_capacity_ = 0, segment_capacity_ = 0;
    std::size_t slot_header_bytes_ = 0, slot_state_bytes_ = 0, motion_ref_bytes_ = 0, segment_bytes_ = 0,
                count_bytes_ = 0;
    // Per frame (GPU only; regrown as needed).
    engine::gfx::Buffer scratch_, jobs_, draws_, chunks_, rings_, buckets_, commands_, counter_, templates_, readback_;
    std::size_t scratch_bytes_ = 0, job_bytes_ = 0, draw_bytes_ = 0, chunk_bytes_ = 0, ring_bytes_ = 0,
                bucket_bytes_ = 0, command_bytes_ = 0, counter_bytes_ = 0, template_bytes_ = 0;
    std::size_t ring_capacity_ = 0;  ///< rings the ring buffer holds
    void* readback_map_ = nullptr;   ///< per readback slot: the ring counter and overflow, read 3 frames later
    /// Per readback slot: the fence after the copy into it (null: nothing in flight), read only once signalled.
    std::array<GLsync, kReadbackSlots> readback_fence_{};
    std::size_t max_block_bytes_ = std::size_t{1} << 27;  ///< GL_MAX_SHADER_STORAGE_BLOCK_SIZE
    uint32_t template_sides_ = 0;    ///< side slots the templates were built for
    std::size_t template_patterns_ = 0;
    // This frame.
    std::size_t visible_ = 0, changed_ = 0, buckets_used_ = 0;
    uint32_t side_slots_ = 0;
    std::size_t materials_ = 0;
    std::vector<uint8_t> material_used_;
    std::vector<uint8_t> changed_item_;  ///< per item of the list upload_bytes() saw: it sends its nodes
    std::vector<Slot*> item_slot_;       ///< per item: its slot when upload_bytes() found one (map nodes are stable)
    /// A run of 8-byte node units (or extra vec4s) the frame copies into the region's node (or extra) array at
    /// `dst`: from `src`, or (src null) from the frame's own at `own` (those made on the render thread).
    struct Piece {
        const void* src = nullptr;
        std::size_t own = 0, count = 0, dst = 0;
    };
    std::vector<Piece> node_pieces_, extra_pieces_;
    std::vector<uint32_t> visible_slots_;
    /// Per wire the last prepare() dispatched, in the ring pass's order (the listed, then the list's changed wires,
    /// then the stream's): what read_rings() needs to find its records.
    struct Dispatched {
        uint64_t wire_id = 0;
        uint32_t slot = 0, segment_first = 0, segments = 0;
    };
    std::vector<Dispatched> dispatched_, listed_;
    std::vector<Dispatched> changed_wires_, stream_wires_;  ///< the frame's curve passes' wires: the list's, the stream's
    std::size_t stream_changed_ = 0, unchanged_ = 0, stream_bytes_ = 0;
    std::vector<uint32_t> last_visible_;  ///< the list kept on the GPU (visible_kept_): unchanged, it is not sent
    engine::gfx::Buffer visible_kept_;
    std::size_t visible_kept_bytes_ = 0;
};

/// The renderer's side of a NodeStream (node_stream.cpp): attach it to the nodes path, or mark it unusable (why);
/// whether a frame is begun and not drawn; fence the frame's region after the draws that read it.
void attach_stream(NodePath& path, NodeStream& stream);
void detach_stream(NodeStream& stream, const Status& why);
bool stream_active(NodeStream& stream);
void end_stream_frame(NodeStream& stream);

}  // namespace wire::render::detail
