// The hanging cables driven as ropes (system tunnel.ropes): spawned between the hooks, settled before frame
// 0, and stepped every frame in the unbent tunnel space under the bent gravity and the passing gusts, against
// the level (rope_contact) and each other; then refined or coarsened (rope adaptation).
#include "tunnel/level_state.hpp"

#include <wire/spline.hpp>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vector_relational.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace tunnel {

namespace {

// A gust front travels down the tunnel at kGustSpeed, one every period; ropes it passes are pushed toward
// the tunnel axis (festoons) or along the tunnel (cross cables), bend, refine, straighten and coarsen.
constexpr double kGustSpeed = 6.0;
constexpr double kGustAccel = 15.0;
constexpr double kGustWidth = 1.4;

// The bend at a rope's piece: the Jacobian of the chain's transform at the piece's centre on the axis, and
// the smallest stretch of z over the piece near the wall (at its ends and middle).
struct PieceBend {
    glm::dmat3 jacobian{1.0};
    double z_scale = 1.0;
};

PieceBend piece_bend(const curved_space::Chain& chain, int piece) {
    PieceBend bend;
    const double zc = kPieceLength * (piece + 0.5);
    const glm::dvec3 c = chain.transform_point({0.0, 0.0, zc});
    constexpr double kEps = 1e-3;
    for (int k = 0; k < 3; ++k) {
        glm::dvec3 d(0.0);
        d[k] = kEps;
        bend.jacobian[k] = (chain.transform_point(glm::dvec3(0.0, 0.0, zc) + d) - c) / kEps;
    }
    bend.z_scale = 1.0;
    for (const glm::dvec2& q : {glm::dvec2(2.4, 0.0), {-2.4, 0.0}, {0.0, 2.4}, {0.0, -2.4}})
        for (double z : {kPieceLength * piece, zc, kPieceLength * (piece + 1)}) {
            const glm::dvec3 p(q, z);
            bend.z_scale = std::min(
                bend.z_scale,
                glm::length(chain.transform_point(p + glm::dvec3(0, 0, kEps)) - chain.transform_point(p)) /
                    kEps);
        }
    return bend;
}

// The acceleration on a rope besides the -y gravity the rope applies itself: gravity (world -y) seen in the
// unbent space of its piece, and the gust when its front (at unbent gust_z) is near the rope's piece.
Rope::AccelerationField rope_field(const glm::dmat3& jacobian, double gravity_mps2, const RopeEnds& e,
                                   const glm::dvec3& anchor_a, bool gusting, double gust_z) {
    const double g = gravity_mps2;
    const glm::dvec3 gravity = glm::inverse(jacobian) * glm::dvec3(0.0, -g, 0.0);
    const glm::dvec3 correction = gravity - glm::dvec3(0.0, -g, 0.0);
    const double z0 = kPieceLength * e.piece_a;
    if (gusting && std::abs(z0 + 2.0 - gust_z) < 2.0 + 4.0 * kGustWidth) {
        const bool across = e.anchor_b >= 4 && e.anchor_a < 4;  // from one wall to the other
        const glm::dvec3 dir = glm::normalize(across ? glm::dvec3(0.0, 0.25, 1.0)
                                                     : glm::dvec3(anchor_a.x < 0.0 ? 1.0 : -1.0, 0.6, 0.0));
        return [dir, gust_z, correction](const glm::dvec3& p) {
            const double u = (p.z - gust_z) / kGustWidth;
            return correction + dir * (kGustAccel * std::exp(-u * u));
        };
    }
    return [correction](const glm::dvec3&) { return correction; };
}

// Two elements of different ropes (rope a's element ea, rope b's element eb) that may touch.
struct RopePair {
    std::size_t a, b, ea, eb;
};

// The element pairs of different ropes whose boxes come within reach of each other (per substep).
void find_rope_pairs(const std::vector<Rope>& ropes, std::vector<glm::dvec3>& lo, std::vector<glm::dvec3>& hi,
                     std::vector<RopePair>& pairs) {
    const std::size_t n = ropes.size();
    pairs.clear();
    constexpr double kReach = 0.08;
    for (std::size_t r = 0; r < n; ++r) {
        lo[r] = glm::dvec3(1e30);
        hi[r] = glm::dvec3(-1e30);
        for (const glm::dvec3& p : ropes[r].positions()) {
            lo[r] = glm::min(lo[r], p);
            hi[r] = glm::max(hi[r], p);
        }
    }
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = a + 1; b < n; ++b) {
            if (glm::any(glm::greaterThan(lo[a] - kReach, hi[b])) ||
                glm::any(glm::greaterThan(lo[b] - kReach, hi[a])))
                continue;
            const auto& pa = ropes[a].positions();
            const auto& pb = ropes[b].positions();
            for (std::size_t i = 0; i + 1 < pa.size(); ++i) {
                const glm::dvec3 al = glm::min(pa[i], pa[i + 1]) - kReach;
                const glm::dvec3 ah = glm::max(pa[i], pa[i + 1]) + kReach;
                for (std::size_t j = 0; j + 1 < pb.size(); ++j) {
                    const glm::dvec3 bl = glm::min(pb[j], pb[j + 1]);
                    const glm::dvec3 bh = glm::max(pb[j], pb[j + 1]);
                    if (glm::any(glm::greaterThan(al, bh)) || glm::any(glm::greaterThan(bl, ah))) continue;
                    pairs.push_back({a, b, i, j});
                }
            }
        }
}

// Pushes apart the paired elements that are closer than the sum of their radii (in the bent metric).
void separate_rope_pairs(std::vector<Rope>& ropes, const std::vector<RopeEnds>& ends,
                         const std::vector<RopePair>& pairs) {
    for (const RopePair& q : pairs) {
        const auto& pa = ropes[q.a].positions();
        const auto& pb = ropes[q.b].positions();
        double sa = 0.0, sb = 0.0;
        closest_segments(pa[q.ea], pa[q.ea + 1], pb[q.eb], pb[q.eb + 1], sa, sb);
        const glm::dvec3 d =
            (pa[q.ea] + sa * (pa[q.ea + 1] - pa[q.ea])) - (pb[q.eb] + sb * (pb[q.eb + 1] - pb[q.eb]));
        const double len = glm::length(d);
        if (len < 1e-9) continue;
        const glm::dvec3 nrm = d / len;
        const double clear = (ropes[q.a].settings().radius_m + ropes[q.b].settings().radius_m) /
                             bent_metric(nrm, std::min(ends[q.a].z_scale, ends[q.b].z_scale));
        if (len < clear) Rope::separate(ropes[q.a], q.ea, sa, ropes[q.b], q.eb, sb, nrm, clear - len);
    }
}

}  // namespace

glm::dvec3 Level::rope_end(int piece, std::size_t anchor, double inset_m, double lift_m) const {
    // Unbent: the ropes are simulated in the unbent tunnel space.
    glm::dvec3 p = state_->anchors[anchor];
    p.x -= p.x < 0.0 ? -inset_m : inset_m;
    p.y += inset_m > 0.0 ? 0.03 : lift_m;
    p.z += kPieceLength * piece;
    return p;
}

void Level::spawn_ropes() {
    State& s = *state_;
    // Festoons between the hooks of each wall, and a few cables across the tunnel.
    auto add_rope = [&](int pa, std::size_t aa, int pb, std::size_t ab, double inset, double slack,
                        uint32_t material, float radius) {
        const double lift = inset > 0.0 ? 0.0 : radius;  // resting on the hook's arm
        const glm::dvec3 a = rope_end(pa, aa, inset, lift);
        const glm::dvec3 b = rope_end(pb, ab, inset, lift);
        const double length = glm::length(b - a) * slack;
        ropes_.emplace_back(a, b, length, 8, RopeSettings{.radius_m = radius});
        wire::WireNodes nodes;
        ropes_.back().write_nodes(nodes);
        for (glm::dvec3& p : nodes.positions) p = chain_.transform_point(p);
        const auto e = wire::systems::spawn_wire(s.registry, std::move(nodes),
                                                 {.radius_m = radius, .material = material});
        s.rope_ends.push_back({pa, aa, pb, ab, cables_.size(),
                               chain_.world_from_segment(static_cast<std::size_t>(pa)), inset, lift});
        cables_.push_back({.entity = e,
                           .hanging = true,
                           .across = (aa < 4) != (ab < 4),
                           .rope = static_cast<int>(ropes_.size() - 1),
                           .material = material,
                           .radius_m = radius});
    };
    for (int k = 0; k < s.settings.pieces; ++k) {
        // Festoons hang from the hook lips, shallow enough to stay clear of the ribs (inner radius ~2.2 m).
        add_rope(k, 0, k, 3, 0.1, 1.03 + 0.02 * hash01(static_cast<uint32_t>(k) + 101u),
                 k % 2 == 0 ? orange : rubber, 0.02f);
        add_rope(k, 4, k, 7, 0.1, 1.03 + 0.02 * hash01(static_cast<uint32_t>(k) + 202u),
                 k % 2 == 0 ? rubber : red, 0.02f);
        // Cables across the tunnel (every other piece), and a diagonal one now and then.
        if (k % 2 == 1)
            add_rope(k, 1 + static_cast<std::size_t>(k % 4 == 1), k, 5 + static_cast<std::size_t>(k % 4 == 1),
                     0.0, 1.10, k % 4 == 1 ? yellow : orange, 0.025f);
        if (k % 4 == 2) add_rope(k, 0, k, 7, 0.0, 1.06, blue, 0.02f);
    }
}

void Level::update_ropes(double dt_s) {
    State& s = *state_;
    stats_.nodes_inserted = 0;
    stats_.nodes_removed = 0;
    stats_.rope_nodes = 0;
    wire::SplineSettings spline;
    spline.kind = options_.spline;
    const double period = (chain_.total_length_m() + 16.0) / kGustSpeed;
    const double gust_z = -6.0 + kGustSpeed * std::fmod(s.rope_time_s, period);
    const bool gusting = options_.gusts && options_.simulate_ropes && s.rope_time_s > 0.0;
    if (options_.simulate_ropes) s.rope_time_s += dt_s;
    const double total_z = chain_.total_length_m();
    const std::size_t n = ropes_.size();

    // The ropes live in the unbent tunnel space: their ends stay on the hooks, the level geometry is made of
    // simple shapes. What the bend changes: the direction of gravity (the piece tilts) and the stretch of z.
    std::vector<Rope::AccelerationField> fields(n);
    std::vector<Collider> colliders(n);
    for (std::size_t r = 0; r < n; ++r) {
        RopeEnds& e = s.rope_ends[r];
        ropes_[r].set_ends(rope_end(e.piece_a, e.anchor_a, e.inset_m, e.lift_m),
                           rope_end(e.piece_b, e.anchor_b, e.inset_m, e.lift_m));
        const PieceBend bend = piece_bend(chain_, e.piece_a);
        e.z_scale = bend.z_scale;
        fields[r] = rope_field(bend.jacobian, ropes_[r].settings().gravity_mps2, e, s.anchors[e.anchor_a],
                               gusting, gust_z);
        const LevelShapes* shapes = &s.shapes;
        const double z_scale = e.z_scale;
        colliders[r] = [shapes, total_z, z_scale](const glm::dvec3& a, const glm::dvec3& b, double radius,
                                                  ElementContact& out) {
            return element_contact(*shapes, total_z, a, b, radius, z_scale, out);
        };
    }

    if (options_.simulate_ropes && dt_s > 0.0 && n > 0) {
        const RopeSettings& rs = ropes_[0].settings();
        // At most 1/30 s per step: a slow window frame (llvmpipe, up to 0.1 s) takes several, so the ropes
        // behave the same at any frame rate.
        const int steps = static_cast<int>(std::ceil(dt_s * 30.0 - 1e-9));
        const double h = dt_s / (steps * rs.substeps);
        std::vector<RopePair> pairs;
        std::vector<glm::dvec3> lo(n), hi(n);
        for (int sub = 0; sub < rs.substeps * steps; ++sub) {
            for (std::size_t r = 0; r < n; ++r) ropes_[r].begin_substep(h, fields[r]);
            find_rope_pairs(ropes_, lo, hi, pairs);
            for (int it = 0; it < rs.iterations; ++it) {
                for (std::size_t r = 0; r < n; ++r) ropes_[r].solve(it, colliders[r]);
                separate_rope_pairs(ropes_, s.rope_ends, pairs);
            }
            for (std::size_t r = 0; r < n; ++r) ropes_[r].end_substep();
        }
    }
    for (std::size_t r = 0; r < n; ++r) {
        if (options_.adapt_ropes) {
            const AdaptResult changed = ropes_[r].adapt(spline);
            stats_.nodes_inserted += changed.inserted;
            stats_.nodes_removed += changed.removed;
        }
        stats_.rope_nodes += ropes_[r].size();
    }
}

}  // namespace tunnel
