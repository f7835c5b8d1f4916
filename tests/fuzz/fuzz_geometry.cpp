// libFuzzer target: arbitrary node arrays (raw doubles incl. NaN, Inf, denormals, huge/tiny values, plus
// structured mutations: duplicates, near-duplicates, far offsets, hairpins) and arbitrary settings through
// build_curve and WirePipeline (several successive states, so node ids appear and vanish). Property: either a
// Status error with a message, or every output finite (curve control points, ring frames, vertices) with
// indices in range.
#include "fuzz_checks.hpp"

#include <wire/pipeline.hpp>
#include <wire/spline.hpp>

#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double special_or_raw(FuzzedDataProvider& in) {
    static constexpr double kSpecial[] = {0.0,   -0.0,  1.0,   -1.0,  0.5,    2.0,    1e-9,   -1e-9, 1e-6,
                                          1e6,   -1e6,  1e-300, 5e-324, 1e300, -1e300, 1.7976931348623157e308,
                                          kInf,  -kInf, std::numeric_limits<double>::quiet_NaN(), 100.0, 3.0};
    return wire_fuzz::special_or_raw(in, kSpecial);
}

wire::PipelineSettings read_settings(FuzzedDataProvider& in) {
    wire::PipelineSettings s;
    s.spline.kind = static_cast<wire::SplineKind>(in.ConsumeIntegralInRange<int>(0, 3));
    s.spline.alpha = in.ConsumeBool() ? special_or_raw(in) : in.ConsumeFloatingPointInRange<double>(0.0, 1.0);
    if (in.ConsumeBool()) s.spline.tension = special_or_raw(in);
    if (in.ConsumeBool()) s.spline.bias = special_or_raw(in);
    if (in.ConsumeBool()) s.spline.continuity = special_or_raw(in);
    s.spline.curvature_tension = in.ConsumeBool();
    s.spline.closed = in.ConsumeBool();
    s.spline.radius_m = in.ConsumeBool() ? static_cast<float>(special_or_raw(in)) : 0.01f;
    if (in.ConsumeBool()) s.spline.merge_epsilon_rel = special_or_raw(in);
    if (in.ConsumeBool()) {
        s.tessellate.tolerance_m = special_or_raw(in);
        s.tessellate.max_rings_per_segment = in.ConsumeIntegralInRange<uint32_t>(0, 16);
    } else {
        s.tessellate.rings_per_segment = in.ConsumeIntegralInRange<uint32_t>(0, 4);
    }
    s.tube.sides = in.ConsumeIntegralInRange<uint32_t>(0, 10);
    s.tube.caps = in.ConsumeBool();
    s.tube.tilt_normals = in.ConsumeBool();
    s.frame_method = static_cast<wire::FrameMethod>(in.ConsumeIntegralInRange<int>(0, 2));
    s.pop_free = in.ConsumeBool();
    if (in.ConsumeBool()) {
        s.blend.blend_s = special_or_raw(in);
        s.blend.max_step_m = special_or_raw(in);
        s.blend.max_blend_s = special_or_raw(in);
    }
    return s;
}

wire::WireNodes read_nodes(FuzzedDataProvider& in) {
    wire::WireNodes n;
    const std::size_t count = in.ConsumeIntegralInRange<std::size_t>(0, 64);
    for (std::size_t i = 0; i < count && in.remaining_bytes() > 0; ++i) {
        const uint8_t op = in.ConsumeIntegral<uint8_t>();
        glm::dvec3 p;
        if (op < 16 && !n.positions.empty()) {
            p = n.positions.back();  // exact duplicate
        } else if (op < 32 && !n.positions.empty()) {
            p = n.positions.back() + glm::dvec3(1e-9, 0.0, 0.0);  // near duplicate
        } else if (op < 40 && n.positions.size() >= 2) {
            p = n.positions[n.positions.size() - 2];  // hairpin: straight back
        } else if (op < 48 && !n.positions.empty()) {
            p = n.positions.back() * 1e6;  // spacing ratio jump / far from the origin
        } else if (op < 128) {
            p = glm::dvec3(in.ConsumeFloatingPointInRange<double>(-5.0, 5.0),
                           in.ConsumeFloatingPointInRange<double>(-5.0, 5.0),
                           in.ConsumeFloatingPointInRange<double>(-5.0, 5.0));
        } else {
            p = glm::dvec3(special_or_raw(in), special_or_raw(in), special_or_raw(in));
        }
        n.positions.push_back(p);
    }
    const std::size_t size = n.positions.size();
    const uint8_t extras = in.ConsumeIntegral<uint8_t>();
    if (extras & 1) {
        n.ids.resize(size);
        for (std::size_t i = 0; i < size; ++i) n.ids[i] = in.ConsumeIntegralInRange<uint32_t>(0, 80);
    }
    if (extras & 2)
        for (std::size_t i = 0; i < size; ++i) n.stretch.push_back(static_cast<float>(special_or_raw(in)));
    if (extras & 4)
        for (std::size_t i = 0; i < size; ++i) n.radius_m.push_back(static_cast<float>(special_or_raw(in)));
    if (extras & 8)
        for (std::size_t i = 0; i < size; ++i) {
            n.theta_rad.push_back(special_or_raw(in));
            n.iz_m4.push_back(special_or_raw(in));
            n.length_m.push_back(special_or_raw(in));
            n.delta_length_m.push_back(special_or_raw(in));
            n.area_m2.push_back(special_or_raw(in));
        }
    if (extras & 16)
        for (std::size_t i = 0; i < size; ++i) {
            n.kb_tension.push_back(static_cast<float>(special_or_raw(in)));
            n.kb_bias.push_back(static_cast<float>(special_or_raw(in)));
            n.kb_continuity.push_back(static_cast<float>(special_or_raw(in)));
        }
    // A wrong-length optional array is a caller error the curve stage reports (not an assert): exercise it.
    if ((extras & 32) && !n.stretch.empty()) n.stretch.pop_back();
    return n;
}

/// WIRE_FUZZ_DUMP=1 prints the decoded input (for triaging a crash file by hand).
void dump(const wire::PipelineSettings& s, const wire::WireNodes& n, int state) {
    std::fprintf(stderr,
                 "state %d: kind %d alpha %.17g tension %.17g bias %.17g continuity %.17g curvature_tension %d closed %d "
                 "radius %.9g merge %.17g rings %u tolerance %.17g max_rings %u sides %u caps %d tilt %d frames %d "
                 "pop_free %d blend %.17g s step %.17g max_blend %.17g s\n",
                 state, int(s.spline.kind), s.spline.alpha, s.spline.tension, s.spline.bias, s.spline.continuity,
                 int(s.spline.curvature_tension), int(s.spline.closed), double(s.spline.radius_m),
                 s.spline.merge_epsilon_rel, s.tessellate.rings_per_segment, s.tessellate.tolerance_m,
                 s.tessellate.max_rings_per_segment, s.tube.sides, int(s.tube.caps), int(s.tube.tilt_normals),
                 int(s.frame_method), int(s.pop_free), s.blend.blend_s, s.blend.max_step_m,
                 s.blend.max_blend_s);
    for (std::size_t i = 0; i < n.size(); ++i) {
        std::fprintf(stderr, "  node %zu: %.17g %.17g %.17g", i, n.positions[i].x, n.positions[i].y, n.positions[i].z);
        if (!n.ids.empty()) std::fprintf(stderr, " id %u", n.ids[i]);
        if (i < n.stretch.size()) std::fprintf(stderr, " stretch %.9g", double(n.stretch[i]));
        if (i < n.radius_m.size()) std::fprintf(stderr, " radius %.9g", double(n.radius_m[i]));
        if (i < n.theta_rad.size())
            std::fprintf(stderr, " physics %.17g %.17g %.17g %.17g %.17g", n.theta_rad[i], n.iz_m4[i], n.length_m[i],
                         n.delta_length_m[i], n.area_m2[i]);
        if (i < n.kb_tension.size())
            std::fprintf(stderr, " tcb %.9g %.9g %.9g", double(n.kb_tension[i]), double(n.kb_bias[i]),
                         double(n.kb_continuity[i]));
        std::fprintf(stderr, "\n");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    FuzzedDataProvider in(data, size);
    const wire::PipelineSettings settings = read_settings(in);
    wire::WirePipeline pipeline;
    const int states = in.ConsumeIntegralInRange<int>(1, 3);
    for (int k = 0; k < states; ++k) {
        const wire::WireNodes nodes = read_nodes(in);
        static const bool want_dump = std::getenv("WIRE_FUZZ_DUMP") != nullptr;
        if (want_dump) dump(settings, nodes, k);

        wire::Curve curve;
        const engine::Status cs = wire::build_curve(nodes, settings.spline, curve);
        if (!cs.ok()) {
            wire_fuzz::require(!cs.message.empty(), "build_curve error without a message");
            wire_fuzz::require(curve.segments.empty(), "build_curve error left segments in the output");
        } else {
            for (const wire::CubicBezier& b : curve.segments)
                wire_fuzz::require(wire_fuzz::finite_vec(b.b0) && wire_fuzz::finite_vec(b.b1) &&
                                       wire_fuzz::finite_vec(b.b2) && wire_fuzz::finite_vec(b.b3),
                                   "build_curve control point not finite");
        }

        const engine::Status ps = pipeline.update(nodes, settings);
        if (!ps.ok()) {
            wire_fuzz::require(!ps.message.empty(), "pipeline error without a message");
            continue;
        }
        wire_fuzz::check_pipeline_outputs(pipeline);
    }
    return 0;
}
