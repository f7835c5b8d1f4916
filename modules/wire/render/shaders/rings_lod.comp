// ---- the LOD (modules/wire/src/lod/update.cpp's per-segment pass, view.hpp's hull depth and plane test) ----
// The view (with u_eye) and the settings' values.
uniform mat3 u_view_rot;  // world -> view rotation (GL view space: looking down -z)
uniform float u_focal, u_tan_x, u_tan_y, u_near, u_far, u_eps, u_band, u_strip_px, u_line_px;
uniform uint u_max_rings, u_max_sides;  // u_max_sides <= kMaxSides
uniform bool u_coarse;
uniform bool u_merge;  // spans below node resolution (LodSettings::keep_node_resolution off)
// 1 - cos(pi / n) at [n >> 2][n & 3], n <= 256: vec4s, so a compiler that gives each element of a uniform array a
// vec4 slot needs 260 components, not 1028 (of the 1024 GL_MAX_COMPUTE_UNIFORM_COMPONENTS guarantees).
uniform vec4 u_sagitta4[65];

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
// complete; one that takes a span gives its segments 1, 0, ..., 0, over what its descendants gave them (a mark, then
// sweep_spans()). A segment's count is its highest such ancestor's: the CPU's top-down walk, which stops at it.
struct Span {
    vec3 c; float r;         // the sphere around its control points (not inflated by the tube radius)
    vec3 a; float dev;       // its chord's first point; every curve point of the span is within dev of the chord
    vec3 b; uint s;          // its chord's last point; its first segment
    uint e, sum, bits, level;  // one past its last segment; its counts' sum now; kOld*, kRestZero, kPattern
};
// Old first count 1 / 0, old rest 0; 1,0..0 now. A span taken above level 0 is written as one mark at its first
// segment (kSpanMark | its length), and sweep_spans() turns the marks into counts in one pass: every loop of the
// wire is O(segments), never O(segments log segments), which matters for the serial work of an invocation (and on
// llvmpipe, which ends an invocation's loops after 65,535 iterations in all).
const uint kOldOne = 1u, kOldZero = 2u, kRestZero = 4u, kPattern = 8u;
const uint kSpanMark = 0x80000000u;
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
// The marks into counts: a span's first segment 1, the rest 0, unless a span before it covers it (then 0).
void sweep_spans() {
    uint zero_until = 0u;
    for (uint k = 0u; k < SEGS; ++k) {
        uint c = counts[H.segment_first + k];
        bool covered = k < zero_until;
        if ((c & kSpanMark) != 0u) {
            counts[H.segment_first + k] = covered ? 0u : 1u;
            zero_until = max(zero_until, k + (c & ~kSpanMark));
        } else if (covered && c != 0u) {
            counts[H.segment_first + k] = 0u;
        }
    }
}
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
        counts[H.segment_first + nd.s] = kSpanMark | (nd.e - nd.s);  // sweep_spans() writes the span
        TOTAL = TOTAL - nd.sum + 1u;
        nd.sum = 1u;
        nd.bits |= kPattern;
    }
    return nd;
}

// One control point of a segment in view: the planes it is outside of, its depth, its off-axis slopes.
void corner(vec3 pt, float rx, float ry, float radius, inout uint seg_out, inout float z_min, inout float a,
            inout float b, inout bool in_front) {
    vec3 q = to_view(pt);
    seg_out &= outside(q, rx, ry, radius);
    z_min = min(z_min, q.z);
    if (q.z >= u_near) {
        a = max(a, abs(q.x) / q.z);
        b = max(b, abs(q.y) / q.z);
    } else {
        in_front = false;
    }
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
        // Written out, not a loop: a compiler that keeps a loop pays for it per segment (llvmpipe's budget).
        corner(p[0], rx, ry, radius, seg_out, z_min, a, b, in_front);
        corner(p[1], rx, ry, radius, seg_out, z_min, a, b, in_front);
        corner(p[2], rx, ry, radius, seg_out, z_min, a, b, in_front);
        corner(p[3], rx, ry, radius, seg_out, z_min, a, b, in_front);
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
    if (merge) sweep_spans();
    radius_px = 0.0;
    if (wire_outside != 0u) {
        slot_state[slot].lod = uvec4(0u);  // culled: the next frame starts afresh (cull_lod)
        return 0u;
    }
    uint wire_max = (H.flags >> kHeaderSidesShift) & kHeaderSidesMask;  // the wire's own most sides, if it has one
    uint max_sides = wire_max == 0u ? u_max_sides : max(3u, min(u_max_sides, wire_max));
    uint required_sides = visible == 0u ? 3u : sides_for_radius(radius, wire_z, wire_k, max_sides);
    uint sides = min(fresh ? required_sides : hysteresis_count(state.x, required_sides, u_band), max_sides);
    radius_px = visible == 0u ? 0.0 : radius * u_focal * wire_k / max(wire_z, u_near);
    uint drawn = drawn_sides_for(radius_px, sides, state.y);
    slot_state[slot].lod = uvec4(sides, drawn, 1u, 1u);
    return TOTAL;
}
