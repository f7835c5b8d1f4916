// How the hanging cables look this frame: the deepest penetration of their rendered tubes into the level or
// each other, and the distances from the eye to the nearest rope and wall cable (LevelFrameStats).
#include "tunnel/level_state.hpp"

#include <wire/curve.hpp>
#include <wire/spline.hpp>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <vector>

namespace tunnel {

void Level::measure_ropes() {
    State& s = *state_;
    const double total_z = chain_.total_length_m();
    wire::SplineSettings spline;
    spline.kind = options_.spline;
    // Penetration of the rendered tube: the curve the wire systems build through the nodes (built here in the
    // unbent space, 8 samples per segment), distances to the shapes measured between bent points.
    std::vector<std::vector<glm::dvec3>> samples(ropes_.size());
    double deepest = 0.0;
    wire::WireNodes nodes;
    wire::Curve curve;
    for (std::size_t r = 0; r < ropes_.size(); ++r) {
        ropes_[r].write_nodes(nodes);
        if (!wire::build_curve(nodes, spline, curve).ok()) continue;
        for (const wire::CubicBezier& seg : curve.segments)
            for (int k = 0; k < 8; ++k) samples[r].push_back(wire::position(seg, k / 8.0));
        samples[r].push_back(nodes.positions.back());
        const double radius = ropes_[r].settings().radius_m;
        // The pinned ends rest on their hooks: skip the samples within 2 radii of an end.
        const glm::dvec3 ea = nodes.positions.front(), eb = nodes.positions.back();
        for (const glm::dvec3& p : samples[r]) {
            if (glm::length(p - ea) < 2.0 * radius || glm::length(p - eb) < 2.0 * radius) continue;
            double d = 0.0;
            glm::dvec3 nrm;
            if (!point_contact(s.shapes, total_z, p, 2.0 * radius, d, nrm)) continue;
            const double bent = glm::length(chain_.transform_point(p) - chain_.transform_point(p - d * nrm));
            const double pen = radius - (d >= 0.0 ? bent : -bent);
            deepest = std::max(deepest, pen);
        }
    }
    std::vector<glm::dvec3> lo(ropes_.size(), glm::dvec3(1e30)), hi(ropes_.size(), glm::dvec3(-1e30));
    for (std::size_t r = 0; r < ropes_.size(); ++r)
        for (const glm::dvec3& p : samples[r]) {
            lo[r] = glm::min(lo[r], p);
            hi[r] = glm::max(hi[r], p);
        }
    for (std::size_t a = 0; a < ropes_.size(); ++a)
        for (std::size_t b = a + 1; b < ropes_.size(); ++b) {
            const auto& pa = samples[a];
            const auto& pb = samples[b];
            if (pa.size() < 2 || pb.size() < 2) continue;
            const double clear = ropes_[a].settings().radius_m + ropes_[b].settings().radius_m;
            if (glm::any(glm::greaterThan(lo[a] - clear, hi[b])) ||
                glm::any(glm::greaterThan(lo[b] - clear, hi[a])))
                continue;
            for (std::size_t i = 0; i + 1 < pa.size(); ++i)
                for (std::size_t j = 0; j + 1 < pb.size(); ++j) {
                    const glm::dvec3 al = glm::min(pa[i], pa[i + 1]) - clear,
                                     ah = glm::max(pa[i], pa[i + 1]) + clear;
                    const glm::dvec3 bl = glm::min(pb[j], pb[j + 1]), bh = glm::max(pb[j], pb[j + 1]);
                    if (glm::any(glm::greaterThan(al, bh)) || glm::any(glm::greaterThan(bl, ah))) continue;
                    double sa = 0.0, sb = 0.0;
                    closest_segments(pa[i], pa[i + 1], pb[j], pb[j + 1], sa, sb);
                    const glm::dvec3 p = pa[i] + sa * (pa[i + 1] - pa[i]);
                    const glm::dvec3 q = pb[j] + sb * (pb[j + 1] - pb[j]);
                    const double pen =
                        clear - glm::length(chain_.transform_point(p) - chain_.transform_point(q));
                    deepest = std::max(deepest, pen);
                }
        }
    stats_.rope_penetration_m = deepest;
    // Close-up distances: eye to the nearest rope and wall cable centre lines.
    const glm::dvec3 eye = camera_.position;
    stats_.camera_rope_m = 1e30;
    for (std::size_t r = 0; r < ropes_.size(); ++r)
        for (const glm::dvec3& p : samples[r])
            stats_.camera_rope_m =
                std::min(stats_.camera_rope_m, glm::length(chain_.transform_point(p) - eye));
    stats_.camera_cable_m = 1e30;
    const double z_eye = s.flight_z_m;
    for (const FixedCable& f : s.fixed)
        for (double z = z_eye - 1.0; z <= z_eye + 1.0; z += 0.02)
            stats_.camera_cable_m =
                std::min(stats_.camera_cable_m, glm::length(chain_.transform_point({f.x, f.y, z}) - eye));
}

}  // namespace tunnel
