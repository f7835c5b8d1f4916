// The accuracy bench's methods: every spline method with frames by double reflection, plus centripetal with
// the rotation and projection frame baselines.
#pragma once

#include <wire/nodes.hpp>
#include <wire/rings.hpp>

#include <string>
#include <vector>

namespace wiretool::bench {

struct Method {
    std::string name;
    wire::SplineSettings spline;
    wire::FrameMethod frames = wire::FrameMethod::double_reflection;
    bool physics = false;    ///< curvature tension from per-node physics arrays
    std::string spline_key;  ///< methods with the same curve share their pop measurement
};

/// The methods in the order of accuracy.csv's rows.
std::vector<Method> methods();

/// The thesis' physics per node for curvature tension: theta = turning angle, L = the two adjacent elements,
/// dL = L (stretch - 1), a solid round section of the wire's radius (Iz = pi r^4/4, A = pi r^2).
void add_physics(wire::WireNodes& n, float stretch);

}  // namespace wiretool::bench
