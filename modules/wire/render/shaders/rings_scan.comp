// One workgroup's prefix sum (the commands and place programs: one workgroup of kLanes invocations walking its
// input kLanes at a time, so their output is in input order whatever order a GPU runs invocations in). Sums
// saturate at kSat (a + b of two values <= kSat cannot wrap), which is associative, so the scan's order of
// additions does not matter either.
layout(local_size_x = 256) in;
const uint kLanes = 256u;
const uint kSat = 0x7fffffffu;
shared uint s_scan[kLanes];
uint sat_add(uint a, uint b) { return min(min(a, kSat) + min(b, kSat), kSat); }
// One Hillis-Steele step: each lane adds the partial sum d lanes before it.
void scan_step(uint lane, uint d) {
    uint add = lane >= d ? s_scan[lane - d] : 0u;
    memoryBarrierShared();
    barrier();
    s_scan[lane] = sat_add(s_scan[lane], add);
    memoryBarrierShared();
    barrier();
}
// The sum of v over the lanes before this one; total: over all lanes. Every lane calls it (uniform control flow).
// The steps are written out, not looped: llvmpipe ends an invocation's loops after 65,535 iterations in all, and
// one invocation here walks every wire (or bucket) 256 at a time.
uint lane_scan(uint v, out uint total) {
    uint lane = gl_LocalInvocationID.x;
    s_scan[lane] = min(v, kSat);
    memoryBarrierShared();
    barrier();
    scan_step(lane, 1u);
    scan_step(lane, 2u);
    scan_step(lane, 4u);
    scan_step(lane, 8u);
    scan_step(lane, 16u);
    scan_step(lane, 32u);
    scan_step(lane, 64u);
    scan_step(lane, 128u);
    total = s_scan[kLanes - 1u];
    uint before = lane == 0u ? 0u : s_scan[lane - 1u];
    barrier();  // every lane has read before the next call writes
    return before;
}
