// The tangent systems' tridiagonal solvers (see tridiagonal.hpp); every one gives each row thomas_kernel's
// operations, so their results are the same bits.
#include "spline/tridiagonal.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES
#include "simd/transpose.hpp"

#include <cassert>
#include <vector>

namespace wire::curve_stage {

namespace {

template <int C>
void thomas(const double* a, const double* b, const double* c, std::size_t n, double* const* r) {
    thread_local std::vector<double> fv;  // top half: c'/pivot; bottom half: a'/pivot (reused, no allocation)
    fv.resize(n);
    thomas_kernel<C>(a, b, c, n, fv.data(), r[0], C == 3 ? r[1] : nullptr, C == 3 ? r[2] : nullptr);
}

}  // namespace

void thomas_cyclic(const double* a, const double* b, const double* c, std::size_t n, double* const* r) {
    const double alpha = c[n - 1], beta = a[0], gamma = -b[0];
    thread_local std::vector<double> bb;
    bb.assign(b, b + n);
    bb[0] = b[0] - gamma;
    bb[n - 1] = b[n - 1] - alpha * beta / gamma;
    thomas<3>(a, bb.data(), c, n, r);
    thread_local std::vector<double> z;
    z.assign(n, 0.0);
    z[0] = gamma, z[n - 1] = alpha;
    double* const zr[1] = {z.data()};
    thomas<1>(a, bb.data(), c, n, zr);
    const double den = 1.0 + z[0] + beta * z[n - 1] / gamma;
    for (int q = 0; q < 3; ++q) {
        const double fact = (r[q][0] + beta * r[q][n - 1] / gamma) / den;
        for (std::size_t i = 0; i < n; ++i) r[q][i] = r[q][i] - fact * z[i];
    }
}

void thomas_pair(TangentSolve& s0, TangentSolve& s1) {
    using v2 = double __attribute__((vector_size(16)));
    const std::size_t n = s0.m, p = n / 2;  // the meeting row, as thomas_kernel's
    assert(s1.m == n && n >= 4);
    const double *const a0 = s0.a, *const a1 = s1.a, *const b0 = s0.b, *const b1 = s1.b;
    const double *const c0 = s0.c, *const c1 = s1.c;
    double *const f0 = s0.f, *const f1 = s1.f;
    double* const r0[3] = {s0.r(0), s0.r(1), s0.r(2)};
    double* const r1[3] = {s1.r(0), s1.r(1), s1.r(2)};
    const auto a = [&](std::size_t i) { return v2{a0[i], a1[i]}; };
    const auto b = [&](std::size_t i) { return v2{b0[i], b1[i]}; };
    const auto c = [&](std::size_t i) { return v2{c0[i], c1[i]}; };
    const auto r = [&](int q, std::size_t i) { return v2{r0[q][i], r1[q][i]}; };
    const auto put_f = [&](std::size_t i, v2 v) { f0[i] = v[0], f1[i] = v[1]; };
    const auto put_r = [&](int q, std::size_t i, v2 v) { r0[q][i] = v[0], r1[q][i] = v[1]; };
    const v2 one = {1.0, 1.0};
    v2 t[3], u[3];  // the top and bottom chains' last rows
    v2 inv = one / b(0);
    v2 ft = c(0) * inv;
    put_f(0, ft);
    for (int q = 0; q < 3; ++q) t[q] = r(q, 0) * inv, put_r(q, 0, t[q]);
    inv = one / b(n - 1);
    v2 fb = a(n - 1) * inv;
    put_f(n - 1, fb);
    for (int q = 0; q < 3; ++q) u[q] = r(q, n - 1) * inv, put_r(q, n - 1, u[q]);
    const auto top = [&](std::size_t i) {
        const v2 ai = a(i), it = one / (b(i) - ai * ft);
        ft = c(i) * it;
        put_f(i, ft);
        for (int q = 0; q < 3; ++q) t[q] = (r(q, i) - ai * t[q]) * it, put_r(q, i, t[q]);
    };
    const auto bottom = [&](std::size_t j) {
        const v2 cj = c(j), ib = one / (b(j) - cj * fb);
        fb = a(j) * ib;
        put_f(j, fb);
        for (int q = 0; q < 3; ++q) u[q] = (r(q, j) - cj * u[q]) * ib, put_r(q, j, u[q]);
    };
    const auto back = [&](std::size_t i, v2* v) {
        const v2 fi = {f0[i], f1[i]};
        for (int q = 0; q < 3; ++q) v[q] = r(q, i) - fi * v[q], put_r(q, i, v[q]);
    };
    std::size_t i = 1, j = n - 2;
    for (; i < p && j > p; ++i, --j) top(i), bottom(j);
    for (; i < p; ++i) top(i);
    for (; j > p; --j) bottom(j);
    // Row p, as thomas_kernel's.
    inv = one / (b(p) - a(p) * ft - c(p) * fb);
    for (int q = 0; q < 3; ++q) t[q] = (r(q, p) - a(p) * t[q] - c(p) * u[q]) * inv, put_r(q, p, t[q]), u[q] = t[q];
    for (i = p, j = p; i > 0 && j + 1 < n;) {
        --i, ++j;
        back(i, t), back(j, u);
    }
    while (i > 0) --i, back(i, t);
    while (j + 1 < n) ++j, back(j, u);
}

#if defined(__GNUC__)
namespace {

using simd::v4d;
using simd::v4p;

// dst[4i + s] = src_s[i], i < n (4x4 transposes of blocks of four rows).
WIRE_VECTOR_CLONES
void to_quad(std::size_t n, const double* s0, const double* s1, const double* s2, const double* s3, double* dst) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const v4d r[4] = {*reinterpret_cast<const v4p*>(s0 + i), *reinterpret_cast<const v4p*>(s1 + i),
                          *reinterpret_cast<const v4p*>(s2 + i), *reinterpret_cast<const v4p*>(s3 + i)};
        v4d c[4];
        simd::transpose4x4(r, c);
        v4p* const o = reinterpret_cast<v4p*>(dst + 4 * i);
        o[0] = c[0], o[1] = c[1], o[2] = c[2], o[3] = c[3];
    }
    for (; i < n; ++i) dst[4 * i] = s0[i], dst[4 * i + 1] = s1[i], dst[4 * i + 2] = s2[i], dst[4 * i + 3] = s3[i];
}

// to_quad's inverse: d_s[i] = src[4i + s].
WIRE_VECTOR_CLONES
void from_quad(std::size_t n, const double* src, double* d0, double* d1, double* d2, double* d3) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        const v4p* const q = reinterpret_cast<const v4p*>(src + 4 * i);
        const v4d r[4] = {q[0], q[1], q[2], q[3]};
        v4d c[4];
        simd::transpose4x4(r, c);
        *reinterpret_cast<v4p*>(d0 + i) = c[0];
        *reinterpret_cast<v4p*>(d1 + i) = c[1];
        *reinterpret_cast<v4p*>(d2 + i) = c[2];
        *reinterpret_cast<v4p*>(d3 + i) = c[3];
    }
    for (; i < n; ++i) d0[i] = src[4 * i], d1[i] = src[4 * i + 1], d2[i] = src[4 * i + 2], d3[i] = src[4 * i + 3];
}

// thomas_kernel<3> on four interleaved systems of n >= 4 rows (a, b, c, the right-hand sides r0..r2 solved in
// place, f the factors): thomas_pair's loop with four lanes.
WIRE_VECTOR_CLONES
void thomas_quad_kernel(std::size_t n, const double* __restrict a_, const double* __restrict b_,
                        const double* __restrict c_, double* __restrict f_, double* __restrict r0_,
                        double* __restrict r1_, double* __restrict r2_) {
    const v4p* const a = reinterpret_cast<const v4p*>(a_);
    const v4p* const b = reinterpret_cast<const v4p*>(b_);
    const v4p* const c = reinterpret_cast<const v4p*>(c_);
    v4p* const f = reinterpret_cast<v4p*>(f_);
    v4p* const r[3] = {reinterpret_cast<v4p*>(r0_), reinterpret_cast<v4p*>(r1_), reinterpret_cast<v4p*>(r2_)};
    const std::size_t p = n / 2;  // the meeting row, as thomas_kernel's
    const v4d one = {1.0, 1.0, 1.0, 1.0};
    v4d t[3], u[3];  // the top and bottom chains' last rows
    v4d inv = one / b[0];
    v4d ft = c[0] * inv;
    f[0] = ft;
    for (int q = 0; q < 3; ++q) t[q] = r[q][0] * inv, r[q][0] = t[q];
    inv = one / b[n - 1];
    v4d fb = a[n - 1] * inv;
    f[n - 1] = fb;
    for (int q = 0; q < 3; ++q) u[q] = r[q][n - 1] * inv, r[q][n - 1] = u[q];
    std::size_t i = 1, j = n - 2;
    // Row k of one chain (no lambdas: a target clone would not inline them): the top chain's row i is
    // WIRE_ROW(i, a, c, ft, t), the bottom chain's row j WIRE_ROW(j, c, a, fb, u) (its sub- and super-diagonals
    // swap roles). fv and v are the chain's factor and right-hand sides, carried from row to row.
#define WIRE_ROW(k, sub, super, fv, v)                                                                     \
    {                                                                                                      \
        const v4d sk = sub[k], ik = one / (b[k] - sk * fv);                                                \
        fv = super[k] * ik;                                                                                \
        f[k] = fv;                                                                                         \
        for (int q = 0; q < 3; ++q) v[q] = (r[q][k] - sk * v[q]) * ik, r[q][k] = v[q];                     \
    }
#define WIRE_BACK(i, v)                                                                                    \
    {                                                                                                      \
        const v4d fi = f[i];                                                                               \
        for (int q = 0; q < 3; ++q) v[q] = r[q][i] - fi * v[q], r[q][i] = v[q];                            \
    }
    for (; i < p && j > p; ++i, --j) {
        WIRE_ROW(i, a, c, ft, t)
        WIRE_ROW(j, c, a, fb, u)
    }
    for (; i < p; ++i) WIRE_ROW(i, a, c, ft, t)
    for (; j > p; --j) WIRE_ROW(j, c, a, fb, u)
    // Row p, as thomas_kernel's.
    inv = one / (b[p] - a[p] * ft - c[p] * fb);
    for (int q = 0; q < 3; ++q) t[q] = (r[q][p] - a[p] * t[q] - c[p] * u[q]) * inv, r[q][p] = t[q], u[q] = t[q];
    for (i = p, j = p; i > 0 && j + 1 < n;) {
        --i, ++j;
        WIRE_BACK(i, t)
        WIRE_BACK(j, u)
    }
    while (i > 0) {
        --i;
        WIRE_BACK(i, t)
    }
    while (j + 1 < n) {
        ++j;
        WIRE_BACK(j, u)
    }
#undef WIRE_ROW
#undef WIRE_BACK
}

}  // namespace

void thomas_quad(TangentSolve* const s[4]) {
    const std::size_t n = s[0]->m;
    assert(s[1]->m == n && s[2]->m == n && s[3]->m == n && n >= 4);
    thread_local std::vector<double> buf;  // grows only: no allocation per call once large enough
    if (buf.size() < 7 * 4 * n) buf.resize(7 * 4 * n);
    double* const a = buf.data();
    double *const b = a + 4 * n, *const c = b + 4 * n, *const f = c + 4 * n, *const r = f + 4 * n;
    to_quad(n, s[0]->a, s[1]->a, s[2]->a, s[3]->a, a);
    to_quad(n, s[0]->b, s[1]->b, s[2]->b, s[3]->b, b);
    to_quad(n, s[0]->c, s[1]->c, s[2]->c, s[3]->c, c);
    for (int q = 0; q < 3; ++q) to_quad(n, s[0]->r(q), s[1]->r(q), s[2]->r(q), s[3]->r(q), r + 4 * n * q);
    thomas_quad_kernel(n, a, b, c, f, r, r + 4 * n, r + 8 * n);
    for (int q = 0; q < 3; ++q) from_quad(n, r + 4 * n * q, s[0]->r(q), s[1]->r(q), s[2]->r(q), s[3]->r(q));
}
#endif

}  // namespace wire::curve_stage
