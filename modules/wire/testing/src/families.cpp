// Random families of realistic wires with an exact answer (see families.hpp).
#include "wire/testing/families.hpp"
#include "wire/testing/random.hpp"

#include "wire/bezier.hpp"
#include "wire/testing/reference.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace wire::families {
namespace {

using glm::dvec3;
constexpr double kPi = std::numbers::pi;

using Rng = testing::Random;

Rng case_rng(uint64_t seed, int index) { return Rng{seed * 0x100000001B3ull + static_cast<uint64_t>(index) * 0x9E3779B97F4A7C15ull}; }

/// A unit vector perpendicular to d (any).
dvec3 perpendicular(const dvec3& d) {
    const dvec3 a = std::abs(d.x) < 0.6 ? dvec3(1.0, 0.0, 0.0) : dvec3(0.0, 1.0, 0.0);
    return glm::normalize(glm::cross(d, a));
}

/// A random rotation (orthonormal basis) as three columns.
struct Frame {
    dvec3 x, y, z;
    [[nodiscard]] dvec3 apply(const dvec3& p) const { return p.x * x + p.y * y + p.z * z; }
};
Frame random_frame(Rng& r) {
    Frame f;
    f.x = r.unit();
    const dvec3 p = perpendicular(f.x);
    const dvec3 q = glm::cross(f.x, p);
    const double a = r.uniform(0.0, 2.0 * kPi);
    f.y = std::cos(a) * p + std::sin(a) * q;
    f.z = glm::cross(f.x, f.y);
    return f;
}

void finish(Case& c, Rng& r, double stretch_lo, double stretch_hi) {
    c.nodes.positions.clear();
    for (double p : c.node_param) c.nodes.positions.push_back(c.truth(p));
    c.nodes.ids.clear();
    for (std::size_t i = 0; i < c.node_param.size(); ++i) c.nodes.ids.push_back(static_cast<uint32_t>(100 + 10 * i));
    c.nodes.stretch.clear();
    for (std::size_t i = 0; i < c.node_param.size(); ++i)
        c.nodes.stretch.push_back(static_cast<float>(r.uniform(stretch_lo, stretch_hi)));
}

/// n increasing parameters from 0 to total: 0 uniform, 1 end-dense (1-cos), 2 jittered (+-35% of a step),
/// 3 end-dense and jittered.
std::vector<double> spacing(Rng& r, int n, double total, int kind, double jitter = 0.35) {
    std::vector<double> s(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        double f = static_cast<double>(i) / (n - 1);
        if ((kind == 2 || kind == 3) && i > 0 && i + 1 < n) f += r.uniform(-jitter, jitter) / (n - 1);
        if (kind == 1 || kind == 3) f = 0.5 * (1.0 - std::cos(kPi * f));
        s[static_cast<std::size_t>(i)] = total * f;
    }
    return s;
}

const char* spacing_name(int kind) {
    static const char* const names[] = {"uniform", "end-dense", "jittered", "end-dense+jittered"};
    return names[kind];
}

std::string fmt(const char* f, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
    char buf[160];
    std::snprintf(buf, sizeof buf, f, a, b, c, d);
    return buf;
}

}  // namespace

std::vector<Case> catenaries(uint64_t seed, int count) {
    std::vector<Case> out;
    for (int i = 0; i < count; ++i) {
        Rng r = case_rng(seed, i);
        const double span = r.uniform(5.0, 60.0), rise = r.uniform(-50.0, 50.0) * kPi / 180.0;
        const double slack = r.log_uniform(0.005, 0.40);
        const int n = r.integer(5, 40), kind = r.integer(0, 3);
        const dvec3 up = r.unit(), across = perpendicular(up);
        const double spin = r.uniform(0.0, 2.0 * kPi);
        const dvec3 horiz = std::cos(spin) * across + std::sin(spin) * glm::cross(up, across);
        const dvec3 p1 = 10.0 * r.unit(), p2 = p1 + span * horiz + span * std::tan(rise) * up;
        const double L = glm::length(p2 - p1) * (1.0 + slack);
        Catenary cat;
        if (!cat.solve(p1, p2, L, up).ok()) continue;  // cannot happen for these ranges (not vertical, L > chord)
        Case c;
        c.family = "catenary";
        c.label = fmt("span %.1f m, rise %.0f deg, slack %.1f%%, ", span, rise * 180.0 / kPi, 100.0 * slack) +
                  std::to_string(n) + " nodes " + spacing_name(kind);
        c.node_param = spacing(r, n, L, kind);
        c.truth = [cat](double s) { return cat.point_at_arc_length(s); };
        finish(c, r, 0.995, 1.0);
        out.push_back(std::move(c));
    }
    return out;
}

std::vector<Case> zigzags(uint64_t seed, int count) {
    std::vector<Case> out;
    for (int i = 0; i < count; ++i) {
        Rng r = case_rng(seed ^ 0x5A5A5A5Aull, i);
        const int corners = r.integer(1, 4);
        std::vector<dvec3> pts{10.0 * r.unit()};
        std::vector<uint8_t> corner{0};
        dvec3 dir = r.unit();
        double min_turn = 180.0, max_turn = 0.0;
        for (int run = 0; run <= corners; ++run) {
            const int inner = r.integer(2, 5);  // collinear nodes strictly between the run's ends
            const double h = r.uniform(0.3, 3.0);
            for (int k = 0; k <= inner; ++k) {
                pts.push_back(pts.back() + h * r.uniform(0.7, 1.3) * dir);
                corner.push_back(0);
            }
            if (run < corners) {  // turn at the run's last node
                corner.back() = 1;
                const double turn = r.uniform(20.0, 120.0);
                min_turn = std::min(min_turn, turn), max_turn = std::max(max_turn, turn);
                const dvec3 p = perpendicular(dir), q = glm::cross(dir, p);
                const double a = r.uniform(0.0, 2.0 * kPi);
                const dvec3 axis = std::cos(a) * p + std::sin(a) * q;
                const double t = turn * kPi / 180.0;
                dir = glm::normalize(std::cos(t) * dir + std::sin(t) * glm::cross(axis, dir));
            }
        }
        Case c;
        c.family = "zigzag";
        c.label = std::to_string(corners) + " corners turning " + fmt("%.0f-%.0f deg, ", min_turn, max_turn) +
                  std::to_string(pts.size()) + " nodes";
        for (std::size_t k = 0; k < pts.size(); ++k) c.node_param.push_back(static_cast<double>(k));
        c.truth = [pts](double t) {
            const std::size_t k = std::min(static_cast<std::size_t>(std::max(t, 0.0)), pts.size() - 2);
            const double u = t - static_cast<double>(k);
            return (1.0 - u) * pts[k] + u * pts[k + 1];
        };
        c.corner = corner;
        finish(c, r, 1.02, 1.10);
        out.push_back(std::move(c));
    }
    return out;
}

std::vector<Case> helices(uint64_t seed, int count) {
    std::vector<Case> out;
    for (int i = 0; i < count; ++i) {
        Rng r = case_rng(seed ^ 0x3C3C3C3Cull, i);
        const double radius = r.uniform(0.2, 2.0), pitch = r.uniform(0.05, 0.6), turns = r.uniform(0.75, 4.0);
        const int per_turn = r.integer(5, 24);
        const int n = std::max(4, static_cast<int>(std::lround(turns * per_turn)) + 1);
        const int kind = r.integer(0, 1) * 2;  // uniform or jittered
        const Frame f = random_frame(r);
        const dvec3 origin = 10.0 * r.unit();
        Case c;
        c.family = "helix";
        c.label = fmt("radius %.2f m, pitch %.2f m/rad, %.2f turns, ", radius, pitch, turns) + std::to_string(n) +
                  " nodes " + spacing_name(kind);
        c.node_param = spacing(r, n, 2.0 * kPi * turns, kind, 0.3);
        c.truth = [=](double th) { return origin + f.apply(dvec3(radius * std::cos(th), radius * std::sin(th), pitch * th)); };
        finish(c, r, 1.0, 1.0);
        out.push_back(std::move(c));
    }
    return out;
}

std::vector<Case> wrapped(uint64_t seed, int count) {
    std::vector<Case> out;
    for (int i = 0; i < count; ++i) {
        Rng r = case_rng(seed ^ 0x77777777ull, i);
        const double radius = r.log_uniform(0.05, 1.5), wrap = r.uniform(30.0, 180.0) * kPi / 180.0;
        const double arc = radius * wrap, elements_on_arc = r.uniform(1.5, 6.0), h = arc / elements_on_arc;
        const double run1 = std::max(3.0 * h, r.uniform(1.0, 6.0)), run2 = std::max(3.0 * h, r.uniform(1.0, 6.0));
        const double total = run1 + arc + run2;
        const int n = std::max(5, static_cast<int>(std::lround(total / h)) + 1);
        const Frame f = random_frame(r);
        const dvec3 origin = 10.0 * r.unit();
        // In the sheave's plane: in along y = R towards +x, tangent point (0, R), clockwise around the centre
        // (origin) by `wrap`, out along the tangent.
        auto local = [=](double s) {
            if (s <= run1) return dvec3(s - run1, radius, 0.0);
            if (s <= run1 + arc) {
                const double a = (s - run1) / radius;
                return dvec3(radius * std::sin(a), radius * std::cos(a), 0.0);
            }
            const double t = s - run1 - arc;
            return dvec3(radius * std::sin(wrap) + t * std::cos(wrap), radius * std::cos(wrap) - t * std::sin(wrap), 0.0);
        };
        Case c;
        c.family = "wrapped";
        c.label = fmt("radius %.3f m, wrap %.0f deg over %.1f elements, runs %.1f", radius, wrap * 180.0 / kPi,
                      elements_on_arc, run1) +
                  fmt(" / %.1f m, ", run2) + std::to_string(n) + " nodes";
        c.node_param = spacing(r, n, total, 2, 0.15);
        c.truth = [=](double s) { return origin + f.apply(local(s)); };
        finish(c, r, 1.01, 1.05);
        out.push_back(std::move(c));
    }
    return out;
}

namespace {
double segment_distance(const dvec3& p, const dvec3& a, const dvec3& b) {
    const dvec3 d = b - a;
    const double t = std::clamp(glm::dot(p - a, d) / std::max(glm::dot(d, d), 1e-300), 0.0, 1.0);
    return glm::length(p - (a + t * d));
}
}  // namespace

double max_deviation_m(const Case& c, const Curve& curve, int samples_per_segment) {
    if (!c.corner.empty()) {  // zigzag: the truth is the node polyline (exact distance to its nearby pieces)
        const std::vector<dvec3>& x = c.nodes.positions;
        double worst = 0.0;
        for (std::size_t k = 0; k < curve.segment_count() && k + 1 < x.size(); ++k) {
            for (int s = 0; s <= samples_per_segment; ++s) {
                const dvec3 p = position(curve.segments[k], static_cast<double>(s) / samples_per_segment);
                double d = HUGE_VAL;
                for (std::size_t j = k > 0 ? k - 1 : 0; j <= std::min(k + 1, x.size() - 2); ++j) d = std::min(d, segment_distance(p, x[j], x[j + 1]));
                worst = std::max(worst, d);
            }
        }
        return worst;
    }
    // Per segment: bracket the foot point on a table of the truth over the segment's parameter interval
    // (widened by half a neighbour interval), then golden-section search on the exact function.
    constexpr int kTable = 48;
    const std::size_t n = c.node_param.size();
    double worst = 0.0;
    std::vector<double> tp;
    std::vector<dvec3> tx;
    for (std::size_t k = 0; k < curve.segment_count() && k + 1 < n; ++k) {
        const double lo = k > 0 ? 0.5 * (c.node_param[k - 1] + c.node_param[k]) : c.node_param[0];
        const double hi = k + 2 < n ? 0.5 * (c.node_param[k + 1] + c.node_param[k + 2]) : c.node_param[n - 1];
        tp.clear(), tx.clear();
        for (int j = 0; j <= kTable; ++j) {
            tp.push_back(lo + (hi - lo) * j / kTable);
            tx.push_back(c.truth(tp.back()));
        }
        for (int s = 0; s <= samples_per_segment; ++s) {
            const dvec3 p = position(curve.segments[k], static_cast<double>(s) / samples_per_segment);
            std::size_t best = 0;
            double bd = HUGE_VAL;
            for (std::size_t j = 0; j < tx.size(); ++j) {
                const double d = glm::length(tx[j] - p);
                if (d < bd) bd = d, best = j;
            }
            double a = tp[best > 0 ? best - 1 : 0], b = tp[std::min(best + 1, tp.size() - 1)];
            const double g = 0.5 * (std::sqrt(5.0) - 1.0);
            double x1 = b - g * (b - a), x2 = a + g * (b - a);
            double f1 = glm::length(c.truth(x1) - p), f2 = glm::length(c.truth(x2) - p);
            for (int it = 0; it < 28; ++it) {
                if (f1 < f2) b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = glm::length(c.truth(x1) - p);
                else a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = glm::length(c.truth(x2) - p);
            }
            worst = std::max(worst, std::min({bd, f1, f2}));
        }
    }
    return worst;
}

TautNumbers taut_numbers(const Case& c, const Curve& curve, int samples_per_segment) {
    TautNumbers t;
    const std::vector<dvec3>& x = c.nodes.positions;
    const std::size_t n = x.size();
    // Run ends: node 0, every corner, the last node.
    std::vector<std::size_t> ends{0};
    for (std::size_t i = 1; i + 1 < n; ++i)
        if (c.corner[i]) ends.push_back(i);
    ends.push_back(n - 1);
    for (std::size_t r = 0; r + 1 < ends.size(); ++r) {
        const std::size_t a = ends[r], b = ends[r + 1];
        double run = 0.0;
        for (std::size_t k = a; k < b; ++k) run += glm::length(x[k + 1] - x[k]);
        for (std::size_t k = a; k < b && k < curve.segment_count(); ++k) {
            const double h = glm::length(x[k + 1] - x[k]);
            const bool near_corner = (k == a && c.corner[a]) || (k + 1 == b && c.corner[b]);
            for (int s = 0; s <= samples_per_segment; ++s) {
                const dvec3 p = position(curve.segments[k], static_cast<double>(s) / samples_per_segment);
                const double from_corner = std::min(c.corner[a] ? glm::length(p - x[a]) : HUGE_VAL,
                                                    c.corner[b] ? glm::length(p - x[b]) : HUGE_VAL);
                // Distance to the run's segment (not its infinite line): overshooting an end along the line counts.
                if (from_corner > 0.05 * h) t.straight_rel = std::max(t.straight_rel, segment_distance(p, x[a], x[b]) / run);
                if (near_corner) {
                    double poly = HUGE_VAL;
                    for (std::size_t j = (k > 0 ? k - 1 : 0); j <= std::min(k + 1, n - 2); ++j)
                        poly = std::min(poly, segment_distance(p, x[j], x[j + 1]));
                    t.bulge_rel = std::max(t.bulge_rel, poly / h);
                }
            }
        }
    }
    return t;
}

Stats stats(const std::vector<double>& v) {
    Stats s;
    if (v.empty()) return s;
    std::vector<double> sorted = v;
    std::sort(sorted.begin(), sorted.end());
    double sum = 0.0;
    for (double x : v) sum += x;
    s.mean = sum / static_cast<double>(v.size());
    s.median = sorted[(sorted.size() - 1) / 2];
    if (sorted.size() % 2 == 0) s.median = 0.5 * (s.median + sorted[sorted.size() / 2]);
    s.p90 = sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(sorted.size()))) - 1)];
    s.max = sorted.back();
    s.worst = static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());
    return s;
}

}  // namespace wire::families
