// The accuracy bench's methods (methods.hpp).
#include "bench/accuracy/methods.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace wiretool::bench {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr float kRadiusM = 0.01f;  // the reference wires' radius

}  // namespace

std::vector<Method> methods() {
    using wire::SplineKind;
    return {
        {"linear", {.kind = SplineKind::linear}, {}, false, "linear"},
        {"uniform", {.kind = SplineKind::catmull_rom, .alpha = 0.0}, {}, false, "uniform"},
        {"centripetal", {.kind = SplineKind::catmull_rom, .alpha = 0.5}, {}, false, "centripetal"},
        {"chordal", {.kind = SplineKind::catmull_rom, .alpha = 1.0}, {}, false, "chordal"},
        {"c2", {.kind = SplineKind::c2}, {}, false, "c2"},
        {"auto", {.kind = SplineKind::automatic}, {}, false, "auto"},
        {"curvature_tension",
         {.kind = SplineKind::catmull_rom, .alpha = 0.5, .curvature_tension = true},
         {},
         true,
         "curvature_tension"},
        {"centripetal+rotation",
         {.kind = SplineKind::catmull_rom, .alpha = 0.5},
         wire::FrameMethod::rotation,
         false,
         "centripetal"},
        {"centripetal+projection",
         {.kind = SplineKind::catmull_rom, .alpha = 0.5},
         wire::FrameMethod::projection,
         false,
         "centripetal"},
    };
}

void add_physics(wire::WireNodes& n, float stretch) {
    const std::size_t count = n.positions.size();
    n.theta_rad.assign(count, 0.0);
    n.iz_m4.assign(count, kPi * std::pow(kRadiusM, 4) / 4.0);
    n.area_m2.assign(count, kPi * kRadiusM * kRadiusM);
    n.length_m.assign(count, 0.0);
    n.delta_length_m.assign(count, 0.0);
    for (std::size_t i = 0; i < count; ++i) {
        const glm::dvec3 in = i > 0 ? n.positions[i] - n.positions[i - 1] : glm::dvec3(0.0);
        const glm::dvec3 out = i + 1 < count ? n.positions[i + 1] - n.positions[i] : glm::dvec3(0.0);
        const double li = glm::length(in), lo = glm::length(out);
        if (li > 0.0 && lo > 0.0)
            n.theta_rad[i] = std::acos(std::clamp(glm::dot(in, out) / (li * lo), -1.0, 1.0));
        n.length_m[i] = li + lo;
        n.delta_length_m[i] = (li + lo) * (static_cast<double>(stretch) - 1.0);
    }
}

}  // namespace wiretool::bench
