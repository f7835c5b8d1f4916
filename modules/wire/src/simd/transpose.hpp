// Internal: four-double vectors (GCC's vector extension) and the 4x4 transpose of four of them, for the kernels
// that turn arrays of records into structures of arrays and back (frames' segment transposes, the four-lane
// tridiagonal solve's interleaving).
#pragma once

namespace wire::simd {

/// Four doubles: one ymm register on AVX2 and AVX-512 machines (a kernel's clones), two xmm halves on the SSE2
/// baseline.
using v4d = double __attribute__((vector_size(32)));
/// Four doubles at any double address (loads and stores through it may alias any double).
using v4p = double __attribute__((vector_size(32), aligned(8), may_alias));

/// c[j][s] = r[s][j]: rows to columns, by eight shuffles (no arithmetic). Always inlined: GCC inlines nothing else
/// into a kernel compiled for another instruction set (WIRE_VECTOR_CLONES).
[[gnu::always_inline]] inline void transpose4x4(const v4d (&r)[4], v4d (&c)[4]) {
    const v4d t0 = __builtin_shufflevector(r[0], r[1], 0, 4, 2, 6);
    const v4d t1 = __builtin_shufflevector(r[0], r[1], 1, 5, 3, 7);
    const v4d t2 = __builtin_shufflevector(r[2], r[3], 0, 4, 2, 6);
    const v4d t3 = __builtin_shufflevector(r[2], r[3], 1, 5, 3, 7);
    c[0] = __builtin_shufflevector(t0, t2, 0, 1, 4, 5), c[1] = __builtin_shufflevector(t1, t3, 0, 1, 4, 5);
    c[2] = __builtin_shufflevector(t0, t2, 2, 3, 6, 7), c[3] = __builtin_shufflevector(t1, t3, 2, 3, 6, 7);
}

}  // namespace wire::simd
