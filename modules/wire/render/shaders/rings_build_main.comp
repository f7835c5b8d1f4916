// The ring pass's rings program, one invocation per dispatched wire, after the place program's ring ranges: the
// wire's rings from the range its job holds, walked in order with their frames and u, and (u_draw) its draw record
// (GpuDraw).
layout(local_size_x = 64) in;
layout(std430, binding = RING_DRAWS) writeonly buffer Draws { GpuDraw draws[]; };

void main() {
    uint w = gl_GlobalInvocationID.x;
    if (w >= u_wires) return;
    uint slot = visible[w];
    load_wire(slot);
    bool caps = (H.flags & kHeaderCaps) != 0u;
    Job job = jobs[w];
    uint n = job.ring_count;
    uint drawn = job.sides;
    float radius_px = job.totals.w;
    if (n == 0u) return;  // culled, or no room in the ring buffer
    RING_FIRST = job.ring_first;
    FEWEST = (job.flags & kJobFromReserve) != 0u;
    // The first normal: the carried previous one projected onto the first tangent, else seeded from an axis.
    vec3 t0 = unit_tangent(load_seg(0u), 0.0);
    if (t0 == vec3(0.0)) t0 = vec3(0.0, 0.0, 1.0);
    vec3 r0 = seed_normal(t0);
    vec4 previous = (job.flags & kJobGivesPrevious) == 0u ? slot_state[slot].first_normal
                    : (job.flags & kJobHasPrevious) != 0u ? vec4(job.previous_normal.xyz, 1.0)
                                                          : vec4(0.0);
    if (previous.w != 0.0) {
        float along = dot(previous.xyz, t0);
        if (abs(along) <= 1e-6 && abs(dot(previous.xyz, previous.xyz) - 1.0) <= 4e-7) {
            r0 = previous.xyz;  // already a unit normal of t0: kept bit for bit (a still wire's frames do not drift)
        } else {
            vec3 p = previous.xyz - along * t0;
            float len = length(p);
            if (len > 1e-6) r0 = p / len;
        }
    }
    vec4 totals = vec4(0.0);
    if (CLOSED) {
        totals = walk(r0, false, 0.0, 0.0);
        totals = walk(r0, true, totals.z, double(totals.y));
    } else {
        totals = walk(r0, true, 0.0, 0.0);
    }
    jobs[w].first_normal = vec4(r0, 1.0);
    jobs[w].totals = vec4(totals.xyz, radius_px);
    slot_state[slot].first_normal = vec4(r0, 1.0);
    if (!u_draw) return;
    // The draw record (GpuDraw).
    bool tilt = false;
    float r_first = node_radius(0u);
    for (uint j = 1u; j < N; ++j) tilt = tilt || node_radius(j) != r_first;
    uint flags = (CLOSED ? kDrawClosed : 0u) | (caps ? kDrawCaps : 0u) | (tilt ? kDrawTilt : 0u) |
                 (drawn == 2u ? kDrawStrip : drawn == 1u ? kDrawLine : 0u);
    vec3 offset = vec3(dvec3(H.origin_m[0], H.origin_m[1], H.origin_m[2]) - u_eye);
    draws[w] = GpuDraw(offset, 7u * RING_FIRST, n, drawn, flags, totals.x);
}
