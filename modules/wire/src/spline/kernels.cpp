// The curve stage's hand-written vector kernels (see kernels.hpp).
#include "spline/kernels.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES, WIRE_SELECT_KERNEL

#include <algorithm>

#if defined(WIRE_HAS_VECTOR_CLONES)
#include <immintrin.h>  // node_segments_avx512
#endif

namespace wire::curve_stage {

// Kernels: the vectorized loops, one function each, so that `__restrict` on their parameters tells the compiler
// the arrays do not overlap (it does not trust that of local pointers into one buffer). Kernels with selects are
// compiled without trapping math: GCC turns their `?:` into vector blends only then. That changes no value (every
// operation is still performed and rounded as written; NaN comparisons keep their meaning), only whether an
// operation whose result is discarded may raise a floating-point exception flag, which nothing here reads
// (WIRE_SELECT_KERNEL, simd/dispatch.hpp).
// Each kernel is also compiled for AVX-512 and AVX2 machines, picked at load time (WIRE_VECTOR_CLONES: 8 and 4
// lanes where baseline x86-64 has 2; 1.44 -> 1.12 ms for the stage on 1,000 moving 64-node wires); every clone's
// results are bit-identical to the baseline's (see the macro).

// Interior rows of the tangent system (node j: incoming chord at index j, outgoing at j + 1; diagonal 2 + w_j).
WIRE_VECTOR_CLONES
void rows_kernel(std::size_t rows, const double* __restrict w, const double* __restrict ex, const double* __restrict ey,
                 const double* __restrict ez, const double* __restrict len, double* __restrict a, double* __restrict b,
                 double* __restrict c, double* __restrict rx, double* __restrict ry, double* __restrict rz) {
    for (std::size_t j = 0; j < rows; ++j) {
        const double hin = len[j], hout = len[j + 1], sum = hin + hout;
        const double aj = hout / sum, cj = hin / sum;
        a[j] = aj, c[j] = cj, b[j] = 2.0 + w[j];
        rx[j] = 3.0 * (aj * ex[j] + cj * ex[j + 1]);
        ry[j] = 3.0 * (aj * ey[j] + cj * ey[j + 1]);
        rz[j] = 3.0 * (aj * ez[j] + cj * ez[j + 1]);
    }
}

// Segment tangents from node tangents per unit chord (D: node k's at k, k + 1's at k + 1) and chord lengths.
WIRE_VECTOR_CLONES
void tangents_kernel(std::size_t segs, const double* __restrict D, const double* __restrict len, double* __restrict t0,
                     double* __restrict t1) {
    for (std::size_t k = 0; k < segs; ++k) {
        t0[k] = D[k] * len[k];
        t1[k] = D[k + 1] * len[k];
    }
}

namespace {

// Writes one Bezier record at o (start point a, inner control points c0..c5, end point b) and returns whether
// every inner control point is within +-limit (false for NaN), tested on the values in the registers (a pass over
// the records just written would wait for the stores). Always inlined: GCC inlines nothing else into a kernel
// compiled with its own options (WIRE_SELECT_KERNEL); __builtin_fabs for the same reason (not std::abs).
[[gnu::always_inline]] inline bool within6(double c0, double c1, double c2, double c3, double c4, double c5,
                                           double limit) {
    return (__builtin_fabs(c0) <= limit) & (__builtin_fabs(c1) <= limit) & (__builtin_fabs(c2) <= limit) &
           (__builtin_fabs(c3) <= limit) & (__builtin_fabs(c4) <= limit) & (__builtin_fabs(c5) <= limit);
}
[[gnu::always_inline]] inline bool write_record(double* __restrict o, double ax, double ay, double az, double c0,
                                                double c1, double c2, double c3, double c4, double c5, double bx,
                                                double by, double bz, double limit) {
    o[0] = ax, o[1] = ay, o[2] = az, o[3] = c0, o[4] = c1, o[5] = c2;
    o[6] = c3, o[7] = c4, o[8] = c5, o[9] = bx, o[10] = by, o[11] = bz;
    return within6(c0, c1, c2, c3, c4, c5, limit);
}

}  // namespace

// Bezier segments k = 0 .. count-1 (12 doubles each, out at 12k) from node coordinates p0 (3 per node, segment
// k's start at 3k), p1 (its end at 3k) and the segment tangents: inner control points B1 = P0 + t0/3 and
// B2 = P1 - t1/3, written straight into the records (one pass: the control points are not stored apart first).
// Returns whether every inner control point is within +-limit (write_record's test).
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL
bool segments_kernel(std::size_t count, const double* __restrict p0, const double* __restrict p1,
                     const double* __restrict t0x, const double* __restrict t0y, const double* __restrict t0z,
                     const double* __restrict t1x, const double* __restrict t1y, const double* __restrict t1z,
                     double* __restrict out, double limit) {
    double ok = 1.0;  // 0 once a value is out of range (a select, which vectorizes where a bool reduction does not)
    for (std::size_t k = 0; k < count; ++k) {
        double* o = out + 12 * k;
        const double ax = p0[3 * k], ay = p0[3 * k + 1], az = p0[3 * k + 2];
        const double bx = p1[3 * k], by = p1[3 * k + 1], bz = p1[3 * k + 2];
        const double c0 = ax + t0x[k] * (1.0 / 3.0), c1 = ay + t0y[k] * (1.0 / 3.0), c2 = az + t0z[k] * (1.0 / 3.0);
        const double c3 = bx - t1x[k] * (1.0 / 3.0), c4 = by - t1y[k] * (1.0 / 3.0), c5 = bz - t1z[k] * (1.0 / 3.0);
        ok = write_record(o, ax, ay, az, c0, c1, c2, c3, c4, c5, bx, by, bz, limit) ? ok : 0.0;
    }
    return ok == 1.0;
}

namespace {

// The same records from node tangents per unit chord (D: segment k's start node at k, its end node at k + 1) and
// the chord lengths: t0 = D[k] len[k], t1 = D[k + 1] len[k] (tangents_kernel's values) taken straight into the
// control points, with no pass through segment tangents (the spline kinds whose tangents are a node's).
// Returns whether every offset t/3 of a control point from its end point is within +-offset_limit (false for NaN),
// a sufficient test for the control points' range that the caller derives from the positions' (checked on entry).
WIRE_VECTOR_CLONES WIRE_SELECT_KERNEL
bool node_segments_kernel(std::size_t count, const double* __restrict p0, const double* __restrict p1,
                          const double* __restrict Dx, const double* __restrict Dy, const double* __restrict Dz,
                          const double* __restrict len, double* __restrict out, double offset_limit) {
    double ok = 1.0;
    for (std::size_t k = 0; k < count; ++k) {
        double* o = out + 12 * k;
        const double ax = p0[3 * k], ay = p0[3 * k + 1], az = p0[3 * k + 2];
        const double bx = p1[3 * k], by = p1[3 * k + 1], bz = p1[3 * k + 2];
        const double h = len[k];
        const double u0 = (Dx[k] * h) * (1.0 / 3.0), u1 = (Dy[k] * h) * (1.0 / 3.0), u2 = (Dz[k] * h) * (1.0 / 3.0);
        const double u3 = (Dx[k + 1] * h) * (1.0 / 3.0), u4 = (Dy[k + 1] * h) * (1.0 / 3.0);
        const double u5 = (Dz[k + 1] * h) * (1.0 / 3.0);
        o[0] = ax, o[1] = ay, o[2] = az, o[3] = ax + u0, o[4] = ay + u1, o[5] = az + u2;
        o[6] = bx - u3, o[7] = by - u4, o[8] = bz - u5, o[9] = bx, o[10] = by, o[11] = bz;
        ok = within6(u0, u1, u2, u3, u4, u5, offset_limit) ? ok : 0.0;
    }
    return ok == 1.0;
}

#if defined(WIRE_HAS_VECTOR_CLONES)
// node_segments_kernel by hand for AVX-512 machines (count >= 8). The compiler's version of that loop scatters
// each 96-byte record with ~12 partial stores and as many shuffles. Here eight segments' offsets u = (D h) / 3
// are computed as the loop computes them and range-tested there, transposed once (8x8: one segment's per row),
// and each record is two stores, [a, a + u0, b.x - u1.x, b.y - u1.y] and [b.z - u1.z, b], by masked additions
// and subtractions of the row: the same operations on the same values as the loop (no fused multiply-add), so
// the records and the test are the loop's, bit for bit. The last block of eight overlaps the one before when
// count is not a multiple of 8 (those records are written twice, with the same values).
#pragma GCC diagnostic push
// GCC 12 warns about the intrinsics' own _mm512_undefined_pd() pass-through operands (a known false positive).
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
__attribute__((target("avx512f"))) bool node_segments_avx512(std::size_t count, const double* __restrict p0,
                                                             const double* __restrict p1, const double* __restrict Dx,
                                                             const double* __restrict Dy, const double* __restrict Dz,
                                                             const double* __restrict len, double* __restrict out,
                                                             double offset_limit) {
    const __m512d third = _mm512_set1_pd(1.0 / 3.0), lim = _mm512_set1_pd(offset_limit), zero = _mm512_setzero_pd();
    const __m512i low_index = _mm512_setr_epi64(0, 1, 2, 0, 1, 2, 8, 9);   // [a a b.x b.y] from a | b
    const __m512i high_index = _mm512_setr_epi64(2, 0, 1, 2, 2, 2, 2, 2);  // [b.z b ...] from b
    __mmask16 bad = 0;  // lanes of an offset not within +-offset_limit (or NaN)
    for (std::size_t k0 = 0;; k0 += 8) {
        const std::size_t k = std::min(k0, count - 8);
        const __m512d h = _mm512_loadu_pd(len + k);
#define WIRE_OFFSET(D) _mm512_mul_pd(_mm512_mul_pd(_mm512_loadu_pd(D), h), third)  // (D h) / 3, as the loop
        // Row s of the transpose, segment k + s's offsets: [u1.z, 0, 0, u0.x, u0.y, u0.z, u1.x, u1.y], each in
        // the lane of the record's first 8 doubles (u1.z: of its last 4) that it is added to or taken from.
        const __m512d v[8] = {WIRE_OFFSET(Dz + k + 1), zero, zero, WIRE_OFFSET(Dx + k), WIRE_OFFSET(Dy + k),
                              WIRE_OFFSET(Dz + k), WIRE_OFFSET(Dx + k + 1), WIRE_OFFSET(Dy + k + 1)};
#undef WIRE_OFFSET
        for (int q : {0, 3, 4, 5, 6, 7}) {
            bad = _mm512_kor(bad, _mm512_cmp_pd_mask(_mm512_abs_pd(v[q]), lim, _CMP_NLE_UQ));
        }
        __m512d t[8], w[8], row[8];
        for (int q = 0; q < 8; q += 2) t[q] = _mm512_unpacklo_pd(v[q], v[q + 1]), t[q + 1] = _mm512_unpackhi_pd(v[q], v[q + 1]);
        for (int q = 0; q < 8; q += 4) {
            w[q] = _mm512_shuffle_f64x2(t[q], t[q + 2], 0x88), w[q + 1] = _mm512_shuffle_f64x2(t[q + 1], t[q + 3], 0x88);
            w[q + 2] = _mm512_shuffle_f64x2(t[q], t[q + 2], 0xDD), w[q + 3] = _mm512_shuffle_f64x2(t[q + 1], t[q + 3], 0xDD);
        }
        for (int q = 0; q < 4; ++q) row[q] = _mm512_shuffle_f64x2(w[q], w[q + 4], 0x88), row[q + 4] = _mm512_shuffle_f64x2(w[q], w[q + 4], 0xDD);
        for (std::size_t s = 0; s < 8; ++s) {
            const std::size_t j = k + s;
            const __m512d a = _mm512_maskz_loadu_pd(0x07, p0 + 3 * j), b = _mm512_maskz_loadu_pd(0x07, p1 + 3 * j);
            __m512d lo = _mm512_permutex2var_pd(a, low_index, b);
            lo = _mm512_mask_add_pd(lo, 0x38, lo, row[s]);
            lo = _mm512_mask_sub_pd(lo, 0xC0, lo, row[s]);
            __m512d hi = _mm512_permutexvar_pd(high_index, b);
            hi = _mm512_mask_sub_pd(hi, 0x01, hi, row[s]);
            _mm512_storeu_pd(out + 12 * j, lo);
            _mm256_storeu_pd(out + 12 * j + 8, _mm512_castpd512_pd256(hi));
        }
        if (k0 + 8 >= count) break;
    }
    return bad == 0;
}
#pragma GCC diagnostic pop
#endif

#if defined(WIRE_HAS_VECTOR_CLONES)
// Whether the CPU (and the OS) run AVX-512 code: decided once, when the library is loaded (not on every call).
const bool kHasAvx512 = simd::cpu_has_avx512();
#endif

}  // namespace

// node_segments_kernel's records and test, by the AVX-512 version where the CPU has it (`widest`; false: the loop).
bool node_segments(std::size_t count, const double* p0, const double* p1, const double* Dx, const double* Dy,
                   const double* Dz, const double* len, double* out, double offset_limit, bool widest) {
#if defined(WIRE_HAS_VECTOR_CLONES)
    if (widest && kHasAvx512 && count >= 8) return node_segments_avx512(count, p0, p1, Dx, Dy, Dz, len, out, offset_limit);
#endif
    (void)widest;
    return node_segments_kernel(count, p0, p1, Dx, Dy, Dz, len, out, offset_limit);
}

}  // namespace wire::curve_stage
