// Which stages of the moving path need double and which could run in float (issue 18), measured over the random
// wire families (wire/families.hpp: catenaries, helices, wrapped cables; fixed seed) placed 0, 1e4, 1e6 and 1e8 m
// from the world origin along a random direction. Reference: the runtime's own double pipeline (build_curve,
// build_rings at 4 rings per segment). Each row is the distribution over the cases of each case's largest error.
//   curve, world float:     node positions stored as float in world space, then the double curve stage; the
//                           figure is how much farther from the exact curve the result lies than the double
//                           input's (geometric: families::max_deviation_m; a change of parametrization along the
//                           same line, e.g. a straight run whose float rounding noise the automatic spline reads as
//                           a taut zig-zag, moves no point off the curve and costs nothing here)
//   curve, relative float:  the same with positions stored as float relative to the wire's first node (camera- or
//                           wire-relative storage)
//   rings, relative float:  the ring stage in float on the double curve's control points made relative to the
//                           wire's origin (ring 0): centres, unit tangents, double-reflection frames, texture u by
//                           the same 3-point Gauss rule
// Usage: example_float_precision [cases_per_family=60]
#include "wire/testing/families.hpp"
#include "wire/packed_nodes.hpp"  // float_point
#include "wire/rings.hpp"
#include "wire/spline.hpp"
#include "wire/tessellate.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace {

using glm::dvec3;
using glm::vec3;

struct RingErrors {
    double centre_m = 0.0;    // largest ring-centre distance to the reference
    double normal_rad = 0.0;  // largest angle between normals
    double u_rel = 0.0;       // largest |u - u_ref| / (u span of the wire)
};

// The ring stage in float, relative to ring 0 (the scheme the 48-byte Ring already uses for its centre).
RingErrors float_rings(const wire::Curve& c, const std::vector<wire::RingParam>& params, const wire::RingSet& ref) {
    RingErrors e;
    const std::size_t n = params.size();
    const dvec3 o = ref.origin_m;
    std::vector<vec3> cen(n), tan(n);
    std::vector<float> u(n, 0.0f);
    constexpr float kX[3] = {0.1127016654f, 0.5f, 0.8872983346f}, kW[3] = {0.2777777778f, 0.4444444444f, 0.2777777778f};
    auto control = [&](uint32_t seg, vec3 (&b)[4]) {
        const wire::CubicBezier& z = c.segments[seg];
        b[0] = vec3(z.b0 - o), b[1] = vec3(z.b1 - o), b[2] = vec3(z.b2 - o), b[3] = vec3(z.b3 - o);
    };
    auto derivative = [](const vec3 (&b)[4], float t) {
        const float s = 1.0f - t;
        return 3.0f * s * s * (b[1] - b[0]) + 6.0f * s * t * (b[2] - b[1]) + 3.0f * t * t * (b[3] - b[2]);
    };
    for (std::size_t i = 0; i < n; ++i) {
        vec3 b[4];
        control(params[i].segment, b);
        const float t = static_cast<float>(params[i].t), s = 1.0f - t;
        cen[i] = s * s * s * b[0] + 3.0f * s * s * t * b[1] + 3.0f * s * t * t * b[2] + t * t * t * b[3];
        tan[i] = glm::normalize(derivative(b, t));
        e.centre_m = std::max(e.centre_m, glm::length(dvec3(cen[i]) - ref.centre_m[i]));
        if (i + 1 < n) {  // u over the interval to the next ring (rings never skip a segment at 4 per segment)
            const float tb = params[i + 1].segment == params[i].segment ? static_cast<float>(params[i + 1].t) : 1.0f;
            float du = 0.0f;
            for (int k = 0; k < 3; ++k) {
                const float tt = t + (tb - t) * kX[k];
                du += (tb - t) * kW[k] * glm::length(derivative(b, tt));
            }
            const float stretch = params[i].segment < c.stretch.size() ? c.stretch[params[i].segment] : 1.0f;
            u[i + 1] = u[i] + du / (6.2831853f * ref.rings[i].radius_m * stretch);
        }
    }
    // Frames: double reflection in float from ring 0's normal.
    vec3 r(ref.frames[0].r);
    const double u_span = std::max(1e-30, ref.u[n - 1] - ref.u[0]);
    for (std::size_t i = 1; i < n; ++i) {
        const vec3 v1 = cen[i] - cen[i - 1];
        const float c1 = glm::dot(v1, v1);
        if (c1 > 0.0f) {
            const vec3 rl = r - (2.0f / c1) * glm::dot(v1, r) * v1;
            const vec3 tl = tan[i - 1] - (2.0f / c1) * glm::dot(v1, tan[i - 1]) * v1;
            const vec3 v2 = tan[i] - tl;
            const float c2 = glm::dot(v2, v2);
            r = c2 > 0.0f ? rl - (2.0f / c2) * glm::dot(v2, rl) * v2 : rl;
        }
        const double cosang = std::clamp(glm::dot(glm::normalize(dvec3(r)), ref.frames[i].r), -1.0, 1.0);
        e.normal_rad = std::max(e.normal_rad, std::acos(cosang));
        e.u_rel = std::max(e.u_rel, std::abs((u[i] - ref.u[i]) + ref.u[0]) / u_span);
    }
    return e;
}

void row(const char* what, const char* unit, double offset, const std::vector<double>& v,
         const std::vector<const wire::families::Case*>& who) {
    const wire::families::Stats s = wire::families::stats(v);
    const std::string worst = s.worst < who.size() ? who[s.worst]->family + ": " + who[s.worst]->label : "";
    std::printf("| %s | %.0e | %zu | %.3g | %.3g | %.3g | %s | %s |\n", what, offset, v.size(), s.median, s.p90, s.max,
                unit, worst.c_str());
}

}  // namespace

int main(int argc, char** argv) {
    int per_family = 60;
    if (argc > 1) {
        const std::string arg = argv[1];
        char* end = nullptr;
        const long v = std::strtol(arg.c_str(), &end, 10);
        if (arg == "-h" || arg == "--help" || end == arg.c_str() || *end != '\0' || v < 1 || v > 100000 || argc > 2) {
            std::fprintf(arg == "-h" || arg == "--help" ? stdout : stderr,
                         "Usage: example_float_precision [cases_per_family=60]  (1..100000)\n"
                         "Which stages of the moving path need double: random family wires 0-1e8 m from the origin, "
                         "curve input stored in float, ring stage in float; distribution per stage and offset.\n");
            return arg == "-h" || arg == "--help" ? 0 : 2;
        }
        per_family = static_cast<int>(v);
    }
    constexpr uint64_t kSeed = 20261124;
    std::vector<wire::families::Case> cases = wire::families::catenaries(kSeed, per_family);
    for (auto& c : wire::families::helices(kSeed, per_family)) cases.push_back(std::move(c));
    for (auto& c : wire::families::wrapped(kSeed, per_family)) cases.push_back(std::move(c));
    std::mt19937_64 rng(kSeed);
    std::normal_distribution<double> gauss;

    std::printf("%zu wires (catenaries, helices, wrapped cables; %d each), 4 rings per segment; per case the largest "
                "error against the double pipeline\n\n",
                cases.size(), per_family);
    std::printf("| stage in float | offset m | cases | median | p90 | max | unit | worst case |\n| --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for (const double offset : {0.0, 1e4, 1e6, 1e8}) {
        std::vector<double> world, relative, ring_centre, ring_normal, ring_u;
        std::vector<const wire::families::Case*> world_case, relative_case, ring_case;
        for (const wire::families::Case& base : cases) {
            const dvec3 dir = glm::normalize(dvec3(gauss(rng), gauss(rng), gauss(rng)));
            wire::WireNodes nodes = base.nodes;
            for (dvec3& p : nodes.positions) p += offset * dir;
            const wire::SplineSettings settings{.kind = wire::SplineKind::automatic};
            wire::Curve curve;
            if (!wire::build_curve(nodes, settings, curve).ok()) continue;
            std::vector<uint32_t> counts(curve.segment_count(), 4);
            std::vector<wire::RingParam> params;
            wire::place_rings(curve, counts, params);
            wire::RingSet ref;
            wire::build_rings(curve, params, {}, ref);
            // Curve stage fed float positions: world space, and relative to the first node. The exact curve moved
            // with the wire (the truth is a function of the case's own coordinates).
            wire::families::Case shifted = base;
            shifted.nodes = nodes;
            shifted.truth = [&base, offset, dir](double s) { return base.truth(s) + offset * dir; };
            const double exact_dev = wire::families::max_deviation_m(shifted, curve);
            wire::WireNodes wf = nodes, rf = nodes;
            const dvec3 first = nodes.positions.front();
            // wire::float_point, not dvec3(vec3(p)): GCC 12 -O3 drops that round trip for two lanes.
            for (dvec3& p : wf.positions) p = wire::float_point(p);
            for (dvec3& p : rf.positions) p = first + wire::float_point(p - first);
            wire::Curve cw, cr;
            if (wire::build_curve(wf, settings, cw).ok() && cw.segment_count() == curve.segment_count()) {
                world.push_back(std::max(0.0, wire::families::max_deviation_m(shifted, cw) - exact_dev));
                world_case.push_back(&base);
            }
            if (wire::build_curve(rf, settings, cr).ok() && cr.segment_count() == curve.segment_count()) {
                relative.push_back(std::max(0.0, wire::families::max_deviation_m(shifted, cr) - exact_dev));
                relative_case.push_back(&base);
            }
            const RingErrors re = float_rings(curve, params, ref);
            ring_centre.push_back(re.centre_m);
            ring_normal.push_back(re.normal_rad);
            ring_u.push_back(re.u_rel);
            ring_case.push_back(&base);
        }
        row("curve, world float", "m", offset, world, world_case);
        row("curve, relative float", "m", offset, relative, relative_case);
        row("rings, relative float: centres", "m", offset, ring_centre, ring_case);
        row("rings, relative float: normals", "rad", offset, ring_normal, ring_case);
        row("rings, relative float: u", "of the wire's u", offset, ring_u, ring_case);
    }
    return 0;
}
