// libFuzzer target: arbitrary bend segments and points through make_chain, Chain::transform, bounds and
// bend_vertices; or (first byte odd) the bytes as SEGS.json text through parse_segments_json first. Property:
// either rejected with a message, or finite outputs for finite points (folding is flagged, not an error).
#include "fuzz_checks.hpp"

#include <curved_space/chain.hpp>
#include <curved_space/segments_json.hpp>

#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double special_or_raw(FuzzedDataProvider& in) {
    static constexpr double kSpecial[] = {0.0,  -0.0,  1.0,    -1.0,   0.5,   3.141592653589793, 6.283185307179586,
                                          1e-9, 1e-6,  1e6,    -1e6,   1e-300, 5e-324, 1e300, -1e300,
                                          kInf, -kInf, std::numeric_limits<double>::quiet_NaN(), 100.0, 1e3};
    return wire_fuzz::special_or_raw(in, kSpecial);
}

void check_chain(const curved_space::Chain& chain, FuzzedDataProvider& in) {
    for (std::size_t i = 0; i <= chain.segment_count(); ++i) {
        const glm::dmat4& m = chain.world_from_segment(i);
        for (int c = 0; c < 4; ++c) wire_fuzz::require(wire_fuzz::finite_vec(m[c]), "chain matrix not finite");
        wire_fuzz::require(std::isfinite(chain.z_start_m(i)), "chain z_start not finite");
        wire_fuzz::require(std::isfinite(chain.kappa_per_m(i)), "chain curvature not finite");
    }
    std::vector<float> positions, normals;
    const int points = in.ConsumeIntegralInRange<int>(0, 16);
    for (int k = 0; k < points; ++k) {
        const glm::dvec3 p(special_or_raw(in), special_or_raw(in), special_or_raw(in));
        const glm::dvec3 n(special_or_raw(in), special_or_raw(in), special_or_raw(in));
        const curved_space::BentVertex v = chain.transform(p, n);
        // The promise is "finite for finite input": only points the float pipeline can carry are checked.
        const bool sane = wire_fuzz::finite_vec(p) && wire_fuzz::finite_vec(n) && glm::length(p) < 1e9 &&
                          glm::length(n) < 1e9;
        if (sane) {
            wire_fuzz::require(wire_fuzz::finite_vec(v.position), "bent position not finite");
            wire_fuzz::require(wire_fuzz::finite_vec(v.normal), "bent normal not finite");
            positions.insert(positions.end(), {float(p.x), float(p.y), float(p.z)});
            normals.insert(normals.end(), {float(n.x), float(n.y), float(n.z)});
        }
    }
    (void)curved_space::bend_vertices(chain, positions, normals);
    for (float f : positions) wire_fuzz::require(std::isfinite(f), "bend_vertices position not finite");
    for (float f : normals) wire_fuzz::require(std::isfinite(f), "bend_vertices normal not finite");
    if (in.ConsumeBool()) {
        curved_space::Aabb box;
        box.min = glm::dvec3(in.ConsumeFloatingPointInRange<double>(-10.0, 0.0),
                             in.ConsumeFloatingPointInRange<double>(-10.0, 0.0),
                             in.ConsumeFloatingPointInRange<double>(-10.0, 0.0));
        box.max = box.min + glm::dvec3(in.ConsumeFloatingPointInRange<double>(0.0, 20.0),
                                       in.ConsumeFloatingPointInRange<double>(0.0, 20.0),
                                       in.ConsumeFloatingPointInRange<double>(0.0, 20.0));
        if (std::getenv("WIRE_FUZZ_DUMP"))
            std::fprintf(stderr, "box %.17g %.17g %.17g .. %.17g %.17g %.17g\n", box.min.x, box.min.y, box.min.z,
                         box.max.x, box.max.y, box.max.z);
        const curved_space::Aabb b = chain.bounds(box);
        wire_fuzz::require(wire_fuzz::finite_vec(b.min) && wire_fuzz::finite_vec(b.max), "bounds not finite");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    std::vector<curved_space::Segment> segments;
    const bool json = data[0] & 1;
    // JSON mode: the text runs from byte 1 to the first NUL; the bytes after it are the point data.
    const auto* body = data + 1;
    const void* nul = json ? std::memchr(body, 0, size - 1) : nullptr;
    const std::size_t text_size = json ? (nul ? static_cast<std::size_t>(static_cast<const uint8_t*>(nul) - body) : size - 1) : 0;
    const std::size_t skip = json ? std::min(text_size + 1, size - 1) : 0;
    FuzzedDataProvider in(body + skip, size - 1 - skip);
    if (json) {
        const std::string text(reinterpret_cast<const char*>(body), text_size);
        const engine::Status st = curved_space::parse_segments_json(text, "fuzz.json", segments);
        if (!st.ok()) {
            wire_fuzz::require(!st.message.empty(), "rejected SEGS.json without a message");
            wire_fuzz::require(st.message.rfind("fuzz.json", 0) == 0, "SEGS.json message does not name the file");
            wire_fuzz::require(segments.empty(), "rejected SEGS.json changed the output");
            return 0;
        }
    } else {
        const int count = in.ConsumeIntegralInRange<int>(0, 32);
        for (int i = 0; i < count; ++i)
            segments.push_back({special_or_raw(in), special_or_raw(in), in.ConsumeBool() ? special_or_raw(in) : 0.0});
    }
    if (std::getenv("WIRE_FUZZ_DUMP"))  // WIRE_FUZZ_DUMP=1 prints the decoded input (triage by hand)
        for (const curved_space::Segment& s : segments)
            std::fprintf(stderr, "segment length %.17g angle %.17g direction %.17g\n", s.length_m, s.angle_rad,
                         s.direction_rad);
    curved_space::Chain chain;
    const engine::Status st = curved_space::make_chain(segments, chain);
    if (!st.ok()) {
        wire_fuzz::require(!st.message.empty(), "make_chain error without a message");
        wire_fuzz::require(chain.segment_count() == 0, "rejected chain changed the output");
        return 0;
    }
    check_chain(chain, in);
    return 0;
}
