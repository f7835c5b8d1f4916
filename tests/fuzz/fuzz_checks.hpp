// Shared property checks of the fuzz targets: every accepted output is finite, every index in range.
// A violated property aborts (libFuzzer then saves the input as a crash file).
#pragma once

#include <wire/pipeline.hpp>

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace wire_fuzz {

/// A double from the fuzzer's bytes: one of the target's `special` values (NaN, Inf, denormals, huge, tiny...)
/// when the first byte indexes one, a value in [-10, 10] for the rest of the lower half, otherwise 8 raw bytes.
inline double special_or_raw(FuzzedDataProvider& in, std::span<const double> special) {
    const uint8_t pick = in.ConsumeIntegral<uint8_t>();
    if (pick < special.size()) return special[pick];
    if (pick < 128) return in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
    double raw = 0.0;
    const auto bytes = in.ConsumeBytes<uint8_t>(sizeof raw);
    if (!bytes.empty()) std::memcpy(&raw, bytes.data(), bytes.size());
    return raw;
}

[[noreturn]] inline void fail(const std::string& what) {
    std::fprintf(stderr, "fuzz property violated: %s\n", what.c_str());
    std::abort();
}

inline void require(bool condition, const char* what) {
    if (!condition) fail(what);
}

template <typename Vec>
bool finite_vec(const Vec& v) {
    for (int i = 0; i < Vec::length(); ++i)
        if (!std::isfinite(static_cast<double>(v[i]))) return false;
    return true;
}

/// Everything a successful WirePipeline::update produced: curve, rings, mesh finite; indices in range.
inline void check_pipeline_outputs(const wire::WirePipeline& p) {
    const wire::Curve& c = p.curve();
    for (const wire::CubicBezier& b : c.segments)
        require(finite_vec(b.b0) && finite_vec(b.b1) && finite_vec(b.b2) && finite_vec(b.b3),
                "curve control point not finite");
    for (float r : c.radius_m) require(std::isfinite(r) && r > 0.0f, "curve radius not finite and positive");
    const wire::RingSet& rs = p.rings();
    require(finite_vec(rs.origin_m), "ring origin not finite");
    for (const wire::Frame& f : rs.frames)
        require(finite_vec(f.t) && finite_vec(f.r) && finite_vec(f.s), "ring frame not finite");
    for (const auto& centre : rs.centre_m) require(finite_vec(centre), "ring centre not finite");
    for (double u : rs.u) require(std::isfinite(u), "ring u not finite");
    const wire::TubeMesh& m = p.mesh();
    require(finite_vec(m.origin_m), "mesh origin not finite");
    for (const wire::TubeVertex& v : m.vertices)
        require(finite_vec(v.position) && finite_vec(v.normal) && finite_vec(v.uv), "mesh vertex not finite");
    for (uint32_t i : m.indices) require(i < m.vertices.size(), "mesh index out of range");
}

}  // namespace wire_fuzz
