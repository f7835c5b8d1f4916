// The ring pass's LOD program, one invocation per dispatched wire: the slot's first normal turned by the wire's
// motion, the rings per segment (the LOD's, or the caller's: place_rings' total) and the drawn sides, into the
// wire's job (ring_count: the rings it wants). The place program then gives each wire its range of the ring buffer
// and its chunk records, in wire order; the rings program reads the job.
layout(local_size_x = 64) in;
uniform uint u_unchanged;
uniform bool u_lod;  // the LOD's counts and sides, else the caller's counts and 3 sides
// Keeps the caller's kJobHasPrevious and kJobGivesPrevious (GpuRingPass), else clears them: the rings program
// then carries the first normal from the slot (the nodes path).
uniform bool u_keep_job_flags;

// v turned by the unit quaternion (sqrt(1 - |m|^2), m) (GpuCurveHeader.motion; no trigonometry: a rotation by angle a has
// |m| = sin(a / 2), and w from it loses precision only near a half turn in one frame).
vec3 turned(vec3 v, vec3 m) {
    float w = sqrt(max(0.0, 1.0 - dot(m, m)));
    vec3 t = 2.0 * cross(m, v);
    return v + w * t + cross(m, t);
}

void main() {
    uint w = gl_GlobalInvocationID.x;
    if (w >= u_wires) return;
    uint slot = visible[w];
    load_wire(slot);
    if (w >= u_unchanged) {
        // Nodes that changed: the slot's last first normal turned by the wire's motion since (the header's
        // rotation: fitted by the curve pass, or by the CPU on id events and blends), as the CPU path's
        // carried_frames turns its own. Culled or not, so the next
        // build carries it from where the wire is.
        vec4 last = slot_state[slot].first_normal;
        vec3 motion = vec3(H.motion[0], H.motion[1], H.motion[2]);
        if (last.w != 0.0) slot_state[slot].first_normal = vec4(turned(last.xyz, motion), 1.0);
    }
    uint flags = u_keep_job_flags ? jobs[w].flags & (kJobHasPrevious | kJobGivesPrevious) : 0u;
    jobs[w].flags = flags;
    // The rings: the LOD's counts, or the caller's (place_rings' total).
    uint n = CLOSED ? 0u : 1u;
    float radius_px = 0.0;
    uint drawn = 0u;
    if (u_lod) {
        vec3 offset = vec3(dvec3(H.origin_m[0], H.origin_m[1], H.origin_m[2]) - u_eye);
        n = lod(slot, offset, radius_px);
        drawn = slot_state[slot].lod.y;
    } else {
        for (uint k = 0u; k < SEGS; ++k) n += count_of(k);
        drawn = 3u;
    }
    jobs[w].ring_count = n;  // 0: culled
    jobs[w].ring_first = 0u;
    jobs[w].sides = drawn;
    jobs[w].totals = vec4(0.0, 0.0, 0.0, radius_px);
}
