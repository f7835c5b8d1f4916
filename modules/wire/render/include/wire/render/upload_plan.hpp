// What the wire renderer uploads, without GL: the compact ring record, the ring expansion's draw counts, the
// bytes a frame sends on each path (cpu-mesh's lists; the nodes path's slots as NodesPlan follows them). The
// renderer and `wiretool bench` share these, so the benchmark's byte counts are the renderer's by construction.
#pragma once

#include "wire/draw.hpp"
#include "wire/packed_ring.hpp"
#include "wire/rings.hpp"

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

namespace wire::render {

// The ring record as the GPU reads it (PackedRing, pack_ring, pack_rings, unpack_frame) lives in the wire core,
// wire/packed_ring.hpp, so the (parallel) rings system can produce it; these names keep the renderer's.
using wire::DecodedFrame;
using wire::kPackedRingWords;
using wire::pack_ring;
using wire::pack_rings;
using wire::PackedRing;
using wire::unpack_frame;

// ---- indexed expansion --------------------------------------------------------------------------------------
// A wire of R rings and n sides has rows of n + 1 vertices (the seam is duplicated for u = 1), one row per ring
// (a closed wire has one more row: ring 0 again with u = u_close), and, on open wires with caps, two caps of
// n + 1 vertices (centre + rim) addressed by vertex ids from kCapVertexBase up. One static index pattern per
// side count: [start cap 3n][end cap 3n][kChunkBands bands of 6n]. Strips (sides 2) and phone-wire lines
// (sides 1): 2 vertices a row (wire::write_strip's layout), no caps; one pattern of kChunkBands bands of 6
// indices shared by both.
//
// One draw for all wires (issue 29): a wire's bands are cut into chunks whose sizes are kChunkBands and then the
// binary digits of the remainder (16, 8, 4, 2, 1), plus one cap chunk on a capped open tube. A chunk is one
// instance of an instanced indexed draw over a prefix of its side count's pattern; its 8-byte record (draw
// index, first band) tells the vertex shader whose rings to read. All chunks of one kind (caps, or a band count)
// and one side count in a material's run are one indirect command, so a frame issues at most
// kChunkKinds commands per (class, material, side count), whatever the number of wires; every chunk draws
// exactly its own triangles (no padding) and each vertex is shaded once per chunk it belongs to (a row at a
// chunk boundary twice).
inline constexpr uint32_t kChunkBands = 16;
inline constexpr uint32_t kChunkKinds = 6;  ///< kind 0: caps; kind k >= 1: chunks of kChunkBands >> (k - 1) bands
inline constexpr uint32_t kCapVertexBase = 1u << 30;

/// One wire's ring expansion as the nodes path's ring pass lays it out (rings.comp's chunk_count_of): `rings`
/// rings of `sides` sides (2: strip, 1: line), closed or open, capped or not.
struct RingExpansion {
    uint32_t rings = 0;
    uint32_t sides = 8;
    bool closed = false;
    bool caps = true;
};
/// Bands (quad rows): rings - 1, plus 1 on a closed wire; 0 without rings.
[[nodiscard]] uint32_t band_count(const RingExpansion& e);
/// Whether the expansion draws anything (bands, or the caps of a capped open tube).
[[nodiscard]] bool draws_anything(const RingExpansion& e);
/// Bands in a chunk of `kind` (>= 1); 0 for the cap kind.
[[nodiscard]] constexpr uint32_t chunk_kind_bands(uint32_t kind) {
    return kind == 0 ? 0u : kChunkBands >> (kind - 1);
}
/// Chunks of each kind the expansion draws (all 0 when it draws nothing).
[[nodiscard]] std::array<uint32_t, kChunkKinds> chunk_counts(const RingExpansion& e);
/// Chunk records the expansion needs: the sum of chunk_counts.
[[nodiscard]] uint32_t chunk_count(const RingExpansion& e);
/// Vertices (unique, as a mesh would hold them) and triangles of the expansion: equal to wire::tube_counts
/// (strip_counts for sides 1 and 2).
[[nodiscard]] uint32_t expanded_vertices(const RingExpansion& e);
[[nodiscard]] uint32_t expanded_triangles(const RingExpansion& e);

// ---- cpu-mesh: bytes per frame ------------------------------------------------------------------------------
inline constexpr std::size_t kDrawRecordBytes = 32;  ///< per drawn item (detail::GpuDraw)
inline constexpr std::size_t kCommandBytes = 20;     ///< per indirect command (DrawElementsIndirectCommand)
inline constexpr std::size_t kChunkRecordBytes = 8;  ///< the nodes path: per chunk (draw index, first band)
inline constexpr std::size_t kVertexDrawIndexBytes = 4;  ///< cpu-mesh: per vertex, the draw index beside it

/// Whether a cpu-mesh item draws anything (vertices and indices; the renderer skips the others).
[[nodiscard]] bool has_geometry(const DrawItem& item);
/// Indirect draw commands a cpu-mesh frame of `list` issues: one per run of (class, material). Classes: opaque
/// (tubes, strips) and blended (lines, sides 1). Bounded by the materials in use, never by the number of wires.
[[nodiscard]] std::size_t draw_commands(const DrawList& list);
/// Bytes a cpu-mesh frame of `list` sends: draw records, indirect commands, vertices + their draw indices +
/// indices.
[[nodiscard]] std::size_t streamed_upload_bytes(const DrawList& list);

/// What the nodes path has of each wire (the renderer's slots, as plan_nodes_frame() follows them): the nodes
/// generation it got, the frame it was last drawn (slots not drawn for retain_frames are evicted, looked for
/// every 16th frame as the renderer does), and the list of unchanged drawn wires it keeps on the GPU.
struct NodesPlan {
    uint32_t retain_frames = 180;  ///< RendererDesc::retain_frames (0 there: 180)
    uint64_t frame = 0;
    struct Sent {
        uint64_t generation = 0, last_frame = 0;
    };
    std::unordered_map<uint64_t, Sent> sent{};
    std::vector<uint64_t> listed{}, last_listed{};  ///< this frame's and the kept list of unchanged drawn wires
    std::size_t kept_bytes = 0;                 ///< capacity of the kept list on the GPU (0: none yet)
};

/// The bytes one draw() of `list` on the nodes path writes (its DrawStats::bytes_uploaded, node stream aside), with
/// `plan` updated as the renderer updates its slots: for each drawn wire whose nodes it has not got (new, evicted,
/// or nodes_generation changed or 0) a 64-byte header and its nodes as wire::pack_nodes packs them (8 bytes each
/// and 8 for the wire quantised, else 16 each; and the extras) or its CPU-built curve's segments (64 bytes each); 4 bytes for each other drawn wire when
/// that list differs from the one kept on the GPU (or outgrew its buffer). Frames the GPU side could not compute
/// (buffers that could not be made) are not modelled.
std::size_t plan_nodes_frame(const DrawList& list, NodesPlan& plan);

}  // namespace wire::render
