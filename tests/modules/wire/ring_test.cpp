// Rings: arc length, stretch-aware u (continuous, monotonic), radius interpolation, fold detection, big wires.
#include "ring_test_curves.hpp"

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <limits>
#include <numbers>

namespace wire::test {
namespace {

TEST(Rings, RecordLayout) {
    EXPECT_EQ(sizeof(Ring), 48u);
    EXPECT_EQ(offsetof(Ring, radius_m), 12u);
    EXPECT_EQ(offsetof(Ring, u), 28u);
    EXPECT_EQ(offsetof(Ring, segment), 44u);
}

// u advances by length / (2 pi R stretch): the thesis' rule, exact on straight segments.
TEST(Rings, UFollowsLengthRadiusAndStretch) {
    Curve c = polyline_curve({{0, 0, 0}, {2, 0, 0}, {2, 3, 0}}, 0.1f);
    c.stretch = {1.0f, 2.0f};
    const RingSet set = rings_for(c, 4);
    const double per_m = 1.0 / (2 * kPi * static_cast<double>(0.1f));
    EXPECT_NEAR(set.u[4], 2.0 * per_m, 1e-9);               // end of segment 0
    EXPECT_NEAR(set.u.back(), 2.0 * per_m + 3.0 * per_m / 2.0, 1e-9);  // stretched: half the repeats per metre
    EXPECT_NEAR(set.length_m, 5.0, 1e-12);
    expect_u_monotonic(set);
}

// u is continuous: sampling finer gives the same u at shared rings (u at the end of segment i is u at the start of
// segment i+1), and the arc length matches a dense polyline.
TEST(Rings, UContinuousAndArcLengthAccurate) {
    Curve c = helix_curve(1.0, 0.3, 2, 5);
    for (std::size_t i = 0; i < c.radius_m.size(); ++i) c.radius_m[i] = 0.02f + 0.01f * static_cast<float>(i % 3);
    for (std::size_t i = 0; i < c.stretch.size(); ++i) c.stretch[i] = 1.0f + 0.25f * static_cast<float>(i % 2);
    const RingSet coarse = rings_for(c, 4);
    const RingSet fine = rings_for(c, 64);
    for (std::size_t i = 0; i < coarse.u.size(); ++i) {
        EXPECT_NEAR(coarse.u[i], fine.u[i * 16], 1e-6 * fine.u.back()) << i;
    }
    double dense = 0.0;
    for (const CubicBezier& s : c.segments) {
        for (int k = 0; k < 20000; ++k) dense += glm::length(position(s, (k + 1) / 20000.0) - position(s, k / 20000.0));
    }
    EXPECT_NEAR(coarse.length_m, dense, 1e-7 * dense);
    expect_u_monotonic(coarse);
    for (std::size_t i = 0; i < coarse.rings.size(); ++i) {
        EXPECT_FLOAT_EQ(coarse.rings[i].u, static_cast<float>(coarse.u[i]));
    }
}

TEST(Rings, RadiusInterpolationIsMonotoneAndHitsNodes) {
    Curve c = polyline_curve({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}}, 0.1f);
    c.radius_m = {0.1f, 0.3f, 0.2f, 0.2f, 1e-6f};
    for (uint32_t s = 0; s < 4; ++s) {
        EXPECT_FLOAT_EQ(static_cast<float>(radius_at(c, s, 0.0)), c.radius_m[s]);
        EXPECT_FLOAT_EQ(static_cast<float>(radius_at(c, s, 1.0)), c.radius_m[s + 1]);
        const double lo = std::min(c.radius_m[s], c.radius_m[s + 1]);
        const double hi = std::max(c.radius_m[s], c.radius_m[s + 1]);
        double prev = radius_at(c, s, 0.0);
        for (int k = 1; k <= 100; ++k) {
            const double r = radius_at(c, s, k / 100.0);
            EXPECT_GE(r, lo * (1 - 1e-6));
            EXPECT_LE(r, hi * (1 + 1e-6));
            EXPECT_GT(r, 0.0);
            EXPECT_TRUE(c.radius_m[s + 1] >= c.radius_m[s] ? r >= prev - 1e-12 : r <= prev + 1e-12);
            prev = r;
        }
    }
}

// A tube thicker than the bend's curvature radius folds: reported, output finite.
TEST(Rings, FoldDetected) {
    const Curve arc = helix_curve(0.1, 0.0, 1, 8, {}, 0.05f);  // circle of radius 0.1 m
    EXPECT_EQ(rings_for(arc, 8).fold_count, 0u);
    const Curve thick = helix_curve(0.1, 0.0, 1, 8, {}, 0.2f);
    const RingSet set = rings_for(thick, 8);
    EXPECT_EQ(set.fold_count, set.rings.size());
    EXPECT_EQ(set.first_fold_ring, 0u);
    expect_orthonormal(set);
    TubeMesh mesh;
    build_tube(set, TubeSettings{}, mesh);
    for (const TubeVertex& v : mesh.vertices) ASSERT_TRUE(finite(v.position) && finite(v.normal));
}

// 100,000 segments of a random smooth wire: finite, orthonormal, monotonic u, watertight mesh.
TEST(Rings, HundredThousandSegments) {
    std::mt19937 rng(11);
    std::normal_distribution<double> step(0.0, 0.05);
    std::vector<glm::dvec3> nodes(100001);
    glm::dvec3 dir(1, 0, 0);
    for (std::size_t i = 1; i < nodes.size(); ++i) {
        dir = glm::normalize(dir + glm::dvec3(step(rng), step(rng), step(rng)));
        nodes[i] = nodes[i - 1] + 0.01 * dir;
    }
    const Curve c = catmull_rom_curve(nodes, 0.002f);
    ASSERT_EQ(c.segment_count(), 100000u);
    const RingSet set = rings_for(c, 2);
    const double worst = expect_orthonormal(set);
    std::printf("  100,000 segments: worst orthonormality error %.1e\n", worst);
    EXPECT_LT(worst, 1e-12);
    expect_u_monotonic(set);
    TubeMesh mesh;
    build_tube(set, TubeSettings{.sides = 6}, mesh);
    const WeldReport w = weld_check(mesh);
    EXPECT_EQ(w.bad_edges, 0u);
    EXPECT_EQ(w.inconsistent_edges, 0u);
}

/// A random wire for the per-ring checks: control points in a box (some far from the origin), with repeated control
/// points (vanishing derivatives), signed zeros, one radius or a radius per node, random stretch; open or closed.
Curve random_ring_curve(std::mt19937& rng) {
    std::uniform_real_distribution<double> coord(-3.0, 3.0);
    std::uniform_int_distribution<int> pick(0, 9);
    const int segments = 1 + static_cast<int>(rng() % 40);
    const bool closed = pick(rng) < 2;
    const glm::dvec3 offset = pick(rng) < 2 ? glm::dvec3(1e6, -2e5, 3e4) : glm::dvec3(0.0);
    auto point = [&] {
        glm::dvec3 p(coord(rng), coord(rng), coord(rng));
        for (int a = 0; a < 3; ++a) {
            const int z = pick(rng);
            if (z == 0) p[a] = 0.0;
            if (z == 1) p[a] = -0.0;
        }
        return pick(rng) == 0 ? p : p + offset;
    };
    std::vector<glm::dvec3> nodes(static_cast<std::size_t>(closed ? segments : segments + 1));
    for (glm::dvec3& n : nodes) n = point();
    std::vector<CubicBezier> segs;
    for (int k = 0; k < segments; ++k) {
        const glm::dvec3 b0 = nodes[static_cast<std::size_t>(k)];
        const glm::dvec3 b3 = nodes[static_cast<std::size_t>(k + 1) % nodes.size()];
        CubicBezier c{b0, point(), point(), b3};
        const int shape = pick(rng);
        if (shape == 0) c.b1 = c.b0;                 // B'(0) = 0
        if (shape == 1) c.b2 = c.b3;                 // B'(1) = 0
        if (shape == 2) c.b1 = c.b2 = c.b3 = c.b0;  // a point
        if (shape == 3) c.b1 = c.b0 + 1e-12 * (c.b1 - c.b0);  // near the noise threshold
        segs.push_back(c);
    }
    Curve curve = make_curve(std::move(segs), 0.01f + 0.05f * static_cast<float>(pick(rng)), closed);
    if (pick(rng) < 5) {
        for (float& r : curve.radius_m) r = 0.005f + 0.02f * static_cast<float>(pick(rng));
    }
    for (float& st : curve.stretch) st = pick(rng) < 3 ? 1.0f + 0.1f * static_cast<float>(pick(rng)) : 1.0f;
    return curve;
}

bool same_bits(const glm::dvec3& a, const glm::dvec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// build_rings computes every ring's centre, tangent, radius and fold test in lanes (structure of arrays). They must
// equal, bit for bit, the per-ring operations as SegmentCoeffs writes them (power basis in t, derivative, the
// 1-norm then length noise bound, unit_tangent()'s limits below it, radius_at(), the squared fold test): random
// wires with vanishing derivatives, signed zeros and far offsets; counts of 0..3 per segment and custom params.
TEST(Rings, LaneSamplesEqualThePerRingOperations) {
    std::mt19937 rng(20261124);
    std::size_t checked = 0, slow = 0, folds = 0;
    for (int w = 0; w < 400; ++w) {
        const Curve c = random_ring_curve(rng);
        std::vector<RingParam> params;
        if (w % 4 == 3) {  // custom params: interior t, crossing with the next ring inside its segment
            for (uint32_t k = 0; k < c.segment_count(); k += 1 + static_cast<uint32_t>(rng() % 3)) {
                params.push_back({k, (rng() % 4) / 4.0});
            }
        } else {
            std::vector<uint32_t> counts(c.segment_count());
            for (uint32_t& n : counts) n = static_cast<uint32_t>(rng() % 4 == 0 ? rng() % 4 : rng() % 2);
            place_rings(c, counts, params);
        }
        RingSet set;
        build_rings(c, params, RingSettings{}, set);
        ASSERT_EQ(set.centre_m.size(), params.size());
        uint32_t fold_count = 0, first_fold = 0;
        for (std::size_t i = 0; i < params.size(); ++i) {
            const CubicBezier& b = c.segments[params[i].segment];
            const double t = params[i].t;
            const glm::dvec3 p1 = 3.0 * (b.b1 - b.b0);
            const glm::dvec3 p2 = 3.0 * (b.b2 - 2.0 * b.b1 + b.b0);
            const glm::dvec3 p3 = b.b3 - 3.0 * b.b2 + 3.0 * b.b1 - b.b0;
            const glm::dvec3 d1 = 2.0 * p2, d2 = 3.0 * p3;
            const glm::dvec3 centre = t == 0.0 ? b.b0 : (t == 1.0 ? b.b3 : b.b0 + t * (p1 + t * (p2 + t * p3)));
            EXPECT_TRUE(same_bits(set.centre_m[i], centre - set.origin_m)) << "wire " << w << " ring " << i;
            const glm::dvec3 d = p1 + t * (d1 + t * d2);
            const glm::dvec3 e = d1 + t * (2.0 * d2);
            const double speed2 = glm::dot(d, d);
            const double speed = std::sqrt(speed2);
            auto norm1 = [](const glm::dvec3& v) { return std::abs(v.x) + std::abs(v.y) + std::abs(v.z); };
            const double bound = 1e-9 * (norm1(p1) + norm1(d1) + norm1(d2));
            const double tiny = 1e-9 * (glm::length(p1) + glm::length(d1) + glm::length(d2));
            slow += speed > bound ? 0 : 1;
            const glm::dvec3 tangent = speed > bound || speed > tiny ? d * (1.0 / speed) : unit_tangent(b, t);
            if (tangent != glm::dvec3(0.0)) {  // a zero tangent takes a neighbour's (compute_frames)
                EXPECT_TRUE(same_bits(set.frames[i].t, tangent)) << "wire " << w << " ring " << i;
            }
            const double radius = radius_at(c, params[i].segment, t);
            const float radius_f = static_cast<float>(radius);
            EXPECT_EQ(std::memcmp(&set.rings[i].radius_m, &radius_f, sizeof radius_f), 0)
                << "wire " << w << " ring " << i;
            const glm::dvec3 bend = glm::cross(d, e);
            const double bend2 = glm::dot(bend, bend);
            if (radius * radius * bend2 >= speed2 * speed2 * speed2 && bend2 > 0.0) {
                if (fold_count++ == 0) first_fold = static_cast<uint32_t>(i);
            }
            ++checked;
        }
        EXPECT_EQ(set.fold_count, fold_count) << "wire " << w;
        if (fold_count > 0) {
            EXPECT_EQ(set.first_fold_ring, first_fold) << "wire " << w;
        }
        folds += fold_count;
    }
    // The family reaches the rare paths: derivatives at the noise bound, folds.
    EXPECT_GT(slow, 50u);
    EXPECT_GT(folds, 50u);
    std::printf("lane samples: %zu rings checked, %zu below the 1-norm bound, %zu folds\n", checked, slow, folds);
}

// With its segment tables build_rings lets compute_frames take the points of rings at segment starts (counts of 0
// and 1: LOD at or below the node resolution) from the tables in lanes; the frames must equal, bit for bit, those of
// compute_frames building every point itself (no tables): random wires with degenerate segments (boundary tangents
// from unit_tangent()'s limits or the previous point), open and closed, with and without a carried-over normal.
TEST(Rings, FramesFromSegmentTablesEqualPointByPoint) {
    std::mt19937 rng(4242);
    std::size_t compared = 0;
    for (int w = 0; w < 400; ++w) {
        const Curve c = random_ring_curve(rng);
        std::vector<uint32_t> counts(c.segment_count());
        for (uint32_t& n : counts) n = w % 5 == 4 ? static_cast<uint32_t>(rng() % 3) : static_cast<uint32_t>(rng() % 2);
        std::vector<RingParam> params;
        place_rings(c, counts, params);
        RingSettings settings;
        if (w % 2 == 0) {
            settings.frames.has_previous_normal = true;
            settings.frames.previous_normal = glm::dvec3(0.3, -0.8, 0.5);
        }
        RingSet set;
        build_rings(c, params, settings, set);
        std::vector<Frame> frames(params.size());
        const FrameInput plain{&c, params, set.origin_m, set.centre_m, set.tangent_scratch, set.arc_length_m, {}, {}};
        const FrameStats stats = compute_frames(plain, settings.frames, frames);
        EXPECT_EQ(stats.subdivided_steps, set.frame_stats.subdivided_steps) << "wire " << w;
        EXPECT_EQ(stats.fallback_steps, set.frame_stats.fallback_steps) << "wire " << w;
        EXPECT_EQ(stats.degenerate_tangents, set.frame_stats.degenerate_tangents) << "wire " << w;
        EXPECT_EQ(stats.seeded_from_previous, set.frame_stats.seeded_from_previous) << "wire " << w;
        EXPECT_EQ(std::memcmp(&stats.holonomy_rad, &set.frame_stats.holonomy_rad, sizeof(double)), 0) << "wire " << w;
        for (std::size_t i = 0; i < params.size(); ++i) {
            EXPECT_EQ(std::memcmp(&frames[i], &set.frames[i], sizeof(Frame)), 0) << "wire " << w << " ring " << i;
        }
        compared += params.size();
    }
    std::printf("frames from tables: %zu rings compared\n", compared);
}

/// integrate(SegmentCoeffs(c, k), 0.0, 1.0)'s arc length of one whole segment, the same operations: 3-point
/// Gauss-Legendre of |B'| in the power basis.
double whole_segment_length(const CubicBezier& b) {
    constexpr double x[3] = {0.1127016653792583, 0.5, 0.8872983346207417};
    constexpr double w[3] = {0.2777777777777778, 0.4444444444444444, 0.2777777777777778};
    const glm::dvec3 p1 = 3.0 * (b.b1 - b.b0);
    const glm::dvec3 p2 = 3.0 * (b.b2 - 2.0 * b.b1 + b.b0);
    const glm::dvec3 p3 = b.b3 - 3.0 * b.b2 + 3.0 * b.b1 - b.b0;
    const glm::dvec3 d1 = 2.0 * p2, d2 = 3.0 * p3;
    double length = 0.0;
    for (int q = 0; q < 3; ++q) {
        const double t = 0.0 + 1.0 * x[q];
        length += (1.0 * w[q]) * glm::length(p1 + t * (d1 + t * d2));
    }
    return length;
}

// An open wire's last ring sits at t = 1 of the last segment; when that segment has no ring of its own (LOD count 0)
// the last interval ends with the whole segment, which build_rings takes from its per-segment table. Arc length
// and u must equal the whole-segment quadrature summed in order, bit for bit (u = length / (2 pi R stretch) on a
// wire of one radius): random open wires with degenerate segments, one radius or a radius per node, random stretch.
TEST(Rings, LastRingOnASegmentWithoutRingsAddsTheWholeSegment) {
    std::mt19937 rng(777);
    std::size_t checked = 0, with_u = 0;
    for (int w = 0; w < 400; ++w) {
        const Curve c = random_ring_curve(rng);
        if (c.closed || c.segment_count() < 2) continue;
        std::vector<uint32_t> counts(c.segment_count());
        for (uint32_t& n : counts) n = static_cast<uint32_t>(rng() % 2);
        counts.back() = 0;
        std::vector<RingParam> params;
        place_rings(c, counts, params);
        RingSet set;
        build_rings(c, params, RingSettings{}, set);
        const std::size_t n = params.size();
        ASSERT_EQ(params[n - 1].t, 1.0);
        const uint32_t a = params[n - 2].segment, last = params[n - 1].segment;
        ASSERT_LT(a, last);
        const bool one_radius = std::all_of(c.radius_m.begin(), c.radius_m.end(),
                                            [&](float r) { return r == c.radius_m[0]; });
        double length = 0.0, u = 0.0;
        for (uint32_t k = a; k <= last; ++k) {
            const double lk = whole_segment_length(c.segments[k]);
            const double stretch = static_cast<double>(c.stretch[k]);
            const double uk = lk * (1.0 / (2.0 * std::numbers::pi * stretch *
                                           std::max(static_cast<double>(c.radius_m[0]), 1e-30)));
            length = k == a ? lk : length + lk;
            u = k == a ? uk : u + uk;
        }
        const double s_end = set.arc_length_m[n - 2] + length;
        EXPECT_EQ(std::memcmp(&set.arc_length_m[n - 1], &s_end, sizeof(double)), 0) << "wire " << w;
        if (one_radius) {
            const double u_end = set.u[n - 2] + u;
            EXPECT_EQ(std::memcmp(&set.u[n - 1], &u_end, sizeof(double)), 0) << "wire " << w;
            ++with_u;
        }
        ++checked;
    }
    EXPECT_GT(checked, 200u);
    EXPECT_GT(with_u, 100u);
    std::printf("last intervals: %zu wires checked, %zu with u\n", checked, with_u);
}

// A stretch that is missing, zero, negative or not finite counts as 1 (SegmentCoeffs::load_radius): u must equal, bit
// for bit, that of the same wire with 1 there. Random wires of one radius (where the per-segment texture scales are
// computed in lanes and the whole set is redone when one stretch is not plain) and of a radius per node.
TEST(Rings, InvalidStretchCountsAsOne) {
    std::mt19937 rng(99);
    const float bad[] = {0.0f, -0.0f, -1.5f, std::numeric_limits<float>::infinity(),
                         std::numeric_limits<float>::quiet_NaN()};
    std::size_t compared = 0;
    for (int w = 0; w < 200; ++w) {
        Curve c = random_ring_curve(rng);
        Curve fixed = c;
        if (w % 4 == 3) {  // missing entries
            const std::size_t keep = rng() % c.stretch.size();
            c.stretch.resize(keep);
            for (std::size_t k = keep; k < fixed.stretch.size(); ++k) fixed.stretch[k] = 1.0f;
        } else {
            for (std::size_t k = 0; k < c.stretch.size(); ++k) {
                if (rng() % 3 != 0) continue;
                c.stretch[k] = bad[rng() % std::size(bad)];
                fixed.stretch[k] = 1.0f;
            }
        }
        std::vector<uint32_t> counts(c.segment_count());
        for (uint32_t& n : counts) n = static_cast<uint32_t>(rng() % 3);
        std::vector<RingParam> params;
        place_rings(c, counts, params);
        RingSet a, b;
        build_rings(c, params, RingSettings{}, a);
        build_rings(fixed, params, RingSettings{}, b);
        ASSERT_EQ(a.u.size(), b.u.size());
        EXPECT_EQ(std::memcmp(a.u.data(), b.u.data(), a.u.size() * sizeof(double)), 0) << "wire " << w;
        compared += a.u.size();
    }
    std::printf("invalid stretch: %zu u values compared\n", compared);
}

TEST(Rings, ReusedSetDoesNotReallocate) {
    const Curve c = helix_curve(1.0, 0.3, 2, 8);
    std::vector<uint32_t> counts;
    segment_ring_counts(c, TessellateSettings{}, counts);
    std::vector<RingParam> params;
    place_rings(c, counts, params);
    RingSet set;
    build_rings(c, params, RingSettings{}, set);
    const Ring* data = set.rings.data();
    const Frame* frames = set.frames.data();
    build_rings(c, params, RingSettings{}, set);
    EXPECT_EQ(set.rings.data(), data);
    EXPECT_EQ(set.frames.data(), frames);
}

}  // namespace
}  // namespace wire::test
