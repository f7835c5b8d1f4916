// One bend segment: the stable single-segment map of paper 001 (DESIGN §4.7) for positions and normals.
// Plain double math, no GL: the reference the chain, the GPU records and the GLSL function follow.
#pragma once

#include <glm/vec3.hpp>

namespace curved_space {

/// A segment of the chain. The unbent mesh runs along +z; this segment covers `length_m` of it and turns the
/// centre line (x = y = 0) into a circular arc of that same length, turning by `angle_rad` toward the
/// direction `direction_rad` in the xy-plane (0 bends toward +x, pi/2 toward +y).
struct Segment {
    double length_m = 0.0;       ///< > 0 and finite
    double angle_rad = 0.0;      ///< finite, any sign; 0 is straight
    double direction_rad = 0.0;  ///< finite
};

/// sin(t)/t without dividing by a small t: series 1 - t^2/6 + t^4/120 for |t| < 1e-4 (error < 1e-28),
/// so sinc(0) == 1 exactly. Relative error a few ulp everywhere.
[[nodiscard]] double sinc(double t);

/// A bent point with its normal. `folded` is set when the point lies at or beyond the bend's centre of
/// curvature (1 - kappa*x <= 0 in the bend frame): the map is not a local diffeomorphism there.
struct BentVertex {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0};  ///< unit length (or zero if the input normal was zero)
    bool folded = false;
};

/// The bend of one segment in its own frame (segment start at the origin, unbent axis +z, z is the local
/// coordinate; any z is accepted, the arc simply continues), with kappa = angle/length:
///   q = Rz(-gamma) p, th = kappa*q.z,
///   X = q.x cos(th) + q.z (th/2) sinc(th/2)^2,  Y = q.y,  Z = q.z sinc(th) - q.x sin(th),
///   p' = Rz(gamma) (X, Y, Z).
/// Normals by the inverse transpose of the Jacobian J = Ry(th) diag(1, 1, 1 - kappa q.x):
///   n' ~ Rz(gamma) Ry(th) (m.x, m.y, m.z / (1 - kappa q.x)),  m = Rz(-gamma) n, normalized.
/// Ry(a) takes +z to (sin a, 0, cos a). kappa = 0 is exactly the identity. Finite for finite input.
[[nodiscard]] BentVertex bend_segment(double kappa_per_m, double cos_gamma, double sin_gamma, const glm::dvec3& p,
                                      const glm::dvec3& n);

/// Convenience: the bend of `segment` (kappa = angle/length) at local point p with normal n.
[[nodiscard]] BentVertex bend_segment(const Segment& segment, const glm::dvec3& p, const glm::dvec3& n);

}  // namespace curved_space
