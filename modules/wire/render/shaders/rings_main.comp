// ---- the walk ----
bool FEWEST = false;  // the wire's rings came from the reserve: one a segment (the LOD's counts are kept)
uint count_of(uint k) {
    if (FEWEST) return 1u;
    uint c = counts[H.segment_first + k];
    return k == 0u ? max(c, 1u) : c;
}

// Walks the rings in order: place_rings' parameters, build_rings' intervals, compute_frames' carry. With
// `write`, rotates ring i's frame by -holonomy * s_i / total (closed loops) and writes it. Returns (u at the
// close, length, holonomy, rings); r0 is ring 0's normal.
vec4 walk(vec3 r0, bool write, float holonomy, double total) {
    Coeffs a = load(0u);
    uint sa = 0u;
    float ta = 0.0;
    vec3 at = unit_tangent(a.c, 0.0);
    if (at == vec3(0.0)) at = vec3(0.0, 0.0, 1.0);
    vec3 r = r0;
    double s = 0.0, u = 0.0;
    uint index = 0u;
    if (write) put_ring(RING_FIRST, a.c.b0, radius_at(a, 0.0), 0.0, r, cross(at, r));
    uint k = 0u, j = 1u;  // the next ring: j-th of segment k
    for (;;) {
        // Next ring's parameter: (k, j / count), segments without rings skipped; an open wire's last at t = 1.
        while (k < SEGS && j >= count_of(k)) { ++k; j = 0u; }
        bool last_open = k == SEGS && !CLOSED;
        if (k == SEGS && !last_open) break;
        uint sb = last_open ? SEGS - 1u : k;
        float tb = last_open ? 1.0 : float(j) / float(count_of(k));
        Coeffs b = a;
        if (sb != sa) b = load(sb);
        // The interval's length and u: the rest of a's segment, the segments crossed, b's part of its own.
        vec2 iv = integrate(a, ta, sb == sa ? tb : 1.0);
        for (uint m = sa + 1u; m < sb; ++m) iv += integrate(load(m), 0.0, 1.0);
        if (sb != sa && tb > 0.0) iv += integrate(b, 0.0, tb);
        s += double(iv.x);
        u += double(iv.y);
        vec3 bt = unit_tangent(b.c, tb);
        if (bt == vec3(0.0)) bt = at;
        r = carry(sa, ta, at, r, sb, tb, bt, false);
        ++index;
        if (write) {
            vec3 rr = r, ss = cross(bt, r);
            if (holonomy != 0.0 && total > 0.0) {
                float angle = float(-double(holonomy) * s / total);
                float ca = cos(angle), sn = sin(angle);
                rr = ca * r + sn * ss;
                ss = ca * ss - sn * r;
            }
            put_ring(RING_FIRST + index, b.c.b0 + offset_at(b.c, tb), radius_at(b, tb), float(u), rr, ss);
        }
        a = b; sa = sb; ta = tb; at = bt;
        if (last_open) break;
        ++j;
    }
    float hol = 0.0;
    if (CLOSED) {
        // Back to ring 0 (t = 1 of the last segment): the loop's length and u, and its twist.
        vec2 iv = integrate(a, ta, 1.0);
        for (uint m = sa + 1u; m < SEGS; ++m) iv += integrate(load(m), 0.0, 1.0);
        s += double(iv.x);
        u += double(iv.y);
        Seg c0 = load_seg(0u);
        vec3 t0 = unit_tangent(c0, 0.0);
        vec3 r_end = carry(sa, ta, at, r, 0u, 0.0, t0, true);
        hol = atan(dot(cross(r0, r_end), t0), dot(r0, r_end));
    }
    return vec4(float(u), float(s), hol, float(index + 1u));
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

// v turned by the unit quaternion (sqrt(1 - |m|^2), m) (GpuCurveHeader.motion; no trigonometry: a rotation by angle a has
// |m| = sin(a / 2), and w from it loses precision only near a half turn in one frame).
vec3 turned(vec3 v, vec3 m) {
    float w = sqrt(max(0.0, 1.0 - dot(m, m)));
    vec3 t = 2.0 * cross(m, v);
    return v + w * t + cross(m, t);
}

void load_wire(uint slot) {
    H = headers[slot];
    N = H.node_count;
    CLOSED = (H.flags & kHeaderClosed) != 0u;
    SEGS = CLOSED ? N : N - 1u;
}

void main() {
    uint w = gl_GlobalInvocationID.x;
    if (u_stage == 2u) {
        // The indirect commands: per bucket (material, side count, chunk kind) its chunk count and first chunk.
        if (w != 0u) return;
        uint first = 0u;
        for (uint b = 0u; b < u_buckets; ++b) {
            uint count = buckets[b];
            uvec2 t = templates[b % (6u * u_side_slots)];
            commands[5u * b] = t.x;
            commands[5u * b + 1u] = count;
            commands[5u * b + 2u] = t.y;
            commands[5u * b + 3u] = 0u;
            commands[5u * b + 4u] = first;
            buckets[u_buckets + b] = first;
            first += count;
        }
        return;
    }
    if (w >= u_wires) return;
    uint slot = visible[w];
    load_wire(slot);
    uint material = H.flags >> kHeaderMaterialShift;
    bool caps = (H.flags & kHeaderCaps) != 0u;
    Job job = jobs[w];
    uint n = CLOSED ? 0u : 1u;
    float radius_px = 0.0;
    uint drawn = 0u;
    if (u_stage != 3u && w >= u_unchanged) {
        // Nodes that changed: the slot's last first normal turned by the wire's motion since (the header's
        // rotation: fitted by the curve pass, or by the CPU on id events and blends), as the CPU path's
        // carried_frames turns its own. Culled or not, so the next
        // build carries it from where the wire is.
        vec4 last = slot_state[slot].first_normal;
        vec3 motion = vec3(H.motion[0], H.motion[1], H.motion[2]);
        if (last.w != 0.0) slot_state[slot].first_normal = vec4(turned(last.xyz, motion), 1.0);
    }
    if (u_stage != 3u) {
        // Stage 0 (GpuRingPass) has the caller's job flags; the nodes path (stage 1) carries from the slot.
        uint flags = u_stage == 0u ? jobs[w].flags & (kJobHasPrevious | kJobGivesPrevious) : 0u;
        jobs[w].flags = flags;
        // The rings: the LOD's counts, or the caller's (place_rings' total); a range of the ring buffer.
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
        if (u_stage == 1u) return;
        job = jobs[w];
    } else {
        n = job.ring_count;
        drawn = job.sides;
        radius_px = job.totals.w;
        if (n == 0u) return;
    }
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
    // The draw record (GpuDraw) and the chunk records of this wire.
    bool tilt = false;
    float r_first = node_radius(0u);
    for (uint j = 1u; j < N; ++j) tilt = tilt || node_radius(j) != r_first;
    uint flags = (CLOSED ? kDrawClosed : 0u) | (caps ? kDrawCaps : 0u) | (tilt ? kDrawTilt : 0u) |
                 (drawn == 2u ? kDrawStrip : drawn == 1u ? kDrawLine : 0u);
    vec3 offset = vec3(dvec3(H.origin_m[0], H.origin_m[1], H.origin_m[2]) - u_eye);
    draws[w] = GpuDraw(offset, 7u * RING_FIRST, n, drawn, flags, totals.x);
    uint band = 0u;
    for (uint kind = 0u; kind < 6u; ++kind) {
        uint c = chunk_count_of(kind, n, drawn, caps);
        if (c == 0u) continue;
        uint at = atomicAdd(buckets[u_buckets + bucket_of(material, drawn, kind)], c);
        for (uint i = 0u; i < c; ++i) {
            uint first_band = kind == 0u ? 0u : band;
            chunks[at + i] = uvec2(w, first_band);
            if (kind != 0u) band += 16u >> (kind - 1u);
        }
    }
}
