// Exact cubic Bezier operations used by the curve stage, multiresolution and the measurements.
#include "wire/bezier.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace wire {
namespace {

// Split at t: returns the left part [0,t] (right = false) or the right part [t,1].
CubicBezier split(const CubicBezier& c, double t, bool right) {
    const glm::dvec3 p01 = glm::mix(c.b0, c.b1, t), p12 = glm::mix(c.b1, c.b2, t), p23 = glm::mix(c.b2, c.b3, t);
    const glm::dvec3 p012 = glm::mix(p01, p12, t), p123 = glm::mix(p12, p23, t);
    const glm::dvec3 p = glm::mix(p012, p123, t);
    if (right) return {p, p123, p23, c.b3};
    return {c.b0, p01, p012, p};
}

constexpr std::array<double, 8> kGaussX = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274,
                                           0.6178762444026438, 0.7554044083550030, 0.8656312023878318,
                                           0.9445750230732326, 0.9894009349916499};
constexpr std::array<double, 8> kGaussW = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025,
                                           0.1495959888165767, 0.1246289712555339, 0.0951585116824928,
                                           0.0622535239386479, 0.0271524594117541};

double gauss_length(const CubicBezier& c, double a, double b) {
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    double sum = 0.0;
    for (std::size_t i = 0; i < kGaussX.size(); ++i) {
        sum += kGaussW[i] * (glm::length(derivative(c, mid + half * kGaussX[i])) +
                             glm::length(derivative(c, mid - half * kGaussX[i])));
    }
    return sum * half;
}

double point_segment_distance2(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    double t = len2 > 0.0 ? glm::dot(p - a, ab) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const glm::dvec3 d = p - (a + t * ab);
    return glm::dot(d, d);
}

double directed_distance(const std::vector<glm::dvec3>& from, const std::vector<glm::dvec3>& to) {
    double worst2 = 0.0;
    if (to.size() == 1) {
        for (const glm::dvec3& p : from) worst2 = std::max(worst2, glm::dot(p - to[0], p - to[0]));
        return std::sqrt(worst2);
    }
    // Exact, with pruning: pieces are grouped in blocks with bounding spheres; blocks are visited outward from
    // the block that held the previous point's nearest piece, skipped when their sphere is farther than the
    // best distance so far, and the scan stops once this point cannot raise the maximum.
    constexpr std::size_t kBlock = 16;
    const std::size_t pieces = to.size() - 1, blocks = (pieces + kBlock - 1) / kBlock;
    std::vector<glm::dvec3> centre(blocks);
    std::vector<double> radius(blocks);
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::size_t first = b * kBlock, last = std::min(pieces, first + kBlock);  // points first..last
        glm::dvec3 lo = to[first], hi = to[first];
        for (std::size_t i = first; i <= last; ++i) lo = glm::min(lo, to[i]), hi = glm::max(hi, to[i]);
        centre[b] = 0.5 * (lo + hi);
        radius[b] = 0.5 * glm::length(hi - lo);
    }
    std::size_t hint = 0;
    for (const glm::dvec3& p : from) {
        double best2 = std::numeric_limits<double>::infinity();
        std::size_t best_block = hint;
        bool done = false;
        for (std::size_t step = 0; step < 2 * blocks && !done; ++step) {
            const std::size_t off = (step + 1) / 2;
            std::size_t b;
            if (step % 2 == 0) {
                if (hint + off >= blocks) continue;
                b = hint + off;
            } else {
                if (off > hint) continue;
                b = hint - off;
            }
            const double lb = std::max(0.0, glm::length(p - centre[b]) - radius[b]);
            if (lb * lb >= best2) continue;
            const std::size_t first = b * kBlock, last = std::min(pieces, first + kBlock);
            for (std::size_t i = first; i < last; ++i) {
                const double d2 = point_segment_distance2(p, to[i], to[i + 1]);
                if (d2 < best2) best2 = d2, best_block = b;
            }
            done = best2 <= worst2;  // cannot raise the maximum any more
        }
        hint = best_block;
        worst2 = std::max(worst2, best2);
    }
    return std::sqrt(worst2);
}

}  // namespace

// The one evaluation used for cut points, so the two pieces on either side of a cut share it bit for bit.
glm::dvec3 cut_point(const CubicBezier& c, double t) {
    if (t <= 0.0) return c.b0;
    if (t >= 1.0) return c.b3;
    return split(c, t, false).b3;
}

CubicBezier sub_segment(const CubicBezier& c, double t0, double t1) {
    if (t0 <= 0.0 && t1 >= 1.0) return c;
    CubicBezier out;
    if (t0 <= 0.0) out = split(c, t1, false);
    else if (t1 >= 1.0) out = split(c, t0, true);
    else out = split(split(c, t0, true), (t1 - t0) / (1.0 - t0), false);
    out.b0 = cut_point(c, t0);
    out.b3 = cut_point(c, t1);
    return out;
}

double arc_length_m(const CubicBezier& c) { return gauss_length(c, 0.0, 0.5) + gauss_length(c, 0.5, 1.0); }

double arc_length_m(const Curve& curve) {
    double sum = 0.0;
    for (const CubicBezier& s : curve.segments) sum += arc_length_m(s);
    return sum;
}

std::vector<glm::dvec3> sample_curve(const Curve& curve, int per_segment) {
    std::vector<glm::dvec3> out;
    per_segment = std::max(per_segment, 1);
    out.reserve(curve.segments.size() * static_cast<std::size_t>(per_segment) + 1);
    for (const CubicBezier& s : curve.segments) {
        for (int i = 0; i < per_segment; ++i) out.push_back(position(s, static_cast<double>(i) / per_segment));
    }
    if (!curve.segments.empty()) out.push_back(curve.segments.back().b3);
    return out;
}

double closest_parameter(const CubicBezier& c, const glm::dvec3& p) {
    constexpr int kScan = 64;
    double best_t = 0.0, best_d2 = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= kScan; ++i) {
        const double t = static_cast<double>(i) / kScan;
        const glm::dvec3 d = position(c, t) - p;
        if (glm::dot(d, d) < best_d2) best_d2 = glm::dot(d, d), best_t = t;
    }
    // Newton on f(t) = (B(t)-p).B'(t) = 0, kept inside the scan cell.
    const double lo = std::max(0.0, best_t - 1.0 / kScan), hi = std::min(1.0, best_t + 1.0 / kScan);
    double t = best_t;
    bool converged = false;
    for (int it = 0; it < 8 && !converged; ++it) {
        const glm::dvec3 d = position(c, t) - p, d1 = derivative(c, t), d2 = second_derivative(c, t);
        const double f = glm::dot(d, d1), fp = glm::dot(d1, d1) + glm::dot(d, d2);
        if (!(fp > 0.0)) break;
        const double next = std::clamp(t - f / fp, lo, hi);
        converged = std::abs(next - t) < 1e-15;
        t = next;
    }
    if (!converged) {
        // Newton crawls where the derivative vanishes (a segment with a zero end tangent: tension 1, a merged
        // node): bisect f on the scan cell instead, where it changes sign.
        auto f = [&](double x) { return glm::dot(position(c, x) - p, derivative(c, x)); };
        double a = lo, b = hi;
        if (f(a) <= 0.0 && f(b) >= 0.0) {
            for (int it = 0; it < 60 && b - a > 1e-16; ++it) {
                const double m = 0.5 * (a + b);
                (f(m) <= 0.0 ? a : b) = m;
            }
            const double bt = 0.5 * (a + b);
            const glm::dvec3 db = position(c, bt) - p, dt = position(c, t) - p;
            if (glm::dot(db, db) < glm::dot(dt, dt)) t = bt;
        }
    }
    const glm::dvec3 dn = position(c, t) - p;
    return glm::dot(dn, dn) <= best_d2 ? t : best_t;
}

double distance_to_polyline(const glm::dvec3& p, const std::vector<glm::dvec3>& points) {
    if (points.empty()) return std::numeric_limits<double>::infinity();
    if (points.size() == 1) return glm::length(p - points[0]);
    double best2 = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i + 1 < points.size(); ++i) best2 = std::min(best2, point_segment_distance2(p, points[i], points[i + 1]));
    return std::sqrt(best2);
}

double curve_jump_m(const Curve& before, const Curve& after, int per_segment) {
    const std::vector<glm::dvec3> a = sample_curve(before, per_segment), b = sample_curve(after, per_segment);
    if (a.empty() || b.empty()) return a.empty() && b.empty() ? 0.0 : std::numeric_limits<double>::infinity();
    return std::max(directed_distance(b, a), directed_distance(a, b));
}

}  // namespace wire
