// The accuracy bench's pops (pops.hpp).
#include "bench/accuracy/pops.hpp"

#include <wire/bezier.hpp>
#include <wire/pop_free.hpp>
#include <wire/spline.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>

namespace wiretool::bench {
namespace {

/// Inserts a node before `at` with id `id`, copying the neighbour's optional per-node entries (physics
/// included).
void insert_node(wire::WireNodes& n, std::size_t at, const glm::dvec3& p, uint32_t id) {
    auto dup = [at](auto& v) {
        if (v.empty()) return;
        const auto value = v[std::min(at, v.size() - 1)];
        v.insert(v.begin() + static_cast<std::ptrdiff_t>(at), value);
    };
    n.positions.insert(n.positions.begin() + static_cast<std::ptrdiff_t>(at), p);
    n.ids.insert(n.ids.begin() + static_cast<std::ptrdiff_t>(at), id);
    dup(n.stretch), dup(n.radius_m), dup(n.theta_rad), dup(n.iz_m4), dup(n.length_m), dup(n.delta_length_m),
        dup(n.area_m2);
}

void remove_node(wire::WireNodes& n, std::size_t at) {
    auto erase = [at](auto& v) {
        if (at < v.size()) v.erase(v.begin() + static_cast<std::ptrdiff_t>(at));
    };
    erase(n.positions), erase(n.ids), erase(n.stretch), erase(n.radius_m), erase(n.theta_rad), erase(n.iz_m4),
        erase(n.length_m), erase(n.delta_length_m), erase(n.area_m2);
}

/// Runs `states` (each shown for at least one frame, then held until the blend ends) and returns the
/// largest jump between consecutive rendered curves, with and without the pop-free blend.
Pops measure_pops(const std::vector<wire::WireNodes>& states, const wire::SplineSettings& spline,
                  int hold_frames, int samples) {
    Pops out;
    for (bool remedy : {false, true}) {
        wire::PopFreeCurve m({.spline = spline, .enabled = remedy});
        wire::Curve prev, cur;
        bool first = true;
        double worst = 0.0;
        for (const wire::WireNodes& st : states) {
            for (int f = 0; f < std::max(1, hold_frames); ++f) {
                if (!m.update(st, cur)) break;
                if (!first) worst = std::max(worst, wire::curve_jump_m(prev, cur, samples));
                first = false;
                prev = cur;
                if (f > 0 && !m.blending()) break;
            }
        }
        (remedy ? out.blended_m : out.unblended_m) = worst;
    }
    return out;
}

}  // namespace

Pops event_pops(const wire::WireNodes& nodes, const wire::SplineSettings& spline, int samples) {
    wire::Curve c;
    if (!wire::build_curve(nodes, spline, c) || c.segment_count() < 3) return {};
    const std::size_t seg = c.segment_count() / 2;
    wire::WireNodes inserted = nodes;
    insert_node(inserted, c.source_node[seg] + 1, wire::position(c.segments[seg], 0.5), 99999u);
    wire::WireNodes removed = inserted;
    const std::size_t victim = std::max<std::size_t>(1, c.source_node[seg] / 2);
    remove_node(removed, victim);
    return measure_pops({nodes, inserted, removed}, spline, 400, samples);
}

std::vector<wire::WireNodes> churn_states(const wire::WireNodes& start, const wire::SplineSettings& spline,
                                          int frames) {
    std::vector<wire::WireNodes> states;
    wire::WireNodes n = start;
    const uint32_t first_inserted_id = 5000;
    unsigned seed = 777u;
    auto rnd = [&seed](std::size_t k) {
        seed = seed * 1664525u + 1013904223u;
        return static_cast<std::size_t>((seed >> 8) % k);
    };
    uint32_t next_id = first_inserted_id;
    for (int f = 0; f < frames; ++f) {
        if (f > 0 && f % 5 == 0) {
            if ((f / 5) % 3 != 0) {
                wire::Curve c;
                if (wire::build_curve(n, spline, c)) {
                    const std::size_t seg = rnd(c.segment_count());
                    insert_node(n, c.source_node[seg] + 1, wire::position(c.segments[seg], 0.5), next_id++);
                }
            } else {
                std::vector<std::size_t> inserted;
                for (std::size_t i = 0; i < n.ids.size(); ++i)
                    if (n.ids[i] >= first_inserted_id) inserted.push_back(i);
                if (!inserted.empty()) remove_node(n, inserted[rnd(inserted.size())]);
            }
        }
        states.push_back(n);
    }
    return states;
}

Pops churn_pops(const std::vector<wire::WireNodes>& states, const wire::SplineSettings& spline, int samples) {
    return measure_pops(states, spline, 1, samples);
}

}  // namespace wiretool::bench
