// Internal: lane types for kernels written once over a lane width: L1 (one double), L2 (SSE2), L4 (AVX2) and L8
// (AVX-512F), each lane doing exactly the scalar arithmetic. L4 and L8 are compiled for their instruction set
// (`#pragma GCC target`): use them only in code compiled for the same one.
#pragma once

#include "simd/dispatch.hpp"  // WIRE_LOD_AVX2

#include <cmath>
#include <cstddef>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(WIRE_LOD_AVX2)
#include <immintrin.h>
#endif

namespace wire::simd {

// std::min, std::max by value, as they compare (glm::min and glm::max too).
inline double min_of(double x, double y) { return y < x ? y : x; }
inline double max_of(double x, double y) { return x < y ? y : x; }

// Lanes for the span hierarchy's kernels (lod/span_kernels.inl): the kernels are written once over a lane type,
// L1 (one double: the scalar code), L2 (two doubles in an SSE2 register) or L4 (four in an AVX register, where
// the CPU has AVX2), so every lane does exactly the scalar arithmetic (each operation the IEEE one, correctly
// rounded, no fused multiply-add): results are bit-identical whichever runs. min_of / max_of / select keep the
// scalar comparisons' operand order (minpd(a, b) is a < b ? a : b), so NaN and signed zeros come out as in the
// scalar code. Besides arithmetic a lane type loads and stores `width` consecutive doubles, splits 2 width
// consecutive ones into the even and the odd ones, and reads `width` consecutive segments' control points.
struct L1 {
    static constexpr std::size_t width = 1;
    double v;
    static L1 splat(double x) { return {x}; }
    static L1 load(const double* p) { return {*p}; }
    static L1 evens(const double* p) { return {p[0]}; }
    static L1 odds(const double* p) { return {p[1]}; }
    void store(double* p) const { *p = v; }
    // x, y, z of the four control points of one segment per lane (p: lane 0's segment, 12 doubles a segment).
    static void points(const double* p, L1 (&x)[4], L1 (&y)[4], L1 (&z)[4]) {
        for (int k = 0; k < 4; ++k) x[k] = {p[3 * k]}, y[k] = {p[3 * k + 1]}, z[k] = {p[3 * k + 2]};
    }
};
struct M1 {
    bool v;
    [[nodiscard]] unsigned bits() const { return v ? 1u : 0u; }  // bit k: lane k
};
inline M1 operator&(M1 a, M1 b) { return {a.v && b.v}; }
inline M1 operator|(M1 a, M1 b) { return {a.v || b.v}; }
inline L1 neg_of(L1 a) { return {-a.v}; }
inline L1 operator+(L1 a, L1 b) { return {a.v + b.v}; }
inline L1 operator-(L1 a, L1 b) { return {a.v - b.v}; }
inline L1 operator*(L1 a, L1 b) { return {a.v * b.v}; }
inline L1 operator/(L1 a, L1 b) { return {a.v / b.v}; }
inline M1 operator<(L1 a, L1 b) { return {a.v < b.v}; }
inline M1 operator<=(L1 a, L1 b) { return {a.v <= b.v}; }
inline L1 sqrt_of(L1 a) { return {std::sqrt(a.v)}; }
inline L1 abs_of(L1 a) { return {std::abs(a.v)}; }
inline L1 min_of(L1 x, L1 y) { return {min_of(x.v, y.v)}; }
inline L1 max_of(L1 x, L1 y) { return {max_of(x.v, y.v)}; }
inline L1 select(M1 m, L1 a, L1 b) { return {m.v ? a.v : b.v}; }
inline L1 ceil_of(L1 a) { return {std::ceil(a.v)}; }

#if defined(__SSE2__)
struct L2 {
    static constexpr std::size_t width = 2;
    __m128d v;
    static L2 splat(double x) { return {_mm_set1_pd(x)}; }
    static L2 load(const double* p) { return {_mm_loadu_pd(p)}; }
    static L2 evens(const double* p) { return {_mm_unpacklo_pd(_mm_loadu_pd(p), _mm_loadu_pd(p + 2))}; }
    static L2 odds(const double* p) { return {_mm_unpackhi_pd(_mm_loadu_pd(p), _mm_loadu_pd(p + 2))}; }
    void store(double* p) const { _mm_storeu_pd(p, v); }
    static void points(const double* p, L2 (&x)[4], L2 (&y)[4], L2 (&z)[4]) {
        L2 c[12];
        for (int k = 0; k < 12; k += 2) {
            const __m128d a = _mm_loadu_pd(p + k), b = _mm_loadu_pd(p + 12 + k);
            c[k] = {_mm_unpacklo_pd(a, b)};
            c[k + 1] = {_mm_unpackhi_pd(a, b)};
        }
        for (int k = 0; k < 4; ++k) x[k] = c[3 * k], y[k] = c[3 * k + 1], z[k] = c[3 * k + 2];
    }
};
struct M2 {
    __m128d v;
    [[nodiscard]] unsigned bits() const { return static_cast<unsigned>(_mm_movemask_pd(v)); }
};
inline M2 operator&(M2 a, M2 b) { return {_mm_and_pd(a.v, b.v)}; }
inline M2 operator|(M2 a, M2 b) { return {_mm_or_pd(a.v, b.v)}; }
inline L2 neg_of(L2 a) { return {_mm_xor_pd(_mm_set1_pd(-0.0), a.v)}; }
inline L2 operator+(L2 a, L2 b) { return {_mm_add_pd(a.v, b.v)}; }
inline L2 operator-(L2 a, L2 b) { return {_mm_sub_pd(a.v, b.v)}; }
inline L2 operator*(L2 a, L2 b) { return {_mm_mul_pd(a.v, b.v)}; }
inline L2 operator/(L2 a, L2 b) { return {_mm_div_pd(a.v, b.v)}; }
inline M2 operator<(L2 a, L2 b) { return {_mm_cmplt_pd(a.v, b.v)}; }
inline M2 operator<=(L2 a, L2 b) { return {_mm_cmple_pd(a.v, b.v)}; }
inline L2 sqrt_of(L2 a) { return {_mm_sqrt_pd(a.v)}; }
inline L2 abs_of(L2 a) { return {_mm_andnot_pd(_mm_set1_pd(-0.0), a.v)}; }
inline L2 min_of(L2 x, L2 y) { return {_mm_min_pd(y.v, x.v)}; }  // y < x ? y : x
inline L2 max_of(L2 x, L2 y) { return {_mm_max_pd(y.v, x.v)}; }  // y > x ? y : x, i.e. x < y ? y : x
inline L2 select(M2 m, L2 a, L2 b) { return {_mm_or_pd(_mm_and_pd(m.v, a.v), _mm_andnot_pd(m.v, b.v))}; }
// std::ceil for x >= 0 (and NaN), without SSE4.1's rounding: below 2^52, (x + 2^52) - 2^52 is x rounded to an
// integer (both operations exact: the sum's spacing is 1), raised by 1 where that fell below x; from 2^52 on
// (and for +inf) x is an integer already, and a NaN stays NaN (the last select).
inline L2 ceil_of(L2 x) {
    const L2 big = L2::splat(0x1p52);
    const L2 t = (x + big) - big;
    return select(x < big, select(t < x, t + L2::splat(1.0), t), x);
}
#endif

#if defined(WIRE_LOD_AVX2)
// The same kernels four lanes wide, compiled for AVX2 (no FMA: the arithmetic stays the scalar code's) and chosen
// at run time where the CPU has it.
#pragma GCC push_options
#pragma GCC target("avx2")
struct L4 {
    static constexpr std::size_t width = 4;
    __m256d v;
    static L4 splat(double x) { return {_mm256_set1_pd(x)}; }
    static L4 load(const double* p) { return {_mm256_loadu_pd(p)}; }
    // unpacklo of p0..3 and p4..7 is p0 p4 p2 p6; lanes (0, 2, 1, 3) of it are p0 p2 p4 p6.
    static L4 evens(const double* p) {
        return {_mm256_permute4x64_pd(_mm256_unpacklo_pd(_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)), 0xD8)};
    }
    static L4 odds(const double* p) {
        return {_mm256_permute4x64_pd(_mm256_unpackhi_pd(_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)), 0xD8)};
    }
    void store(double* p) const { _mm256_storeu_pd(p, v); }
    // Three 4 x 4 transposes: rows are the lanes' segments, columns 4 consecutive doubles of them.
    static void points(const double* p, L4 (&x)[4], L4 (&y)[4], L4 (&z)[4]) {
        L4 c[12];
        for (int k = 0; k < 12; k += 4) {
            const __m256d r0 = _mm256_loadu_pd(p + k), r1 = _mm256_loadu_pd(p + 12 + k);
            const __m256d r2 = _mm256_loadu_pd(p + 24 + k), r3 = _mm256_loadu_pd(p + 36 + k);
            const __m256d t0 = _mm256_unpacklo_pd(r0, r1), t1 = _mm256_unpackhi_pd(r0, r1);
            const __m256d t2 = _mm256_unpacklo_pd(r2, r3), t3 = _mm256_unpackhi_pd(r2, r3);
            c[k] = {_mm256_permute2f128_pd(t0, t2, 0x20)};
            c[k + 1] = {_mm256_permute2f128_pd(t1, t3, 0x20)};
            c[k + 2] = {_mm256_permute2f128_pd(t0, t2, 0x31)};
            c[k + 3] = {_mm256_permute2f128_pd(t1, t3, 0x31)};
        }
        for (int k = 0; k < 4; ++k) x[k] = c[3 * k], y[k] = c[3 * k + 1], z[k] = c[3 * k + 2];
    }
};
struct M4 {
    __m256d v;
    [[nodiscard]] unsigned bits() const { return static_cast<unsigned>(_mm256_movemask_pd(v)); }
};
inline M4 operator&(M4 a, M4 b) { return {_mm256_and_pd(a.v, b.v)}; }
inline M4 operator|(M4 a, M4 b) { return {_mm256_or_pd(a.v, b.v)}; }
inline L4 neg_of(L4 a) { return {_mm256_xor_pd(_mm256_set1_pd(-0.0), a.v)}; }
inline L4 operator+(L4 a, L4 b) { return {_mm256_add_pd(a.v, b.v)}; }
inline L4 operator-(L4 a, L4 b) { return {_mm256_sub_pd(a.v, b.v)}; }
inline L4 operator*(L4 a, L4 b) { return {_mm256_mul_pd(a.v, b.v)}; }
inline L4 operator/(L4 a, L4 b) { return {_mm256_div_pd(a.v, b.v)}; }
inline M4 operator<(L4 a, L4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LT_OQ)}; }
inline M4 operator<=(L4 a, L4 b) { return {_mm256_cmp_pd(a.v, b.v, _CMP_LE_OQ)}; }
inline L4 sqrt_of(L4 a) { return {_mm256_sqrt_pd(a.v)}; }
inline L4 abs_of(L4 a) { return {_mm256_andnot_pd(_mm256_set1_pd(-0.0), a.v)}; }
inline L4 min_of(L4 x, L4 y) { return {_mm256_min_pd(y.v, x.v)}; }
inline L4 max_of(L4 x, L4 y) { return {_mm256_max_pd(y.v, x.v)}; }
inline L4 select(M4 m, L4 a, L4 b) { return {_mm256_blendv_pd(b.v, a.v, m.v)}; }
inline L4 ceil_of(L4 a) { return {_mm256_ceil_pd(a.v)}; }
#pragma GCC pop_options

// Eight lanes (AVX-512F), where the CPU has it; the same kernels again.
#pragma GCC push_options
#pragma GCC target("avx512f")
#pragma GCC diagnostic push
// GCC 12 warns about the intrinsics' own _mm512_undefined_pd() pass-through operands (a known false positive).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
struct L8 {
    static constexpr std::size_t width = 8;
    __m512d v;
    static L8 splat(double x) { return {_mm512_set1_pd(x)}; }
    static L8 load(const double* p) { return {_mm512_loadu_pd(p)}; }
    static L8 evens(const double* p) {
        const __m512i idx = _mm512_set_epi64(14, 12, 10, 8, 6, 4, 2, 0);
        return {_mm512_permutex2var_pd(_mm512_loadu_pd(p), idx, _mm512_loadu_pd(p + 8))};
    }
    static L8 odds(const double* p) {
        const __m512i idx = _mm512_set_epi64(15, 13, 11, 9, 7, 5, 3, 1);
        return {_mm512_permutex2var_pd(_mm512_loadu_pd(p), idx, _mm512_loadu_pd(p + 8))};
    }
    void store(double* p) const { _mm512_storeu_pd(p, v); }
    // L4's 4 x 4 transposes on segments s and s + 4 at once: row s holds doubles k .. k + 3 of segment s in its
    // low half and of segment s + 4 in its high half; the in-lane unpacks transpose both halves' 2 x 2 blocks,
    // and one two-source permute per output puts the blocks of segments 0 .. 7 in order.
    static void points(const double* p, L8 (&x)[4], L8 (&y)[4], L8 (&z)[4]) {
        const __m512i even_blocks = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);  // a0 b0 a2 b2 (2-double blocks)
        const __m512i odd_blocks = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);  // a1 b1 a3 b3
        L8 c[12];
        for (int k = 0; k < 12; k += 4) {
            __m512d r[4];
            for (int s = 0; s < 4; ++s)
                r[s] = _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_loadu_pd(p + 12 * s + k)),
                                          _mm256_loadu_pd(p + 12 * (s + 4) + k), 1);
            const __m512d t0 = _mm512_unpacklo_pd(r[0], r[1]), t1 = _mm512_unpackhi_pd(r[0], r[1]);
            const __m512d t2 = _mm512_unpacklo_pd(r[2], r[3]), t3 = _mm512_unpackhi_pd(r[2], r[3]);
            c[k] = {_mm512_permutex2var_pd(t0, even_blocks, t2)};
            c[k + 1] = {_mm512_permutex2var_pd(t1, even_blocks, t3)};
            c[k + 2] = {_mm512_permutex2var_pd(t0, odd_blocks, t2)};
            c[k + 3] = {_mm512_permutex2var_pd(t1, odd_blocks, t3)};
        }
        for (int k = 0; k < 4; ++k) x[k] = c[3 * k], y[k] = c[3 * k + 1], z[k] = c[3 * k + 2];
    }
};
struct M8 {
    __mmask8 v;
    [[nodiscard]] unsigned bits() const { return v; }
};
inline M8 operator&(M8 a, M8 b) { return {static_cast<__mmask8>(a.v & b.v)}; }
inline M8 operator|(M8 a, M8 b) { return {static_cast<__mmask8>(a.v | b.v)}; }
inline L8 operator+(L8 a, L8 b) { return {_mm512_add_pd(a.v, b.v)}; }
inline L8 operator-(L8 a, L8 b) { return {_mm512_sub_pd(a.v, b.v)}; }
inline L8 operator*(L8 a, L8 b) { return {_mm512_mul_pd(a.v, b.v)}; }
inline L8 operator/(L8 a, L8 b) { return {_mm512_div_pd(a.v, b.v)}; }
inline M8 operator<(L8 a, L8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LT_OQ)}; }
inline M8 operator<=(L8 a, L8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ)}; }
inline L8 sqrt_of(L8 a) { return {_mm512_sqrt_pd(a.v)}; }
inline L8 abs_of(L8 a) { return {_mm512_abs_pd(a.v)}; }
inline L8 neg_of(L8 a) {
    return {_mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(a.v), _mm512_set1_epi64(INT64_MIN)))};
}
inline L8 min_of(L8 x, L8 y) { return {_mm512_min_pd(y.v, x.v)}; }
inline L8 max_of(L8 x, L8 y) { return {_mm512_max_pd(y.v, x.v)}; }
inline L8 select(M8 m, L8 a, L8 b) { return {_mm512_mask_blend_pd(m.v, b.v, a.v)}; }
inline L8 ceil_of(L8 a) { return {_mm512_roundscale_pd(a.v, _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC)}; }
#pragma GCC diagnostic pop
#pragma GCC pop_options
#endif

}  // namespace wire::simd
