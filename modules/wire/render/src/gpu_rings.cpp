// The ring stage on the GPU (see gpu_rings.hpp).
#include "wire/render/gpu_rings.hpp"

#include "gpu_wire_data.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace wire::render {
namespace {

// One invocation per wire. The CPU reference for every function named after one: modules/wire/src/rings.cpp
// (build_rings, radius, u) and modules/wire/src/frames.cpp (compute_frames, mirrors, Transporter).
constexpr const char* kRingSource = R"glsl(#version 450 core
layout(local_size_x = 64) in;
GPU_WIRE_HEADER
// Per dispatched wire: inputs (previous normal for the tests' path) and what the passes found.
struct Job {
    uint ring_first;     // out: first ring record (allocated by the LOD stage)
    uint ring_count;     // out: rings (0: culled, or the ring buffer was full)
    uint flags;          // in (stage 0): bit 1 the job gives the previous normal (bit 0: previous_normal is one);
                         // else the slot's last frame's ring 0 normal is carried. Out: bit 2 the rings came from
                         // the reserve (one a segment)
    uint sides;          // out: drawn sides (3.. a tube, 2 a strip, 1 a line)
    vec4 previous_normal;
    vec4 first_normal;   // out: ring 0's r
    vec4 totals;         // out: u where a closed loop closes, length, holonomy, projected radius (pixels)
};
// Per slot, kept between frames: the LOD's state (sides, drawn sides, 1 when it holds a previous frame's, 1
// visible) and ring 0's normal of the last frame (w = 1 when set). A slot is zeroed when it is given to a wire.
struct SlotState { uvec4 lod; vec4 first_normal; };
layout(std430, binding = RING_HEADERS) readonly buffer Headers { Header headers[]; };  // by slot
layout(std430, binding = RING_SEGMENTS) readonly buffer Segments { vec4 segments[]; };  // b0, b1 - b0, b2 - b1, b3 - b2; w: see below
layout(std430, binding = RING_JOBS) buffer Jobs { Job jobs[]; };
// Rings per segment (at Header.segment_first): the caller's, or (u_lod) the LOD's, over the previous frame's.
layout(std430, binding = RING_COUNTS) buffer Counts { uint counts[]; };
layout(std430, binding = RING_RINGS) writeonly buffer Rings { uint ring_words[]; };  // PackedRing: 7 words
layout(std430, binding = RING_SLOTS) buffer Slots { SlotState slot_state[]; };
// Rings allocated, wires that did not fit, rings allocated from the reserve (u_ring_reserve records after
// u_ring_capacity: one ring a segment for every listed wire, so a wire that does not fit is drawn coarse, not
// missing, until the ring buffer has grown), triangles the draw expands (u_draw: wire::tube_counts' and
// strip_counts').
layout(std430, binding = RING_COUNTER) buffer Counter {
    uint ring_counter; uint overflow; uint reserve_counter; uint triangles;
};
// The slot of each dispatched wire: the first u_unchanged were listed by the CPU (their nodes did not change), the
// others by this frame's curve passes (their nodes changed: CURVE_SLOT_LIST).
layout(std430, binding = RING_VISIBLE) readonly buffer Visible { uint visible[]; };
// u_draw: the single draw's records (wire::render's GpuDraw, the chunk records and the indirect commands).
struct Draw { vec3 offset_m; uint ring_first; uint ring_count; uint sides; uint flags; float u_close; };
layout(std430, binding = RING_DRAWS) writeonly buffer Draws { Draw draws[]; };
layout(std430, binding = RING_CHUNKS) writeonly buffer Chunks { uvec2 chunks[]; };
layout(std430, binding = RING_BUCKETS) buffer Buckets { uint buckets[]; };  // u_buckets chunk counts, then as many cursors
layout(std430, binding = RING_COMMANDS) writeonly buffer Commands { uint commands[]; };  // 5 words each, one per bucket
layout(std430, binding = RING_TEMPLATES) readonly buffer Templates { uvec2 templates[]; };  // (count, first index) per side slot and kind
uniform uint u_wires;
uniform uint u_unchanged;
uniform uint u_ring_capacity;
uniform uint u_ring_reserve;
uniform uint u_stage;  // 0: LOD (or the caller's counts) and rings; 1: LOD only; 2: the commands; 3: rings only
uniform bool u_draw;
uniform uint u_buckets, u_side_slots;
// The LOD (wire/lod.hpp, per-segment evaluation at node resolution): the view and the settings' values.
uniform bool u_lod;
uniform mat3 u_view_rot;  // world -> view rotation (GL view space: looking down -z)
uniform dvec3 u_eye;
uniform float u_focal, u_tan_x, u_tan_y, u_near, u_far, u_eps, u_band, u_strip_px, u_line_px;
uniform uint u_max_rings, u_max_sides;  // u_max_sides <= kMaxSides
uniform bool u_coarse;
uniform bool u_merge;  // spans below node resolution (LodSettings::keep_node_resolution off)
// 1 - cos(pi / n) at [n >> 2][n & 3], n <= 256: vec4s, so a compiler that gives each element of a uniform array a
// vec4 slot needs 260 components, not 1028 (of the 1024 GL_MAX_COMPUTE_UNIFORM_COMPONENTS guarantees).
uniform vec4 u_sagitta4[65];

const float kPi = 3.14159265358979;
const float kSplitCos = 0.70710678;  // a step turning more than 45 degrees is split
const uint kMaxDepth = 10u;          // FrameSettings::max_subdivision_depth's default

Header H;
uint N, SEGS, RING_FIRST;
bool CLOSED;

// ---- a segment: b0 and the differences of its control points ----
struct Seg { vec3 b0; vec3 d0; vec3 d1; vec3 d2; };
Seg load_seg(uint k) {
    uint s = 4u * (H.segment_first + k);
    return Seg(segments[s].xyz, segments[s + 1u].xyz, segments[s + 2u].xyz, segments[s + 3u].xyz);
}
// B(t) - b0: the Bezier of control points 0, d0, d0 + d1, d0 + d1 + d2.
vec3 offset_at(Seg c, float t) {
    float s = 1.0 - t;
    vec3 e1 = c.d0, e2 = c.d0 + c.d1, e3 = e2 + c.d2;
    if (t == 1.0) return e3;
    return (3.0 * s * s * t) * e1 + (3.0 * s * t * t) * e2 + (t * t * t) * e3;
}
vec3 deriv(Seg c, float t) { float s = 1.0 - t; return 3.0 * ((s * s) * c.d0 + (2.0 * s * t) * c.d1 + (t * t) * c.d2); }
vec3 second_deriv(Seg c, float t) { return 6.0 * ((1.0 - t) * (c.d1 - c.d0) + t * (c.d2 - c.d1)); }
float max_abs(vec3 v) { return max(abs(v.x), max(abs(v.y), abs(v.z))); }

// unit_tangent(): the derivative's direction, else its one-sided limits (B'', then B''', then the chord).
vec3 unit_tangent(Seg c, float t) {
    vec3 e2 = c.d0 + c.d1, e3 = e2 + c.d2;
    float tiny = 1e-6 * max(max_abs(c.d0), max(max_abs(e2), max_abs(e3))) + 1e-30;
    vec3 d1 = deriv(c, t);
    float l1 = length(d1);
    if (l1 > tiny) return d1 / l1;
    vec3 d2 = (t >= 1.0 ? -1.0 : 1.0) * second_deriv(c, t);
    float l2 = length(d2);
    if (l2 > tiny) return d2 / l2;
    vec3 d3 = 6.0 * (c.d2 - 2.0 * c.d1 + c.d0);
    float l3 = length(d3);
    if (l3 > tiny) return d3 / l3;
    float lc = length(e3);
    if (lc > tiny) return e3 / lc;
    return vec3(0.0);
}

// ---- radius and u (SegmentCoeffs in rings.cpp) ----
// Node j's radius: segment j's start (w of its b0), the last node of an open wire its last segment's end.
float node_radius(uint j) {
    uint s = 4u * (H.segment_first + min(j, SEGS - 1u));
    return j < SEGS ? segments[s].w : segments[s + 1u].w;
}
float node_slope(uint k) {
    bool has_left = CLOSED || k > 0u, has_right = CLOSED || k + 1u < N;
    float rk = node_radius(k);
    float dl = has_left ? rk - node_radius(k == 0u ? N - 1u : k - 1u) : 0.0;
    float dr = has_right ? node_radius(k + 1u == N ? 0u : k + 1u) - rk : 0.0;
    if (!has_left) return dr;
    if (!has_right) return dl;
    if (dl * dr <= 0.0) return 0.0;
    float lim = 3.0 * min(abs(dl), abs(dr));
    return clamp(0.5 * (dl + dr), -lim, lim);
}
struct Coeffs { Seg c; vec4 r; float u_per_m; float u_scale; bool constant; };
Coeffs load(uint k) {
    Coeffs o;
    o.c = load_seg(k);
    uint a = min(k, N - 1u);
    uint b = CLOSED ? (a + 1u == N ? 0u : a + 1u) : min(a + 1u, N - 1u);
    float ra = node_radius(a), rb = node_radius(b);
    float ma = node_slope(a), mb = node_slope(b);
    o.r = vec4(ra, ma, -3.0 * ra - 2.0 * ma + 3.0 * rb - mb, 2.0 * ra + ma - 2.0 * rb + mb);
    float st = segments[4u * (H.segment_first + k) + 2u].w;
    if (!(st > 0.0)) st = 1.0;
    o.constant = o.r.y == 0.0 && o.r.z == 0.0 && o.r.w == 0.0;
    o.u_per_m = o.constant ? 1.0 / (2.0 * kPi * st * max(o.r.x, 1e-30)) : 0.0;
    o.u_scale = o.constant ? 0.0 : 1.0 / (2.0 * kPi * st);
    return o;
}
float radius_at(Coeffs o, float t) { return o.r.x + t * (o.r.y + t * (o.r.z + t * o.r.w)); }
// Length and u from ta to tb (3-point Gauss-Legendre of |B'| and |B'| / R).
vec2 integrate(Coeffs o, float ta, float tb) {
    float h = tb - ta;
    if (!(h > 0.0)) return vec2(0.0);
    const float x[3] = float[3](0.1127016653792583, 0.5, 0.8872983346207417);
    const float w[3] = float[3](0.2777777777777778, 0.4444444444444444, 0.2777777777777778);
    float len = 0.0, u = 0.0;
    for (int q = 0; q < 3; ++q) {
        float t = ta + h * x[q];
        float speed = length(deriv(o.c, t));
        len += (h * w[q]) * speed;
        if (!o.constant) u += (h * w[q]) * speed / max(radius_at(o, t), 1e-30);
    }
    return vec2(len, o.constant ? len * o.u_per_m : u * o.u_scale);
}

// ---- frames (frames.cpp) ----
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


// ---- the LOD (modules/wire/src/lod/update.cpp's per-segment pass, view.hpp's hull depth and plane test) ----
uint hysteresis_count(uint old_count, uint raw, float band) {
    if (old_count == 0u || raw >= old_count || band < 0.0) return raw;
    if (float(old_count) <= float(raw) * (1.0 + band) + 1.0) return old_count;
    return min(old_count, raw + 1u + raw / 8u);
}
// n = ceil(pi / acos(1 - x)) is the least n with x >= 1 - cos(pi / n) (the sagitta of an n-gon per unit
// radius): found in a table of those, computed in double on the CPU, so no inverse cosine in float (GLSL leaves
// its precision to the driver: llvmpipe's moved a 6 px tube from 4 to 5 sides).
uint sides_for_radius(float radius, float z, float k, uint max_sides) {
    float r_px = radius * u_focal * k / max(z, u_near);
    if (!(r_px > 0.0)) return 3u;
    float x = u_eps / r_px;
    if (x >= 0.5) return 3u;
    for (uint n = 4u; n < max_sides; ++n) {
        if (x >= u_sagitta4[n >> 2u][n & 3u]) return n;
    }
    return max_sides;
}
uint drawn_sides_for(float radius_px, uint sides, uint old_drawn) {
    float keep = 1.0 + max(u_band, 0.0);
    if (u_line_px > 0.0 && (radius_px < u_line_px || (old_drawn == 1u && radius_px < u_line_px * keep))) return 1u;
    if (u_strip_px > 0.0 && (radius_px < u_strip_px || (old_drawn == 2u && radius_px < u_strip_px * keep))) return 2u;
    return sides;
}
vec3 to_view(vec3 rel) { vec3 q = u_view_rot * rel; return vec3(q.x, q.y, -q.z); }
uint outside(vec3 q, float rx, float ry, float r) {
    uint m = 0u;
    m |= (q.x + q.z * u_tan_x < -rx) ? 1u : 0u;
    m |= (q.z * u_tan_x - q.x < -rx) ? 2u : 0u;
    m |= (q.y + q.z * u_tan_y < -ry) ? 4u : 0u;
    m |= (q.z * u_tan_y - q.y < -ry) ? 8u : 0u;
    m |= (q.z - u_near < -r) ? 16u : 0u;
    m |= (u_far - q.z < -r) ? 32u : 0u;
    return m;
}
// ---- spans below node resolution (wire/lod.hpp's header comment: lod/bounds.cpp builds the hierarchy, lod/span_walk.hpp
// walks it) ----
// The hierarchy is built bottom-up as the walk over the segments visits them, as a binary counter: a node of level l
// covers 2^l segments, and a level's odd last node stands alone for its parent (the same sphere and deviation:
// the same decision), so what is left on the stack at the end merges from the top. Each node is decided when it is
// complete; one that takes a span writes 1, 0, ..., 0 over its segments, over what its descendants wrote. A segment's
// highest such ancestor writes last: the CPU's top-down walk, which stops at it.
struct Span {
    vec3 c; float r;         // the sphere around its control points (not inflated by the tube radius)
    vec3 a; float dev;       // its chord's first point; every curve point of the span is within dev of the chord
    vec3 b; uint s;          // its chord's last point; its first segment
    uint e, sum, bits, level;  // one past its last segment; its counts' sum now; kOld*, kRestZero, kPattern
};
const uint kOldOne = 1u, kOldZero = 2u, kRestZero = 4u, kPattern = 8u;  // old first count 1 / 0, old rest 0; 1,0..0 now
bool INSIDE;        // the wire's sphere (its control points' box, inflated) lies inside the frustum
float SPAN_K;       // the off-axis factor bounded over that sphere (capped at the screen edge), when INSIDE
vec3 OFFSET;        // the wire's origin - eye
float RADIUS_MAX;   // the wire's largest tube radius
uint TOTAL;         // rings of the wire so far

// SpanMerger::ratio: the span's deviation over the tolerance at its sphere's nearest depth (<= 1: one interval).
float span_ratio(Span nd) {
    uint len = nd.e - nd.s;
    if (len > 1u && CLOSED && 3u * len > SEGS) return 1.0 / 0.0;  // a loop keeps >= 3 intervals
    vec3 q = to_view(OFFSET + nd.c);
    float c = u_focal / u_eps;
    if (!INSIDE) {
        if (u_coarse) {
            float ri = nd.r + RADIUS_MAX;
            float sx = sqrt(1.0 + u_tan_x * u_tan_x), sy = sqrt(1.0 + u_tan_y * u_tan_y);
            bool away = q.x + q.z * u_tan_x < -ri * sx || q.z * u_tan_x - q.x < -ri * sx ||
                       q.y + q.z * u_tan_y < -ri * sy || q.z * u_tan_y - q.y < -ri * sy ||
                       q.z - u_near < -ri || u_far - q.z < -ri;
            if (away) return 0.0;  // off screen: one interval
        }
        float k = sqrt(1.0 + u_tan_x * u_tan_x + u_tan_y * u_tan_y);  // reaching behind the near plane: the corner's
        if (q.z - nd.r >= u_near) {
            float a = (abs(q.x) + nd.r) / (q.z - nd.r), b = (abs(q.y) + nd.r) / (q.z - nd.r);
            k = sqrt(1.0 + a * a + b * b);  // the span's chord may leave the screen: not capped
        }
        return nd.dev * c * k / max(q.z - nd.r, u_near);
    }
    return nd.dev * c * SPAN_K / max(q.z - nd.r, u_near);
}
// Whether the span takes one interval of the counts: at the hysteresis threshold for a new span, at the tolerance
// for one the previous frame had.
bool takes_span(Span nd) {
    float r = span_ratio(nd);
    bool was = (nd.bits & (kOldOne | kRestZero)) == (kOldOne | kRestZero);
    float new_scale = u_band < 0.0 ? 1.0 : 1.0 / (1.0 + u_band);
    return r <= new_scale || (r <= 1.0 && was);
}
// Level 0: segment k (control points from the wire's origin) whose count was just written.
Span leaf_span(Seg c, uint k, uint count, uint old_count) {
    vec3 p1 = c.b0 + c.d0, p2 = p1 + c.d1, p3 = p2 + c.d2;
    vec3 lo = min(min(c.b0, p1), min(p2, p3)), hi = max(max(c.b0, p1), max(p2, p3));
    Span nd;
    nd.c = 0.5 * (lo + hi);
    nd.r = 0.5 * length(hi - lo) * (1.0 + 1e-6);
    // min(the hull's distance to the chord, Wang's 3M/4 for one ring)
    vec3 ab = p3 - c.b0, q1 = c.d0, q2 = c.d0 + c.d1;
    float len2 = dot(ab, ab);
    float inv = len2 > 0.0 ? 1.0 / len2 : 0.0;
    vec3 v1 = q1 - clamp(dot(q1, ab) * inv, 0.0, 1.0) * ab, v2 = q2 - clamp(dot(q2, ab) * inv, 0.0, 1.0) * ab;
    float hull = sqrt(max(dot(v1, v1), dot(v2, v2)));
    float m = max(length(c.d1 - c.d0), length(c.d2 - c.d1));
    nd.dev = min(hull, 0.75 * m);
    if (isnan(nd.dev) || isinf(nd.dev)) nd.dev = 1.0 / 0.0;
    nd.a = c.b0;
    nd.b = p3;
    nd.s = k;
    nd.e = k + 1u;
    nd.sum = count;
    nd.level = 0u;
    nd.bits = kRestZero | (old_count == 1u ? kOldOne : 0u) | (old_count == 0u ? kOldZero : 0u);
    if (takes_span(nd)) {
        counts[H.segment_first + k] = 1u;
        TOTAL = TOTAL - count + 1u;
        nd.sum = 1u;
    }
    if (nd.sum == 1u) nd.bits |= kPattern;
    return nd;
}
void write_zeros(uint s, uint e) { for (uint i = s; i < e; ++i) counts[H.segment_first + i] = 0u; }
// A node from its two children (merge_spheres; deviation max(d_left, d_right) + dist(M, A-B)), decided.
Span merge_span(Span l, Span rt) {
    Span nd;
    vec3 d = rt.c - l.c;
    float dist = length(d);
    if (dist + rt.r <= l.r) {
        nd.c = l.c, nd.r = l.r;
    } else if (dist + l.r <= rt.r) {
        nd.c = rt.c, nd.r = rt.r;
    } else {
        float rad = 0.5 * ((dist + l.r) + rt.r);
        nd.c = l.c + d * ((rad - l.r) / dist);
        nd.r = rad * (1.0 + 1e-6);
    }
    vec3 ab = rt.b - l.a, q = l.b - l.a;
    float len2 = dot(ab, ab);
    float t = len2 > 0.0 ? clamp(dot(q, ab) / len2, 0.0, 1.0) : 0.0;
    nd.dev = max(l.dev, rt.dev) + length(q - t * ab);
    if (isnan(nd.dev)) nd.dev = 1.0 / 0.0;
    nd.a = l.a;
    nd.b = rt.b;
    nd.s = l.s;
    nd.e = rt.e;
    nd.sum = l.sum + rt.sum;
    nd.level = max(l.level, rt.level) + 1u;
    bool rest_zero = (l.bits & kRestZero) != 0u && (rt.bits & (kOldZero | kRestZero)) == (kOldZero | kRestZero);
    nd.bits = (l.bits & (kOldOne | kOldZero)) | (rest_zero ? kRestZero : 0u);
    if (takes_span(nd)) {
        if ((l.bits & kPattern) == 0u) {
            counts[H.segment_first + l.s] = 1u;
            write_zeros(l.s + 1u, l.e);
        }
        if ((rt.bits & kPattern) == 0u) write_zeros(rt.s, rt.e);
        else counts[H.segment_first + rt.s] = 0u;
        TOTAL = TOTAL - nd.sum + 1u;
        nd.sum = 1u;
        nd.bits |= kPattern;
    }
    return nd;
}

// Writes the wire's counts (over the previous ones unless restart) and state; returns its ring total, 0 when
// culled. radius_px: the projected radius.
uint lod(uint slot, vec3 offset, out float radius_px) {
    float radius = 0.0;
    for (uint j = 0u; j < N; ++j) radius = max(radius, node_radius(j));
    float rx = radius * sqrt(1.0 + u_tan_x * u_tan_x), ry = radius * sqrt(1.0 + u_tan_y * u_tan_y);
    uvec4 state = slot_state[slot].lod;
    bool fresh = state.z == 0u;
    uint wire_outside = 63u, visible = 0u;
    TOTAL = CLOSED ? 0u : 1u;
    float wire_z = 1.0 / 0.0, wire_k = 1.0;
    float scale = u_eps / u_focal;
    bool merge = u_merge && SEGS < (1u << 30);
    if (merge) {
        // The wire's sphere (curve_bounding_sphere: its control points' box, inflated by the largest radius) and
        // sphere_screen_bound's inside test and off-axis factor.
        vec3 lo = vec3(1.0 / 0.0), hi = vec3(-1.0 / 0.0);
        for (uint k = 0u; k < SEGS; ++k) {
            Seg c = load_seg(k);
            vec3 p1 = c.b0 + c.d0, p2 = p1 + c.d1, p3 = p2 + c.d2;
            lo = min(lo, min(min(c.b0, p1), min(p2, p3)));
            hi = max(hi, max(max(c.b0, p1), max(p2, p3)));
        }
        float r = 0.5 * length(hi - lo) * (1.0 + 1e-6) + radius;
        vec3 q = to_view(offset + 0.5 * (lo + hi));
        float rxs = r * sqrt(1.0 + u_tan_x * u_tan_x), rys = r * sqrt(1.0 + u_tan_y * u_tan_y);
        INSIDE = q.x + q.z * u_tan_x >= rxs && q.z * u_tan_x - q.x >= rxs && q.y + q.z * u_tan_y >= rys &&
                 q.z * u_tan_y - q.y >= rys && q.z - u_near >= r && u_far - q.z >= r;
        float a = u_tan_x, b = u_tan_y;
        if (q.z - r > 0.0) {
            a = min(a, (abs(q.x) + r) / (q.z - r));
            b = min(b, (abs(q.y) + r) / (q.z - r));
        }
        SPAN_K = sqrt(1.0 + a * a + b * b);
        OFFSET = offset;
        RADIUS_MAX = radius;
    }
    Span stack[32];
    int top = 0;
    for (uint k = 0u; k < SEGS; ++k) {
        Seg c = load_seg(k);
        vec3 p[4];
        p[0] = offset + c.b0; p[1] = p[0] + c.d0; p[2] = p[1] + c.d1; p[3] = p[2] + c.d2;
        uint seg_out = 63u;
        float z_min = 1.0 / 0.0, a = 0.0, b = 0.0;
        bool in_front = true;
        for (int i = 0; i < 4; ++i) {
            vec3 q = to_view(p[i]);
            seg_out &= outside(q, rx, ry, radius);
            z_min = min(z_min, q.z);
            if (q.z >= u_near) {
                a = max(a, abs(q.x) / q.z);
                b = max(b, abs(q.y) / q.z);
            } else {
                in_front = false;
            }
        }
        if (!in_front) { a = u_tan_x; b = u_tan_y; }
        a = min(a, u_tan_x);
        b = min(b, u_tan_y);
        z_min = max(z_min, u_near);
        float hk = sqrt(1.0 + a * a + b * b);
        wire_outside &= seg_out;
        bool seg_visible = seg_out == 0u;
        uint raw = 1u;
        if (seg_visible || !u_coarse) {
            float m = max(length(c.d1 - c.d0), length(c.d2 - c.d1));  // Wang's M: the second differences
            float eps_world = scale * z_min / hk;
            float cnt = ceil(sqrt((3.0 * m) / (4.0 * eps_world)));
            bool ok = eps_world > 0.0 && !isinf(m) && !isnan(m);
            raw = ok ? (cnt < float(u_max_rings) ? max(uint(cnt), 1u) : u_max_rings) : u_max_rings;
            if (seg_visible) {
                ++visible;
                wire_z = min(wire_z, z_min);
                wire_k = max(wire_k, hk);
            }
        }
        uint old_count = fresh ? 0u : counts[H.segment_first + k];
        uint count = min(old_count > raw ? hysteresis_count(old_count, raw, u_band) : raw, u_max_rings);
        counts[H.segment_first + k] = count;
        TOTAL += count;
        if (merge) {
            stack[top++] = leaf_span(c, k, count, old_count);
            while (top >= 2 && stack[top - 1].level == stack[top - 2].level) {
                stack[top - 2] = merge_span(stack[top - 2], stack[top - 1]);
                --top;
            }
        }
    }
    while (top >= 2) {  // the last nodes of odd levels, up to the root
        stack[top - 2] = merge_span(stack[top - 2], stack[top - 1]);
        --top;
    }
    radius_px = 0.0;
    if (wire_outside != 0u) {
        slot_state[slot].lod = uvec4(0u);  // culled: the next frame starts afresh (cull_lod)
        return 0u;
    }
    uint wire_max = (H.flags >> 8u) & 255u;  // the wire's own most sides, if it has one
    uint max_sides = wire_max == 0u ? u_max_sides : max(3u, min(u_max_sides, wire_max));
    uint required_sides = visible == 0u ? 3u : sides_for_radius(radius, wire_z, wire_k, max_sides);
    uint sides = min(fresh ? required_sides : hysteresis_count(state.x, required_sides, u_band), max_sides);
    radius_px = visible == 0u ? 0.0 : radius * u_focal * wire_k / max(wire_z, u_near);
    uint drawn = drawn_sides_for(radius_px, sides, state.y);
    slot_state[slot].lod = uvec4(sides, drawn, 1u, 1u);
    return TOTAL;
}

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

// v turned by the unit quaternion (sqrt(1 - |m|^2), m) (Header.motion; no trigonometry: a rotation by angle a has
// |m| = sin(a / 2), and w from it loses precision only near a half turn in one frame).
vec3 turned(vec3 v, vec3 m) {
    float w = sqrt(max(0.0, 1.0 - dot(m, m)));
    vec3 t = 2.0 * cross(m, v);
    return v + w * t + cross(m, t);
}

void load_wire(uint slot) {
    H = headers[slot];
    N = H.node_count;
    CLOSED = (H.flags & kClosed) != 0u;
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
    uint material = H.flags >> 16u;
    bool caps = (H.flags & kCaps) != 0u;
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
        uint flags = u_stage == 0u ? jobs[w].flags & 3u : 0u;
        jobs[w].flags = flags;
        // The rings: the LOD's counts, or the caller's (place_rings' total); a range of the ring buffer.
        if (u_lod) {
            vec3 offset = vec3(dvec3(H.origin[0], H.origin[1], H.origin[2]) - u_eye);
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
            jobs[w].flags = flags | 4u;
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
    FEWEST = (job.flags & 4u) != 0u;
    // The first normal: the carried previous one projected onto the first tangent, else seeded from an axis.
    vec3 t0 = unit_tangent(load_seg(0u), 0.0);
    if (t0 == vec3(0.0)) t0 = vec3(0.0, 0.0, 1.0);
    vec3 r0 = seed_normal(t0);
    // Job flags bit 1: the job gives the previous normal (bit 0: there is one); else the slot's last frame's.
    vec4 previous = (job.flags & 2u) == 0u           ? slot_state[slot].first_normal
                    : (job.flags & 1u) != 0u ? vec4(job.previous_normal.xyz, 1.0)
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
    uint flags = (CLOSED ? 1u : 0u) | (caps ? 2u : 0u) | (tilt ? 4u : 0u) | (drawn == 2u ? 8u : 0u) |
                 (drawn == 1u ? 16u : 0u);
    vec3 offset = vec3(dvec3(H.origin[0], H.origin[1], H.origin[2]) - u_eye);
    draws[w] = Draw(offset, 7u * RING_FIRST, n, drawn, flags, totals.x);
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
)glsl";

using detail::Job;
using detail::SlotState;

}  // namespace

namespace detail {

void set_lod_uniforms(const engine::gfx::Program& program, const LodView& v, const LodSettings& st) {
    const auto at = [&](const char* name) { return program.uniform_location(name); };
    const glm::mat3 rotation(glm::dmat3(v.view_from_world));
    glUniformMatrix3fv(at("u_view_rot"), 1, GL_FALSE, &rotation[0][0]);
    glUniform3d(at("u_eye"), v.eye_m.x, v.eye_m.y, v.eye_m.z);
    glUniform1f(at("u_focal"), static_cast<float>(v.focal_px));
    glUniform1f(at("u_tan_x"), static_cast<float>(v.tan_half_x));
    glUniform1f(at("u_tan_y"), static_cast<float>(v.tan_half_y));
    glUniform1f(at("u_near"), static_cast<float>(v.near_m));
    glUniform1f(at("u_far"), static_cast<float>(v.far_m));
    // LodSettings' defaults, as update_lod reads them (lod/view.hpp, Limits in lod/update.cpp).
    const double tol = st.tolerance_px > 0.0 ? std::max(st.tolerance_px, 1e-6) : 0.5;
    glUniform1f(at("u_eps"), static_cast<float>(tol));
    glUniform1f(at("u_band"), static_cast<float>(st.hysteresis_band == 0.0 ? 0.25 : st.hysteresis_band));
    glUniform1f(at("u_strip_px"), static_cast<float>(st.strip_radius_px == 0.0 ? 2.0 : st.strip_radius_px));
    glUniform1f(at("u_line_px"), static_cast<float>(st.line_radius_px == 0.0 ? 0.5 : st.line_radius_px));
    glUniform1ui(at("u_max_rings"), st.max_rings_per_segment ? st.max_rings_per_segment : 256u);
    glUniform1ui(at("u_max_sides"), std::clamp<uint32_t>(st.max_sides ? st.max_sides : 32u, 3u, kMaxSides));
    glUniform1i(at("u_coarse"), st.coarse_offscreen_segments ? 1 : 0);
    glUniform1i(at("u_merge"), st.keep_node_resolution ? 0 : 1);
    static_assert(kMaxSides + 1 <= 4 * 65, "u_sagitta4 holds n = 0 .. kMaxSides");
    static const std::array<float, 4 * 65> sagitta = [] {
        std::array<float, 4 * 65> t{};
        for (uint32_t n = 3; n <= kMaxSides; ++n) t[n] = static_cast<float>(1.0 - std::cos(std::numbers::pi / n));
        return t;
    }();
    glUniform4fv(at("u_sagitta4"), 65, sagitta.data());
}

const char* ring_source() { return kRingSource; }

}  // namespace detail

engine::Expected<GpuRingPass> GpuRingPass::create() {
    engine::Expected<engine::gfx::Program> program =
        engine::gfx::make_program({.label = "wire gpu rings", .compute = detail::with_wire_header(kRingSource)});
    if (!program) return program.error();
    GpuRingPass pass;
    pass.program_ = std::move(*program);
    return pass;
}

Status GpuRingPass::build(const GpuCurvePass& curves, std::span<const GpuRingJob> jobs, const GpuLodFrame* lod) {
    const std::vector<GpuCurveHeader>& headers = curves.header_data_;
    if (jobs.size() != headers.size()) {
        return Status::error("the ring pass got " + std::to_string(jobs.size()) + " jobs for the curve pass's " +
                             std::to_string(headers.size()) + " wires");
    }
    const uint32_t max_rings = lod == nullptr || lod->settings.max_rings_per_segment == 0
                                   ? 256u
                                   : lod->settings.max_rings_per_segment;
    std::vector<Job> job_data(jobs.size());
    std::vector<uint32_t> counts, count_first(jobs.size()), segments(jobs.size()), visible(jobs.size());
    std::size_t rings = 0, count_total = 0;
    bool carry_last = false;
    for (std::size_t w = 0; w < jobs.size(); ++w) {
        const GpuCurveHeader& h = headers[w];
        const bool closed = (h.flags & detail::kHeaderClosed) != 0;
        const std::size_t segs = closed ? h.node_count : h.node_count - 1;
        Job& j = job_data[w];
        count_first[w] = h.segment_first;
        segments[w] = static_cast<uint32_t>(segs);
        visible[w] = h.slot;
        count_total += segs;
        j.flags = jobs[w].carry_last ? 0u : 2u | (jobs[w].has_previous_normal ? 1u : 0u);
        carry_last = carry_last || jobs[w].carry_last;
        j.previous_normal[0] = jobs[w].previous_normal.x;
        j.previous_normal[1] = jobs[w].previous_normal.y;
        j.previous_normal[2] = jobs[w].previous_normal.z;
        if (lod != nullptr) {
            rings += (closed ? 0 : 1) + segs * max_rings;
            continue;
        }
        if (jobs[w].counts.size() != segs) {
            return Status::error("wire " + std::to_string(w) + ": " + std::to_string(jobs[w].counts.size()) +
                                 " ring counts for its " + std::to_string(segs) + " segments");
        }
        // place_rings: counts[k] rings on segment k (segment 0 at least one), an open wire one more at the end.
        rings += closed ? 0 : 1;
        for (std::size_t k = 0; k < segs; ++k) rings += k == 0 ? std::max<uint32_t>(jobs[w].counts[k], 1) : jobs[w].counts[k];
        counts.insert(counts.end(), jobs[w].counts.begin(), jobs[w].counts.end());
    }
    if (lod != nullptr && lod->ring_capacity != 0) rings = lod->ring_capacity;
    if (jobs.empty()) {
        count_first_.clear(), segments_.clear();
        return Status::success();
    }
    // The counts and the LOD's per-wire state stay on the GPU while the wires' layout does (the hysteresis).
    const bool keep = lod != nullptr && lod_ && count_first == count_first_ && segments == segments_;
    if (!keep) {
        if (counts.empty()) counts.assign(count_total, 0);
        auto count_buffer = engine::gfx::make_buffer(std::span<const uint32_t>(counts), "wire gpu ring counts");
        std::vector<SlotState> state(jobs.size());
        if (carry_last && state_wires_ == jobs.size()) {
            // The first normals carry over to the same wires (the LOD's state restarts with the new layout).
            glGetNamedBufferSubData(state_.id(), 0, static_cast<GLsizeiptr>(state.size() * sizeof(SlotState)),
                                    state.data());
            for (SlotState& st : state) st.lod[0] = st.lod[1] = st.lod[2] = st.lod[3] = 0;
        }
        auto state_buffer = engine::gfx::make_buffer(std::span<const SlotState>(state), "wire gpu slot state");
        if (!count_buffer) return Status::error(count_buffer.error().message);
        if (!state_buffer) return Status::error(state_buffer.error().message);
        counts_ = std::move(*count_buffer), state_ = std::move(*state_buffer);
    } else {
        for (std::size_t w = 0; w < jobs.size(); ++w) {
            if (!jobs[w].restart_lod) continue;
            glClearNamedBufferSubData(state_.id(), GL_RGBA32UI, static_cast<GLintptr>(visible[w] * sizeof(SlotState)),
                                      sizeof(SlotState::lod), GL_RGBA_INTEGER, GL_UNSIGNED_INT, nullptr);
        }
    }
    auto job_buffer = engine::gfx::make_buffer(std::span<const Job>(job_data), "wire gpu ring jobs");
    const uint32_t zero_counter[4] = {0, 0, 0, 0};
    auto counter = engine::gfx::make_buffer(std::span<const uint32_t>(zero_counter), "wire gpu ring counter");
    auto visible_buffer = engine::gfx::make_buffer(std::span<const uint32_t>(visible), "wire gpu visible slots");
    if (!job_buffer) return Status::error(job_buffer.error().message);
    if (!counter) return Status::error(counter.error().message);
    if (!visible_buffer) return Status::error(visible_buffer.error().message);
    jobs_ = std::move(*job_buffer), counter_ = std::move(*counter), visible_ = std::move(*visible_buffer);
    if (rings > ring_capacity_ || !rings_) {
        auto ring_buffer = engine::gfx::make_buffer({.size_bytes = std::max<std::size_t>(rings, 1) * sizeof(PackedRing),
                                                     .label = "wire gpu rings"});
        if (!ring_buffer) return Status::error(ring_buffer.error().message);
        rings_ = std::move(*ring_buffer);
        ring_capacity_ = std::max<std::size_t>(rings, 1);
    }
    count_first_ = std::move(count_first), segments_ = std::move(segments);
    state_wires_ = jobs.size();
    count_total_ = count_total;
    lod_ = lod != nullptr;
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingHeaders, curves.headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingSegments, curves.segments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingJobs, jobs_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingCounts, counts_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingRings, rings_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingSlots, state_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingCounter, counter_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kRingVisible, visible_.id());
    program_.use();
    const auto at = [&](const char* name) { return program_.uniform_location(name); };
    glUniform1ui(at("u_wires"), static_cast<GLuint>(jobs.size()));
    glUniform1ui(at("u_stage"), 0u);
    // Every wire is "changed" (its header's motion turns its kept first normal) when a job carries the last one.
    glUniform1ui(at("u_unchanged"), carry_last ? 0u : static_cast<GLuint>(jobs.size()));
    glUniform1i(at("u_draw"), 0);
    glUniform1ui(at("u_ring_capacity"), static_cast<GLuint>(std::min<std::size_t>(ring_capacity_, 0xffffffffu)));
    glUniform1ui(at("u_ring_reserve"), 0u);  // a wire that does not fit is reported (GpuRingResult::overflow)
    glUniform1i(at("u_lod"), lod != nullptr ? 1 : 0);
    if (lod != nullptr) detail::set_lod_uniforms(program_, lod->view, lod->settings);
    glDispatchCompute(static_cast<GLuint>((jobs.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glUseProgram(0);
    return Status::success();
}

void GpuRingPass::read(std::vector<GpuRingResult>& out) const {
    out.clear();
    if (count_first_.empty()) return;
    uint32_t counter[2] = {0, 0};
    glGetNamedBufferSubData(counter_.id(), 0, sizeof(counter), counter);
    const std::size_t used = std::min<std::size_t>(counter[0], ring_capacity_);
    std::vector<PackedRing> rings(used);
    if (used != 0) {
        glGetNamedBufferSubData(rings_.id(), 0, static_cast<GLsizeiptr>(used * sizeof(PackedRing)), rings.data());
    }
    std::vector<Job> jobs(count_first_.size());
    glGetNamedBufferSubData(jobs_.id(), 0, static_cast<GLsizeiptr>(jobs.size() * sizeof(Job)), jobs.data());
    std::vector<uint32_t> counts(count_total_);
    glGetNamedBufferSubData(counts_.id(), 0, static_cast<GLsizeiptr>(counts.size() * sizeof(uint32_t)), counts.data());
    std::vector<SlotState> state(jobs.size());
    if (lod_) glGetNamedBufferSubData(state_.id(), 0, static_cast<GLsizeiptr>(state.size() * sizeof(SlotState)), state.data());
    out.resize(jobs.size());
    for (std::size_t w = 0; w < out.size(); ++w) {
        GpuRingResult& r = out[w];
        const Job& j = jobs[w];
        const bool fits = j.ring_count != 0 && std::size_t{j.ring_first} + j.ring_count <= used;
        if (fits) r.rings.assign(rings.begin() + j.ring_first, rings.begin() + j.ring_first + j.ring_count);
        r.counts.assign(counts.begin() + count_first_[w], counts.begin() + count_first_[w] + segments_[w]);
        r.first_normal = glm::vec3(j.first_normal[0], j.first_normal[1], j.first_normal[2]);
        r.sides = j.sides;
        r.u_close = j.totals[0];
        r.length_m = j.totals[1];
        r.holonomy_rad = j.totals[2];
        r.radius_px = j.totals[3];
        if (lod_) {
            r.sides = state[w].lod[0];
            r.drawn_sides = state[w].lod[1];
            r.visible = state[w].lod[3] != 0;
            r.overflow = r.visible && !fits;
        } else {
            r.overflow = !fits;
        }
    }
}

}  // namespace wire::render
