// The ring pass's LOD program, one invocation per dispatched wire: the slot's first normal turned by the wire's
// motion, the rings per segment (the LOD's, or the caller's: place_rings' total), a range of the ring buffer for
// them, and (u_draw) the chunk counts of the wire's buckets and its triangles. The rings program reads the job it
// writes.
// Rings allocated, wires that did not fit, rings allocated from the reserve (u_ring_reserve records after
// u_ring_capacity: one ring a segment for every listed wire, so a wire that does not fit is drawn coarse, not
// missing, until the ring buffer has grown), triangles the draw expands (u_draw: wire::tube_counts' and
// strip_counts').
layout(std430, binding = RING_COUNTER) buffer Counter {
    uint ring_counter; uint overflow; uint reserve_counter; uint triangles;
};
uniform uint u_unchanged;
uniform uint u_ring_capacity;
uniform uint u_ring_reserve;
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
    uint material = H.flags >> kHeaderMaterialShift;
    bool caps = (H.flags & kHeaderCaps) != 0u;
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
    // The rings: the LOD's counts, or the caller's (place_rings' total); a range of the ring buffer.
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
    jobs[w].ring_count = 0u;
    jobs[w].sides = drawn;
    jobs[w].totals = vec4(0.0, 0.0, 0.0, radius_px);
    if (n == 0u) return;  // culled
    uint first = atomicAdd(ring_counter, n);
    jobs[w].ring_first = first;
    if (first + n > u_ring_capacity) {
        atomicAdd(overflow, 1u);
        // One ring a segment from the reserve (sized for every listed wire): coarse for a frame, not missing.
        uint fewest = SEGS + (CLOSED ? 0u : 1u);
        first = u_ring_capacity + atomicAdd(reserve_counter, fewest);
        if (first + fewest > u_ring_capacity + u_ring_reserve) return;
        n = fewest;
        jobs[w].ring_first = first;
        jobs[w].flags = flags | kJobFromReserve;
    }
    jobs[w].ring_count = n;
    if (u_draw) {
        for (uint kind = 0u; kind < 6u; ++kind) {
            uint c = chunk_count_of(kind, n, drawn, caps);
            if (c != 0u) atomicAdd(buckets[bucket_of(material, drawn, kind)], c);
        }
        uint bands = n - 1u + (CLOSED ? 1u : 0u);
        uint tris = drawn <= 2u ? 2u * bands : (2u * bands + (!CLOSED && caps ? 2u : 0u)) * drawn;
        if (tris != 0u) atomicAdd(triangles, tris);
    }
}
