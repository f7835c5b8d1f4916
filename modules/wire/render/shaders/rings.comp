// The ring program: its storage blocks, uniforms and the wire being walked.
// One invocation per wire. The CPU reference for every function named after one: modules/wire/src/rings.cpp
// (build_rings, radius, u) and modules/wire/src/frames.cpp (compute_frames, mirrors, Transporter).
layout(local_size_x = 64) in;
layout(std430, binding = RING_HEADERS) readonly buffer Headers { GpuCurveHeader headers[]; };  // by slot
layout(std430, binding = RING_SEGMENTS) readonly buffer Segments { vec4 segments[]; };  // b0, b1 - b0, b2 - b1, b3 - b2; w: see below
layout(std430, binding = RING_JOBS) buffer Jobs { Job jobs[]; };
// Rings per segment (at GpuCurveHeader.segment_first): the caller's, or (u_lod) the LOD's, over the previous frame's.
layout(std430, binding = RING_COUNTS) buffer Counts { uint counts[]; };
layout(std430, binding = RING_RINGS) writeonly buffer Rings { uint ring_words[]; };  // PackedRing: 7 words
layout(std430, binding = RING_SLOTS) buffer Slots { SlotState slot_state[]; };
// Rings allocated, wires that did not fit, rings allocated from the reserve (u_ring_reserve records after
// u_ring_capacity: one ring a segment for every listed wire, so a wire that does not fit is drawn coarse, not
// missing, until the ring buffer has grown), triangles the draw expands (u_draw: wire::tube_counts' and
// strip_counts').
layout(std430, binding = RING_COUNTER) buffer Counter {
    uint ring_counter; uint overflow; uint reserve_counter; uint triangles;
};
// The slot of each dispatched wire: the first u_unchanged were listed by the CPU (their nodes did not change), the
// others by this frame's curve passes (their nodes changed: CURVE_SLOT_LIST).
layout(std430, binding = RING_VISIBLE) readonly buffer Visible { uint visible[]; };
// u_draw: the single draw's records (GpuDraw, the chunk records and the indirect commands).
layout(std430, binding = RING_DRAWS) writeonly buffer Draws { GpuDraw draws[]; };
layout(std430, binding = RING_CHUNKS) writeonly buffer Chunks { uvec2 chunks[]; };
layout(std430, binding = RING_BUCKETS) buffer Buckets { uint buckets[]; };  // u_buckets chunk counts, then as many cursors
layout(std430, binding = RING_COMMANDS) writeonly buffer Commands { uint commands[]; };  // 5 words each, one per bucket
layout(std430, binding = RING_TEMPLATES) readonly buffer Templates { uvec2 templates[]; };  // (count, first index) per side slot and kind
uniform uint u_wires;
uniform uint u_unchanged;
uniform uint u_ring_capacity;
uniform uint u_ring_reserve;
uniform uint u_stage;  // 0: LOD (or the caller's counts) and rings; 1: LOD only; 2: the commands; 3: rings only
uniform bool u_draw;
uniform uint u_buckets, u_side_slots;
// The LOD (wire/lod.hpp, per-segment evaluation at node resolution): the view and the settings' values.
uniform bool u_lod;
uniform mat3 u_view_rot;  // world -> view rotation (GL view space: looking down -z)
uniform dvec3 u_eye;
uniform float u_focal, u_tan_x, u_tan_y, u_near, u_far, u_eps, u_band, u_strip_px, u_line_px;
uniform uint u_max_rings, u_max_sides;  // u_max_sides <= kMaxSides
uniform bool u_coarse;
uniform bool u_merge;  // spans below node resolution (LodSettings::keep_node_resolution off)
// 1 - cos(pi / n) at [n >> 2][n & 3], n <= 256: vec4s, so a compiler that gives each element of a uniform array a
// vec4 slot needs 260 components, not 1028 (of the 1024 GL_MAX_COMPUTE_UNIFORM_COMPONENTS guarantees).
uniform vec4 u_sagitta4[65];

const float kPi = 3.14159265358979;
const float kSplitCos = 0.70710678;  // a step turning more than 45 degrees is split
const uint kMaxDepth = 10u;          // FrameSettings::max_subdivision_depth's default

GpuCurveHeader H;
uint N, SEGS, RING_FIRST;
bool CLOSED;
