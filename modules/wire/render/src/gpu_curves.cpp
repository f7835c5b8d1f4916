// The curve stage on the GPU (see gpu_curves.hpp).
#include "wire/render/gpu_curves.hpp"

#include "wire/packed_nodes.hpp"
#include "wire/spline.hpp"

#include "gpu_wire_data.hpp"

#include <epoxy/gl.h>
#include <glm/common.hpp>

#include <algorithm>
#include <string>

namespace wire::render {
namespace {


// One invocation per wire. Per curve node j: its incoming and outgoing chords (an open end reflects the missing
// neighbour: the missing chord equals the other), the knot ratio rho = (l_out / l_in)^alpha, and the
// Kochanek-Bartels tangents at j (the same formulas as catmull_rom_tangents in modules/wire/src/spline/build.cpp,
// in float); node j writes its incoming segment (put_segment), holding its outgoing tangent for the next node.
constexpr const char* kCurveSource = R"glsl(#version 450 core
layout(local_size_x = 64) in;
GPU_WIRE_HEADER
layout(std430, binding = CURVE_HEADERS) readonly buffer Headers { Header headers[]; };
layout(std430, binding = CURVE_NODES) readonly buffer Nodes { vec4 nodes[]; };  // xyz: offset from the origin; w: radius
layout(std430, binding = CURVE_SEGMENTS) writeonly buffer Segments { vec4 segments[]; };  // 4 per segment: see put_segment
layout(std430, binding = CURVE_SCRATCH) buffer Scratch { dvec4 scratch[]; };  // c2: 2 per node (solve state, then D)
// Per-node tension, bias, continuity (vec4 a node), then stretch (4 segments a vec4), from Header.extra_first.
layout(std430, binding = CURVE_EXTRAS) readonly buffer Extras { vec4 extras[]; };
// u_persist: each wire's header goes on to its slot (the ring pass reads it there every frame).
layout(std430, binding = CURVE_SLOT_HEADERS) writeonly buffer SlotHeaders { Header slot_headers[]; };
// u_motion: per slot, the motion reference of its last upload (motion_reference's samples of its curve nodes:
// origin.xyz the upload's origin, origin.w the determinacy; counts.x samples, counts.y nodes, 0 samples: none;
// p[k].xyz the sample's offset from the origin, p[k].w its weight).
struct MotionRef { vec4 origin; uvec4 counts; vec4 p[10]; };
layout(std430, binding = CURVE_MOTION_REFS) buffer MotionRefs { MotionRef refs[]; };
// u_list: each wire's slot goes to slot_list[u_list_first + w] (the ring pass's list of this frame's wires).
layout(std430, binding = CURVE_SLOT_LIST) writeonly buffer SlotList { uint slot_list[]; };
uniform uint u_wires;
uniform bool u_list;
uniform uint u_list_first;
uniform bool u_persist;
uniform bool u_motion;

vec3 node(Header h, uint j) { return nodes[h.node_first + j].xyz; }

// c2 (kind 2): node tangents per unit chord D from the C2 spline's tangent system with chordal knots (rows
// a D[j-1] + 2 D[j] + c D[j+1] = 3 (a e_in + c e_out), a = h_out / (h_in + h_out), c = h_in / (h_in + h_out));
// open ends not-a-knot (3 nodes: the parabola; 2: the chord), closed loops cyclic (Sherman-Morrison). As
// start_tangents / finish_tangents in modules/wire/src/spline/build.cpp with no node tensed. In double: the
// not-a-knot end D0 = (r0 - D1) / beta0 cancels by the ratio of the first two chords (beta0 = h1 / (h0 + h1)),
// which in float moved a 4-node wire with 100:1 chords by 1e-4 of its extent; the float nodes' differences are
// exact in double. D[j] goes to scratch[2 (first + j)].xyz.
uint sidx(Header h, uint j) { return 2u * (h.node_first + j); }
dvec3 dnode(Header h, uint j) { return dvec3(node(h, j % h.node_count)); }
dvec3 chord(Header h, uint k) { return dnode(h, k + 1u) - dnode(h, k); }
double hlen(Header h, uint k) { return length(chord(h, k)); }
dvec3 unit_chord(Header h, uint k) { return chord(h, k) / hlen(h, k); }

// Row j of the interior system: (a, b, c) and its right-hand side.
// The automatic spline (kind 3): the c2 system with node j's tension weight w_j on the diagonal (Nielson's
// nu-spline) and its ends blending from not-a-knot to free as the nodes next to them get tensed, the weights read
// from the turning pattern as concentrated_turns does on the CPU (modules/wire/src/spline/tension.cpp, the same
// operations in double; the weights' exponentials in float: GLSL has no double exp), then each node's tension
// scaling both its tangents (build_curve's end_curve): 1 - t, t wire-wide or, for nodes that carry tension or the
// physics arrays, per node in the extras (x).
bool automatic(Header h) { return ((h.flags >> 1u) & 3u) == 3u; }
double keep_at(Header h, uint j) {
    if (!automatic(h)) return 1.0;
    return 1.0lf - double((h.flags & kHasPerNode) != 0u ? extras[h.extra_first + j].x : h.kb.y);
}
dvec3 e_out(Header h, uint j) { return unit_chord(h, j % h.node_count); }
dvec3 e_in(Header h, uint j) { return unit_chord(h, (j + h.node_count - 1u) % h.node_count); }
// Curvature vector and chord-bisector tangent of node j (an open wire's end nodes take their neighbour's).
uint inner(Header h, uint j) {
    bool closed = (h.flags & kClosed) != 0u;
    return closed ? j % h.node_count : clamp(j, 1u, h.node_count - 2u);
}
dvec3 kvec(Header h, uint j) {
    j = inner(h, j);
    uint n = h.node_count;
    return (e_out(h, j) - e_in(h, j)) * (2.0lf / (hlen(h, (j + n - 1u) % n) + hlen(h, j)));
}
dvec3 tvec(Header h, uint j) {
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
vec3 turn_weights(Header h, uint j) {
    uint n = h.node_count;
    bool closed = (h.flags & kClosed) != 0u;
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

void row(Header h, uint j, out dvec3 abc, out dvec3 rhs) {
    uint n = h.node_count;
    uint kin = (j + n - 1u) % n, kout = j % n;
    double hin = hlen(h, kin), hout = hlen(h, kout), sum = hin + hout;
    double a = hout / sum, c = hin / sum;
    abc = dvec3(a, 2.0 + double(turn_weights(h, j % n).x), c);
    rhs = 3.0 * (a * unit_chord(h, kin) + c * unit_chord(h, kout));
}

void c2_tangents(Header h, bool closed) {
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
float seg_stretch(Header h, uint k) {
    if ((h.flags & kHasStretch) == 0u) return 1.0;
    uint base = h.extra_first + ((h.flags & kHasPerNode) != 0u ? h.node_count : 0u);
    return extras[base + k / 4u][k % 4u];
}
void put_segment(Header h, uint k, vec3 p0, vec3 t0, vec3 t1, vec3 chord_k) {
    uint s = 4u * (h.segment_first + k);
    segments[s] = vec4(p0, nodes[h.node_first + k].w);
    segments[s + 1u] = vec4(t0 / 3.0, nodes[h.node_first + (k + 1u) % h.node_count].w);
    segments[s + 2u] = vec4(chord_k - (t0 + t1) / 3.0, seg_stretch(h, k));
    segments[s + 3u] = vec4(t1 / 3.0, 0.0);
}

// The wire's motion since its last upload (kFitMotion), as wire/motion.cpp fits it on the CPU: the reference
// (motion_reference: nodes 0, 1, 2, 3, then steps growing 1.5x, the last node; weights (1 + s / 4l)^-4 with the
// reach l grown 4x from two elements until the determinacy 2 e2 / e1^2 reaches 1e-3), Horn's weighted fit (the
// top eigenvector of his 4x4 matrix by Theobald's characteristic polynomial: Newton from the spread, then the
// adjugate's largest column), the confidence smoothstep(1e-4, 1e-3, determinacy) and carried_rotation's fraction
// of the angle. In double, from the float offsets (differences of two uploads' origins in double). Matched by
// index: the CPU asks for this only when the nodes were not merged and the ids at the samples sat where they sit.
uint ref_indices(uint n, out uint at[10]) {
    uint i = 0u, step = 1u, count = 0u;
    for (;;) {
        at[count++] = i;
        if (i + 1u >= n || count == 10u) return count;
        if (i >= 3u) step = max(step + 1u, (step * 3u) / 2u);
        i = count + 1u == 10u ? n - 1u : min(n - 1u, i + step);
    }
}
double determinacy(dvec3 p[10], double wt[10], uint m) {
    double wsum = 0.0lf;
    dvec3 c = dvec3(0.0lf);
    for (uint k = 0u; k < m; ++k) wsum += wt[k], c += wt[k] * p[k];
    if (!(wsum > 0.0lf)) return 0.0lf;
    c /= wsum;
    double xx = 0.0lf, yy = 0.0lf, zz = 0.0lf, xy = 0.0lf, xz = 0.0lf, yz = 0.0lf;
    for (uint k = 0u; k < m; ++k) {
        dvec3 d = p[k] - c;
        xx += wt[k] * d.x * d.x, yy += wt[k] * d.y * d.y, zz += wt[k] * d.z * d.z;
        xy += wt[k] * d.x * d.y, xz += wt[k] * d.x * d.z, yz += wt[k] * d.y * d.z;
    }
    double e1 = xx + yy + zz, e2 = xx * yy - xy * xy + xx * zz - xz * xz + yy * zz - yz * yz;
    if (!(e1 > 0.0lf)) return 0.0lf;
    return max(0.0lf, 2.0lf * e2 / (e1 * e1));
}
MotionRef make_ref(Header h) {
    MotionRef r;
    uint at[10];
    uint m = ref_indices(h.node_count, at);
    r.counts = uvec4(m, h.node_count, 0u, 0u);
    dvec3 p[10];
    double arc[10], wt[10];
    double s = 0.0lf;
    for (uint k = 0u; k < 10u; ++k) {
        p[k] = dvec3(0.0lf), arc[k] = 0.0lf, wt[k] = 0.0lf;
        if (k >= m) continue;
        p[k] = dvec3(node(h, at[k]));
        if (k != 0u) s += length(p[k] - p[k - 1u]);
        arc[k] = s;
    }
    double whole = arc[m - 1u], reach = max(arc[min(2u, m - 1u)], 1e-300lf), det = 0.0lf;
    for (;;) {
        for (uint k = 0u; k < m; ++k) {
            double q = 1.0lf / (1.0lf + arc[k] / (4.0lf * reach));
            wt[k] = (q * q) * (q * q);
        }
        det = determinacy(p, wt, m);
        if (det >= 1e-3lf || !(reach < whole)) break;
        reach *= 4.0lf;
    }
    r.origin = vec4(h.origin[0], h.origin[1], h.origin[2], float(det));
    for (uint k = 0u; k < 10u; ++k) r.p[k] = vec4(vec3(p[k]), float(wt[k]));
    return r;
}
double minor3(dmat4 a, int r, int c) {
    dmat3 s;
    int ii = 0;
    for (int i = 0; i < 4; ++i) {
        if (i == r) continue;
        int jj = 0;
        for (int j = 0; j < 4; ++j) {
            if (j == c) continue;
            s[ii][jj] = a[i][j];
            ++jj;
        }
        ++ii;
    }
    return determinant(s);
}
// The unit quaternion (x, y, z, w) turning the state `from` into `to` (identity where fit_motion gives none).
vec4 fit_motion(MotionRef from, MotionRef to) {
    const vec4 none = vec4(0.0, 0.0, 0.0, 1.0);
    uint m = from.counts.x;
    if (m < 3u || from.counts.y != to.counts.y || to.counts.x != m) return none;
    dvec3 shift = dvec3(to.origin.xyz) - dvec3(from.origin.xyz);
    bool moved = false;
    for (uint k = 0u; k < m; ++k) moved = moved || dvec3(to.p[k].xyz) + shift != dvec3(from.p[k].xyz);
    if (!moved) return none;
    double t = clamp((double(from.origin.w) - 1e-4lf) / (1e-3lf - 1e-4lf), 0.0lf, 1.0lf);
    double confidence = t * t * (3.0lf - 2.0lf * t);
    if (!(confidence > 0.0lf)) return none;
    double wsum = 0.0lf;
    dvec3 ca = dvec3(0.0lf), cb = dvec3(0.0lf);
    for (uint k = 0u; k < m; ++k) {
        double wk = double(from.p[k].w);
        wsum += wk, ca += wk * dvec3(from.p[k].xyz), cb += wk * (dvec3(to.p[k].xyz) + shift);
    }
    if (!(wsum > 0.0lf)) return none;
    ca /= wsum, cb /= wsum;
    dmat3 S = dmat3(0.0lf);  // S[r][c] = sum w x_r y_c
    double spread = 0.0lf;
    for (uint k = 0u; k < m; ++k) {
        double wk = double(from.p[k].w);
        dvec3 x = dvec3(from.p[k].xyz) - ca, y = dvec3(to.p[k].xyz) + shift - cb;
        spread += 0.5lf * wk * (dot(x, x) + dot(y, y));
        for (int r = 0; r < 3; ++r) S[r] += wk * x[r] * y;
    }
    if (!(spread > 0.0lf)) return none;
    double sxx = S[0][0], sxy = S[0][1], sxz = S[0][2], syx = S[1][0], syy = S[1][1], syz = S[1][2],
           szx = S[2][0], szy = S[2][1], szz = S[2][2];
    dmat4 N = dmat4(sxx + syy + szz, syz - szy, szx - sxz, sxy - syx,
                    syz - szy, sxx - syy - szz, sxy + syx, szx + sxz,
                    szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy,
                    sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz);
    dmat4 N2 = N * N;
    double tr2 = 0.0lf, tr3 = 0.0lf;
    dmat4 N3 = N2 * N;
    for (int i = 0; i < 4; ++i) tr2 += N2[i][i], tr3 += N3[i][i];
    double c2 = -0.5lf * tr2, c1 = -tr3 / 3.0lf, c0 = determinant(N);
    double x = spread;
    for (int it = 0; it < 60; ++it) {
        double x2 = x * x;
        double p = (x2 + c2) * x2 + c1 * x + c0, dp = 4.0lf * x2 * x + 2.0lf * c2 * x + c1;
        if (!(dp != 0.0lf)) break;
        double step = p / dp;
        x -= step;
        if (!(abs(step) > 1e-15lf * abs(x))) break;
    }
    dmat4 A = N - x * dmat4(1.0lf);
    int j = 0;
    double diag = -1.0lf;
    for (int k = 0; k < 4; ++k) {
        double d = abs(minor3(A, k, k));
        if (d > diag) diag = d, j = k;
    }
    dvec4 q;
    for (int i = 0; i < 4; ++i) q[i] = (((i + j) & 1) != 0 ? -1.0lf : 1.0lf) * minor3(A, j, i);
    double len = length(q);
    if (!(len > 0.0lf)) return none;
    q /= len;
    if (q.x < 0.0lf) q = -q;  // (w, x, y, z): the shorter way round
    vec4 rot = vec4(vec3(q.yzw), float(q.x));
    if (confidence >= 1.0lf) return rot;
    // carried_rotation: a fraction of the angle about the same axis.
    float sin_half = length(rot.xyz);
    if (!(sin_half > 0.0)) return none;
    float half_angle = atan(sin_half, rot.w) * float(confidence);
    return vec4(sin(half_angle) * (rot.xyz / sin_half), cos(half_angle));
}

void main() {
    uint w = gl_GlobalInvocationID.x;
    if (w >= u_wires) return;
    Header h = headers[w];
    if (u_list) slot_list[u_list_first + w] = h.slot;
    if (u_persist && u_motion) {
        // This upload's reference (none for given segments) and, when asked, the motion fitted against the last.
        MotionRef to;
        to.counts = uvec4(0u);
        if ((h.flags & kGivenSegments) == 0u) to = make_ref(h);
        if ((h.flags & kFitMotion) != 0u) {
            vec4 q = fit_motion(refs[h.slot], to);
            h.motion[0] = q.x, h.motion[1] = q.y, h.motion[2] = q.z;
        }
        refs[h.slot] = to;
    }
    if (u_persist) slot_headers[h.slot] = h;
    if ((h.flags & kGivenSegments) != 0u) {  // a blended curve: its segments as they came
        uint segs = (h.flags & 1u) != 0u ? h.node_count : h.node_count - 1u;
        for (uint k = 0u; k < 4u * segs; ++k) segments[4u * h.segment_first + k] = nodes[h.node_first + k];
        return;
    }
    uint n = h.node_count;
    bool closed = (h.flags & 1u) != 0u;
    uint kind = (h.flags >> 1u) & 3u;
    uint segs = closed ? n : n - 1u;
    if (kind >= 2u) {
        c2_tangents(h, closed);
        for (uint k = 0u; k < segs; ++k) {
            dvec3 p0 = dnode(h, k), p1 = dnode(h, k + 1u);
            double len = hlen(h, k);
            // keep: the node's tension scales both its tangents (automatic; 1 for c2).
            double keep0 = keep_at(h, k), keep1 = keep_at(h, (k + 1u) % n);
            dvec3 t0 = scratch[sidx(h, k)].xyz * (len * keep0), t1 = scratch[sidx(h, (k + 1u) % n)].xyz * (len * keep1);
            uint s = 4u * (h.segment_first + k);
            segments[s] = vec4(vec3(p0), nodes[h.node_first + k].w);
            segments[s + 1u] = vec4(vec3(t0 / 3.0), nodes[h.node_first + (k + 1u) % n].w);
            segments[s + 2u] = vec4(vec3((p1 - p0) - (t0 + t1) / 3.0), seg_stretch(h, k));
            segments[s + 3u] = vec4(vec3(t1 / 3.0), 0.0);
        }
        return;
    }
    // Node j's tangents: t0 starts its outgoing segment j, t1 ends its incoming one (j - 1); segment j - 1 is
    // written at node j from the previous node's t0, and a closed loop's last segment at the end from node 0's t1.
    float alpha = h.kb.x, keep = 1.0 - h.kb.y, b = h.kb.z, c = h.kb.w;
    vec3 prev_t0 = vec3(0.0), first_t1 = vec3(0.0);
    for (uint j = 0u; j < n; ++j) {
        bool has_in = closed || j > 0u, has_out = closed || j + 1u < n;
        uint kin = has_in ? (j == 0u ? segs - 1u : j - 1u) : 0u;
        uint kout = has_out ? (j == segs ? 0u : j) : segs - 1u;
        vec3 cin = node(h, (kin + 1u) % n) - node(h, kin);
        vec3 cout = node(h, (kout + 1u) % n) - node(h, kout);
        vec3 din = has_in ? cin : cout;
        vec3 dout = has_out ? cout : cin;
        vec3 t0, t1;
        if (kind == 0u) {
            t0 = dout;
            t1 = din;
        } else {
            if ((h.flags & kHasPerNode) != 0u) {
                vec4 k = extras[h.extra_first + j];
                keep = 1.0 - k.x;
                b = k.y;
                c = k.z;
            }
            float lin = length(din), lout = length(dout);
            float rho;
            if (alpha == 1.0) rho = lout / lin;
            else if (alpha == 0.5) rho = sqrt(lout / lin);
            else rho = exp(clamp(alpha * (log(lout) - log(lin)), -80.0, 80.0));
            rho = clamp(rho, 1e-30, 1e30);
            float wt = rho / (1.0 + rho), iw = 1.0 / (1.0 + rho);
            t0 = keep * (((1.0 + b) * (1.0 + c) * rho * wt) * din + ((1.0 - b) * (1.0 - c) * iw) * dout);
            t1 = keep * (((1.0 + b) * (1.0 - c) * wt) * din + ((1.0 - b) * (1.0 + c) * iw / rho) * dout);
        }
        if (j == 0u) first_t1 = t1;
        else put_segment(h, j - 1u, node(h, j - 1u), prev_t0, t1, cin);
        prev_t0 = t0;
    }
    if (closed) put_segment(h, n - 1u, node(h, n - 1u), prev_t0, first_t1, node(h, 0u) - node(h, n - 1u));
}
)glsl";

}  // namespace

engine::Expected<GpuCurvePass> GpuCurvePass::create() {
    engine::Expected<engine::gfx::Program> program =
        engine::gfx::make_program({.label = "wire gpu curves", .compute = detail::with_wire_header(kCurveSource)});
    if (!program) return program.error();
    GpuCurvePass pass;
    pass.program_ = std::move(*program);
    return pass;
}

bool GpuCurvePass::supported(const SplineSettings& spline, const WireNodes& nodes) {
    (void)nodes;
    return gpu_builds(spline.kind);
}

namespace detail {

const char* curve_source() { return kCurveSource; }

std::string with_wire_header(const char* source) {
    std::string s(source);
    const std::string key = "GPU_WIRE_HEADER";
    const std::size_t at = s.find(key);
    if (at == std::string::npos) return s;
    std::string text;
    for (const BindingMacro& m : kBindingMacros) text += "#define " + std::string(m.name) + " " + std::to_string(m.binding) + "\n";
    s.replace(at, key.size(), text + kWireHeaderGlsl);
    return s;
}

GpuCurveHeader packed_header(const PackedNodes& p, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                             const WireMotion& motion, uint32_t node_first, uint32_t extra_first) {
    GpuCurveHeader h;
    h.node_first = node_first;
    h.node_count = static_cast<uint32_t>(p.nodes.size());
    h.segment_first = segment_first;
    const uint32_t kind = p.kind == SplineKind::linear      ? kKindLinear
                          : p.kind == SplineKind::c2        ? kKindC2
                          : p.kind == SplineKind::automatic ? kKindAutomatic
                                                            : kKindCatmullRom;
    h.flags = (p.closed ? kHeaderClosed : 0u) | (kind << kHeaderKindShift) | (caps ? kHeaderCaps : 0u) |
              (p.per_node_kb ? kHeaderPerNode : 0u) | (p.stretch ? kHeaderStretch : 0u) |
              (motion.fit ? kHeaderFitMotion : 0u) | (material << kHeaderMaterialShift);
    h.alpha = p.alpha, h.tension = p.tension, h.bias = p.bias, h.continuity = p.continuity;
    h.extra_first = extra_first;
    h.slot = slot;
    h.origin_m[0] = static_cast<float>(p.origin_m.x), h.origin_m[1] = static_cast<float>(p.origin_m.y),
    h.origin_m[2] = static_cast<float>(p.origin_m.z);  // exact: pack_nodes made it a float_point
    h.motion[0] = motion.rotation.x, h.motion[1] = motion.rotation.y, h.motion[2] = motion.rotation.z;
    return h;
}

void append_packed(const PackedNodes& p, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                   const WireMotion& motion, WireUpload& out) {
    out.headers.push_back(packed_header(p, segment_first, slot, material, caps, motion,
                                        static_cast<uint32_t>(out.nodes.size()),
                                        static_cast<uint32_t>(out.extras.size())));
    out.nodes.insert(out.nodes.end(), p.nodes.begin(), p.nodes.end());
    out.extras.insert(out.extras.end(), p.extras.begin(), p.extras.end());
}

Status append_wire(const WireNodes& wn, const SplineSettings& spline, uint32_t segment_first, uint32_t slot,
                   uint32_t material, bool caps, const WireMotion& motion, WireUpload& out, uint32_t& segments) {
    thread_local PackedNodes packed;
    if (Status st = pack_nodes(wn, spline, packed); !st) return st;
    append_packed(packed, segment_first, slot, material, caps, motion, out);
    segments = static_cast<uint32_t>(packed.segment_count());
    return Status::success();
}

void append_segments(const Curve& curve, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                     const WireMotion& motion, WireUpload& out) {
    glm::dvec3 lo = curve.segments.front().b0, hi = lo;
    for (const CubicBezier& c : curve.segments) {
        for (const glm::dvec3* p : {&c.b0, &c.b1, &c.b2, &c.b3}) lo = glm::min(lo, *p), hi = glm::max(hi, *p);
    }
    const glm::dvec3 origin = float_point(0.5 * (lo + hi));
    GpuCurveHeader h;
    h.node_first = static_cast<uint32_t>(out.nodes.size());
    h.node_count = static_cast<uint32_t>(curve.closed ? curve.segment_count() : curve.segment_count() + 1);
    h.segment_first = segment_first;
    h.flags = (curve.closed ? kHeaderClosed : 0u) | (caps ? kHeaderCaps : 0u) | kHeaderGivenSegments |
              (material << kHeaderMaterialShift);
    h.slot = slot;
    h.origin_m[0] = static_cast<float>(origin.x), h.origin_m[1] = static_cast<float>(origin.y),
    h.origin_m[2] = static_cast<float>(origin.z);
    h.motion[0] = motion.rotation.x, h.motion[1] = motion.rotation.y, h.motion[2] = motion.rotation.z;
    out.headers.push_back(h);
    const std::size_t n = curve.radius_m.size();
    const auto radius = [&](std::size_t j) { return n == 0 ? kDefaultWireRadius_m : curve.radius_m[j % n]; };
    for (std::size_t k = 0; k < curve.segment_count(); ++k) {
        const CubicBezier& c = curve.segments[k];
        const float stretch = k < curve.stretch.size() ? curve.stretch[k] : 1.0f;
        out.nodes.emplace_back(glm::vec3(c.b0 - origin), radius(k));
        out.nodes.emplace_back(glm::vec3(c.b1 - c.b0), radius(k + 1));
        out.nodes.emplace_back(glm::vec3(c.b2 - c.b1), stretch);
        out.nodes.emplace_back(glm::vec3(c.b3 - c.b2), 0.0f);
    }
}

}  // namespace detail

Status GpuCurvePass::build(std::span<const GpuCurveWire> wires) {
    thread_local detail::WireUpload up;
    up.clear();
    origins_.clear();
    uint32_t segment_first = 0;
    for (std::size_t w = 0; w < wires.size(); ++w) {
        const GpuCurveWire& wire = wires[w];
        const std::string name = "wire " + std::to_string(w) + ": ";
        if (wire.nodes == nullptr) return Status::error(name + "no nodes");
        uint32_t segs = 0;
        if (Status st = detail::append_wire(*wire.nodes, wire.spline, segment_first, static_cast<uint32_t>(w), 0,
                                            true, {wire.motion, wire.fit_motion}, up, segs);
            !st) {
            return Status::error(name + st.message);
        }
        const GpuCurveHeader& h = up.headers.back();
        origins_.emplace_back(h.origin_m[0], h.origin_m[1], h.origin_m[2]);
        segment_first += segs;
    }
    header_data_ = up.headers;
    std::vector<glm::vec4>& node_data = up.nodes;
    std::vector<glm::vec4>& extras = up.extras;
    segment_total_ = segment_first;
    node_bytes_ = node_data.size() * sizeof(glm::vec4);
    header_bytes_ = header_data_.size() * sizeof(GpuCurveHeader);
    extra_bytes_ = extras.size() * sizeof(glm::vec4);
    if (extras.empty()) extras.emplace_back(0.0f);  // a buffer of size 0 cannot be bound
    if (wires.empty()) return Status::success();

    auto headers = engine::gfx::make_buffer(std::span<const GpuCurveHeader>(header_data_), "wire gpu curve headers");
    auto nodes = engine::gfx::make_buffer(std::span<const glm::vec4>(node_data), "wire gpu curve nodes");
    auto segments = engine::gfx::make_buffer({.size_bytes = segment_total_ * 4 * sizeof(glm::vec4),
                                              .dynamic = true, .label = "wire gpu curve segments"});
    auto scratch = engine::gfx::make_buffer({.size_bytes = node_data.size() * 2 * sizeof(glm::dvec4),
                                             .label = "wire gpu curve scratch"});
    auto extra_buffer = engine::gfx::make_buffer(std::span<const glm::vec4>(extras), "wire gpu curve extras");
    for (const auto* b : {&headers, &nodes, &segments, &scratch, &extra_buffer}) {
        if (!*b) return Status::error(b->error().message);
    }
    headers_ = std::move(*headers), nodes_ = std::move(*nodes), segments_ = std::move(*segments);
    scratch_ = std::move(*scratch), extras_ = std::move(*extra_buffer);
    if (motion_ref_wires_ != wires.size() || !motion_refs_) {  // the wires' references, kept for the next build
        auto refs = engine::gfx::make_buffer({.size_bytes = wires.size() * detail::kMotionRefBytes,
                                              .label = "wire gpu curve motion references"});
        if (!refs) return Status::error(refs.error().message);
        motion_refs_ = std::move(*refs);
        glClearNamedBufferData(motion_refs_.id(), GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
        motion_ref_wires_ = wires.size();
    }
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveHeaders, headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveNodes, nodes_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveSegments, segments_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveScratch, scratch_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveExtras, extras_.id());
    // Slot w is wire w: the headers go back onto themselves (with the motion the GPU fitted), the references stay.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveSlotHeaders, headers_.id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveMotionRefs, motion_refs_.id());
    // No slot list here (u_list off); something is bound all the same, as some drivers check every block's binding.
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, detail::kCurveSlotList, scratch_.id());
    program_.use();
    glUniform1ui(program_.uniform_location("u_wires"), static_cast<GLuint>(wires.size()));
    glUniform1i(program_.uniform_location("u_list"), 0);
    glUniform1i(program_.uniform_location("u_persist"), 1);
    glUniform1i(program_.uniform_location("u_motion"), 1);
    glDispatchCompute(static_cast<GLuint>((wires.size() + 63) / 64), 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glUseProgram(0);
    return Status::success();
}

void GpuCurvePass::read_segments(std::vector<GpuCurveResult>& out) const {
    out.clear();
    if (header_data_.empty()) return;
    std::vector<glm::vec4> data(segment_total_ * 4);
    glGetNamedBufferSubData(segments_.id(), 0, static_cast<GLsizeiptr>(data.size() * sizeof(glm::vec4)), data.data());
    out.resize(header_data_.size());
    for (std::size_t w = 0; w < header_data_.size(); ++w) {
        const GpuCurveHeader& h = header_data_[w];
        GpuCurveResult& r = out[w];
        r.origin_m = origins_[w];
        r.closed = (h.flags & detail::kHeaderClosed) != 0;
        const std::size_t segs = r.closed ? h.node_count : h.node_count - 1;
        r.segments.resize(segs);
        for (std::size_t k = 0; k < segs; ++k) {
            const glm::vec4* s = &data[4 * (h.segment_first + k)];
            const glm::dvec3 b0(s[0]), b1 = b0 + glm::dvec3(s[1]), b2 = b1 + glm::dvec3(s[2]);
            r.segments[k] = CubicBezier{b0, b1, b2, b2 + glm::dvec3(s[3])};
        }
    }
}

}  // namespace wire::render
