// wire_curve_report: prints the numbers quoted for the curve stage (catenary accuracy per spline kind,
// the stretched-then-bent run, pops with and without the multiresolution pop-free blend).
#include "curve_cases.hpp"

#include <chrono>
#include <cstdio>

using namespace wire;
using namespace wire::testing;

int main() {
    const Catenary cable = hanging_cable();
    std::printf("catenary: 20 m cable from (0,0,0) to (16,2,0), a = %.6f m, xi = %.9f\n", cable.a(), cable.xi());
    std::printf("\n== max distance to the exact catenary (m) ==\n%-22s", "kind");
    const int counts[] = {8, 16, 32};
    for (int c : counts) std::printf("  n=%-2d even   n=%-2d dense", c, c);
    std::printf("\n");
    for (const NamedSettings& v : spline_variants()) {
        std::printf("%-22s", v.name.c_str());
        for (int c : counts) {
            for (bool dense : {false, true}) {
                Curve curve;
                const Status st = build_curve(cable_nodes(cable, c, dense), v.settings, curve);
                std::printf("  %11.3e", st ? catenary_error_m(curve, cable) : -1.0);
            }
        }
        std::printf("\n");
    }
    for (float stretch : {1.0f, 1.02f, 1.06f}) {
        std::printf("\n== stretched run + tight bend, stretch %.2f ==\n%-22s %14s %14s %10s\n", stretch, "kind",
                    "straight dev m", "overshoot m", "kink deg");
        for (const NamedSettings& v : spline_variants()) {
            Curve curve;
            if (!build_curve(stretched_bend_nodes(stretch), v.settings, curve)) continue;
            const BendNumbers b = measure_bend(curve);
            std::printf("%-22s %14.3e %14.3e %10.3f\n", v.name.c_str(), b.straight_dev_m, b.overshoot_m, b.kink_deg);
        }
    }
    std::printf("\n== taut zig-zag (+-2 cm every 2 m): max distance to the node polyline (m) ==\n%-22s %14s %14s %14s\n", "kind", "stretch 1.00", "stretch 1.03", "stretch 1.06");
    for (const NamedSettings& v : spline_variants()) {
        std::printf("%-22s", v.name.c_str());
        for (float stretch : {1.0f, 1.03f, 1.06f}) {
            Curve curve;
            const WireNodes n = kinked_taut_nodes(stretch);
            std::printf(" %14.3e", build_curve(n, v.settings, curve) ? polyline_deviation_m(curve, n) : -1.0);
        }
        std::printf("\n");
    }
    std::printf("\n== build_curve on a 100,000-node random walk (ms, best of 3) ==\n");
    {
        WireNodes walk;
        glm::dvec3 p(0.0), dir(1.0, 0.0, 0.0);
        unsigned seed = 7;
        auto rnd = [&seed]() { seed = seed * 1664525u + 1013904223u; return (seed >> 8) * (1.0 / 16777216.0) - 0.5; };
        for (int i = 0; i < 100000; ++i) {
            dir = glm::normalize(dir + 0.1 * glm::dvec3(rnd(), rnd(), rnd()));
            p += 0.01 * dir;
            walk.positions.push_back(p);
        }
        for (const NamedSettings& v : spline_variants()) {
            double best = 1e30;
            for (int r = 0; r < 3; ++r) {
                Curve c;
                const auto t0 = std::chrono::steady_clock::now();
                (void)build_curve(walk, v.settings, c);
                best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
            }
            std::printf("%-22s %8.2f\n", v.name.c_str(), best);
        }
    }
    std::printf("\n== pop on the 20 m cable (16 nodes), max jump between consecutive frames (m) ==\n");
    std::printf("%-22s %-26s %12s %12s %7s %12s\n", "kind", "event", "no remedy", "geomorph", "frames", "final gap");
    for (const NamedSettings& v : spline_variants()) {
        const WireNodes base = cable_nodes(cable, 16);
        const WireNodes inserted = cable_with_inserted_node(cable, v.settings);
        const WireNodes on_cat = cable_with_inserted_node(cable, v.settings, true);
        const WireNodes removed = cable_with_removed_node(cable);
        const struct { const char* name; const WireNodes& from; const WireNodes& to; } events[] = {
            {"insert on curve", base, inserted}, {"remove inserted", inserted, base}, {"remove node 8", base, removed},
            {"insert on catenary", base, on_cat}};
        for (const auto& e : events) {
            const PopNumbers p = measure_pop(v.settings, e.from, e.to);
            std::printf("%-22s %-26s %12.3e %12.3e %7d %12.1e\n", v.name.c_str(), e.name, p.unblended_m, p.blended_max_m, p.frames, p.final_gap_m);
        }
    }
    return 0;
}
