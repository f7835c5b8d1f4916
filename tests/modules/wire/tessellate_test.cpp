// Ring placement: exact fixed parameters, closed wires without a duplicate, external counts, and the adaptive
// (Wang) count keeping every point of the cubic within the tolerance of the ring-centre polyline.
#include "ring_test_curves.hpp"

namespace wire::test {
namespace {

TEST(Tessellate, FixedParametersAreExact) {
    const Curve c = helix_curve(1.0, 0.3, 1, 4);
    std::vector<uint32_t> counts;
    segment_ring_counts(c, TessellateSettings{.rings_per_segment = 5}, counts);
    std::vector<RingParam> params;
    place_rings(c, counts, params);
    ASSERT_EQ(params.size(), 4u * 5u + 1u);
    EXPECT_EQ(ring_count(counts, false), params.size());
    for (uint32_t s = 0; s < 4; ++s) {
        for (uint32_t k = 0; k < 5; ++k) {
            EXPECT_EQ(params[s * 5 + k].segment, s);
            EXPECT_EQ(params[s * 5 + k].t, static_cast<double>(k) / 5.0);
        }
    }
    EXPECT_EQ(params.back().segment, 3u);
    EXPECT_EQ(params.back().t, 1.0);

    Curve closed = c;
    closed.closed = true;
    place_rings(closed, counts, params);
    EXPECT_EQ(params.size(), 20u);  // the first ring closes the loop
    EXPECT_EQ(params.back().t, 4.0 / 5.0);
}

TEST(Tessellate, ExternalCountsAndDefaults) {
    const Curve c = helix_curve(1.0, 0.3, 1, 4);
    // 0: the segment gets no ring (the interval from the previous ring crosses it); segment 0 always gets one.
    const std::vector<uint32_t> counts = {1, 0, 3, 2};
    std::vector<RingParam> params;
    place_rings(c, counts, params);
    ASSERT_EQ(params.size(), 1u + 0u + 3u + 2u + 1u);
    EXPECT_EQ(ring_count(counts, false), params.size());
    EXPECT_EQ(params[0].segment, 0u);
    EXPECT_EQ(params[1].segment, 2u);
    EXPECT_EQ(params[1].t, 0.0);
    EXPECT_EQ(params[2].t, 1.0 / 3.0);
    const std::vector<uint32_t> first_zero = {0, 0, 0, 0};
    place_rings(c, first_zero, params);
    ASSERT_EQ(params.size(), 2u);  // one interval over the whole wire
    EXPECT_EQ(ring_count(first_zero, false), 2u);
    EXPECT_EQ(params[1].segment, 3u);
    EXPECT_EQ(params[1].t, 1.0);
    std::vector<uint32_t> defaults;
    segment_ring_counts(c, TessellateSettings{}, defaults);
    EXPECT_EQ(defaults, std::vector<uint32_t>(4, 8u));
}

// place_rings writes the common counts (0 and 1) without a branch on which: the same parameters as the plain rule
// (segment i gets counts[i] rings at j / counts[i], segment 0 at least one, an open wire one more at t = 1) on
// random counts, open and closed, ending in crossed segments.
TEST(Tessellate, PlaceRingsEqualsThePlainRule) {
    std::mt19937 rng(7);
    const Curve base = helix_curve(1.0, 0.3, 2, 20);
    std::vector<RingParam> params;
    for (int trial = 0; trial < 500; ++trial) {
        Curve c = base;
        c.segments.resize(1 + rng() % c.segments.size());
        c.closed = trial % 3 == 0;
        std::vector<uint32_t> counts(c.segment_count());
        for (uint32_t& n : counts) n = static_cast<uint32_t>(rng() % 3 == 0 ? rng() % 5 : rng() % 2);
        if (trial % 5 == 0) {  // ending in crossed segments
            const auto zeros = static_cast<std::ptrdiff_t>(1 + rng() % counts.size());
            std::fill(counts.end() - zeros, counts.end(), 0u);
        }
        std::vector<RingParam> expected;
        for (std::size_t i = 0; i < counts.size(); ++i) {
            const uint32_t n = i == 0 ? std::max<uint32_t>(counts[i], 1) : counts[i];
            for (uint32_t j = 0; j < n; ++j) {
                expected.push_back({static_cast<uint32_t>(i), j == 0 ? 0.0 : static_cast<double>(j) / n});
            }
        }
        if (!c.closed) expected.push_back({static_cast<uint32_t>(counts.size() - 1), 1.0});
        place_rings(c, counts, params);
        ASSERT_EQ(params.size(), expected.size()) << "trial " << trial;
        for (std::size_t k = 0; k < expected.size(); ++k) {
            EXPECT_EQ(params[k].segment, expected[k].segment) << "trial " << trial << " ring " << k;
            EXPECT_EQ(params[k].t, expected[k].t) << "trial " << trial << " ring " << k;
        }
    }
}

/// Distance from p to the segment ab.
double point_segment_distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double h = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + h * ab));
}

TEST(Tessellate, AdaptiveCountMeetsTolerance) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coord(-1.0, 1.0);
    std::vector<CubicBezier> segs;
    for (int i = 0; i < 40; ++i) {
        const glm::dvec3 p0 = segs.empty() ? glm::dvec3(0.0) : segs.back().b3;
        segs.push_back(CubicBezier{p0, p0 + glm::dvec3(coord(rng), coord(rng), coord(rng)),
                                   p0 + glm::dvec3(coord(rng), coord(rng), coord(rng)) * 2.0,
                                   p0 + glm::dvec3(coord(rng), coord(rng), coord(rng))});
    }
    const Curve random = make_curve(segs, 0.01f);
    const Curve helix = helix_curve(2.0, 0.5, 2, 7);
    for (const Curve* curve : {&random, &helix}) {
        for (double eps : {1e-1, 1e-2, 1e-3, 1e-4}) {
            std::vector<uint32_t> counts;
            segment_ring_counts(*curve, TessellateSettings{.tolerance_m = eps, .max_rings_per_segment = 100000},
                                counts);
            std::vector<RingParam> params;
            place_rings(*curve, counts, params);
            std::vector<glm::dvec3> centres;
            for (const RingParam& p : params) centres.push_back(position(curve->segments[p.segment], p.t));
            // Every densely sampled point lies within eps of its own chord (that of its parameter interval).
            double worst_ratio = 0.0;
            std::size_t first = 0;
            for (std::size_t s = 0; s < curve->segment_count(); ++s) {
                const uint32_t n = counts[s];
                for (int k = 0; k <= 4000; ++k) {
                    const double t = k / 4000.0;
                    const std::size_t j = std::min<std::size_t>(static_cast<std::size_t>(t * n), n - 1);
                    const double d = point_segment_distance(position(curve->segments[s], t), centres[first + j],
                                                            centres[first + j + 1]);
                    worst_ratio = std::max(worst_ratio, d / eps);
                }
                first += n;
            }
            EXPECT_LE(worst_ratio, 1.0) << "eps " << eps;
            EXPECT_GT(worst_ratio, 0.1) << "eps " << eps << ": Wang's bound should not be wildly loose";
        }
    }
    // Clamp and degenerate inputs.
    const CubicBezier straight{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
    EXPECT_EQ(wang_ring_count(straight, 1e-6, 64), 1u);
    EXPECT_EQ(wang_ring_count(random.segments[0], 1e-12, 64), 64u);
    EXPECT_EQ(wang_ring_count(random.segments[0], 0.0, 64), 64u);
}

}  // namespace
}  // namespace wire::test
