// The single-segment bend in double: positions and Jacobian normals, never dividing by the angle.
#include "curved_space/bend.hpp"

#include <cmath>

#include <glm/geometric.hpp>

namespace curved_space {

double sinc(double t) {
    const double t2 = t * t;
    if (std::abs(t) < 1e-4) return 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0);
    return std::sin(t) / t;
}

BentVertex bend_segment(double kappa_per_m, double cos_gamma, double sin_gamma, const glm::dvec3& p,
                        const glm::dvec3& n) {
    // Into the bend frame, where the segment turns toward +x.
    const glm::dvec3 q{cos_gamma * p.x + sin_gamma * p.y, -sin_gamma * p.x + cos_gamma * p.y, p.z};
    const glm::dvec3 m{cos_gamma * n.x + sin_gamma * n.y, -sin_gamma * n.x + cos_gamma * n.y, n.z};

    const double th = kappa_per_m * q.z;
    const double c = std::cos(th);
    const double s = std::sin(th);
    const double half = 0.5 * th;
    const double sinc_half = sinc(half);
    // z (th/2) sinc(th/2)^2 = r (1 - cos th) and z sinc(th) = r sin th with r = 1/kappa, without the 1/kappa.
    const glm::dvec3 b{q.x * c + q.z * half * sinc_half * sinc_half, q.y, q.z * sinc(th) - q.x * s};

    // Normal: Ry(th) (m.x, m.y, m.z / stretch); scaled by |stretch| to avoid the division, which keeps the
    // direction of J^-T m for either sign of the stretch and stays finite at stretch = 0.
    const double stretch = 1.0 - kappa_per_m * q.x;
    const double sign = stretch < 0.0 ? -1.0 : 1.0;
    glm::dvec3 a{std::abs(stretch) * m.x, std::abs(stretch) * m.y, sign * m.z};
    if (glm::dot(a, a) == 0.0) a = m;  // folded exactly at the axis with a purely tangential normal
    const glm::dvec3 nb{c * a.x + s * a.z, a.y, -s * a.x + c * a.z};

    BentVertex out;
    out.position = {cos_gamma * b.x - sin_gamma * b.y, sin_gamma * b.x + cos_gamma * b.y, b.z};
    const glm::dvec3 nw{cos_gamma * nb.x - sin_gamma * nb.y, sin_gamma * nb.x + cos_gamma * nb.y, nb.z};
    const double len = glm::length(nw);
    out.normal = len > 0.0 ? nw / len : nw;
    out.folded = stretch <= 0.0;
    return out;
}

BentVertex bend_segment(const Segment& segment, const glm::dvec3& p, const glm::dvec3& n) {
    return bend_segment(segment.angle_rad / segment.length_m, std::cos(segment.direction_rad),
                        std::sin(segment.direction_rad), p, n);
}

}  // namespace curved_space
