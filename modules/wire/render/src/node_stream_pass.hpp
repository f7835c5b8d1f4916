// Internal: the node stream's copying pass (node_stream.cpp): each node read once, checked, offset and written as
// the curve pass reads it, with the box and the shortest chord the merge rule needs measured on the way.
#pragma once

#include "wire/nodes.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/render/node_stream.hpp"

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <cfloat>
#include <cstddef>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace wire::render::detail {




inline SplineSettings spline_of(const StreamStyle& s) {
    SplineSettings spline;
    spline.kind = s.kind;
    spline.alpha = s.alpha;
    spline.tension = s.tension, spline.bias = s.bias, spline.continuity = s.continuity;
    spline.closed = s.closed;
    spline.radius_m = s.radius_m;
    return spline;
}

inline Status check_style(const StreamStyle& s) {
    if (!gpu_builds(s.kind)) return Status::error("style: the GPU builds linear, Catmull-Rom, c2 and automatic wires");
    WireNodes probe;
    probe.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    if (Status st = check_curve_input(probe, spline_of(s)); !st) {
        return Status::error("style: " + st.message);
    }
    return Status::success();
}

/// What the copying pass measured: the offsets' box, the shortest chord (squared), whether every value passed.
struct Measure {
    glm::vec3 lo{FLT_MAX}, hi{-FLT_MAX};
    float min_chord2 = FLT_MAX;
    bool ok = true;
};

/// The one pass: node j's offset from `offset(j)` (its range check folded into ok), its radius, written as the
/// curve pass reads it; the box and the shortest chord on the way.
template <class Offset>
Measure copy_nodes(std::size_t n, Offset offset, const float* radius, std::size_t radius_stride, float wire_radius,
                   bool closed, glm::vec4* dst) {
    Measure m;
    glm::vec3 prev{};
    bool ok = true;
    for (std::size_t j = 0; j < n; ++j) {
        bool in_range = true;
        const glm::vec3 o = offset(j, in_range);
        float r = wire_radius;
        if (radius != nullptr) {
            const float given = *reinterpret_cast<const float*>(reinterpret_cast<const char*>(radius) + j * radius_stride);
            // Finite and >= 0, and 0 or at least the smallest radius (check_nodes'); NaN fails both.
            in_range &= given >= 0.0f && given <= FLT_MAX && (given == 0.0f || given >= 1e-6f);
            r = given > 0.0f ? given : wire_radius;
        }
        ok &= in_range;
        dst[j] = glm::vec4(o, r);
        m.lo = glm::min(m.lo, o), m.hi = glm::max(m.hi, o);
        if (j > 0) {
            const glm::vec3 d = o - prev;
            m.min_chord2 = std::min(m.min_chord2, glm::dot(d, d));
        }
        prev = o;
    }
    if (closed && n >= 2) {
        const glm::vec3 d = glm::vec3(dst[0]) - prev;
        m.min_chord2 = std::min(m.min_chord2, glm::dot(d, d));
    }
    m.ok = ok;
    return m;
}

#if defined(__SSE2__)
/// copy_nodes for nodes without per-node radius, four lanes a node (x, y, z, radius): the offsets, their box and
/// chords in SSE registers, the range test a mask (NaN fails it), no branch per node. `load(j, ok)` gives node j's
/// offset with lane 3 zero and ANDs its range test into `ok`.
template <class Load>
Measure copy_nodes_sse(std::size_t n, Load load, float wire_radius, bool closed, glm::vec4* dst) {
    Measure m;
    if (n == 0) return m;
    const __m128 radius = _mm_set_ps(wire_radius, 0.0f, 0.0f, 0.0f);
    __m128 lo = _mm_set1_ps(FLT_MAX), hi = _mm_set1_ps(-FLT_MAX), chord = _mm_set1_ps(FLT_MAX);
    __m128d ok = _mm_castsi128_pd(_mm_set1_epi32(-1));
    const auto squared = [](__m128 d) {  // |d|^2 in every lane (lane 3 of d is zero)
        const __m128 d2 = _mm_mul_ps(d, d);
        const __m128 s = _mm_add_ps(d2, _mm_shuffle_ps(d2, d2, _MM_SHUFFLE(2, 3, 0, 1)));
        return _mm_add_ps(s, _mm_shuffle_ps(s, s, _MM_SHUFFLE(1, 0, 3, 2)));
    };
    const __m128 first = load(0, ok);
    __m128 prev = first;
    _mm_store_ps(&dst[0].x, _mm_or_ps(first, radius));
    lo = _mm_min_ps(lo, first), hi = _mm_max_ps(hi, first);
    for (std::size_t j = 1; j < n; ++j) {
        const __m128 o = load(j, ok);
        _mm_store_ps(&dst[j].x, _mm_or_ps(o, radius));
        lo = _mm_min_ps(lo, o), hi = _mm_max_ps(hi, o);
        chord = _mm_min_ps(chord, squared(_mm_sub_ps(o, prev)));
        prev = o;
    }
    if (closed && n >= 2) chord = _mm_min_ps(chord, squared(_mm_sub_ps(first, prev)));
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo), _mm_store_ps(h, hi);
    m.lo = glm::vec3(l[0], l[1], l[2]), m.hi = glm::vec3(h[0], h[1], h[2]);
    m.min_chord2 = _mm_cvtss_f32(chord);
    // NaN offsets leave the min/max alone: the range mask caught them (a NaN compares false).
    m.ok = _mm_movemask_pd(ok) == 3;
    return m;
}
#endif

/// Whether nothing the merge rule (merge_nodes: eps = max(1e-9 diag, 64 DBL_EPSILON max |p|)) could join lies
/// in the float offsets: the shortest chord clears eps by more than the offsets' rounding.
inline bool clears_merge(const Measure& m, const glm::dvec3& origin, std::size_t n, bool closed) {
    if (!m.ok || n < (closed ? 3u : 2u)) return false;
    const glm::dvec3 lo(m.lo), hi(m.hi);
    const double diag = glm::length(hi - lo);
    const double max_abs = std::max(glm::length(origin + lo), glm::length(origin + hi));
    const double eps = std::max(1e-9 * diag, 64.0 * DBL_EPSILON * max_abs);
    const double reach = std::max(glm::length(lo), glm::length(hi));
    const double margin = eps + 4e-7 * reach + 1e-30;  // float offsets: 2^-24 relative, a chord two of them
    return static_cast<double>(m.min_chord2) > margin * margin;
}


}  // namespace wire::render::detail
