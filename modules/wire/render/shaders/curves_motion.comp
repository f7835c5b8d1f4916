// The wire's motion since its last upload (kHeaderFitMotion), as wire/motion.cpp fits it on the CPU: the reference
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
MotionRef make_ref(GpuCurveHeader h) {
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
    r.origin = vec4(h.origin_m[0], h.origin_m[1], h.origin_m[2], float(det));
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
