// Internal: choosing instruction sets for the hot loops: load-time clones of a kernel (WIRE_VECTOR_CLONES), select
// kernels (WIRE_SELECT_KERNEL), hand-made versions picked at load time (WIRE_RANGE_*), and the CPU's widths.
#pragma once

/// On x86-64 with GCC: the function is compiled for AVX-512, AVX2 and the baseline (SSE2), and the loader picks the
/// widest one the CPU has (an ifunc: one indirect call per call). Only for loops written so the compiler vectorizes
/// them. Every clone gives the same results, bit for bit: wire_core is compiled with -ffp-contract=off (no fused
/// multiply-add changes a rounding) and these loops use only correctly rounded operations (+, -, *, /, sqrt, min,
/// max, comparisons). Elsewhere (Clang, sanitizers, other CPUs): one plain function.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(WIRE_NO_VECTOR_CLONES) && \
    !defined(__SANITIZE_ADDRESS__)
#define WIRE_HAS_VECTOR_CLONES 1  // also for hand-made versions chosen at load time (WIRE_RANGE_VERSIONS)
#define WIRE_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define WIRE_VECTOR_CLONES
#endif

/// A kernel whose `?:` selects should become vector blends: GCC if-converts them only without trapping math. No
/// value changes (every operation is still performed and rounded as written; NaN comparisons keep their meaning);
/// only whether an operation whose result is discarded may raise a floating-point exception flag, which nothing
/// here reads.
#if defined(__GNUC__) && !defined(__clang__)
#define WIRE_SELECT_KERNEL __attribute__((optimize("no-trapping-math")))
#else
#define WIRE_SELECT_KERNEL
#endif

/// A function with a second, hand-written version for AVX2 machines (`__attribute__((target("avx2")))`), chosen at
/// load time like the kernels' clones (for reductions the compiler does not vectorize); the same condition as
/// WIRE_VECTOR_CLONES'. The baseline version is marked WIRE_RANGE_DEFAULT.
#if defined(WIRE_HAS_VECTOR_CLONES)
#define WIRE_RANGE_VERSIONS 1
#define WIRE_RANGE_DEFAULT __attribute__((target("default")))
#else
#define WIRE_RANGE_DEFAULT
#endif

/// The LOD's span kernels in AVX2 (four lanes) and AVX-512F (eight lanes) besides the SSE2 baseline, chosen at run
/// time (simd/lanes.hpp); WIRE_LOD_NO_AVX2 leaves the baseline only.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(WIRE_LOD_NO_AVX2)
#define WIRE_LOD_AVX2 1
#endif

namespace wire::simd {

#if defined(__x86_64__) && defined(__GNUC__)
/// Whether the CPU (and the OS) run AVX-512F / AVX2 code.
inline bool cpu_has_avx512() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f");
}
inline bool cpu_has_avx2() {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2");
}
#endif

}  // namespace wire::simd
