// The wire systems bench's scenes (field_scenes.hpp).
#include "bench/scenes/field_scenes.hpp"

#include <wire/testing/reference.hpp>

#include <glm/geometric.hpp>

#include <cmath>
#include <vector>

namespace wiretool::bench {

const char* scene_name(SceneKind k) {
    switch (k) {
        case SceneKind::standard:
            return "standard";
        case SceneKind::offscreen:
            return "offscreen";
        case SceneKind::swaying:
            return "swaying";
        case SceneKind::far:
            return "far";
    }
    return "?";
}

int scene_wire_count(SceneKind k) {
    return k == SceneKind::far ? 10000 : 1000;
}

wire::WireNodes hanging_wire(int i) {
    const int row = i % 20, col = i / 20;
    const glm::dvec3 p1(-5.0, 0.6 * row, -1.5 * col);
    const glm::dvec3 p2 = p1 + glm::dvec3(10.0, 0.3 * std::sin(0.7 * i), 0.2 * std::sin(0.3 * i));
    const double length_m = glm::length(p2 - p1) * (1.03 + 0.004 * (i % 13));
    wire::Catenary cable;
    (void)cable.solve(p1, p2, length_m);  // p1, p2 are never vertically aligned here
    std::vector<double> s(kFieldNodes);
    for (int k = 0; k < kFieldNodes; ++k) s[static_cast<std::size_t>(k)] = length_m * k / (kFieldNodes - 1);
    wire::WireNodes n;
    n.positions = cable.points_at_arc_lengths(s);
    return n;
}

double ground_m(double x, double z) {
    return 12.0 * std::sin(x / 310.0) * std::cos(z / 270.0) + 6.0 * std::sin(z / 130.0);
}

FarWire far_wire(int i) {
    constexpr int kPower = 6000;  // the rest are rigging
    glm::dvec3 p1, p2;
    double slack = 1.02;
    float radius = 0.015f;
    auto hash = [](int a, int b) {  // a fixed pseudo-random number in [0, 1)
        const double v = std::sin(12.9898 * a + 78.233 * b) * 43758.5453;
        return v - std::floor(v);
    };
    if (i < kPower) {
        const int route = i % 12, k = i / 12;  // k: 500 conductors per route
        const int span = k / 3, phase = k % 3;
        const double angle = 0.4 + 0.52 * route + 0.1 * hash(route, 1);
        const glm::dvec3 dir(std::cos(angle), 0.0, std::sin(angle));
        const glm::dvec3 side(-dir.z, 0.0, dir.x);
        const glm::dvec3 start(-900.0 + 150.0 * route, 0.0, -950.0 + 60.0 * route);
        const double s0 = 190.0 * span, s1 = s0 + 120.0 + 140.0 * hash(route, span);
        auto tower = [&](double s) {
            // A route longer than the landscape folds back as a parallel line 45 m to the side (a corridor).
            const double lap = std::floor(s / 2400.0);
            glm::dvec3 p = start + dir * std::fmod(s, 2400.0) + side * (3.5 * (phase - 1) + 45.0 * lap);
            p.x = std::fmod(p.x + 3000.0, 2000.0) - 1000.0;
            p.z = std::fmod(p.z + 3000.0, 2000.0) - 1000.0;
            p.y = ground_m(p.x, p.z) + 18.0 + 8.0 * hash(route, static_cast<int>(s));
            return p;
        };
        p1 = tower(s0);
        p2 = p1 + dir * (s1 - s0);
        p2.y = ground_m(p2.x, p2.z) + 18.0 + 8.0 * hash(route, span + 7);
        slack = 1.02 + 0.02 * hash(i, 3);
        radius = 0.015f;
    } else {
        const int j = i - kPower, cluster = j % 60, k = j / 60;
        const glm::dvec3 base(-950.0 + 1900.0 * hash(cluster, 11), 0.0, -950.0 + 1900.0 * hash(cluster, 13));
        const double mast = 15.0 + 30.0 * hash(cluster, 17);
        const double a = 6.2831853 * hash(cluster * 97 + k, 19);
        const double reach = 12.0 + 30.0 * hash(cluster * 89 + k, 23);
        p1 = base + glm::dvec3(0.0, ground_m(base.x, base.z) + mast * (0.5 + 0.5 * hash(k, 29)), 0.0);
        p2 = base + glm::dvec3(reach * std::cos(a), 0.0, reach * std::sin(a));
        p2.y = ground_m(p2.x, p2.z) + 1.0 + 6.0 * hash(k, 31);
        slack = 1.01 + 0.02 * hash(i, 37);
        radius = 0.008f + 0.012f * static_cast<float>(hash(i, 41));
    }
    const double length_m = glm::length(p2 - p1) * slack;
    wire::Catenary cable;
    (void)cable.solve(p1, p2, length_m);  // never vertically aligned: every cable has a horizontal run
    std::vector<double> s(kFieldNodes);
    for (int k = 0; k < kFieldNodes; ++k) s[static_cast<std::size_t>(k)] = length_m * k / (kFieldNodes - 1);
    FarWire w;
    w.nodes.positions = cable.points_at_arc_lengths(s);
    w.radius_m = radius;
    return w;
}

void sway_nodes(wire::WireNodes& nodes, std::size_t wire_index, int frame) {
    for (std::size_t k = 1; k + 1 < nodes.positions.size(); ++k)
        nodes.positions[k].z += 0.002 * std::sin(0.1 * frame + 0.1 * static_cast<double>(k + wire_index));
}

}  // namespace wiretool::bench
