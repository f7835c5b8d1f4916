// The span hierarchy's lane kernels (span_kernels.inl) compiled at each width (SSE2, AVX2, AVX-512F: the same
// bits), and the choice of the widest the CPU has.
#include "lod/span_kernels.hpp"

#include "simd/lanes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <string_view>
#include <type_traits>

namespace wire::lod_stage {
namespace {

using namespace simd;  // the lane types and their operations

#if defined(__SSE2__)
namespace span_sse2 {
using W = L2;
#include "lod/span_kernels.inl"
}  // namespace span_sse2
#else
namespace span_sse2 {
using W = L1;
#include "lod/span_kernels.inl"
}  // namespace span_sse2
#endif

#if defined(WIRE_LOD_AVX2)
// The same kernels four lanes wide, compiled for AVX2 (no FMA: the arithmetic stays the scalar code's) and chosen
// at run time where the CPU has it.
#pragma GCC push_options
#pragma GCC target("avx2")
namespace span_avx2 {
using W = L4;
#include "lod/span_kernels.inl"
}  // namespace span_avx2
#pragma GCC pop_options

// Eight lanes (AVX-512F), where the CPU has it; the same kernels again.
#pragma GCC push_options
#pragma GCC target("avx512f")
#pragma GCC diagnostic push
// GCC 12 warns about the intrinsics' own _mm512_undefined_pd() pass-through operands (a known false positive).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
namespace span_avx512 {
using W = L8;
#define WIRE_LOD_TAIL4 1
#include "lod/span_kernels.inl"
#undef WIRE_LOD_TAIL4
}  // namespace span_avx512
#pragma GCC diagnostic pop
#pragma GCC pop_options
#endif

}  // namespace

SpanKernels choose_span_kernels() {
#if defined(WIRE_LOD_AVX2)
    // Only "2" and "4" cap the width; anything else (unset, or not one of those) leaves the widest.
    const char* cap = std::getenv("WIRE_LOD_LANES");
    const std::string_view lanes_text = cap != nullptr ? cap : "";
    const int lanes = lanes_text == "2" ? 2 : lanes_text == "4" ? 4 : 8;
    if (lanes >= 8 && simd::cpu_has_avx512())
        return {span_avx512::span_level0, span_avx512::span_merge_level, span_avx512::span_merge_deviations, span_avx512::span_merge_spheres, span_avx512::hull_depth_kernel,
                span_avx512::wang_counts, span_avx512::span_ratios, span_avx512::wire_box};
    if (lanes >= 4 && simd::cpu_has_avx2())
        return {span_avx2::span_level0, span_avx2::span_merge_level, span_avx2::span_merge_deviations, span_avx2::span_merge_spheres, span_avx2::hull_depth_kernel,
                span_avx2::wang_counts, span_avx2::span_ratios, span_avx2::wire_box};
#endif
    return {span_sse2::span_level0, span_sse2::span_merge_level, span_sse2::span_merge_deviations, span_sse2::span_merge_spheres, span_sse2::hull_depth_kernel,
            span_sse2::wang_counts, span_sse2::span_ratios, span_sse2::wire_box};
}

}  // namespace wire::lod_stage
