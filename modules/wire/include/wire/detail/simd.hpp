// Internal: building the hot loops for several instruction sets.
#pragma once

/// On x86-64 with GCC: the function is compiled for AVX2, AVX-512 and the baseline (SSE2), and the loader picks
/// the widest one the CPU has (an ifunc; the choice costs one indirect call per call). Only for loops written so
/// the compiler vectorizes them. The results are the same on every clone, bit for bit: wire_core is compiled with
/// -ffp-contract=off (no fused multiply-add ever changes a rounding) and these loops use only correctly rounded
/// operations (+, -, *, /, sqrt, min, max, comparisons). Elsewhere (Clang, sanitizers, other CPUs): one plain
/// function.
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(WIRE_NO_VECTOR_CLONES) && \
    !defined(__SANITIZE_ADDRESS__)
#define WIRE_VECTOR_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define WIRE_VECTOR_CLONES
#endif
