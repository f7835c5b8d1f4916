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
