// Internal: what the GPU wire passes share. The per-wire header (its GLSL twin: shaders/wire_header.comp), and the
// CPU side of a wire's upload: its curve nodes (float offsets from its origin, the radius in w), header and extras
// (per-node tension, bias, continuity; per-segment stretch). The renderer's nodes path and the test passes (wire::render_testing) use both.
#pragma once

#include "wire/lod.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/curve.hpp"
#include "wire/status.hpp"

#include "engine/gfx/resources.hpp"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wire::render::detail {

/// The per-wire record the passes read (std430, 64 bytes; its GLSL twin is shaders/wire_header.comp). Per-node
/// tension, bias and continuity (Catmull-Rom wires that carry them, or the curvature-driven tension, computed on
/// the CPU with build_curve's formula) and per-segment stretch travel in an "extras" array only for wires that have
/// them.
struct GpuCurveHeader {
    uint32_t node_first = 0;     ///< first curve node of this upload
    uint32_t node_count = 0;     ///< curve nodes (merged)
    uint32_t segment_first = 0;  ///< first segment (and per-segment ring count) in the persistent storage
    /// bit 0 closed; bits 1-2 kind (0 linear, 1 Catmull-Rom, 2 c2); bit 3 caps; bit 4 per-node kb in the extras
    /// (a vec4 a node: tension, bias, continuity); bit 5 stretch in the extras (4 segments a vec4, after the kb);
    /// bit 6 the segments are given (a blend); bit 7 the curve pass fits the motion (and writes it here, on the slot's
    /// copy); bits 8-15 the wire's most sides; bits 16-31 material
    uint32_t flags = 0;
    float alpha = 0.5f, tension = 0.0f, bias = 0.0f, continuity = 0.0f;
    uint32_t extra_first = 0;  ///< first vec4 of the wire's extras
    uint32_t slot = 0;         ///< the wire's persistent slot (LOD and frame state)
    float origin_m[3] = {0.0f, 0.0f, 0.0f};  ///< the wire's origin (its nodes' box centre as float_point), metres
    /// The rotation carrying the slot's last first normal to this upload: the vector part (sin(angle / 2) axis) of
    /// wire::carried_rotation, whose w >= 0 the GPU recovers; zero: none (the plain projection).
    float motion[3] = {0.0f, 0.0f, 0.0f};
};
static_assert(sizeof(GpuCurveHeader) == 64, "GpuCurveHeader is the 64-byte std430 record");

/// The most radial sides the GPU LOD gives (LodSettings::max_sides above it is taken as this).
inline constexpr uint32_t kMaxSides = 256;

/// The shader storage binding points of the curve and ring programs, dense from 0: GL guarantees 8 bindings and 8
/// blocks a stage, NVIDIA 16 (a binding past that fails to link there, never on llvmpipe). The GLSL names them by
/// macros of the same names in capitals (kRingJobs: RING_JOBS), defined by curve_program_source() and
/// ring_program_source() (shaders.hpp), so both sides read
/// one number.
enum CurveBinding : uint32_t {
    kCurveHeaders, kCurveNodes, kCurveSegments, kCurveScratch, kCurveExtras, kCurveSlotHeaders, kCurveMotionRefs,
    kCurveSlotList, kCurveBindings
};
enum RingBinding : uint32_t {
    kRingHeaders, kRingSegments, kRingJobs, kRingCounts, kRingRings, kRingSlots, kRingCounter,
    kRingVisible, kRingDraws, kRingChunks, kRingBuckets, kRingCommands, kRingTemplates, kRingBindings
};
/// The binding macros the compute programs define: (GLSL name, binding).
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

inline constexpr uint32_t kHeaderClosed = 1u, kHeaderCaps = 8u, kHeaderPerNode = 16u, kHeaderStretch = 32u,
                          kHeaderGivenSegments = 64u, kHeaderFitMotion = 128u;
/// The curve pass's per-slot motion reference (GLSL MotionRef): 12 vec4.
inline constexpr std::size_t kMotionRefBytes = 192;
inline constexpr uint32_t kHeaderKindShift = 1u, kHeaderMaterialShift = 16u;
inline constexpr uint32_t kKindLinear = 0u, kKindCatmullRom = 1u, kKindC2 = 2u, kKindAutomatic = 3u;

/// The ring pass's per-dispatched-wire record (GLSL Job in shaders/rings.comp, std430).
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

/// Appends a curve given as segments (a wire in a pop-free blend): 4 vec4 a segment in `nodes` (b0 from the
/// origin with its start node's radius in w; b1 - b0 with the end node's radius; b2 - b1 with the stretch;
/// b3 - b2), which the curve pass copies.
void append_segments(const Curve& curve, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                     const WireMotion& motion, WireUpload& out);

}  // namespace wire::render::detail
