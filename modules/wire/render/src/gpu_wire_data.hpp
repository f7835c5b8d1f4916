// Internal: what the GPU wire passes share. The per-wire header's GLSL (the same record as GpuCurveHeader), and the
// CPU side of a wire's upload: its curve nodes (float offsets from its origin, the radius in w), header and extras
// (per-node tension, bias, continuity; per-segment stretch). GpuCurvePass and the renderer's nodes path use both.
#pragma once

#include "wire/lod.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/render/gpu_curves.hpp"

#include "engine/gfx/resources.hpp"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wire::render::detail {

/// GpuCurveHeader in GLSL (std430, 64 bytes) and its flag bits; `GPU_WIRE_HEADER` in a source is replaced by it.
inline constexpr const char* kWireHeaderGlsl = R"glsl(
const uint kClosed = 1u, kCaps = 8u, kHasPerNode = 16u, kHasStretch = 32u, kGivenSegments = 64u, kFitMotion = 128u;
struct Header {
    uint node_first;     // this frame's curve nodes (the curve pass reads them)
    uint node_count;     // curve nodes (merged)
    uint segment_first;  // the wire's segments, and its per-segment ring counts
    uint flags;          // bit 0 closed; 1-2 kind (0 linear, 1 Catmull-Rom, 2 c2, 3 automatic); 3 caps; 4 per-node
                         // values (kb, or the automatic spline's weights);
                         // 5 stretch; 6 the segments are given (4 vec4 each at node_first); 7 the motion is
                         // fitted on the GPU (the curve pass writes it); 8-15 the wire's
                         // most sides (0: the LOD settings'); 16-31 material
    vec4 kb;             // alpha, tension, bias, continuity (wire-wide)
    uint extra_first;    // per-node kb (a vec4 a node), then stretch (4 segments a vec4), in the extras
    uint slot;           // the wire's persistent slot (ring pass state)
    float origin[3];     // the wire's origin, world metres (a point with float coordinates)
    float motion[3];     // the rotation carrying the slot's last first normal here: a unit quaternion's x, y, z
};
)glsl";

/// The shader storage binding points of the curve and ring programs, dense from 0: GL guarantees 8 bindings and 8
/// blocks a stage, NVIDIA 16 (a binding past that fails to link there, never on llvmpipe). The GLSL names them by
/// macros of the same names in capitals (kRingJobs: RING_JOBS), defined by with_wire_header(), so both sides read
/// one number.
enum CurveBinding : uint32_t {
    kCurveHeaders, kCurveNodes, kCurveSegments, kCurveScratch, kCurveExtras, kCurveSlotHeaders, kCurveMotionRefs,
    kCurveSlotList, kCurveBindings
};
enum RingBinding : uint32_t {
    kRingHeaders, kRingSegments, kRingJobs, kRingCounts, kRingRings, kRingSlots, kRingCounter,
    kRingVisible, kRingDraws, kRingChunks, kRingBuckets, kRingCommands, kRingTemplates, kRingBindings
};
/// The binding macros with_wire_header() defines: (GLSL name, binding).
struct BindingMacro {
    const char* name;
    uint32_t binding;
};
inline constexpr BindingMacro kBindingMacros[] = {
    {"CURVE_HEADERS", kCurveHeaders}, {"CURVE_NODES", kCurveNodes}, {"CURVE_SEGMENTS", kCurveSegments},
    {"CURVE_SCRATCH", kCurveScratch}, {"CURVE_EXTRAS", kCurveExtras}, {"CURVE_SLOT_HEADERS", kCurveSlotHeaders},
    {"CURVE_MOTION_REFS", kCurveMotionRefs}, {"CURVE_SLOT_LIST", kCurveSlotList}, {"RING_HEADERS", kRingHeaders},
    {"RING_SEGMENTS", kRingSegments}, {"RING_JOBS", kRingJobs}, {"RING_COUNTS", kRingCounts},
    {"RING_RINGS", kRingRings}, {"RING_SLOTS", kRingSlots}, {"RING_COUNTER", kRingCounter},
    {"RING_VISIBLE", kRingVisible}, {"RING_DRAWS", kRingDraws}, {"RING_CHUNKS", kRingChunks},
    {"RING_BUCKETS", kRingBuckets}, {"RING_COMMANDS", kRingCommands}, {"RING_TEMPLATES", kRingTemplates},
};

/// `source` with GPU_WIRE_HEADER replaced by the binding macros (kBindingMacros) and kWireHeaderGlsl.
std::string with_wire_header(const char* source);

inline constexpr uint32_t kHeaderClosed = 1u, kHeaderCaps = 8u, kHeaderPerNode = 16u, kHeaderStretch = 32u,
                          kHeaderGivenSegments = 64u, kHeaderFitMotion = 128u;
/// The curve pass's per-slot motion reference (GLSL MotionRef): 12 vec4.
inline constexpr std::size_t kMotionRefBytes = 192;
inline constexpr uint32_t kHeaderKindShift = 1u, kHeaderMaterialShift = 16u;
inline constexpr uint32_t kKindLinear = 0u, kKindCatmullRom = 1u, kKindC2 = 2u, kKindAutomatic = 3u;

/// The ring pass's per-dispatched-wire record (GLSL Job in ring_source(), std430).
struct Job {
    uint32_t ring_first = 0, ring_count = 0;
    uint32_t flags = 0;  ///< out bit 2: the rings came from the reserve (one a segment)
    uint32_t sides = 0;  ///< out: drawn sides
    float previous_normal[4] = {0, 0, 0, 0};
    float first_normal[4] = {0, 0, 0, 0};
    float totals[4] = {0, 0, 0, 0};  ///< u where a closed loop closes, length, holonomy, radius in pixels
};
static_assert(sizeof(Job) == 64, "the ring pass's std430 job record");
inline constexpr uint32_t kJobFromReserve = 4u;
/// The ring pass's per-slot state kept between frames (GLSL SlotState, std430).
struct SlotState {
    uint32_t lod[4] = {0, 0, 0, 0};
    float first_normal[4] = {0, 0, 0, 0};
};
static_assert(sizeof(SlotState) == 32, "the ring pass's std430 slot record");

/// A wire's motion since its last upload: the rotation (GpuCurveHeader::motion), or the GPU fits it.
struct WireMotion {
    glm::vec3 rotation{};
    bool fit = false;
};

/// One frame's upload of wires for the curve pass.
struct WireUpload {
    std::vector<GpuCurveHeader> headers;
    std::vector<glm::vec4> nodes;   ///< 16 bytes a curve node
    std::vector<glm::vec4> extras;  ///< only for wires that carry per-node kb or stretch
    void clear() { headers.clear(), nodes.clear(), extras.clear(); }
};

/// The header of a wire packed by wire::pack_nodes, its nodes and extras at node_first and extra_first.
GpuCurveHeader packed_header(const PackedNodes& packed, uint32_t segment_first, uint32_t slot, uint32_t material,
                             bool caps, const WireMotion& motion, uint32_t node_first, uint32_t extra_first);

/// Appends a wire packed by wire::pack_nodes (the systems pack on their worker threads).
void append_packed(const PackedNodes& packed, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                   const WireMotion& motion, WireUpload& out);

/// Appends one wire (validated nodes: build_curve's checks) with its header's segment_first, slot, the
/// material and caps bits and its motion (GpuCurveHeader::motion). Fails naming what is wrong (not a supported kind, too few distinct nodes); nothing is
/// appended then. `segments` (out): the wire's segment count.
Status append_wire(const WireNodes& nodes, const SplineSettings& spline, uint32_t segment_first, uint32_t slot,
                   uint32_t material, bool caps, const WireMotion& motion, WireUpload& out, uint32_t& segments);

/// The ring program's LOD uniforms for a view and settings (LodSettings' defaults applied as update_lod does).
void set_lod_uniforms(const engine::gfx::Program& program, const LodView& view, const LodSettings& settings);

/// The ring program's GLSL (GPU_WIRE_HEADER not yet replaced): gpu_rings.cpp.
const char* ring_source();
/// The curve program's GLSL (GPU_WIRE_HEADER not yet replaced): gpu_curves.cpp.
const char* curve_source();

/// Appends a curve given as segments (a wire in a pop-free blend): 4 vec4 a segment in `nodes` (b0 from the
/// origin with its start node's radius in w; b1 - b0 with the end node's radius; b2 - b1 with the stretch;
/// b3 - b2), which the curve pass copies.
void append_segments(const Curve& curve, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                     const WireMotion& motion, WireUpload& out);

}  // namespace wire::render::detail
