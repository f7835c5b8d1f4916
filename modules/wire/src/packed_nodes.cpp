// The nodes path's packed nodes (packed_nodes.hpp).
#include "wire/packed_nodes.hpp"

#include "spline/merge.hpp"
#include "spline/validate.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <string>

namespace wire {

bool gpu_builds(SplineKind kind) {
    return kind == SplineKind::linear || kind == SplineKind::c2 || kind == SplineKind::catmull_rom ||
           kind == SplineKind::automatic;
}

Status pack_nodes(const WireNodes& wn, const SplineSettings& spline, PackedNodes& out) {
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
    double chord = 0.0;
    for (std::size_t k = 1; k <= chords.segs; ++k) chord = std::max(chord, chords.len[k]);
    out.origin_m = float_point(0.5 * (lo + hi));
    out.half_diagonal_m = glm::length(glm::max(hi - out.origin_m, out.origin_m - lo));  // the box from the origin
    out.max_chord_m = chord;
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
    // w: build_curve's Curve::radius_m (a node's radius, else the wire's).
    const float wire_radius = spline.radius_m > 0.0f ? spline.radius_m : kDefaultWireRadius_m;
    out.nodes.resize(n);
    out.max_radius_m = wire_radius;
    for (std::size_t j = 0; j < n; ++j) {
        const float r = wn.radius_m.empty() ? 0.0f : wn.radius_m[source[j]];
        const float radius = r > 0.0f ? r : wire_radius;
        out.max_radius_m = std::max(out.max_radius_m, static_cast<double>(radius));
        out.nodes[j] = glm::vec4(glm::vec3(curve[j] - out.origin_m), radius);
    }
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
