// The records and flag bits the CPU and the GPU programs share: one text, valid as C++ and as GLSL.
// C++: src/gpu_records.hpp includes it inside namespace wire::render::detail after defining GLSL's uint, vec3,
// vec4, uvec4 with std430's sizes (a vec4's 16-byte alignment) and WIRE_CONST / WIRE_ZERO. GLSL: the compute
// programs and the ring vertex shader take it as a piece of their source (src/shaders.cpp), which defines both
// macros. std430 aligns a vec3 to 16 bytes and C++ cannot say so: a vec3 stands only where an offset of 16 falls.
// tests/modules/wire/render/gpu_layout_test.cpp checks every field's offset as the driver laid it out.
#ifndef WIRE_GPU_RECORDS_H
#define WIRE_GPU_RECORDS_H

// The per-wire header (std430, 64 bytes): written by the CPU per upload, copied by the curve pass to the wire's
// slot, read there by the ring pass every frame. Per-node tension, bias and continuity and per-segment stretch
// travel in the extras only for wires that have them.
struct GpuCurveHeader {
    uint node_first WIRE_ZERO;     // this upload's first curve node
    uint node_count WIRE_ZERO;     // curve nodes (merged)
    uint segment_first WIRE_ZERO;  // the wire's first segment (and per-segment ring count), persistent storage
    uint flags WIRE_ZERO;          // kHeader* bits, the kind, the wire's most sides and its material (below)
    vec4 kb;                       // alpha, tension, bias, continuity (wire-wide)
    uint extra_first WIRE_ZERO;    // per-node kb (a vec4 a node), then stretch (4 segments a vec4), in the extras
    uint slot WIRE_ZERO;           // the wire's persistent slot (LOD and frame state)
    float origin_m[3] WIRE_ZERO;   // the wire's origin (its nodes' box centre as a float point), metres
    // The rotation carrying the slot's last first normal to this upload: the vector part (sin(angle / 2) axis)
    // of wire::carried_rotation, whose w >= 0 the GPU recovers; zero: none (the plain projection).
    float motion[3] WIRE_ZERO;
};
WIRE_CONST uint kHeaderClosed = 1u;
WIRE_CONST uint kHeaderKindShift = 1u, kHeaderKindMask = 3u;  // bits 1-2: the spline kind (kKind*)
WIRE_CONST uint kHeaderCaps = 8u;
WIRE_CONST uint kHeaderPerNode = 16u;        // per-node kb in the extras (or the automatic spline's weights)
WIRE_CONST uint kHeaderStretch = 32u;        // per-segment stretch in the extras, after the kb
WIRE_CONST uint kHeaderGivenSegments = 64u;  // the segments are given (a blend): 4 vec4 each at node_first
WIRE_CONST uint kHeaderFitMotion = 128u;     // the curve pass fits the motion (and writes it on the slot's copy)
WIRE_CONST uint kHeaderSidesShift = 8u, kHeaderSidesMask = 255u;  // bits 8-15: the wire's most sides (0: LOD's)
WIRE_CONST uint kHeaderQuantised = 65536u;                         // bit 16: the nodes are 8-byte fixed point
WIRE_CONST uint kHeaderMaterialShift = 17u;                        // bits 17-31: the material
WIRE_CONST uint kMaxMaterials = 32768u;
// A wire's nodes at node_first, in 8-byte units (uvec2) of the node array. Float records: 2 units a node, the
// offset from the origin and the radius as floats (x, y, z, r). kHeaderQuantised: one unit holding the wire's radius
// (a float's bits) and its quantum's exponent e + kQuantExpBias, then one unit a node: its offset as three 21-bit
// integers q (x in bits 0-20, y in 21-41, z in 42-62 of the 64), biased by kQuantBias: offset = (q - kQuantBias) 2^e
// metres, exact in float. Given segments (kHeaderGivenSegments): 4 vec4 a segment, 2 units each.
WIRE_CONST uint kQuantBits = 21u, kQuantMask = 2097151u, kQuantBias = 1048576u, kQuantExpBias = 256u;
WIRE_CONST uint kKindLinear = 0u, kKindCatmullRom = 1u, kKindC2 = 2u, kKindAutomatic = 3u;

// The curve pass's per-slot motion reference: motion_reference's samples of the last upload's curve nodes.
// origin.xyz the upload's origin, origin.w the determinacy; counts.x samples (0: none), counts.y nodes; p[k].xyz
// the sample's offset from the origin, p[k].w its weight.
struct MotionRef {
    vec4 origin;
    uvec4 counts;
    vec4 p[10];
};

// The ring pass's per-dispatched-wire record: inputs (the previous normal, for the test passes) and what the
// passes found.
struct Job {
    uint ring_first WIRE_ZERO;  // out: first ring record (the place program's prefix sum, in wire order)
    uint ring_count WIRE_ZERO;  // out: rings wanted (LOD program), then given (place program; 0: culled, or none left)
    uint flags WIRE_ZERO;       // in: kJobHasPrevious, kJobGivesPrevious; out: kJobFromReserve
    uint sides WIRE_ZERO;       // out: drawn sides (3.. a tube, 2 a strip, 1 a line)
    vec4 previous_normal;
    vec4 first_normal;  // out: ring 0's r
    vec4 totals;        // out: u where a closed loop closes, length, holonomy, projected radius (pixels)
};
// In (the test passes' stage): the job gives the previous normal (kJobGivesPrevious), and it is one
// (kJobHasPrevious); without kJobGivesPrevious the slot's last frame's ring 0 normal is carried. Out: the rings
// came from the reserve (one a segment).
WIRE_CONST uint kJobHasPrevious = 1u, kJobGivesPrevious = 2u, kJobFromReserve = 4u;

// The ring pass's per-slot state kept between frames: the LOD's (sides, drawn sides, 1 when it holds a previous
// frame's, 1 visible) and ring 0's normal of the last frame (w = 1 when set). Zeroed when a slot is given.
struct SlotState {
    uvec4 lod;
    vec4 first_normal;
};

// The per-draw record the ring pass (or the CPU, on cpu-mesh) writes and the vertex shader reads.
struct GpuDraw {
    vec3 offset_m;             // the wire's origin minus the camera position (the difference taken in double)
    uint ring_first WIRE_ZERO;  // first 32-bit word of the wire's PackedRings (the nodes path's ring pass writes them)
    uint ring_count WIRE_ZERO;
    uint sides WIRE_ZERO;
    uint flags WIRE_ZERO;  // kDraw* bits
    float u_close WIRE_ZERO;
};
WIRE_CONST uint kDrawClosed = 1u, kDrawCaps = 2u, kDrawTilt = 4u;
WIRE_CONST uint kDrawStrip = 8u, kDrawLine = 16u;  // a camera-facing strip (sides 2), a phone-wire line (sides 1)

#endif
