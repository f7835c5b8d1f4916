// ---- frames (frames.cpp) ----
const float kSplitCos = 0.70710678;  // a step turning more than 45 degrees is split
const uint kMaxDepth = 10u;          // FrameSettings::max_subdivision_depth's default
vec3 seed_normal(vec3 t) {
    vec3 a = abs(t);
    vec3 e = a.x <= a.y && a.x <= a.z ? vec3(1.0, 0.0, 0.0) : (a.y <= a.z ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0));
    return normalize(e - dot(e, t) * t);
}
vec3 orthonormalize(vec3 r, vec3 t) {
    vec3 p = r - dot(r, t) * t;
    float len2 = dot(p, p);
    return len2 > 1e-12 ? p * inversesqrt(len2) : seed_normal(t);
}
vec3 rotate_minimal(vec3 t0, vec3 t1, vec3 r0) {
    float c = dot(t0, t1);
    if (c < -1.0 + 1e-6) return orthonormalize(r0, t1);
    vec3 v = cross(t0, t1);
    return c * r0 + cross(v, r0) + v * (dot(v, r0) / (1.0 + c));
}
// B(tb) - B(ta) by Simpson's rule on B' (a quadratic: exact), so a short step's chord keeps float precision
// relative to itself; the difference of two offsets would carry their rounding (2^-24 of the segment), which on
// a hairpin sub-step of 2^-10 of a ring interval turned its chord by 1e-3 rad and the frame with it.
vec3 chord(Seg c, float ta, float tb) {
    return ((tb - ta) / 6.0) * (deriv(c, ta) + 4.0 * deriv(c, 0.5 * (ta + tb)) + deriv(c, tb));
}
// mirrors(): 0 ok, 1 split, 2 degenerate. v1 is the chord from a to b; `noise` the size below which it counts
// as a repeated point (then the tangents' sum stands in for it, as on the CPU).
const uint kOk = 0u, kSplit = 1u, kDegenerate = 2u;
uint mirrors(vec3 chord_ab, float noise, vec3 at, vec3 bt, out vec3 v1, out vec3 v2, out float f1, out float f2) {
    v1 = chord_ab;
    float c1 = dot(v1, v1);
    f1 = 0.0; v2 = vec3(0.0); f2 = 0.0;
    if (c1 <= noise * noise * 64.0) {
        v1 = at + bt;
        c1 = dot(v1, v1);
        if (c1 < 1e-12) return kDegenerate;
    }
    f1 = 2.0 / c1;
    vec3 tl = at - (f1 * dot(v1, at)) * v1;
    v2 = bt - tl;
    float c2 = dot(v2, v2);
    if (c2 < 1e-12) return kDegenerate;
    f2 = 2.0 / c2;
    return (c2 < 0.1 || dot(at, bt) < kSplitCos) ? kSplit : kOk;
}
// Transporter::step (double reflection, the hairpin guard's recursion as an explicit stack): r from (ta, tangent
// at) to (tb, tangent bt) on segment c.
vec3 reflect_step(Seg c, float ta, vec3 at, vec3 r, float tb, vec3 bt) {
    float st_t[kMaxDepth + 1u];
    vec3 st_tan[kMaxDepth + 1u];
    uint st_d[kMaxDepth + 1u];
    int top = 1;
    st_t[0] = tb; st_tan[0] = bt; st_d[0] = 0u;
    float tc = ta;
    vec3 ct = at;
    // The derivative's scale: a chord below 2^-23 of it times the parameter step is rounding.
    float scale = 3.0 * (max_abs(c.d0) + max_abs(c.d1) + max_abs(c.d2)) * 1.2e-7;
    while (top > 0) {
        int i = top - 1;
        vec3 v1, v2;
        float f1, f2;
        uint m = mirrors(chord(c, tc, st_t[i]), scale * (st_t[i] - tc), ct, st_tan[i], v1, v2, f1, f2);
        if (m != kOk && st_d[i] < kMaxDepth && st_t[i] > tc) {
            float tm = 0.5 * (tc + st_t[i]);
            vec3 mt = unit_tangent(c, tm);
            if (mt == vec3(0.0)) mt = ct;
            st_d[i] += 1u;
            st_t[top] = tm; st_tan[top] = mt; st_d[top] = st_d[i];
            ++top;
            continue;
        }
        if (m == kDegenerate) {
            r = orthonormalize(rotate_minimal(ct, st_tan[i], r), st_tan[i]);
        } else {
            r -= (f1 * dot(v1, r)) * v1;
            r -= (f2 * dot(v2, r)) * v2;
            r = orthonormalize(r, st_tan[i]);
        }
        tc = st_t[i]; ct = st_tan[i];
        --top;
    }
    return r;
}
// compute_frames' carry: from ring a (segment sa, ta, tangent at) to ring b, through the start of every segment
// between (wrap: b is ring 0, reached at t = 1 of the last segment).
vec3 carry(uint sa, float ta, vec3 at, vec3 r, uint sb, float tb, vec3 bt, bool wrap) {
    uint end = wrap ? SEGS : sb + (tb > 0.0 ? 1u : 0u);
    uint seg = sa;
    float t = ta;
    vec3 ct = at;
    Seg c = load_seg(seg);
    for (uint k = sa + 1u; k < end; ++k) {
        Seg next = load_seg(k);
        vec3 nt = unit_tangent(next, 0.0);
        if (nt == vec3(0.0)) nt = ct;
        r = reflect_step(c, t, ct, r, 1.0, nt);
        seg = k; t = 0.0; ct = nt; c = next;
    }
    float te = !wrap && sb == seg ? tb : 1.0;
    return reflect_step(c, t, ct, r, te, bt);
}

// ---- PackedRing (packed_ring.cpp) ----
layout(std430, binding = RING_RINGS) writeonly buffer Rings { uint ring_words[]; };  // PackedRing: 7 words
uint encode20(float v) { return uint(clamp((v * (0.5 / 0.70710678118654752) + 0.5) * 1048575.0, 0.0, 1048575.0) + 0.5); }
uvec2 pack_frame(vec3 r, vec3 s) {
    vec3 t = cross(r, s);
    float m00 = r.x, m10 = r.y, m20 = r.z, m01 = s.x, m11 = s.y, m21 = s.z, m02 = t.x, m12 = t.y, m22 = t.z;
    float q[4];  // x, y, z, w
    float trace = m00 + m11 + m22;
    if (trace > 0.0) {
        float k = 2.0 * sqrt(trace + 1.0), inv = 1.0 / k;
        q[3] = 0.25 * k; q[0] = (m21 - m12) * inv; q[1] = (m02 - m20) * inv; q[2] = (m10 - m01) * inv;
    } else if (m00 > m11 && m00 > m22) {
        float k = 2.0 * sqrt(max(1e-30, 1.0 + m00 - m11 - m22)), inv = 1.0 / k;
        q[3] = (m21 - m12) * inv; q[0] = 0.25 * k; q[1] = (m01 + m10) * inv; q[2] = (m02 + m20) * inv;
    } else if (m11 > m22) {
        float k = 2.0 * sqrt(max(1e-30, 1.0 + m11 - m00 - m22)), inv = 1.0 / k;
        q[3] = (m02 - m20) * inv; q[0] = (m01 + m10) * inv; q[1] = 0.25 * k; q[2] = (m12 + m21) * inv;
    } else {
        float k = 2.0 * sqrt(max(1e-30, 1.0 + m22 - m00 - m11)), inv = 1.0 / k;
        q[3] = (m10 - m01) * inv; q[0] = (m02 + m20) * inv; q[1] = (m12 + m21) * inv; q[2] = 0.25 * k;
    }
    uint largest = 0u;
    for (uint i = 1u; i < 4u; ++i) if (abs(q[i]) > abs(q[largest])) largest = i;
    float sgn = q[largest] < 0.0 ? -1.0 : 1.0;
    uint e[3];
    uint j = 0u;
    for (uint i = 0u; i < 4u; ++i) if (i != largest) e[j++] = encode20(sgn * q[i]);
    return uvec2(largest | (e[0] << 2u) | (e[1] << 22u), (e[1] >> 10u) | (e[2] << 10u));
}
void put_ring(uint index, vec3 centre, float radius, float u, vec3 r, vec3 s) {
    uint b = 7u * index;
    ring_words[b] = floatBitsToUint(centre.x);
    ring_words[b + 1u] = floatBitsToUint(centre.y);
    ring_words[b + 2u] = floatBitsToUint(centre.z);
    ring_words[b + 3u] = floatBitsToUint(radius);
    ring_words[b + 4u] = floatBitsToUint(u);
    uvec2 f = pack_frame(r, s);
    ring_words[b + 5u] = f.x;
    ring_words[b + 6u] = f.y;
}

// ---- the walk ----
uint RING_FIRST;  // the wire's first ring in the ring buffer
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
