// The curve program (wire::build_curve on the GPU): its storage blocks, the node helpers, the Kochanek-Bartels and
// c2 tangents, and put_segment.
// One invocation per wire. Per curve node j: its incoming and outgoing chords (an open end reflects the missing
// neighbour: the missing chord equals the other), the knot ratio rho = (l_out / l_in)^alpha, and the
// Kochanek-Bartels tangents at j (the same formulas as catmull_rom_tangents in modules/wire/src/spline/build.cpp,
// in float); node j writes its incoming segment (put_segment), holding its outgoing tangent for the next node.
layout(local_size_x = 64) in;
layout(std430, binding = CURVE_HEADERS) readonly buffer Headers { GpuCurveHeader headers[]; };
// The nodes in 8-byte units, float or quantised (gpu_records.h, GpuCurveHeader::node_first): node() and radius().
layout(std430, binding = CURVE_NODES) readonly buffer Nodes { uvec2 nodes[]; };
layout(std430, binding = CURVE_SEGMENTS) writeonly buffer Segments { vec4 segments[]; };  // 4 per segment: see put_segment
layout(std430, binding = CURVE_SCRATCH) buffer Scratch { dvec4 scratch[]; };  // c2: 2 per node (solve state, then D)
// Per-node tension, bias, continuity (vec4 a node), then stretch (4 segments a vec4), from GpuCurveHeader.extra_first.
layout(std430, binding = CURVE_EXTRAS) readonly buffer Extras { vec4 extras[]; };
// u_persist: each wire's header goes on to its slot (the ring pass reads it there every frame).
layout(std430, binding = CURVE_SLOT_HEADERS) writeonly buffer SlotHeaders { GpuCurveHeader slot_headers[]; };
// u_motion: per slot, the motion reference of its last upload (MotionRef).
layout(std430, binding = CURVE_MOTION_REFS) buffer MotionRefs { MotionRef refs[]; };
// u_list: each wire's slot goes to slot_list[u_list_first + w] (the ring pass's list of this frame's wires).
layout(std430, binding = CURVE_SLOT_LIST) writeonly buffer SlotList { uint slot_list[]; };
uniform uint u_wires;
uniform bool u_list;
uniform uint u_list_first;
uniform bool u_persist;
uniform bool u_motion;

// Curve node j's offset from the origin, and its radius. Branch-free: both formats are decoded and one selected.
// node() is inlined wherever it is called (the automatic spline's turn weights alone call it some 60 times, in
// ten places), and a branch here multiplied the program's control flow: llvmpipe took 7 minutes to compile it
// (9 s branch-free; ShaderResources.CurveProgramHasNoBranchInNode).
vec3 node(GpuCurveHeader h, uint j) {
    bool quantised = (h.flags & kHeaderQuantised) != 0u;
    uint at = quantised ? h.node_first + 1u + j : h.node_first + 2u * j;
    uvec2 w = nodes[at];
    uint z = nodes[quantised ? at : at + 1u].x;  // the float record's z (in bounds either way)
    uvec3 q = uvec3(w.x, (w.x >> kQuantBits) | (w.y << (32u - kQuantBits)), w.y >> (2u * kQuantBits - 32u));
    ivec3 v = ivec3(q & uvec3(kQuantMask)) - ivec3(int(kQuantBias));
    vec3 held = ldexp(vec3(v), ivec3(int(nodes[h.node_first].y) - int(kQuantExpBias)));
    return quantised ? held : uintBitsToFloat(uvec3(w, z));
}
float radius(GpuCurveHeader h, uint j) {
    bool quantised = (h.flags & kHeaderQuantised) != 0u;
    return uintBitsToFloat(quantised ? nodes[h.node_first].x : nodes[h.node_first + 2u * j + 1u].y);
}
// Given segments: vec4 k of the wire's (two units each).
vec4 given(GpuCurveHeader h, uint k) {
    uint a = h.node_first + 2u * k;
    return uintBitsToFloat(uvec4(nodes[a], nodes[a + 1u]));
}

// c2 (kind 2): node tangents per unit chord D from the C2 spline's tangent system with chordal knots (rows
// a D[j-1] + 2 D[j] + c D[j+1] = 3 (a e_in + c e_out), a = h_out / (h_in + h_out), c = h_in / (h_in + h_out));
// open ends not-a-knot (3 nodes: the parabola; 2: the chord), closed loops cyclic (Sherman-Morrison). As
// start_tangents / finish_tangents in modules/wire/src/spline/build.cpp with no node tensed. In double: the
// not-a-knot end D0 = (r0 - D1) / beta0 cancels by the ratio of the first two chords (beta0 = h1 / (h0 + h1)),
// which in float moved a 4-node wire with 100:1 chords by 1e-4 of its extent; the float nodes' differences are
// exact in double. D[j] goes to scratch[2 (first + j)].xyz.
uint sidx(GpuCurveHeader h, uint j) { return 2u * (h.node_first + j); }
dvec3 dnode(GpuCurveHeader h, uint j) { return dvec3(node(h, j % h.node_count)); }
dvec3 chord(GpuCurveHeader h, uint k) { return dnode(h, k + 1u) - dnode(h, k); }
double hlen(GpuCurveHeader h, uint k) { return length(chord(h, k)); }
dvec3 unit_chord(GpuCurveHeader h, uint k) { return chord(h, k) / hlen(h, k); }

// Row j of the interior system: (a, b, c) and its right-hand side.
// The automatic spline (kind 3): the c2 system with node j's tension weight w_j on the diagonal (Nielson's
// nu-spline) and its ends blending from not-a-knot to free as the nodes next to them get tensed, the weights read
// from the turning pattern as concentrated_turns does on the CPU (modules/wire/src/spline/tension.cpp, the same
// operations in double; the weights' exponentials in float: GLSL has no double exp), then each node's tension
// scaling both its tangents (build_curve's end_curve): 1 - t, t wire-wide or, for nodes that carry tension or the
// physics arrays, per node in the extras (x).
bool automatic(GpuCurveHeader h) { return ((h.flags >> kHeaderKindShift) & kHeaderKindMask) == kKindAutomatic; }
double keep_at(GpuCurveHeader h, uint j) {
    if (!automatic(h)) return 1.0;
    return 1.0lf - double((h.flags & kHeaderPerNode) != 0u ? extras[h.extra_first + j].x : h.kb.y);
}
dvec3 e_out(GpuCurveHeader h, uint j) { return unit_chord(h, j % h.node_count); }
dvec3 e_in(GpuCurveHeader h, uint j) { return unit_chord(h, (j + h.node_count - 1u) % h.node_count); }
// Curvature vector and chord-bisector tangent of node j (an open wire's end nodes take their neighbour's).
uint inner(GpuCurveHeader h, uint j) {
    bool closed = (h.flags & kHeaderClosed) != 0u;
    return closed ? j % h.node_count : clamp(j, 1u, h.node_count - 2u);
}
dvec3 kvec(GpuCurveHeader h, uint j) {
    j = inner(h, j);
    uint n = h.node_count;
    return (e_out(h, j) - e_in(h, j)) * (2.0lf / (hlen(h, (j + n - 1u) % n) + hlen(h, j)));
}
dvec3 tvec(GpuCurveHeader h, uint j) {
    j = inner(h, j);
    dvec3 b = e_in(h, j) + e_out(h, j);
    double lb = length(b);
    return lb > 1e-12lf ? b / lb : e_out(h, j);
}
// k carried from the node at one end of an edge (tangents ta -> tb) to the other: forwards (sign 1) or back (-1).
dvec3 carry_k(dvec3 ta, dvec3 tb, dvec3 v, double sgn) {
    double c = dot(ta, tb);
    if (c <= -1.0lf + 1e-12lf) return -v;
    dvec3 a = cross(ta, tb);
    return v * c + sgn * cross(a, v) + a * (dot(a, v) / (1.0lf + c));
}
float smoothstep_d(double e0, double e1, double x) {
    double t = clamp((x - e0) * (1.0lf / (e1 - e0)), 0.0lf, 1.0lf);
    return float(t * t * (3.0lf - 2.0lf * t));
}
// (w, g, max(g, straight)) of node j: 0 where its neighbours predict its turn (the spread test).
vec3 turn_weights(GpuCurveHeader h, uint j) {
    uint n = h.node_count;
    bool closed = (h.flags & kHeaderClosed) != 0u;
    if (!automatic(h) || n < 3u || (!closed && (j == 0u || j + 1u >= n))) return vec3(0.0);
    uint jp = (j + n - 1u) % n, jn = (j + 1u) % n;
    double hin = hlen(h, jp), hout = hlen(h, j);
    dvec3 tp = tvec(h, closed ? jp : j - 1u), t = tvec(h, j), tn = tvec(h, closed ? jn : j + 1u);
    dvec3 f = carry_k(tp, t, kvec(h, closed ? jp : j - 1u), 1.0);
    dvec3 b = carry_k(t, tn, kvec(h, closed ? jn : j + 1u), -1.0);
    dvec3 p = (hout * f + hin * b) * (1.0lf / (hin + hout));
    dvec3 k = kvec(h, j);
    double lk2 = dot(k, k), lp2 = dot(p, p);
    dvec3 m = k - p;
    double miss2 = dot(m, m);
    double s2 = (lk2 + lp2) + 2.0lf * min(lk2, lp2);
    if (s2 >= 1.1830521861667747e-271lf && s2 <= 1.0715086071862673e301lf && miss2 <= 0.3024lf * s2) return vec3(0.0);  // predicted (the certificate)
    double lk = sqrt(lk2), sum = lk + sqrt(lp2);
    if (!(sum > 0.0lf) || !(sum <= 1.7976931348623157e308lf) || miss2 <= (0.55lf * sum) * (0.55lf * sum)) return vec3(0.0);
    double d = sqrt(miss2) / sum;
    double turn = 0.5lf * sum * (hin + hout);
    float unshared = smoothstep_d(0.55lf, 0.85lf, d) * smoothstep_d(1e-8lf, 1e-6lf, turn);
    if (unshared == 0.0) return vec3(0.0);
    double share = lk / sum;
    float g = unshared * smoothstep_d(0.3lf, 0.45lf, share);
    float straight = unshared * (1.0 - smoothstep_d(0.0lf, 0.1lf, share));
    float w = (g != 0.0 ? exp(g * log(1.0 + 3e4)) - 1.0 : 0.0) + (straight != 0.0 ? exp(straight * log(31.0)) - 1.0 : 0.0);
    return vec3(w, g, max(g, straight));
}

void row(GpuCurveHeader h, uint j, out dvec3 abc, out dvec3 rhs) {
    uint n = h.node_count;
    uint kin = (j + n - 1u) % n, kout = j % n;
    double hin = hlen(h, kin), hout = hlen(h, kout), sum = hin + hout;
    double a = hout / sum, c = hin / sum;
    abc = dvec3(a, 2.0 + double(turn_weights(h, j % n).x), c);
    rhs = 3.0 * (a * unit_chord(h, kin) + c * unit_chord(h, kout));
}

void c2_tangents(GpuCurveHeader h, bool closed) {
    uint n = h.node_count;
    if (closed) {
        // Rows 0 .. n-1 (row j is node j's, wrapping); Thomas on the modified matrix for x (rhs) and z (u) at once.
        dvec3 abc0, r0, abcl, rl;
        row(h, 0u, abc0, r0);
        row(h, n - 1u, abcl, rl);
        double alpha = abcl.z, beta = abc0.x, gamma = -abc0.y;
        double cp = 0.0;
        dvec4 dp = dvec4(0.0);
        for (uint j = 0u; j < n; ++j) {
            dvec3 abc, rhs;
            row(h, j, abc, rhs);
            double b = abc.y;
            if (j == 0u) b -= gamma;
            if (j == n - 1u) b -= alpha * beta / gamma;
            dvec4 d = dvec4(rhs, j == 0u ? gamma : (j == n - 1u ? alpha : 0.0));
            double a = j == 0u ? 0.0 : abc.x;
            double pivot = b - a * cp;
            cp = abc.z / pivot;
            dp = (d - a * dp) / pivot;
            scratch[sidx(h, j)] = dp;
            scratch[sidx(h, j) + 1u] = dvec4(cp, 0.0, 0.0, 0.0);
        }
        dvec4 x = dp;
        for (uint i = n - 1u; i-- > 0u;) {
            x = scratch[sidx(h, i)] - scratch[sidx(h, i) + 1u].x * x;
            scratch[sidx(h, i)] = x;
        }
        dvec4 x0 = scratch[sidx(h, 0u)], xl = scratch[sidx(h, n - 1u)];
        double den = 1.0 + x0.w + beta * xl.w / gamma;
        dvec3 fact = (x0.xyz + beta * xl.xyz / gamma) / den;
        for (uint i = 0u; i < n; ++i) {
            dvec4 v = scratch[sidx(h, i)];
            scratch[sidx(h, i)] = dvec4(v.xyz - fact * v.w, 0.0);
        }
        return;
    }
    if (n == 2u) {
        dvec3 e = unit_chord(h, 0u);
        scratch[sidx(h, 0u)] = dvec4(e, 0.0);
        scratch[sidx(h, 1u)] = dvec4(e, 0.0);
        return;
    }
    uint segs = n - 1u;
    double h0 = hlen(h, 0u), h1 = hlen(h, 1u), hl = hlen(h, segs - 1u), hp = hlen(h, segs - 2u);
    dvec3 s0 = unit_chord(h, 0u), s1 = unit_chord(h, 1u), sl = unit_chord(h, segs - 1u), sp = unit_chord(h, segs - 2u);
    if (n == 3u) {
        // The parabola (not-a-knot at both ends), blended with the free-ended tensed solution by g of node 1.
        dvec3 p0 = s0 - h0 * (s1 - s0) / (h0 + h1), p1 = (h1 * s0 + h0 * s1) / (h0 + h1);
        dvec3 p2 = s1 + h1 * (s1 - s0) / (h0 + h1);
        double g1 = double(turn_weights(h, 1u).y);
        if (g1 != 0.0) {
            dvec3 abc, rhs;
            row(h, 1u, abc, rhs);
            dvec3 t1 = (rhs - 1.5 * (abc.x * s0 + abc.z * s1)) / (abc.y - 0.5 * (abc.x + abc.z));
            dvec3 t0 = 0.5 * (3.0 * s0 - t1), t2 = 0.5 * (3.0 * s1 - t1);
            p0 = (1.0 - g1) * p0 + g1 * t0;
            p1 = (1.0 - g1) * p1 + g1 * t1;
            p2 = (1.0 - g1) * p2 + g1 * t2;
        }
        scratch[sidx(h, 0u)] = dvec4(p0, 0.0);
        scratch[sidx(h, 1u)] = dvec4(p1, 0.0);
        scratch[sidx(h, 2u)] = dvec4(p2, 0.0);
        return;
    }
    // End rows beta D0 + D1 = r (not-a-knot, blending to free: beta = 2, r = 3 s as a node next to the end gets
    // tensed), eliminated into the first and last interior rows.
    dvec3 r0n = (s0 * (h1 * (3.0 * h0 + 2.0 * h1)) + (h0 * h0) * s1) / ((h0 + h1) * (h0 + h1));
    dvec3 rln = (sl * (hp * (3.0 * hl + 2.0 * hp)) + (hl * hl) * sp) / ((hp + hl) * (hp + hl));
    double g0 = double(max(turn_weights(h, 1u).z, n > 3u ? turn_weights(h, 2u).z : 0.0));
    double gl = double(max(turn_weights(h, n - 2u).z, n > 3u ? turn_weights(h, n - 3u).z : 0.0));
    double beta0 = (1.0 - g0) * h1 / (h0 + h1) + 2.0 * g0, betal = (1.0 - gl) * hp / (hp + hl) + 2.0 * gl;
    dvec3 r0 = (1.0 - g0) * r0n + (3.0 * g0) * s0, rl = (1.0 - gl) * rln + (3.0 * gl) * sl;
    uint m = n - 2u;
    double cp = 0.0;
    dvec3 dp = dvec3(0.0);
    for (uint r = 0u; r < m; ++r) {
        dvec3 abc, rhs;
        row(h, r + 1u, abc, rhs);
        double a = abc.x, b = abc.y, c = abc.z;
        if (r == 0u) { rhs -= (a / beta0) * r0; b -= a / beta0; a = 0.0; }
        if (r == m - 1u) { rhs -= (c / betal) * rl; b -= c / betal; c = 0.0; }
        double pivot = b - a * cp;
        cp = c / pivot;
        dp = (rhs - a * dp) / pivot;
        scratch[sidx(h, r + 1u)] = dvec4(dp, 0.0);
        scratch[sidx(h, r + 1u) + 1u] = dvec4(cp, 0.0, 0.0, 0.0);
    }
    dvec3 x = dp;
    for (uint r = m - 1u; r-- > 0u;) {
        x = scratch[sidx(h, r + 1u)].xyz - scratch[sidx(h, r + 1u) + 1u].x * x;
        scratch[sidx(h, r + 1u)] = dvec4(x, 0.0);
    }
    scratch[sidx(h, 0u)] = dvec4((r0 - scratch[sidx(h, 1u)].xyz) / beta0, 0.0);
    scratch[sidx(h, n - 1u)] = dvec4((rl - scratch[sidx(h, n - 2u)].xyz) / betal, 0.0);
}

// Segment k as b0 (relative to the wire's origin) and its control points' differences b1 - b0, b2 - b1, b3 - b2,
// from the node tangents t0 (at its start) and t1 (at its end): b1 - b0 = t0 / 3, b2 - b1 = chord - (t0 + t1) / 3,
// b3 - b2 = t1 / 3. The differences keep their own relative precision, so the ring pass's derivatives and chords
// do not inherit the rounding of the offsets (2^-24 of the wire's extent, which on a 100 m wire of 5 cm segments is
// 1e-4 of a segment).
// The w components carry what the ring pass reads per segment: the radii of its start and end nodes and its
// stretch.
float seg_stretch(GpuCurveHeader h, uint k) {
    if ((h.flags & kHeaderStretch) == 0u) return 1.0;
    uint base = h.extra_first + ((h.flags & kHeaderPerNode) != 0u ? h.node_count : 0u);
    return extras[base + k / 4u][k % 4u];
}
void put_segment(GpuCurveHeader h, uint k, vec3 p0, vec3 t0, vec3 t1, vec3 chord_k) {
    uint s = 4u * (h.segment_first + k);
    segments[s] = vec4(p0, radius(h, k));
    segments[s + 1u] = vec4(t0 / 3.0, radius(h, (k + 1u) % h.node_count));
    segments[s + 2u] = vec4(chord_k - (t0 + t1) / 3.0, seg_stretch(h, k));
    segments[s + 3u] = vec4(t1 / 3.0, 0.0);
}
