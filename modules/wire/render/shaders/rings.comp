// The ring pass's per-wire programs (LOD, rings): their shared storage blocks, uniforms and the wire being walked.
// One invocation per wire (the LOD and rings programs' mains say 64 a workgroup). The CPU reference for every function named after one: modules/wire/src/rings.cpp
// (build_rings, radius, u) and modules/wire/src/frames.cpp (compute_frames, mirrors, Transporter).
layout(std430, binding = RING_HEADERS) readonly buffer Headers { GpuCurveHeader headers[]; };  // by slot
layout(std430, binding = RING_SEGMENTS) readonly buffer Segments { vec4 segments[]; };  // b0, b1 - b0, b2 - b1, b3 - b2; w: see below
layout(std430, binding = RING_JOBS) buffer Jobs { Job jobs[]; };
// Rings per segment (at GpuCurveHeader.segment_first): the caller's, or (u_lod) the LOD's, over the previous frame's.
layout(std430, binding = RING_COUNTS) buffer Counts { uint counts[]; };
layout(std430, binding = RING_SLOTS) buffer Slots { SlotState slot_state[]; };
// The slot of each dispatched wire: the first u_unchanged were listed by the CPU (their nodes did not change), the
// others by this frame's curve passes (their nodes changed: CURVE_SLOT_LIST).
layout(std430, binding = RING_VISIBLE) readonly buffer Visible { uint visible[]; };
uniform uint u_wires;
uniform bool u_draw;  // the single draw's records: chunk counts (LOD), the draw and chunk records (rings)
uniform dvec3 u_eye;  // the view's eye: the LOD's view, the draw record's offset

const float kPi = 3.14159265358979;

GpuCurveHeader H;
uint N, SEGS;
bool CLOSED;
bool FEWEST = false;  // the wire's rings came from the reserve: one a segment (the LOD's counts are kept)
uint count_of(uint k) {
    if (FEWEST) return 1u;
    uint c = counts[H.segment_first + k];
    return k == 0u ? max(c, 1u) : c;
}

// The chunk records a wire draws (upload_plan.hpp's chunk_counts): a cap chunk on a capped open tube, bands by
// 16, then the remainder's binary digits.
uint chunk_count_of(uint kind, uint rings, uint drawn, bool caps) {
    uint bands = rings == 0u ? 0u : rings - 1u + (CLOSED ? 1u : 0u);
    bool geometry = drawn <= 2u ? bands > 0u : (bands > 0u || (!CLOSED && caps));
    if (!geometry || rings == 0u) return 0u;
    if (kind == 0u) return drawn > 2u && !CLOSED && caps ? 1u : 0u;
    if (kind == 1u) return bands / 16u;
    return (bands & (16u >> (kind - 1u))) != 0u ? 1u : 0u;
}
uint bucket_of(uint material, uint drawn, uint kind) { return (material * u_side_slots + drawn) * 6u + kind; }

void load_wire(uint slot) {
    H = headers[slot];
    N = H.node_count;
    CLOSED = (H.flags & kHeaderClosed) != 0u;
    SEGS = CLOSED ? N : N - 1u;
}
