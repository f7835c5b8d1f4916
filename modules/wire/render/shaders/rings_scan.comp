// One workgroup's prefix sum (the commands and place programs: one workgroup of kLanes invocations walking its
// input kLanes at a time, so their output is in input order whatever order a GPU runs invocations in). Sums
// saturate at kSat (a + b of two values <= kSat cannot wrap), which is associative, so the scan's order of
// additions does not matter either.
layout(local_size_x = 256) in;
const uint kLanes = 256u;
const uint kSat = 0x7fffffffu;
shared uint s_scan[kLanes];
uint sat_add(uint a, uint b) { return min(min(a, kSat) + min(b, kSat), kSat); }
// The sum of v over the lanes before this one; total: over all lanes. Every lane calls it (uniform control flow).
uint lane_scan(uint v, out uint total) {
    uint lane = gl_LocalInvocationID.x;
    s_scan[lane] = min(v, kSat);
    memoryBarrierShared();
    barrier();
    for (uint d = 1u; d < kLanes; d <<= 1u) {
        uint add = lane >= d ? s_scan[lane - d] : 0u;
        memoryBarrierShared();
        barrier();
        s_scan[lane] = sat_add(s_scan[lane], add);
        memoryBarrierShared();
        barrier();
    }
    total = s_scan[kLanes - 1u];
    uint before = lane == 0u ? 0u : s_scan[lane - 1u];
    barrier();  // every lane has read before the next call writes
    return before;
}
