// Properties of the curved-space CPU reference: lengths, joins, circle closure, alpha -> 0, Jacobian
// normals, straight continuation, errors, bend direction, bounds and folding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "curved_space/bend.hpp"
#include "curved_space/chain.hpp"
#include "curved_space/gpu.hpp"

namespace {

using curved_space::Chain;
using curved_space::Segment;
using glm::dvec3;
constexpr double pi = std::numbers::pi;

Chain build(const std::vector<Segment>& segments) {
    Chain chain;
    const engine::Status status = curved_space::make_chain(segments, chain);
    EXPECT_TRUE(status.ok()) << status.message;
    return chain;
}

// A chain that turns in several directions, with a straight piece and a negative angle.
std::vector<Segment> mixed_segments() {
    return {{4.0, 0.5, 0.0}, {2.0, -1.2, 0.3}, {3.0, 0.0, 1.0}, {1.5, 2.0, pi / 2}, {5.0, 0.8, -2.0}};
}

dvec3 world_vector(const glm::dmat4& m, const dvec3& v) { return dvec3(m * glm::dvec4(v, 0.0)); }
dvec3 world_point(const glm::dmat4& m, const dvec3& p) { return dvec3(m * glm::dvec4(p, 1.0)); }

// Unit tangent of the centre line at local z of segment i, analytically: Ry(th) +z in the bend frame.
dvec3 centre_tangent(const Chain& chain, std::size_t i, double z_local) {
    const double th = chain.kappa_per_m(i) * z_local;
    return world_vector(chain.world_from_bend(i), {std::sin(th), 0.0, std::cos(th)});
}

TEST(CurvedSpaceSinc, StableNearZero) {
    EXPECT_EQ(curved_space::sinc(0.0), 1.0);
    EXPECT_EQ(curved_space::sinc(1e-300), 1.0);
    for (double t : {1e-12, 1e-6, 9.9e-5, 1.01e-4, 1e-3, 0.5, 3.0})
        EXPECT_NEAR(curved_space::sinc(t), std::sin(t) / t, 2e-16) << t;
    EXPECT_NEAR(curved_space::sinc(pi), 0.0, 1e-16);
}

TEST(CurvedSpaceBend, MatchesPaperRadiusForm) {
    // Paper 001: x' = x + r' - cos(beta) r', z' = sin(beta) r', r' = r - x, r = d / alpha, beta = z/d alpha.
    const double d = 3.0;
    const double alpha = 1.1;
    const double r = d / alpha;
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    std::uniform_real_distribution<double> uz(0.0, d);
    for (int k = 0; k < 1000; ++k) {
        const dvec3 p{u(rng), u(rng), uz(rng)};
        const double beta = p.z / d * alpha;
        const double rp = r - p.x;
        const dvec3 expected{p.x + rp - std::cos(beta) * rp, p.y, std::sin(beta) * rp};
        const dvec3 got = curved_space::bend_segment({d, alpha, 0.0}, p, {0, 0, 1}).position;
        EXPECT_LT(glm::length(got - expected), 1e-14);
    }
}

TEST(CurvedSpaceChain, CentreLineKeepsLength) {
    const Chain chain = build(mixed_segments());
    const double total = chain.total_length_m();
    ASSERT_DOUBLE_EQ(total, 15.5);
    // Polyline of N samples underestimates an arc by about L (kappa h)^2 / 24: kappa <= 1.34, h = 7.75e-5
    // gives < 1.5e-9 * L in the worst segment, so sample through Richardson extrapolation of N and 2N.
    auto polyline = [&](int n) {
        double length = 0.0;
        dvec3 previous = chain.transform_point({0, 0, 0});
        for (int k = 1; k <= n; ++k) {
            const dvec3 p = chain.transform_point({0, 0, total * k / n});
            length += glm::length(p - previous);
            previous = p;
        }
        return length;
    };
    const double coarse = polyline(100000);
    const double fine = polyline(200000);
    const double extrapolated = fine + (fine - coarse) / 3.0;
    const double relative = std::abs(extrapolated - total) / total;
    std::printf("[ measure  ] centre line length relative error %.3g (polyline 2e5: %.3g)\n", relative,
                std::abs(fine - total) / total);
    EXPECT_LT(relative, 1e-9);
}

TEST(CurvedSpaceChain, SegmentsJoinWithMatchingPositionAndTangent) {
    const Chain chain = build(mixed_segments());
    for (std::size_t i = 0; i + 1 < chain.segment_count(); ++i) {
        const double d = chain.segment(i).length_m;
        const double boundary = chain.z_start_m(i + 1);
        // Exactly at the boundary, from both sides, on and off the axis.
        for (const dvec3 offset : {dvec3(0, 0, 0), dvec3(0.3, -0.2, 0), dvec3(-0.25, 0.4, 0)}) {
            const dvec3 left = world_point(chain.world_from_segment(i),
                                           curved_space::bend_segment(chain.segment(i), offset + dvec3(0, 0, d),
                                                                      {0, 0, 1})
                                               .position);
            const dvec3 right = chain.transform_point(offset + dvec3(0, 0, boundary));
            EXPECT_LT(glm::length(left - right), 1e-12) << "boundary " << i;
        }
        const dvec3 tangent_left = centre_tangent(chain, i, d);
        const dvec3 tangent_right = world_vector(chain.world_from_segment(i + 1), {0, 0, 1});
        EXPECT_LT(glm::length(tangent_left - tangent_right), 1e-12) << "boundary " << i;

        // Just inside each side: positions meet to within the gap, finite-difference tangents agree.
        const double eps = 1e-7;
        const double h = 1e-5;
        const dvec3 a = chain.transform_point({0, 0, boundary - eps});
        const dvec3 b = chain.transform_point({0, 0, boundary + eps});
        EXPECT_NEAR(glm::length(b - a), 2 * eps, 1e-12);
        const dvec3 ta = glm::normalize(a - chain.transform_point({0, 0, boundary - eps - h}));
        const dvec3 tb = glm::normalize(chain.transform_point({0, 0, boundary + eps + h}) - b);
        EXPECT_LT(glm::length(ta - tb), 2e-5) << "boundary " << i;
        EXPECT_LT(glm::length(ta - tangent_left), 1e-5);
        // Normals of a wall parallel to the axis (n.z = 0, a tunnel's) are continuous across the boundary.
        // (With n.z != 0 off the axis they are not: the z-stretch 1 - kappa x jumps with kappa.)
        const dvec3 n{0.6, -0.8, 0.0};
        const dvec3 na = chain.transform({0.1, 0.2, std::nextafter(boundary, 0.0)}, n).normal;
        const dvec3 nb = chain.transform({0.1, 0.2, boundary}, n).normal;
        EXPECT_LT(glm::length(na - nb), 1e-12);
    }
}

TEST(CurvedSpaceChain, ThousandSegmentsCloseACircle) {
    for (const double gamma : {0.0, 0.7}) {
        const double total = 100.0;
        const std::vector<Segment> segments(1000, Segment{total / 1000, 2 * pi / 1000, gamma});
        const Chain chain = build(segments);
        const dvec3 start = chain.transform_point({0, 0, 0});
        const dvec3 end = chain.transform_point({0, 0, total});
        const double closure = glm::length(end - start);
        const dvec3 end_tangent = world_vector(chain.world_from_segment(1000), {0, 0, 1});
        const double tangent_error = glm::length(end_tangent - dvec3(0, 0, 1));
        std::printf("[ measure  ] gamma %.1f: circle closure %.3g m (%.3g of length), end tangent error %.3g\n",
                    gamma, closure, closure / total, tangent_error);
        EXPECT_LT(closure, 1e-5 * total);
        EXPECT_LT(tangent_error, 1e-9);
        // Half way round: the far side of a circle of radius L / 2pi, in the bend direction.
        const double radius = total / (2 * pi);
        const dvec3 half = chain.transform_point({0, 0, total / 2});
        EXPECT_LT(glm::length(half - dvec3(2 * radius * std::cos(gamma), 2 * radius * std::sin(gamma), 0)), 1e-9);
    }
}

TEST(CurvedSpaceChain, TinyAndZeroAngleAreTheStraightMap) {
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    // alpha = 0: bit for bit the straight map (the identity here), across several segments and outside.
    const Chain zero = build({{1.0, 0.0, 0.4}, {0.5, 0.0, -1.0}, {2.0, -0.0, 3.0}});
    for (int k = 0; k < 2000; ++k) {
        const dvec3 p{u(rng), u(rng), -1.0 + 5.5 * unit(rng)};
        const dvec3 n = glm::normalize(dvec3{u(rng), u(rng), u(rng)});
        const curved_space::BentVertex bent = zero.transform(p, n);
        EXPECT_LT(glm::length(bent.position - p), 1e-15);
        EXPECT_LT(glm::length(bent.normal - n), 1e-15);
    }
    // alpha = 1e-12 over 1 m: the exact map moves |x| <= 0.25, z in [-0.5, 1.25] by < 0.9e-12, so the
    // result must equal the straight map to 1e-12 (no 0/0, no cancellation blow-up).
    for (const double alpha : {1e-12, -1e-12, 1e-300}) {
        const Chain chain = build({{1.0, alpha, 0.4}});
        double worst = 0.0;
        for (int k = 0; k < 2000; ++k) {
            const dvec3 p{0.25 * u(rng), 0.25 * u(rng), -0.5 + 1.75 * unit(rng)};
            const dvec3 n = glm::normalize(dvec3{u(rng), u(rng), u(rng)});
            const curved_space::BentVertex bent = chain.transform(p, n);
            ASSERT_TRUE(std::isfinite(bent.position.x) && std::isfinite(bent.position.y) &&
                        std::isfinite(bent.position.z));
            worst = std::max(worst, glm::length(bent.position - p));
            EXPECT_LT(glm::length(bent.position - p), 1e-12) << alpha;
            // The exact normal turns by up to alpha (plus a z-stretch of kappa |x| <= 0.25 alpha).
            EXPECT_LT(glm::length(bent.normal - n), 1.5e-12) << alpha;
            EXPECT_FALSE(bent.folded);
        }
        std::printf("[ measure  ] alpha %.0e: max |bent - straight| %.3g m\n", alpha, worst);
    }
}

TEST(CurvedSpaceChain, JacobianNormalMatchesFiniteDifferences) {
    const Chain chain = build(mixed_segments());
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double worst = 0.0;
    int tested = 0;
    while (tested < 3000) {
        // A point strictly inside a segment (central differences must not straddle a boundary) or outside.
        const std::size_t i = static_cast<std::size_t>(unit(rng) * 7.0);
        double z = 0.0;
        if (i == 0) {
            z = -2.0 * unit(rng) - 1e-3;
        } else if (i == 6) {
            z = chain.total_length_m() + 2.0 * unit(rng) + 1e-3;
        } else {
            const std::size_t s = i - 1;
            z = chain.z_start_m(s) + chain.segment(s).length_m * (0.001 + 0.998 * unit(rng));
        }
        const dvec3 p{0.5 * u(rng), 0.5 * u(rng), z};
        const dvec3 n = glm::normalize(dvec3{u(rng), u(rng), u(rng)});
        // Two tangent directions of the surface through p with normal n.
        const dvec3 helper = std::abs(n.x) < 0.6 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
        const dvec3 t1 = glm::normalize(glm::cross(n, helper));
        const dvec3 t2 = glm::cross(n, t1);
        const curved_space::BentVertex bent = chain.transform(p, n);
        ASSERT_FALSE(bent.folded);
        EXPECT_NEAR(glm::length(bent.normal), 1.0, 1e-14);
        const double h = 1e-5;
        for (const dvec3& t : {t1, t2}) {
            const dvec3 image = (chain.transform_point(p + h * t) - chain.transform_point(p - h * t)) / (2 * h);
            const double cosine = std::abs(glm::dot(bent.normal, image)) / glm::length(image);
            worst = std::max(worst, cosine);
        }
        // The normal keeps its side: it still points away from the surface the way n did.
        const dvec3 along = (chain.transform_point(p + h * n) - chain.transform_point(p - h * n)) / (2 * h);
        EXPECT_GT(glm::dot(bent.normal, along), 0.0);
        ++tested;
    }
    std::printf("[ measure  ] max |n' . t'| / |t'| = %.3g over %d points\n", worst, tested);
    EXPECT_LT(worst, 1e-6);
}

TEST(CurvedSpaceChain, StraightBeforeAndAfterTheChain) {
    // A chain placed away from the origin: world_from_chain is M[0].
    glm::dmat4 world_from_chain(1.0);
    world_from_chain[0] = glm::dvec4(0, 1, 0, 0);  // x -> y, y -> -x: a quarter turn about z
    world_from_chain[1] = glm::dvec4(-1, 0, 0, 0);
    world_from_chain[3] = glm::dvec4(1e6, -2e6, 3.0, 1);
    Chain chain;
    ASSERT_TRUE(curved_space::make_chain(mixed_segments(), chain, world_from_chain).ok());
    const double total = chain.total_length_m();
    const glm::dmat4& end = chain.world_from_segment(chain.segment_count());
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int k = 0; k < 1000; ++k) {
        const dvec3 xy{u(rng), u(rng), 0.0};
        const double s = 10.0 * std::abs(u(rng)) + 1e-9;
        const dvec3 n = glm::normalize(dvec3{u(rng), u(rng), u(rng)});
        // Before: the start frame, rigidly.
        const curved_space::BentVertex before = chain.transform(xy + dvec3(0, 0, -s), n);
        EXPECT_LT(glm::length(before.position - world_point(world_from_chain, xy + dvec3(0, 0, -s))), 1e-8);
        EXPECT_LT(glm::length(before.normal - world_vector(world_from_chain, n)), 1e-12);
        // After: the end frame, rigidly: the centre line continues along the end tangent.
        const curved_space::BentVertex after = chain.transform(xy + dvec3(0, 0, total + s), n);
        EXPECT_LT(glm::length(after.position - world_point(end, xy + dvec3(0, 0, s))), 1e-8);
        EXPECT_LT(glm::length(after.normal - world_vector(end, n)), 1e-12);
    }
    const dvec3 end_point = chain.transform_point({0, 0, total});
    const dvec3 end_tangent = centre_tangent(chain, chain.segment_count() - 1, chain.segment(4).length_m);
    EXPECT_LT(glm::length(chain.transform_point({0, 0, total + 7.0}) - (end_point + 7.0 * end_tangent)), 1e-8);
    EXPECT_LT(glm::length(chain.transform_point({0, 0, -7.0}) - world_point(world_from_chain, {0, 0, -7.0})), 1e-8);
}

TEST(CurvedSpaceChain, InvalidSegmentsAreRejectedWithTheirIndexAndField) {
    const double nan = std::nan("");
    const double inf = std::numeric_limits<double>::infinity();
    struct Case {
        std::vector<Segment> segments;
        const char* message;
        int index;
    };
    const std::vector<Case> cases{
        {{{1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {-1, 0.2, 0}}, "segment 3: length must be positive, got -1", 3},
        {{{0, 0, 0}}, "segment 0: length must be positive, got 0", 0},
        {{{1, 0, 0}, {nan, 0, 0}}, "segment 1: length must be finite, got nan", 1},
        {{{inf, 0, 0}}, "segment 0: length must be finite, got inf", 0},
        {{{1, 0, 0}, {1, 0, 0}, {2, nan, 0}}, "segment 2: angle must be finite, got nan", 2},
        {{{1, -inf, 0}}, "segment 0: angle must be finite, got -inf", 0},
        {{{1, 0.5, 0}, {1, 0.5, inf}}, "segment 1: direction must be finite, got inf", 1},
        {{{1, 0.5, 0}, {0.25, 0.5, 0}, {-0.5, 0, 0}}, "segment 2: length must be positive, got -0.5", 2},
    };
    for (const Case& c : cases) {
        Chain chain = build({{2.0, 1.0, 0.0}});
        const engine::Status status = curved_space::make_chain(c.segments, chain);
        EXPECT_FALSE(status.ok());
        EXPECT_EQ(status.message, c.message);
        EXPECT_EQ(status.index, c.index);
        // The chain given is left as it was.
        EXPECT_EQ(chain.segment_count(), 1u);
        EXPECT_EQ(chain.total_length_m(), 2.0);
    }
    // An empty chain is valid: the identity.
    Chain empty;
    ASSERT_TRUE(curved_space::make_chain({}, empty).ok());
    EXPECT_EQ(empty.transform_point({1, 2, 3}), dvec3(1, 2, 3));
}

TEST(CurvedSpaceChain, DirectionRotatesTheBend) {
    const double d = 2.0;
    const double r = d / (pi / 2);
    const Chain toward_x = build({{d, pi / 2, 0.0}});
    EXPECT_LT(glm::length(toward_x.transform_point({0, 0, d}) - dvec3(r, 0, r)), 1e-14);
    EXPECT_LT(glm::length(centre_tangent(toward_x, 0, d) - dvec3(1, 0, 0)), 1e-15);
    const Chain toward_y = build({{d, pi / 2, pi / 2}});
    EXPECT_LT(glm::length(toward_y.transform_point({0, 0, d}) - dvec3(0, r, r)), 1e-14);
    EXPECT_LT(glm::length(world_vector(toward_y.world_from_segment(1), {0, 0, 1}) - dvec3(0, 1, 0)), 1e-15);
    // The y-offset side of the mesh is the inner side when bending toward +y: it gets shorter.
    const dvec3 inner = toward_y.transform_point({0, 0.5, d});
    EXPECT_LT(glm::length(inner - dvec3(0, r - (r - 0.5) * std::cos(pi / 2), (r - 0.5) * std::sin(pi / 2))), 1e-14);
    // Negative angle == opposite direction.
    const Chain negative = build({{d, -pi / 2, 0.0}});
    EXPECT_LT(glm::length(negative.transform_point({0.1, 0.2, d}) - build({{d, pi / 2, pi}}).transform_point({0.1, 0.2, d})),
              1e-14);
}

TEST(CurvedSpaceChain, FoldingIsFlaggedAndFinite) {
    const double d = 1.0;
    const Chain chain = build({{d, 2.0, 0.0}});  // radius 0.5
    for (const double x : {0.49, 0.5, 0.51, 3.0, -3.0}) {
        const curved_space::BentVertex bent = chain.transform({x, 0.1, 0.5}, {0, 0, 1});
        EXPECT_EQ(bent.folded, x >= 0.5) << x;
        for (int k = 0; k < 3; ++k) {
            EXPECT_TRUE(std::isfinite(bent.position[k]));
            EXPECT_TRUE(std::isfinite(bent.normal[k]));
        }
        EXPECT_NEAR(glm::length(bent.normal), 1.0, 1e-14);
    }
    // A tangential normal exactly on the axis of curvature: still a unit normal.
    const curved_space::BentVertex axis = chain.transform({0.5, 0, 0.5}, {1, 0, 0});
    EXPECT_TRUE(axis.folded);
    EXPECT_NEAR(glm::length(axis.normal), 1.0, 1e-14);
    // bend_vertices counts folded vertices.
    std::vector<float> positions{0.0f, 0.0f, 0.5f, 0.7f, 0.0f, 0.5f, 0.7f, 0.0f, 2.0f, -0.7f, 0.0f, 0.5f};
    std::vector<float> normals{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    EXPECT_EQ(curved_space::bend_vertices(chain, positions, normals), 1u);
}

TEST(CurvedSpaceChain, BendVerticesIsTheReferenceTransform) {
    const Chain chain = build(mixed_segments());
    const dvec3 origin{0.0, 0.0, 3.0};
    std::vector<float> positions;
    std::vector<float> normals;
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int k = 0; k < 300; ++k) {
        positions.insert(positions.end(), {0.5f * u(rng), 0.5f * u(rng), 10.0f * u(rng)});
        const glm::vec3 n = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
        normals.insert(normals.end(), {n.x, n.y, n.z});
    }
    std::vector<float> bent_positions = positions;
    std::vector<float> bent_normals = normals;
    EXPECT_EQ(curved_space::bend_vertices(chain, bent_positions, bent_normals, origin), 0u);
    for (std::size_t v = 0; v < 300; ++v) {
        const dvec3 p = origin + dvec3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
        const dvec3 n(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
        const curved_space::BentVertex ref = chain.transform(p, n);
        for (int k = 0; k < 3; ++k) {
            EXPECT_EQ(bent_positions[3 * v + static_cast<std::size_t>(k)], static_cast<float>((ref.position - origin)[k]));
            EXPECT_EQ(bent_normals[3 * v + static_cast<std::size_t>(k)], static_cast<float>(ref.normal[k]));
        }
    }
}

TEST(CurvedSpaceBounds, EnclosesTheBentBoxAndIsNearlyTight) {
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double worst_slack = 0.0;
    for (int trial = 0; trial < 40; ++trial) {
        std::vector<Segment> segments;
        const int count = 1 + static_cast<int>(unit(rng) * 6);
        for (int s = 0; s < count; ++s)
            segments.push_back({0.5 + 4 * unit(rng), 2.5 * u(rng), pi * u(rng)});
        const Chain chain = build(segments);
        const double total = chain.total_length_m();
        curved_space::Aabb box;
        box.min = {-unit(rng), -unit(rng), -3 + (total + 3) * unit(rng) * 0.5};
        box.max = {unit(rng), unit(rng), box.min.z + (total + 6) * unit(rng)};
        const curved_space::Aabb bounds = chain.bounds(box);
        dvec3 lo(1e300);
        dvec3 hi(-1e300);
        auto check = [&](const dvec3& t) {
            const dvec3 p = box.min + t * (box.max - box.min);
            const dvec3 q = chain.transform_point(p);
            lo = glm::min(lo, q);
            hi = glm::max(hi, q);
            for (int a = 0; a < 3; ++a) {
                EXPECT_GE(q[a], bounds.min[a] - 1e-12) << "trial " << trial;
                EXPECT_LE(q[a], bounds.max[a] + 1e-12) << "trial " << trial;
            }
        };
        // The extremes of an affine cross-section lie on the four edges along z: sample those densely,
        // then random points inside.
        for (int k = 0; k <= 4000; ++k)
            for (const glm::dvec2 corner : {glm::dvec2(0, 0), glm::dvec2(1, 0), glm::dvec2(0, 1), glm::dvec2(1, 1)})
                check({corner.x, corner.y, k / 4000.0});
        for (int k = 0; k < 5000; ++k) check({unit(rng), unit(rng), unit(rng)});
        // Not much larger than the sampled extent (slack about 1e-3 of the local size).
        for (int a = 0; a < 3; ++a) {
            worst_slack = std::max({worst_slack, lo[a] - bounds.min[a], bounds.max[a] - hi[a]});
            EXPECT_LT(lo[a] - bounds.min[a], 0.01) << "trial " << trial << " axis " << a;
            EXPECT_LT(bounds.max[a] - hi[a], 0.01) << "trial " << trial << " axis " << a;
        }
    }
    std::printf("[ measure  ] bounds: largest slack over the sampled extent %.3g m\n", worst_slack);
}

TEST(CurvedSpaceGpuRecords, CameraRelativeInDouble) {
    glm::dmat4 world_from_chain(1.0);
    world_from_chain[3] = glm::dvec4(1e6, 2e6, -1e6, 1.0);
    Chain chain;
    ASSERT_TRUE(curved_space::make_chain(mixed_segments(), chain, world_from_chain).ok());
    const dvec3 camera{1e6 + 1.0, 2e6 - 2.0, -1e6 + 0.5};
    const std::vector<curved_space::GpuSegment> records = curved_space::gpu_segments(chain, camera);
    ASSERT_EQ(records.size(), chain.segment_count() + 1);
    for (std::size_t i = 0; i < records.size(); ++i) {
        const glm::dmat4& m = chain.world_from_bend(i);
        const dvec3 expected = dvec3(m[3]) - camera;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(records[i].world_from_bend[3][k], expected[k], 1e-5);
        EXPECT_EQ(records[i].params.x, static_cast<float>(chain.z_start_m(i)));
        EXPECT_EQ(records[i].params.z, static_cast<float>(chain.kappa_per_m(i)));
    }
    EXPECT_EQ(records.back().params.y, 0.0f);
    EXPECT_EQ(records.back().params.z, 0.0f);
    EXPECT_FALSE(curved_space::glsl_bend_source().empty());
}

}  // namespace
