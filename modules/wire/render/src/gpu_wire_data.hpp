// Internal: what the GPU wire passes share: the records (gpu_records.hpp), the binding points, and the CPU side
// of a wire's upload: its curve nodes (wire::PackedNodes' records), header and extras
// (per-node tension, bias, continuity; per-segment stretch). The renderer's nodes path and the test passes
// (wire::render_testing) use them.
#pragma once

#include "wire/lod.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/curve.hpp"
#include "wire/status.hpp"

#include "engine/gfx/resources.hpp"

#include "gpu_records.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wire::render::detail {

/// The most radial sides the GPU LOD gives (LodSettings::max_sides above it is taken as this).
inline constexpr uint32_t kMaxSides = 256;

/// The shader storage binding points of the curve program and of the ring pass's programs, dense from 0 (the ring
/// pass's between its four programs, each declaring the blocks it reads): GL guarantees 8 bindings and 8 blocks a
/// stage, NVIDIA 16 (a binding past that fails to link there, never on llvmpipe). The GLSL names them by macros of
/// the same names in capitals (kRingJobs: RING_JOBS), defined by every program's source (shaders.hpp), so both
/// sides read one number.
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

/// A wire's motion since its last upload: the rotation (GpuCurveHeader::motion), or the GPU fits it.
struct WireMotion {
    glm::vec3 rotation{};
    bool fit = false;
};

/// One frame's upload of wires for the curve pass.
struct WireUpload {
    std::vector<GpuCurveHeader> headers;
    std::vector<glm::uvec2> nodes;  ///< the node array in 8-byte units (PackedNodes::records; given segments)
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

/// The ring LOD program's uniforms for a view and settings (LodSettings' defaults applied as update_lod does), on
/// `program`, the program in use.
void set_lod_uniforms(const engine::gfx::Program& program, const LodView& view, const LodSettings& settings);

/// Appends `v` to a node array (two 8-byte units).
void push_vec4(std::vector<glm::uvec2>& nodes, const glm::vec4& v);

/// Appends a curve given as segments (a wire in a pop-free blend): 4 vec4 a segment in `nodes` (b0 from the
/// origin with its start node's radius in w; b1 - b0 with the end node's radius; b2 - b1 with the stretch;
/// b3 - b2), which the curve pass copies.
void append_segments(const Curve& curve, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                     const WireMotion& motion, WireUpload& out);

}  // namespace wire::render::detail
