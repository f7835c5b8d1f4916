// The per-wire header (GpuCurveHeader in gpu_wire_data.hpp, std430, 64 bytes) and its flag bits.
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
