// Frames: fourth-order convergence of double reflection on a helix (rotation: second, projection: first order),
// and the hard cases of DESIGN §5 that concern frames (straight, hairpin, cusp, zero-length, loops, far origin).
#include "ring_test_curves.hpp"

#include <cstdio>

namespace wire::test {
namespace {

/// Max |twist| (degrees) of `set` against `ref` at their common rings (ref has ref_n rings per segment, set n).
double max_twist_deg(const RingSet& set, uint32_t n, const RingSet& ref, uint32_t ref_n) {
    const uint32_t step = ref_n / n;
    double worst = 0.0;
    for (std::size_t i = 0; i < set.frames.size(); ++i) {
        const Frame& f = set.frames[i];
        const Frame& g = ref.frames[i * step];
        EXPECT_LT(glm::length(f.t - g.t), 1e-12);  // same ring, same analytic tangent
        worst = std::max(worst, std::abs(angle_about(g.r, f.r, g.t)));
    }
    return worst * 180.0 / kPi;
}

/// Least-squares slope of log(err) against log(n): minus the convergence order.
double loglog_slope(const std::vector<double>& n, const std::vector<double>& err) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double k = static_cast<double>(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) {
        const double x = std::log(n[i]), y = std::log(err[i]);
        sx += x; sy += y; sxx += x * x; sxy += x * y;
    }
    return (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

RingSettings with_method(FrameMethod m) {
    RingSettings s;
    s.frames.method = m;
    return s;
}

// The target: 3-turn helix through 16 nodes per turn, exact node tangents, twist against the same wire at
// 256 rings per segment; double reflection is fourth order and < 1e-3 degrees at 4 rings per segment.
TEST(Frames, HelixConvergenceOrders) {
    const Curve helix = helix_curve(1.0, 0.3, 3, 16);
    constexpr uint32_t kRef = 256;
    const RingSet ref = rings_for(helix, kRef);
    expect_orthonormal(ref);

    struct Case {
        FrameMethod method;
        const char* name;
        std::vector<uint32_t> fit_n;
        double min_order, max_order;
    };
    const Case cases[] = {
        {FrameMethod::double_reflection, "double reflection", {2, 4, 8, 16}, 3.5, 4.5},
        {FrameMethod::rotation, "rotation", {4, 8, 16, 32, 64}, 1.7, 2.5},
        {FrameMethod::projection, "projection", {4, 8, 16, 32, 64}, 0.8, 1.3},
    };
    for (const Case& c : cases) {
        std::vector<double> ns, errs;
        std::printf("  %-18s", c.name);
        for (uint32_t n : {1u, 2u, 4u, 8u, 16u, 32u, 64u}) {
            const RingSet set = rings_for(helix, n, with_method(c.method));
            expect_orthonormal(set);
            const double e = max_twist_deg(set, n, ref, kRef);
            std::printf(" N=%u: %.3e", n, e);
            if (std::find(c.fit_n.begin(), c.fit_n.end(), n) != c.fit_n.end()) {
                ns.push_back(n);
                errs.push_back(e);
            }
            if (c.method == FrameMethod::double_reflection && n == 4) {
                EXPECT_LT(e, 1e-3) << "twist at 4 rings per segment (degrees)";
            }
        }
        const double order = -loglog_slope(ns, errs);
        std::printf("  order %.2f\n", order);
        EXPECT_GT(order, c.min_order) << c.name;
        EXPECT_LT(order, c.max_order) << c.name;
    }
}

// Informational: the cubic wire's frames against the exact RMF of the true helix (the difference is the cubic
// interpolation of the helix, not the frame method). th(s) = th0 - tau s, tau = b / c^2.
TEST(Frames, HelixAgainstExactRmf) {
    const double a = 1.0, b = 0.3, c = std::sqrt(a * a + b * b), tau = b / (c * c);
    const int per_turn = 64;
    const Curve helix = helix_curve(a, b, 3, per_turn);
    const RingSet set = rings_for(helix, 8);
    auto frenet = [&](double th, glm::dvec3& n, glm::dvec3& bn) {
        const glm::dvec3 t = glm::dvec3(-a * std::sin(th), a * std::cos(th), b) / c;
        n = glm::dvec3(-std::cos(th), -std::sin(th), 0.0);
        bn = glm::cross(t, n);
    };
    glm::dvec3 n0, b0;
    frenet(0.0, n0, b0);
    const double th0 = std::atan2(glm::dot(set.frames[0].r, b0), glm::dot(set.frames[0].r, n0));
    double worst = 0.0;
    for (std::size_t i = 0; i < set.frames.size(); ++i) {
        const double th = (set.params[i].segment + set.params[i].t) * 2.0 * kPi / per_turn;
        glm::dvec3 n, bn;
        frenet(th, n, bn);
        const double phi = th0 - tau * c * th;  // s = c * th
        const glm::dvec3 exact = std::cos(phi) * n + std::sin(phi) * bn;
        worst = std::max(worst, std::abs(angle_about(exact, set.frames[i].r, set.frames[i].t)));
    }
    std::printf("  cubic helix (64 nodes/turn, 8 rings/segment) vs exact helix RMF: %.3e deg\n", worst * 180 / kPi);
    EXPECT_LT(worst * 180 / kPi, 1e-2);
}

TEST(Frames, StraightWireKeepsOneFrame) {
    const Curve line = polyline_curve({{0, 0, 0}, {1, 2, 3}, {2, 4, 6}, {3, 6, 9}}, 0.1f);
    const RingSet set = rings_for(line, 8);
    expect_orthonormal(set, 1e-12);
    for (const Frame& f : set.frames) {
        EXPECT_LT(glm::length(f.r - set.frames[0].r), 1e-12);
    }
}

/// Consecutive frames never turn by much more than the tangent does (a flip would be ~180 degrees), and every
/// ring's frame agrees with the finely sampled RMF at the same parameter to `max_twist_deg`.
void expect_continuous(const RingSet& set, const RingSet& ref, uint32_t n, uint32_t ref_n, double max_twist_deg) {
    double worst_excess = 0.0, worst_twist = 0.0;
    for (std::size_t i = 0; i < set.frames.size(); ++i) {
        const Frame& g = ref.frames[i * (ref_n / n)];
        worst_twist = std::max(worst_twist, std::abs(angle_about(g.r, set.frames[i].r, g.t)) * 180 / kPi);
        if (i == 0) continue;
        const Frame& a = set.frames[i - 1];
        const Frame& b = set.frames[i];
        // Rotation angle of the map taking frame a to frame b: trace = 1 + 2 cos(angle).
        const double trace = glm::dot(a.t, b.t) + glm::dot(a.r, b.r) + glm::dot(a.s, b.s);
        const double frame_angle = std::acos(std::clamp((trace - 1.0) / 2.0, -1.0, 1.0));
        const double tangent_angle = std::acos(std::clamp(glm::dot(a.t, b.t), -1.0, 1.0));
        worst_excess = std::max(worst_excess, frame_angle - tangent_angle);
    }
    std::printf("  %u rings/segment: frame turn beyond tangent turn <= %.2f deg, twist vs fine %.2e deg\n", n,
                worst_excess * 180 / kPi, worst_twist);
    EXPECT_LT(worst_excess * 180 / kPi, 15.0);
    EXPECT_LT(worst_twist, max_twist_deg);
}

// A 180-degree hairpin of radius 1 cm between two 1 m straights, climbing out of plane: frames stay continuous
// and accurate even at one ring per segment (the guard splits steps that turn by more than 45 degrees).
TEST(Frames, HairpinIsContinuous) {
    const double k = 4.0 / 3.0 * (std::sqrt(2.0) - 1.0);  // quarter-circle Bezier handle
    const double r = 0.01;
    const glm::dvec3 z(0, 0.3, 1);  // the turn climbs
    std::vector<CubicBezier> segs = {
        hermite({0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}),
        CubicBezier{{1, 0, 0}, {1 + k * r, 0, 0}, glm::dvec3(1 + r, r - k * r, 0) + 0.01 * z,
                    glm::dvec3(1 + r, r, 0) + 0.01 * z},
        CubicBezier{glm::dvec3(1 + r, r, 0) + 0.01 * z, glm::dvec3(1 + r, r + k * r, 0) + 0.01 * z,
                    glm::dvec3(1 + k * r, 2 * r, 0) + 0.02 * z, glm::dvec3(1, 2 * r, 0) + 0.02 * z},
        hermite(glm::dvec3(1, 2 * r, 0) + 0.02 * z, {-1, 0, 0}, glm::dvec3(0, 2 * r, 0) + 0.02 * z, {-1, 0, 0}),
    };
    const Curve hairpin = make_curve(segs, 0.002f);
    const RingSet ref = rings_for(hairpin, 256);
    for (uint32_t n : {1u, 2u, 4u, 8u}) {
        const RingSet set = rings_for(hairpin, n);
        expect_orthonormal(set);
        expect_continuous(set, ref, n, 256, 0.5);
    }
    // The rotation baseline at one ring per segment, for comparison (no guard).
    RingSettings rotation;
    rotation.frames.method = FrameMethod::rotation;
    const RingSet base = rings_for(hairpin, 1, rotation);
    const double base_twist = std::abs(angle_about(ref.frames.back().r, base.frames.back().r, ref.frames.back().t));
    std::printf("  rotation method at 1 ring/segment: end twist %.2f deg\n", base_twist * 180 / kPi);
}

// A loop whose tangent is the mirror image of the start tangent one step later (c2 = 0 exactly at one ring per
// segment): the hairpin guard subdivides and the frame matches the finely sampled one.
TEST(Frames, LoopWithinOneStepIsSubdivided) {
    const Curve loop = make_curve({CubicBezier{{0, 0, 0}, {3, 3, 0}, {2, -1, 0}, {1, 0, 0}}}, 0.01f);
    RingSettings in_plane;  // seed the normal in the plane of the loop: the hard direction
    in_plane.frames.has_previous_normal = true;
    in_plane.frames.previous_normal = glm::dvec3(-1, 1, 0);
    const RingSet coarse = rings_for(loop, 1, in_plane);
    const RingSet fine = rings_for(loop, 512, in_plane);
    expect_orthonormal(coarse);
    EXPECT_GE(coarse.frame_stats.subdivided_steps, 1u);
    EXPECT_TRUE(coarse.frame_stats.seeded_from_previous);
    const double twist = std::abs(angle_about(fine.frames.back().r, coarse.frames.back().r, fine.frames.back().t));
    std::printf("  loop in one step: %u subdivided, end twist vs fine %.3e deg\n", coarse.frame_stats.subdivided_steps,
                twist * 180 / kPi);
    EXPECT_LT(twist * 180 / kPi, 0.1);
}

// A cusp (derivative zero mid-segment: the curve turns back on itself) and a zero-length segment.
TEST(Frames, CuspAndZeroLengthSegment) {
    const glm::dvec3 p(1, 0, 0);
    const Curve cusp = make_curve({CubicBezier{{0, 0, 0}, p, p, {0, 0.0, 0}},  // B'(0.5) = 0
                                   hermite({0, 0, 0}, {0, 1, 0.5}, {0, 1, 1}, {0, 1, 0}),
                                   CubicBezier{{0, 1, 1}, {0, 1, 1}, {0, 1, 1}, {0, 1, 1}},  // one point
                                   hermite({0, 1, 1}, {1, 0, 0}, {1, 1, 1}, {1, 0, 0})},
                                  0.01f);
    for (uint32_t n : {1u, 2u, 3u, 4u, 16u}) {
        const RingSet set = rings_for(cusp, n);
        expect_orthonormal(set);
        EXPECT_GE(set.frame_stats.degenerate_tangents, 1u);  // the one-point segment's rings
        TubeMesh mesh;
        build_tube(set, TubeSettings{.sides = 6}, mesh);
        for (const TubeVertex& v : mesh.vertices) {
            ASSERT_TRUE(finite(v.position) && finite(v.normal));
        }
        const WeldReport w = weld_check(mesh);
        EXPECT_EQ(w.bad_edges, 0u) << n;
    }
    bool degenerate = false;
    EXPECT_EQ(unit_tangent(cusp.segments[2], 0.5, &degenerate), glm::dvec3(0.0));
    EXPECT_TRUE(degenerate);
    const glm::dvec3 t = unit_tangent(cusp.segments[0], 0.5, &degenerate);
    EXPECT_TRUE(degenerate);
    EXPECT_LT(glm::length(t - glm::dvec3(-1, 0, 0)), 1e-12);  // outgoing direction at the cusp
}

// A closed loop of 3 nodes that leaves its plane: nonzero holonomy, removed so the frame closes up.
TEST(Frames, ClosedLoopHolonomyRemoved) {
    // Three nodes with tangents out of the triangle's plane.
    const glm::dvec3 p[3] = {{1, 0, 0}, {-0.5, 0.866, 0}, {-0.5, -0.866, 0}};
    std::vector<CubicBezier> segs;
    for (int i = 0; i < 3; ++i) {
        const glm::dvec3 a = p[i], b = p[(i + 1) % 3];
        const double lift[3] = {1.0, -1.0, 0.5};  // tangents leave the triangle's plane, continuously per node
        const glm::dvec3 ma = 0.5 * (p[(i + 1) % 3] - p[(i + 2) % 3]) + glm::dvec3(0, 0, lift[i]);
        const glm::dvec3 mb = 0.5 * (p[(i + 2) % 3] - p[i]) + glm::dvec3(0, 0, lift[(i + 1) % 3]);
        segs.push_back(hermite(a, ma, b, mb));
    }
    const Curve loop = make_curve(segs, 0.05f, true);
    RingSettings keep;
    keep.frames.keep_holonomy = true;
    const RingSet raw = rings_for(loop, 64, keep);
    const RingSet fixed = rings_for(loop, 64);
    expect_orthonormal(fixed);
    EXPECT_EQ(fixed.rings.size(), 3u * 64u);  // no duplicate ring
    EXPECT_NEAR(raw.frame_stats.holonomy_rad, fixed.frame_stats.holonomy_rad, 1e-15);
    std::printf("  3-node loop holonomy %.4f deg\n", fixed.frame_stats.holonomy_rad * 180 / kPi);
    EXPECT_GT(std::abs(fixed.frame_stats.holonomy_rad), 1e-3);

    // Carry the last ring's frame to ring 0 by a minimal rotation: it must land on ring 0's normal.
    auto closing_twist = [](const RingSet& s) {
        const Frame& last = s.frames.back();
        const Frame& first = s.frames.front();
        const glm::dvec3 axis = glm::cross(last.t, first.t);
        const double c = glm::dot(last.t, first.t);
        const glm::dvec3 r = c * last.r + glm::cross(axis, last.r) + axis * (glm::dot(axis, last.r) / (1 + c));
        return std::abs(angle_about(first.r, r, first.t)) * 180 / kPi;
    };
    // Corrected, the join (last ring -> ring 0) twists by exactly its arc-length share of the correction, like
    // every other step: no seam.
    const double share_deg = std::abs(fixed.frame_stats.holonomy_rad) * 180 / kPi *
                             (fixed.arc_length_m.back() - fixed.arc_length_m[fixed.frames.size() - 1]) /
                             fixed.arc_length_m.back();
    std::printf("  closing twist: raw %.4f deg, corrected %.4f deg (its arc-length share %.4f deg)\n",
                closing_twist(raw), closing_twist(fixed), share_deg);
    EXPECT_GT(closing_twist(raw), 10.0);
    EXPECT_NEAR(closing_twist(fixed), share_deg, 1e-3);

    // Exactly: the same segments as an open wire end (at node 0, same tangent) on the uncorrected transport, and
    // undoing the holonomy there lands on ring 0's normal.
    Curve open = loop;
    open.closed = false;
    open.radius_m.push_back(open.radius_m[0]);
    open.source_node.push_back(0);
    RingSettings seeded;
    seeded.frames.has_previous_normal = true;
    seeded.frames.previous_normal = fixed.frames[0].r;
    const RingSet unrolled = rings_for(open, 64, seeded);
    const Frame& end = unrolled.frames.back();
    EXPECT_LT(glm::length(end.t - fixed.frames[0].t), 1e-12);
    EXPECT_NEAR(angle_about(fixed.frames[0].r, end.r, end.t), fixed.frame_stats.holonomy_rad, 1e-9);
    // The correction is spread linearly in arc length: no single step takes more than its share.
    for (std::size_t i = 1; i < fixed.frames.size(); ++i) {
        const double d = angle_about(raw.frames[i].r, fixed.frames[i].r, fixed.frames[i].t);
        const double expected = -raw.frame_stats.holonomy_rad * fixed.arc_length_m[i] / fixed.arc_length_m.back();
        EXPECT_NEAR(d, expected, 1e-9);
    }
}

// 1e6 m from the origin: the same frames as at the origin, centres accurate to float precision of the extent.
TEST(Frames, FarFromOrigin) {
    const glm::dvec3 far(1e6, -1e6, 1e6);
    const RingSet near_set = rings_for(helix_curve(1.0, 0.3, 3, 16), 8);
    const RingSet far_set = rings_for(helix_curve(1.0, 0.3, 3, 16, far), 8);
    expect_orthonormal(far_set);
    ASSERT_EQ(near_set.rings.size(), far_set.rings.size());
    double worst_angle = 0.0, worst_pos = 0.0;
    for (std::size_t i = 0; i < far_set.frames.size(); ++i) {
        worst_angle = std::max(worst_angle, glm::length(far_set.frames[i].r - near_set.frames[i].r));
        const glm::dvec3 world = far_set.origin_m + glm::dvec3(far_set.rings[i].centre_m);
        const glm::dvec3 exact = position(helix_curve(1.0, 0.3, 3, 16, far).segments[far_set.params[i].segment],
                                          far_set.params[i].t);
        worst_pos = std::max(worst_pos, glm::length(world - exact));
    }
    std::printf("  1e6 m: frame difference %.2e, centre error %.2e m\n", worst_angle, worst_pos);
    EXPECT_LT(worst_angle, 1e-6);
    EXPECT_LT(worst_pos, 2e-6);
}

// Temporal coherence: a slightly moved wire keeps its first frame (turned by no more than its first tangent).
TEST(Frames, FirstFrameCarriedOver) {
    // First tangent near the boundary where the least-aligned world axis switches from x to y.
    auto wire_at = [](double e) {
        const glm::dvec3 t0 = glm::normalize(glm::dvec3(0.1, 0.1 + e, 1.0));
        return make_curve({hermite({0, 0, 0}, t0, {0.2, 0.3, 1.0}, {0.2, 0.3, 1.0})}, 0.01f);
    };
    const RingSet a = rings_for(wire_at(-1e-4), 8);
    RingSettings carry;
    carry.frames.has_previous_normal = true;
    carry.frames.previous_normal = a.frames[0].r;
    const RingSet b = rings_for(wire_at(1e-4), 8, carry);
    const RingSet b_reseeded = rings_for(wire_at(1e-4), 8);
    EXPECT_TRUE(b.frame_stats.seeded_from_previous);
    auto angle = [](const glm::dvec3& x, const glm::dvec3& y) {
        return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
    };
    const double tangent_change = angle(a.frames[0].t, b.frames[0].t);
    const double carried = angle(a.frames[0].r, b.frames[0].r);
    const double reseeded = angle(a.frames[0].r, b_reseeded.frames[0].r);
    std::printf("  first tangent turned %.2e rad: carried normal turned %.2e rad, axis re-seeded %.2f rad\n",
                tangent_change, carried, reseeded);
    EXPECT_LE(carried, tangent_change * (1 + 1e-9));
    EXPECT_GT(reseeded, 1.0);  // what every peer does: the tube spins
    // A previous normal parallel to the new tangent falls back to the axis seed, still orthonormal.
    RingSettings parallel;
    parallel.frames.has_previous_normal = true;
    parallel.frames.previous_normal = b.frames[0].t;
    const RingSet c = rings_for(wire_at(1e-4), 8, parallel);
    EXPECT_FALSE(c.frame_stats.seeded_from_previous);
    expect_orthonormal(c);
}

}  // namespace
}  // namespace wire::test
