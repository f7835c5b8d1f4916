// The nodes path's packed nodes (packed_nodes.hpp).
#include "wire/packed_nodes.hpp"

#include "spline/merge.hpp"
#include "spline/validate.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>

namespace wire {

bool gpu_builds(SplineKind kind) {
    return kind == SplineKind::linear || kind == SplineKind::c2 || kind == SplineKind::catmull_rom ||
           kind == SplineKind::automatic;
}

Status pack_nodes(const WireNodes& wn, const SplineSettings& spline, PackedNodes& out, NodeFormat format) {
    if (!gpu_builds(spline.kind)) {
        return Status::error("the GPU curve pass does not build this spline kind (it builds linear, Catmull-Rom, "
                             "c2 and automatic wires)");
    }
    // check_curve_input's checks, with the merge done once (curve_nodes) for the count and the packing.
    if (Status st = curve_stage::check_settings(spline); !st) return st;
    if (Status st = curve_stage::check_sizes(wn); !st) return st;
    const bool physics = spline.curvature_tension && !wn.theta_rad.empty() && !wn.iz_m4.empty() &&
                         !wn.length_m.empty() && !wn.delta_length_m.empty() && !wn.area_m2.empty();
    if (Status st = curve_stage::check_nodes(wn, physics); !st) return st;
    // The merge as build_curve does it (curve_nodes), read in place: the merged nodes (the input's own array when
    // nothing merges, the common case), their sources, their chords and the input's box, each computed once.
    thread_local curve_stage::Merged merged;
    thread_local curve_stage::Chords chords;
    std::size_t n = 0;
    const glm::dvec3* curve = curve_stage::merge_nodes(wn, spline, merged, chords, n);
    if (Status st = curve_stage::check_distinct(wn.size(), n, spline.closed); !st) return st;
    const uint32_t* source = merged.first.data();
    const uint32_t* last = merged.last.data();
    // The origin: the centre of the nodes' box (float offsets then span at most half the wire). The input's box:
    // the merged nodes are among the input's, so it holds them (and is theirs up to the merge tolerance).
    const glm::dvec3 lo = merged.lo, hi = merged.hi;
    double chord = 0.0, shortest = HUGE_VAL;
    for (std::size_t k = 1; k <= chords.segs; ++k) chord = std::max(chord, chords.len[k]), shortest = std::min(shortest, chords.len[k]);
    out.origin_m = float_point(0.5 * (lo + hi));
    out.half_diagonal_m = glm::length(glm::max(hi - out.origin_m, out.origin_m - lo));  // the box from the origin
    out.closed = spline.closed;
    out.kind = spline.kind;
    out.alpha = static_cast<float>(spline.alpha);
    out.tension = static_cast<float>(spline.tension);
    out.bias = static_cast<float>(spline.bias);
    out.continuity = static_cast<float>(spline.continuity);
    out.extras.clear();
    const bool kb = !wn.kb_tension.empty() || !wn.kb_bias.empty() || !wn.kb_continuity.empty();
    out.per_node_kb = spline.kind == SplineKind::catmull_rom && (kb || physics);
    // The automatic spline reads its weights from the turning pattern on the GPU; its per-node tension (and the
    // curvature-driven one) travels as the Catmull-Rom's does (only the tension is read).
    if (spline.kind == SplineKind::automatic) out.per_node_kb = !wn.kb_tension.empty() || physics;
    if (out.per_node_kb) {
        // The per-node values build_curve reads (catmull_rom_tangents), its tension combined with the
        // curvature-driven one: t = 1 - (1 - t_user)(1 - t_curv).
        for (std::size_t j = 0; j < n; ++j) {
            const uint32_t src = source[j];
            const double t_user = wn.kb_tension.empty() ? spline.tension : wn.kb_tension[src];
            const double b = wn.kb_bias.empty() ? spline.bias : wn.kb_bias[src];
            const double c = wn.kb_continuity.empty() ? spline.continuity : wn.kb_continuity[src];
            const double t_curv = physics ? curvature_tension(wn.theta_rad[src], wn.iz_m4[src], wn.length_m[src],
                                                              wn.delta_length_m[src], wn.area_m2[src])
                                          : 0.0;
            const double t = 1.0 - (1.0 - t_user) * (1.0 - t_curv);
            out.extras.emplace_back(static_cast<float>(t), static_cast<float>(b), static_cast<float>(c), 0.0f);
        }
    }
    const std::size_t segs = spline.closed ? n : n - 1;
    out.stretch = !wn.stretch.empty();
    if (out.stretch) {  // build_curve's Curve::stretch: the element starting at a group's last node
        for (std::size_t k = 0; k < segs; k += 4) {
            glm::vec4 v(1.0f);
            for (std::size_t i = 0; i < 4 && k + i < segs; ++i) v[static_cast<int>(i)] = wn.stretch[last[k + i]];
            out.extras.push_back(v);
        }
    }
    // The radius: build_curve's Curve::radius_m (a node's radius, else the wire's).
    const float wire_radius = spline.radius_m > 0.0f ? spline.radius_m : kDefaultWireRadius_m;
    const auto radius_of = [&](std::size_t j) {
        const float r = wn.radius_m.empty() ? 0.0f : wn.radius_m[source[j]];
        return r > 0.0f ? r : wire_radius;
    };
    bool one_radius = true;
    out.max_radius_m = wire_radius;
    if (!wn.radius_m.empty()) {
        const float r0 = radius_of(0);
        for (std::size_t j = 0; j < n; ++j) {
            const float r = radius_of(j);
            one_radius &= r == r0;
            out.max_radius_m = std::max(out.max_radius_m, static_cast<double>(r));
        }
    }
    // The quantum 2^e: the smallest whose 21-bit integers hold the largest offset component (the box from the
    // origin), kept if it holds the nodes within the file comment's bounds.
    const glm::dvec3 reach = glm::max(hi - out.origin_m, out.origin_m - lo);
    const double most = std::max({reach.x, reach.y, reach.z});
    int e = std::ilogb(std::max(most, 1e-300)) - 19;
    if (std::nearbyint(std::ldexp(most, -e)) > double(kQuantBias - 1)) ++e;
    const double half_quantum = std::ldexp(0.5, e);
    out.quantised = format == NodeFormat::fitted && one_radius && e >= -120 && half_quantum <= kQuantumOfRadius * radius_of(0) &&
                    half_quantum <= kQuantumOfChord * shortest;
    if (out.quantised && spline.kind == SplineKind::automatic) {
        // The automatic spline reads each node's turn (tension.cpp: below ~1e-6 rad it is rounding noise of
        // collinear nodes; above, a turn its neighbours do not predict is tensed). Nodes moved by at most delta
        // turn a node by at most 2 delta (1 / h_in + 1 / h_out): quantised only where that stays below 1/16 of
        // every node's turn (its sine, which is smaller), so the quantum can neither make nor unmake a turn.
        const double delta = std::sqrt(3.0) * half_quantum;
        const std::size_t first = spline.closed ? 0 : 1, end = spline.closed ? n : n - 1;
        for (std::size_t i = first; i < end && out.quantised; ++i) {
            const glm::dvec3 a(chords.ex[i], chords.ey[i], chords.ez[i]);
            const glm::dvec3 b(chords.ex[i + 1], chords.ey[i + 1], chords.ez[i + 1]);
            const double most_noise = 32.0 * delta * (1.0 / chords.len[i] + 1.0 / chords.len[i + 1]);
            const glm::dvec3 c = glm::cross(a, b);
            out.quantised = glm::dot(a, b) <= 0.0 || glm::dot(c, c) >= most_noise * most_noise;
        }
    }
    out.quantum_exp = out.quantised ? e : 0;
    out.node_count = n;
    out.records.resize(out.quantised ? n + 1 : 2 * n);
    if (out.quantised) {
        out.records[0] = glm::uvec2(std::bit_cast<uint32_t>(radius_of(0)), static_cast<uint32_t>(e + int(kQuantExpBias)));
        for (std::size_t j = 0; j < n; ++j) {
            const glm::dvec3 o = curve[j] - out.origin_m;
            const auto q = [&](double v) { return static_cast<uint32_t>(std::llrint(std::ldexp(v, -e)) + kQuantBias); };
            const uint32_t x = q(o.x), y = q(o.y), z = q(o.z);
            out.records[j + 1] = glm::uvec2(x | (y << kQuantBits), (y >> (32 - kQuantBits)) | (z << (2 * kQuantBits - 32)));
        }
        // The held nodes lie within half a quantum of the input on each axis: the cull's box and chords grow by it.
        out.half_diagonal_m += std::sqrt(3.0) * half_quantum;
        chord += 2.0 * std::sqrt(3.0) * half_quantum;
    } else {
        for (std::size_t j = 0; j < n; ++j) {
            const glm::vec3 o(curve[j] - out.origin_m);
            out.records[2 * j] = glm::uvec2(std::bit_cast<uint32_t>(o.x), std::bit_cast<uint32_t>(o.y));
            out.records[2 * j + 1] = glm::uvec2(std::bit_cast<uint32_t>(o.z), std::bit_cast<uint32_t>(radius_of(j)));
        }
    }
    out.max_chord_m = chord;
    // K of node_bounding_sphere: 2 |1 - t| (1 + |b|) (1 + |c|) at the worst node (t with the curvature-driven
    // tension, as the GPU gets it); 1 for linear.
    out.tangent_factor = 1.0;
    if (spline.kind == SplineKind::catmull_rom) {
        const auto factor = [](double t, double b, double c) {
            return 2.0 * std::abs(1.0 - t) * (1.0 + std::abs(b)) * (1.0 + std::abs(c));
        };
        out.tangent_factor = std::max(1.0, factor(spline.tension, spline.bias, spline.continuity));
        if (out.per_node_kb) {
            for (std::size_t j = 0; j < n; ++j) {
                const glm::vec4& e = out.extras[j];
                out.tangent_factor = std::max(out.tangent_factor, factor(e.x, e.y, e.z));
            }
        }
    }
    return Status::success();
}

glm::vec4 PackedNodes::node(std::size_t j) const {
    if (!quantised) {
        const glm::uvec2 a = records[2 * j], b = records[2 * j + 1];
        return {std::bit_cast<float>(a.x), std::bit_cast<float>(a.y), std::bit_cast<float>(b.x),
                std::bit_cast<float>(b.y)};
    }
    const glm::uvec2 w = records[j + 1];
    const uint32_t x = w.x & kQuantMask, y = ((w.x >> kQuantBits) | (w.y << (32 - kQuantBits))) & kQuantMask,
                   z = (w.y >> (2 * kQuantBits - 32)) & kQuantMask;
    const auto v = [&](uint32_t q) {
        return std::ldexp(static_cast<float>(static_cast<int32_t>(q) - static_cast<int32_t>(kQuantBias)), quantum_exp);
    };
    return {v(x), v(y), v(z), std::bit_cast<float>(records[0].x)};
}

glm::dvec3 PackedNodes::held(const glm::dvec3& world_m) const {
    const glm::dvec3 o = world_m - origin_m;
    if (!quantised) return origin_m + float_point(o);
    const auto q = [&](double v) { return std::ldexp(std::nearbyint(std::ldexp(v, -quantum_exp)), quantum_exp); };
    return origin_m + glm::dvec3(q(o.x), q(o.y), q(o.z));
}

glm::dvec3 float_point(const glm::dvec3& p) {
    volatile float x = static_cast<float>(p.x), y = static_cast<float>(p.y), z = static_cast<float>(p.z);
    return {x, y, z};
}

BoundingSphere packed_bounding_sphere(const PackedNodes& p) {
    if (p.kind != SplineKind::linear && p.kind != SplineKind::catmull_rom) return {};
    BoundingSphere s;
    s.centre_m = p.origin_m;
    s.tube_radius_m = p.max_radius_m;
    s.radius_m = p.half_diagonal_m + std::sqrt(3.0) * (p.tangent_factor * p.max_chord_m / 3.0 * (1.0 + 1e-9)) +
                 p.max_radius_m;
    return s;
}

}  // namespace wire
