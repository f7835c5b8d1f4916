// The curve stage's input checks: settings, array sizes, node values (finite, in range), with specific messages.
#include "spline/validate.hpp"

#include "simd/dispatch.hpp"  // WIRE_RANGE_VERSIONS

#include <glm/geometric.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace wire::curve_stage {

using glm::dvec3;

std::string describe(double v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::string node_prefix(std::size_t i) { return "node " + std::to_string(i) + ": "; }

namespace {

// Smallest accepted tube radius (metres) and node stretch: texture u grows as arc length / (2 pi radius stretch)
// and is stored as float; with both >= 1e-6 it stays below ~1e32 for any curve within kMaxCoordinate_m (a
// denormal radius overflowed it to Inf: fuzz_geometry). The radius polynomial between nodes is monotone, so
// node radii bound it from below.
constexpr float kMinRadius_m = 1e-6f;
constexpr float kMinStretch = 1e-6f;

template <class T>
bool size_ok(const std::vector<T>& v, std::size_t n) { return v.empty() || v.size() == n; }

}  // namespace

Status check_sizes(const WireNodes& w) {
    const std::size_t n = w.positions.size();
    // The common case in one branch-free test (every array empty or one per node); the message below.
    bool fits = true;
    for_each_node_array([&](const char*, auto member) {
        const std::size_t size = (w.*member).size();
        fits &= (size == 0) | (size == n);
    });
    if (fits) return Status::success();
    Status first = Status::success();
    for_each_node_array([&](const char* name, auto member) {
        const std::size_t size = (w.*member).size();
        if (first.ok() && !size_ok(w.*member, n)) {
            first = Status::error(std::string(name) + " has " + std::to_string(size) + " entries for " +
                                  std::to_string(n) + " nodes (must be empty or one per node)");
        }
    });
    return first;
}

Status check_settings(const SplineSettings& s) {
    const struct { const char* name; double v; } finite[] = {
        {"alpha", s.alpha}, {"tension", s.tension}, {"bias", s.bias}, {"continuity", s.continuity},
        {"radius_m", s.radius_m}, {"merge_epsilon_rel", s.merge_epsilon_rel}};
    for (const auto& f : finite) {
        if (!std::isfinite(f.v)) return Status::error(std::string("settings.") + f.name + " is " + describe(f.v));
    }
    if (s.radius_m < 0.0f) return Status::error("settings.radius_m is " + describe(s.radius_m) + " (must be > 0; 0 means 1 cm)");
    if (s.radius_m > 0.0f && s.radius_m < kMinRadius_m)
        return Status::error("settings.radius_m is " + describe(s.radius_m) + " (below the smallest supported radius, 1e-6 m)");
    if (s.merge_epsilon_rel < 0.0) return Status::error("settings.merge_epsilon_rel is " + describe(s.merge_epsilon_rel) + " (must be >= 0)");
    return Status::success();
}

namespace {

// all_within has a second version for AVX2 machines, chosen at load time like the kernels' clones (the compiler
// does not vectorize this reduction, and GCC's vector types split slowly on the SSE2 baseline): WIRE_RANGE_VERSIONS.
// Its callers are in this file: a call from another file would reach the baseline version only (the dispatch is
// this file's), so they call values_within().

// True when |v[i]| <= limit for every i < count (false for NaN and Inf): an AND of vector comparisons, no branch
// per value.
WIRE_RANGE_DEFAULT
bool all_within(const double* v, std::size_t count, double limit) {
    std::size_t i = 0;
    bool all = true;
#if defined(__SSE2__)
    const __m128d lim = _mm_set1_pd(limit), sign = _mm_set1_pd(-0.0);
    __m128d ok = _mm_cmpeq_pd(lim, lim);  // all ones (limit is a number)
    for (; i + 2 <= count; i += 2) ok = _mm_and_pd(ok, _mm_cmple_pd(_mm_andnot_pd(sign, _mm_loadu_pd(v + i)), lim));
    all = _mm_movemask_pd(ok) == 3;
#endif
    for (; i < count; ++i) all &= std::abs(v[i]) <= limit;
    return all;
}

#if defined(WIRE_RANGE_VERSIONS)
__attribute__((target("avx2"))) bool all_within(const double* v, std::size_t count, double limit) {
    using v4d = double __attribute__((vector_size(32)));
    using v4i = long long __attribute__((vector_size(32)));
    const v4d hi = {limit, limit, limit, limit};
    const v4i magnitude = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};  // clears the sign bit: |x|
    v4i ok0 = {-1, -1, -1, -1}, ok1 = ok0;
    std::size_t i = 0;
    for (; i + 8 <= count; i += 8) {  // two independent chains
        v4i x0, x1;
        std::memcpy(&x0, v + i, sizeof x0);
        std::memcpy(&x1, v + i + 4, sizeof x1);
        ok0 &= reinterpret_cast<v4d>(x0 & magnitude) <= hi;
        ok1 &= reinterpret_cast<v4d>(x1 & magnitude) <= hi;
    }
    for (; i + 4 <= count; i += 4) {
        v4i x;
        std::memcpy(&x, v + i, sizeof x);
        ok0 &= reinterpret_cast<v4d>(x & magnitude) <= hi;
    }
    ok0 &= ok1;
    bool all = (ok0[0] & ok0[1] & ok0[2] & ok0[3]) != 0;
    for (; i < count; ++i) all &= std::abs(v[i]) <= limit;
    return all;
}

#endif

}  // namespace

// True when v[i] > limit for every i < count (false for NaN).
bool all_above(const double* v, std::size_t count, double limit) {
    std::size_t i = 0;
    bool all = true;
#if defined(__SSE2__)
    const __m128d lim = _mm_set1_pd(limit);
    __m128d ok = _mm_cmpeq_pd(lim, lim);  // all ones (limit is a number)
    for (; i + 2 <= count; i += 2) ok = _mm_and_pd(ok, _mm_cmpgt_pd(_mm_loadu_pd(v + i), lim));
    all = _mm_movemask_pd(ok) == 3;
#endif
    for (; i < count; ++i) all &= v[i] > limit;
    return all;
}

Status check_nodes(const WireNodes& w, bool use_physics) {
    static const char* const kAxis[3] = {"x", "y", "z"};
    // Positions in one branch-free pass: every coordinate finite and in range (NaN and Inf fail the comparison).
    // When they pass, the per-node checks below skip them; a bad one is found there, with its message.
    static_assert(sizeof(glm::dvec3) == 3 * sizeof(double), "positions: 3 contiguous doubles a node");
    const bool positions_ok =
        !w.positions.empty() && all_within(&w.positions[0].x, 3 * w.positions.size(), kMaxCoordinate_m);
    if (positions_ok && w.stretch.empty() && w.radius_m.empty() && w.kb_tension.empty() && w.kb_bias.empty() &&
        w.kb_continuity.empty() && !use_physics) {
        return Status::success();
    }
    for (std::size_t i = 0; i < w.positions.size(); ++i) {
        for (int a = 0; a < 3 && !positions_ok; ++a) {
            const double v = w.positions[i][a];
            if (!std::isfinite(v)) return Status::error(node_prefix(i) + "position." + kAxis[a] + " is " + describe(v), static_cast<int>(i));
            if (std::abs(v) > kMaxCoordinate_m)
                return Status::error(node_prefix(i) + "position." + kAxis[a] + " is " + describe(v) +
                                         " (beyond the supported range of +-1e12 m)", static_cast<int>(i));
        }
        if (!w.stretch.empty() && !(w.stretch[i] >= kMinStretch && std::isfinite(w.stretch[i]))) {
            return Status::error(node_prefix(i) + "stretch is " + describe(w.stretch[i]) + " (must be finite and >= 1e-6)", static_cast<int>(i));
        }
        if (!w.radius_m.empty() && !(w.radius_m[i] >= 0.0f && std::isfinite(w.radius_m[i]))) {
            return Status::error(node_prefix(i) + "radius_m is " + describe(w.radius_m[i]) +
                                     " (must be finite and >= 0; 0 uses the wire's radius)", static_cast<int>(i));
        }
        if (!w.radius_m.empty() && w.radius_m[i] > 0.0f && w.radius_m[i] < kMinRadius_m) {
            return Status::error(node_prefix(i) + "radius_m is " + describe(w.radius_m[i]) +
                                     " (below the smallest supported radius, 1e-6 m)", static_cast<int>(i));
        }
        const struct { const char* name; const std::vector<float>& v; } kb[] = {
            {"kb_tension", w.kb_tension}, {"kb_bias", w.kb_bias}, {"kb_continuity", w.kb_continuity}};
        for (const auto& k : kb) {
            if (!k.v.empty() && !std::isfinite(k.v[i])) return Status::error(node_prefix(i) + k.name + " is " + describe(k.v[i]), static_cast<int>(i));
        }
        if (use_physics) {
            const struct { const char* name; double v; } ph[] = {
                {"theta_rad", w.theta_rad[i]}, {"iz_m4", w.iz_m4[i]}, {"length_m", w.length_m[i]},
                {"delta_length_m", w.delta_length_m[i]}, {"area_m2", w.area_m2[i]}};
            for (const auto& p : ph) {
                if (!std::isfinite(p.v)) return Status::error(node_prefix(i) + p.name + " is " + describe(p.v), static_cast<int>(i));
            }
            if (!(w.area_m2[i] > 0.0)) return Status::error(node_prefix(i) + "area_m2 is " + describe(w.area_m2[i]) + " (must be > 0)", static_cast<int>(i));
        }
    }
    return Status::success();
}

bool values_within(const double* v, std::size_t count, double limit) { return all_within(v, count, limit); }

Status check_distinct(std::size_t input, std::size_t merged, bool closed) {
    if (merged < 2) {
        return Status::error("a wire needs at least 2 distinct nodes, got " + std::to_string(input) + " node(s) and " +
                             std::to_string(merged) + " after merging coincident ones");
    }
    if (closed && merged < 3) {
        return Status::error("a closed loop needs at least 3 distinct nodes, got " + std::to_string(merged) +
                             " after merging coincident ones");
    }
    return Status::success();
}

}  // namespace wire::curve_stage
