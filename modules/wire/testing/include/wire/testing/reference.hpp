// Exact references for accuracy tests: the catenary of DESIGN 4.8 (hanging cable of given length).
#pragma once

#include "wire/status.hpp"

#include <glm/vec3.hpp>

#include <vector>

namespace wire {

/// A catenary hanging between p1 and p2 with arc length length_m (> chord), gravity along -up.
/// Solved as DESIGN 4.8: Newton on ln(sinh(xi)/xi) = ln(r), r = sqrt(L^2 - dy^2)/dx (series below 0.01,
/// overflow-free ln sinh above), a = dx/(2 xi), x0 = dx/2 - a artanh(dy/L), u1 = -x0/a, and the
/// cancellation-free height y(x) = 2a sinh((u+u1)/2) sinh((u-u1)/2), u = (x-x0)/a (x from p1 along the span).
/// Relative accuracy ~1e-15 of the span for any sag, from nearly taut (a = 1e9 m) to deep.
class Catenary {
public:
    /// Fails (with a message) when the input is not finite, the ends are vertically aligned, or L <= chord.
    [[nodiscard]] Status solve(const glm::dvec3& p1, const glm::dvec3& p2, double length_m,
                               const glm::dvec3& up = glm::dvec3(0.0, 1.0, 0.0));

    [[nodiscard]] double a() const { return a_; }
    [[nodiscard]] double xi() const { return xi_; }
    [[nodiscard]] double length_m() const { return length_; }
    [[nodiscard]] double span_m() const { return dx_; }

    /// Height above p1 at horizontal distance x from p1 (metres), its slope dy/dx and second derivative.
    [[nodiscard]] double height(double x) const;
    [[nodiscard]] double slope(double x) const;
    /// Arc length from p1 to horizontal distance x, and its inverse (x for arc length s in [0, L]).
    [[nodiscard]] double arc_length_at(double x) const;
    [[nodiscard]] double x_at_arc_length(double s) const;
    /// World point at horizontal distance x / at arc length s from p1.
    [[nodiscard]] glm::dvec3 point_at_x(double x) const;
    [[nodiscard]] glm::dvec3 point_at_arc_length(double s) const;
    /// Points at the given arc lengths (any spacing, e.g. dense near the ends).
    [[nodiscard]] std::vector<glm::dvec3> points_at_arc_lengths(const std::vector<double>& s) const;
    /// Distance from p to the catenary (x restricted to [0, span]): dense bracket + Newton on the foot point.
    [[nodiscard]] double distance(const glm::dvec3& p) const;

private:
    glm::dvec3 p1_{}, across_{}, up_{}, side_{};
    double dx_ = 0.0, dy_ = 0.0, length_ = 0.0, xi_ = 0.0, a_ = 0.0, x0_ = 0.0, u1_ = 0.0;
};

}  // namespace wire
