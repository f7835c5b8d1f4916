// The exact catenary reference (DESIGN 4.8).
#include "wire/testing/reference.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace wire {
namespace {

// ln(sinh(xi)/xi) and its derivative coth(xi) - 1/xi, both accurate for tiny and huge xi.
double log_sinhc(double xi) {
    if (xi < 0.01) {
        const double x2 = xi * xi;
        return x2 / 6.0 - x2 * x2 / 180.0 + x2 * x2 * x2 / 2835.0;
    }
    return xi + std::log1p(-std::exp(-2.0 * xi)) - std::numbers::ln2 - std::log(xi);
}
double log_sinhc_derivative(double xi) {
    if (xi < 0.01) {
        const double x2 = xi * xi;
        return xi / 3.0 - xi * x2 / 45.0 + 2.0 * xi * x2 * x2 / 945.0;
    }
    return 1.0 / std::tanh(xi) - 1.0 / xi;
}

}  // namespace

Status Catenary::solve(const glm::dvec3& p1, const glm::dvec3& p2, double length_m, const glm::dvec3& up) {
    for (int i = 0; i < 3; ++i) {
        if (!std::isfinite(p1[i]) || !std::isfinite(p2[i]) || !std::isfinite(up[i])) return Status::error("catenary: non-finite end point or up vector");
    }
    if (!std::isfinite(length_m)) return Status::error("catenary: non-finite length");
    const double ul = glm::length(up);
    if (!(ul > 0.0)) return Status::error("catenary: zero up vector");
    up_ = up / ul;
    const glm::dvec3 d = p2 - p1;
    dy_ = glm::dot(d, up_);
    const glm::dvec3 horiz = d - dy_ * up_;
    dx_ = glm::length(horiz);
    if (!(dx_ > 0.0)) return Status::error("catenary: end points are vertically aligned (no horizontal run)");
    if (!(length_m > glm::length(d))) return Status::error("catenary: length must exceed the chord");
    p1_ = p1, across_ = horiz / dx_, side_ = glm::cross(across_, up_), length_ = length_m;

    // r - 1 without cancellation: sqrt(L^2 - dy^2)/dx - 1.
    const double q = std::sqrt((length_m - dy_) * (length_m + dy_));
    const double log_r = std::log(q / dx_);
    const double r = q / dx_;
    double xi = r < 3.0 ? std::sqrt(6.0 * (r - 1.0)) : std::log(2.0 * r) + std::log(std::log(2.0 * r));
    for (int it = 0; it < 100; ++it) {
        const double f = log_sinhc(xi) - log_r, fp = log_sinhc_derivative(xi);
        if (!(fp > 0.0)) break;
        double next = xi - f / fp;
        if (!(next > 0.0)) next = 0.5 * xi;  // stay in the positive branch
        const bool done = std::abs(next - xi) <= 1e-15 * xi;
        xi = next;
        if (done) break;
    }
    xi_ = xi;
    a_ = dx_ / (2.0 * xi_);
    x0_ = dx_ / 2.0 - a_ * std::atanh(dy_ / length_m);
    u1_ = -x0_ / a_;
    return Status::success();
}

double Catenary::height(double x) const {
    const double u = (x - x0_) / a_;
    return 2.0 * a_ * std::sinh((u + u1_) / 2.0) * std::sinh((u - u1_) / 2.0);
}
double Catenary::slope(double x) const { return std::sinh((x - x0_) / a_); }
double Catenary::arc_length_at(double x) const {
    const double u = (x - x0_) / a_;
    // a (sinh u - sinh u1) = 2a cosh((u+u1)/2) sinh((u-u1)/2): no cancellation near x = 0.
    return 2.0 * a_ * std::cosh((u + u1_) / 2.0) * std::sinh((u - u1_) / 2.0);
}
double Catenary::x_at_arc_length(double s) const { return x0_ + a_ * std::asinh(s / a_ + std::sinh(u1_)); }
glm::dvec3 Catenary::point_at_x(double x) const { return p1_ + x * across_ + height(x) * up_; }
glm::dvec3 Catenary::point_at_arc_length(double s) const {
    if (s <= 0.0) return p1_;
    return point_at_x(x_at_arc_length(s));
}
std::vector<glm::dvec3> Catenary::points_at_arc_lengths(const std::vector<double>& s) const {
    std::vector<glm::dvec3> out;
    out.reserve(s.size());
    for (double v : s) out.push_back(point_at_arc_length(v));
    return out;
}

double Catenary::distance(const glm::dvec3& p) const {
    const glm::dvec3 rel = p - p1_;
    const double px = glm::dot(rel, across_), py = glm::dot(rel, up_), pz = glm::dot(rel, side_);
    // In the catenary's plane: minimize g(x) = (x-px)^2 + (y(x)-py)^2 over [0, dx].
    auto g = [&](double x) { const double ex = x - px, ey = height(x) - py; return ex * ex + ey * ey; };
    constexpr int kScan = 256;
    double best_x = 0.0, best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= kScan; ++i) {
        const double x = dx_ * i / kScan;
        if (const double v = g(x); v < best) best = v, best_x = x;
    }
    const double lo = std::max(0.0, best_x - dx_ / kScan), hi = std::min(dx_, best_x + dx_ / kScan);
    double x = best_x;
    for (int it = 0; it < 20; ++it) {
        const double yx = height(x), s = slope(x), c2 = std::cosh((x - x0_) / a_) / a_;
        const double f = (x - px) + (yx - py) * s, fp = 1.0 + s * s + (yx - py) * c2;
        if (!(fp > 0.0)) break;
        const double next = std::clamp(x - f / fp, lo, hi);
        if (std::abs(next - x) <= 1e-16 * dx_) { x = next; break; }
        x = next;
    }
    const double in_plane = std::min(g(x), best);
    return std::sqrt(in_plane + pz * pz);
}

}  // namespace wire
