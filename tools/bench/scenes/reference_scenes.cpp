// The accuracy bench's reference scenes (reference_scenes.hpp).
#include "bench/scenes/reference_scenes.hpp"

#include "bench/scenes/camera_paths.hpp"

#include <glm/geometric.hpp>

#include <cmath>
#include <cstddef>
#include <functional>
#include <numbers>

namespace wiretool::bench {
namespace {

constexpr double kPi = std::numbers::pi;

void set_ids(wire::WireNodes& n) {
    n.ids.clear();
    for (std::size_t i = 0; i < n.positions.size(); ++i) n.ids.push_back(static_cast<uint32_t>(100 + 10 * i));
}

/// Nodes at `params` of `curve`, plus the dense truth polyline (`dense_count` samples over [p0, p1]).
void sample_truth(ReferenceScene& s, const std::function<glm::dvec3(double)>& curve,
                  const std::vector<double>& params, double p0, double p1, int dense_count) {
    s.node_param = params;
    for (double p : params) s.nodes.positions.push_back(curve(p));
    for (int i = 0; i <= dense_count; ++i) {
        const double p = p0 + (p1 - p0) * i / dense_count;
        s.dense.push_back(curve(p));
        s.dense_param.push_back(p);
    }
    set_ids(s.nodes);
}

}  // namespace

ReferenceScene catenary_scene(const std::string& name) {
    ReferenceScene s;
    s.name = name;
    s.description =
        "20 m catenary (0,0,0)-(16,2,0), 16 nodes at s = L(1-cos(pi i/15))/2 (dense near the ends)";
    s.catenary_truth = true;
    (void)s.catenary.solve(glm::dvec3(0.0), glm::dvec3(16.0, 2.0, 0.0), 20.0);
    std::vector<double> arc;
    for (int i = 0; i < 16; ++i)
        arc.push_back(s.catenary.length_m() * 0.5 * (1.0 - std::cos(kPi * i / 15.0)));
    s.nodes.positions = s.catenary.points_at_arc_lengths(arc);
    set_ids(s.nodes);
    return s;
}

ReferenceScene helix_scene() {
    ReferenceScene s;
    s.name = "helix";
    s.description = "helix radius 1 m, pitch 0.3 m/rad, 3 turns, 12 nodes per turn (exact RMF: DESIGN 4.3)";
    const double a = 1.0, b = 0.3;
    std::vector<double> params;
    for (int i = 0; i <= 36; ++i) params.push_back(2.0 * kPi * i / 12.0);
    sample_truth(
        s, [&](double th) { return glm::dvec3(a * std::cos(th), a * std::sin(th), b * th); }, params, 0.0,
        params.back(), 40000);
    return s;
}

ReferenceScene stretched_bend_scene() {
    ReferenceScene s;
    s.name = "stretched_bend";
    s.description =
        "6% stretched straight run (nodes every 2 m), 0.1 m element turning 90 deg, long run down; "
        "world error = distance off the straight line over the run";
    for (int i = 0; i <= 5; ++i) s.nodes.positions.emplace_back(2.0 * i, 0.0, 0.0);
    s.nodes.positions.emplace_back(10.0, -0.1, 0.0);
    s.nodes.positions.emplace_back(10.0, -2.1, 0.0);
    s.nodes.positions.emplace_back(10.0, -4.1, 0.0);
    s.stretch = 1.06f;
    s.nodes.stretch.assign(s.nodes.positions.size(), s.stretch);
    s.straight_segments = 5;
    set_ids(s.nodes);
    return s;
}

ReferenceScene hairpin_scene() {
    ReferenceScene s;
    s.name = "hairpin";
    s.description =
        "hairpin: two 5 m legs joined by a half circle of radius 0.25 m, nodes every 1 m and every 45 deg";
    const double r = 0.25, leg = 5.0, arc = kPi * r;
    auto u_shape = [=](double p) {  // p = arc length from the start of the first leg
        if (p <= leg) return glm::dvec3(leg - p, r, 0.0);
        if (p <= leg + arc) {
            const double a = (p - leg) / r;
            return glm::dvec3(-r * std::sin(a), r * std::cos(a), 0.0);
        }
        return glm::dvec3(p - leg - arc, -r, 0.0);
    };
    std::vector<double> params;
    for (int i = 0; i <= 5; ++i) params.push_back(i);
    for (int k = 1; k <= 3; ++k) params.push_back(leg + arc * k / 4.0);
    for (int i = 0; i <= 5; ++i) params.push_back(leg + arc + i);
    sample_truth(s, u_shape, params, 0.0, params.back(), 20000);
    return s;
}

ReferenceScene random_walk_scene() {
    ReferenceScene s;
    s.name = "random_walk";
    s.description =
        "smooth random 3D curve (6-term random Fourier series, ~12 m) through 40 nodes at random spacing";
    unsigned seed = 12345u;
    auto rnd = [&seed] {
        seed = seed * 1664525u + 1013904223u;
        return (seed >> 8) * (1.0 / 16777216.0) - 0.5;
    };
    std::vector<glm::dvec3> ca, cb;
    for (int k = 1; k <= 6; ++k) {
        ca.emplace_back(rnd(), rnd(), rnd());
        cb.emplace_back(rnd(), rnd(), rnd());
    }
    auto curve = [=](double p) {
        glm::dvec3 x(8.0 * p, 0.0, 0.0);
        for (int k = 1; k <= 6; ++k)
            x += (2.0 / k) * (ca[static_cast<std::size_t>(k - 1)] * std::sin(2 * kPi * k * p) +
                              cb[static_cast<std::size_t>(k - 1)] * std::cos(2 * kPi * k * p));
        return x;
    };
    std::vector<double> params{0.0};
    std::vector<double> steps;
    for (int i = 0; i < 39; ++i) steps.push_back(0.4 + rnd() + 0.5);  // in [0.4, 1.4]
    double total = 0.0;
    for (double st : steps) total += st;
    for (double st : steps) params.push_back(params.back() + st / total);
    params.back() = 1.0;
    sample_truth(s, curve, params, 0.0, 1.0, 40000);
    return s;
}

ReferenceScene churn_scene() {
    ReferenceScene s = catenary_scene("churn");
    s.churn = true;
    s.description =
        "the 20 m catenary refined and coarsened: every 5 frames a node is inserted exactly "
        "on the curve (2 events of 3) or an inserted node removed (1 of 3)";
    return s;
}

std::vector<ReferenceScene> reference_scenes(const Options& o) {
    std::vector<ReferenceScene> scenes;
    auto want = [&](const std::string& n) { return selected(o, n); };
    if (want("catenary")) scenes.push_back(catenary_scene("catenary"));
    if (want("helix")) scenes.push_back(helix_scene());
    if (want("stretched_bend")) scenes.push_back(stretched_bend_scene());
    if (want("hairpin")) scenes.push_back(hairpin_scene());
    if (want("random_walk")) scenes.push_back(random_walk_scene());
    if (want("churn")) scenes.push_back(churn_scene());
    for (ReferenceScene& s : scenes) s.view = whole_wire_view(s.nodes.positions);
    return scenes;
}

}  // namespace wiretool::bench
