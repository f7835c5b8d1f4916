// The renderer's CPU side (no GL): the 28-byte packed ring record's precision, measured on random frames and on
// the rings of random realistic wires (fixed seeds; median / p90 / max and the worst case printed); the
// ring expansion's counts (the nodes path's chunks) against wire::tube_counts. The nodes path's byte model:
// nodes_plan_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "wire/pipeline.hpp"
#include "wire/render/upload_plan.hpp"
#include "wire/tube.hpp"

namespace {

using wire::render::PackedRing;

struct Stats {
    std::vector<double> v;
    double worst_input = 0.0;
    void add(double x) { v.push_back(x); }
    double q(double p) {
        std::sort(v.begin(), v.end());
        return v.empty() ? 0.0 : v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
    }
};

/// Largest difference between the decoded frame vectors and the record's (radians, for unit vectors).
double frame_error(const wire::Ring& ring) {
    const wire::render::DecodedFrame f = wire::render::unpack_frame(wire::render::pack_ring(ring));
    const glm::dvec3 r(ring.normal), s(ring.binormal);
    const glm::dvec3 t = glm::cross(r, s);
    return std::max({glm::length(glm::dvec3(f.normal) - r), glm::length(glm::dvec3(f.binormal) - s),
                     glm::length(glm::dvec3(f.tangent) - t)});
}

// Random frames (uniform random rotations, 200,000 of them): the quaternion's 20-bit components keep every
// frame vector within 4e-6 of the float record's. On screen the rim point moves by radius_px * error: < 0.01 px
// for tubes up to 2,500 px in radius (the 0.5 px LOD tolerance is 50x larger than that).
TEST(PackedRingTest, FramePrecisionOnRandomRotations) {
    std::mt19937 rng(12);
    std::normal_distribution<double> g;
    Stats s;
    double worst = 0.0;
    glm::dquat worst_q{};
    for (int i = 0; i < 200000; ++i) {
        glm::dquat q(g(rng), g(rng), g(rng), g(rng));  // normalized Gaussian 4-vector: uniform rotation
        q = glm::normalize(q);
        const glm::dmat3 m = glm::mat3_cast(q);
        wire::Ring ring;
        ring.normal = glm::vec3(m[0]);
        ring.binormal = glm::vec3(m[1]);
        const double e = frame_error(ring);
        s.add(e);
        if (e > worst) worst = e, worst_q = q;
    }
    const double p50 = s.q(0.5), p90 = s.q(0.9), max = s.q(1.0);
    std::printf("frame error over 200000 random rotations: median %.3g, p90 %.3g, max %.3g (worst q = %.6f %.6f "
                "%.6f %.6f); 0.01 px holds up to a radius of %.0f px\n",
                p50, p90, max, worst_q.w, worst_q.x, worst_q.y, worst_q.z, 0.01 / max);
    EXPECT_LT(max, 4e-6);
    EXPECT_GT(0.01 / max, 2500.0);
}

// Rings of random realistic wires (sagging cables and helices, 0.5-40 m, radius 2 mm-10 cm, 8-120 nodes):
// the frame error as above; centre and radius are stored as the same floats as wire::Ring (exact); u is the
// same float, and its error against the double u (RingSet::u) stays < 1e-4 of the texture period.
TEST(PackedRingTest, RealisticWiresKeepFrameAndTexturePrecision) {
    std::mt19937 rng(2024);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    Stats frame, u_error;
    std::size_t rings_checked = 0;
    double worst_u = 0.0, worst_u_value = 0.0;
    for (int w = 0; w < 60; ++w) {
        const int count = 8 + static_cast<int>(uni(rng) * 112);
        const double length = 0.5 + 39.5 * uni(rng) * uni(rng);
        const double radius = 0.002 + 0.098 * uni(rng) * uni(rng);
        wire::WireNodes nodes;
        const bool helix = w % 3 == 0;
        for (int i = 0; i < count; ++i) {
            const double t = static_cast<double>(i) / (count - 1);
            if (helix) {
                const double a = t * length / 0.5;
                nodes.positions.push_back({0.5 * std::cos(a), 0.1 * a, 0.5 * std::sin(a)});
            } else {
                nodes.positions.push_back(
                    {length * t, -0.1 * length * 4.0 * t * (1.0 - t), 0.02 * length * std::sin(7.0 * t + w)});
            }
        }
        wire::PipelineSettings settings;
        settings.spline.radius_m = static_cast<float>(radius);
        settings.tessellate.rings_per_segment = 8;
        wire::WirePipeline p;
        ASSERT_TRUE(p.update(nodes, settings).ok());
        const wire::RingSet& rs = p.rings();
        for (std::size_t i = 0; i < rs.rings.size(); ++i) {
            const wire::Ring& ring = rs.rings[i];
            const PackedRing packed = wire::render::pack_ring(ring);
            ASSERT_EQ(packed.centre_m[0], ring.centre_m.x);
            ASSERT_EQ(packed.centre_m[1], ring.centre_m.y);
            ASSERT_EQ(packed.centre_m[2], ring.centre_m.z);
            ASSERT_EQ(packed.radius_m, ring.radius_m);
            frame.add(frame_error(ring));
            const double eu = std::abs(static_cast<double>(packed.u) - rs.u[i]);
            u_error.add(eu);
            if (eu > worst_u) worst_u = eu, worst_u_value = rs.u[i];
            ++rings_checked;
        }
    }
    const double f50 = frame.q(0.5), f90 = frame.q(0.9), fmax = frame.q(1.0);
    const double u50 = u_error.q(0.5), u90 = u_error.q(0.9), umax = u_error.q(1.0);
    std::printf("%zu rings of 60 wires: frame error median %.3g p90 %.3g max %.3g; u error (texture periods) "
                "median %.3g p90 %.3g max %.3g (at u = %.1f)\n",
                rings_checked, f50, f90, fmax, u50, u90, umax, worst_u_value);
    EXPECT_GT(rings_checked, 5000u);
    EXPECT_LT(fmax, 4e-6);
    EXPECT_LT(umax, 1e-4);
}

// Indexed expansion counts equal the CPU mesh's, for open/closed, capped/uncapped, 1..300 rings, 3..32 sides;
// chunks cover every band exactly once: kChunkBands-band chunks, then the remainder's binary digits, plus one cap
// chunk on a capped open tube.
TEST(UploadPlanTest, ExpansionCountsMatchTubeCounts) {
    for (uint32_t sides : {3u, 7u, 16u, 32u}) {
        for (std::size_t count : {std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{128},
                                  std::size_t{129}, std::size_t{257}, std::size_t{300}}) {
            for (bool closed : {false, true}) {
                for (bool caps : {false, true}) {
                    const wire::render::RingExpansion item{
                        .rings = static_cast<uint32_t>(count), .sides = sides, .closed = closed, .caps = caps};
                    const wire::TubeCounts c = wire::tube_counts(count, closed, {.sides = sides, .caps = caps});
                    if (!wire::render::draws_anything(item)) {
                        EXPECT_EQ(c.indices, 0u) << count << " rings";
                        continue;
                    }
                    EXPECT_EQ(wire::render::expanded_vertices(item), c.vertices);
                    EXPECT_EQ(wire::render::expanded_triangles(item) * 3, c.indices);
                    const uint32_t bands = wire::render::band_count(item);
                    const auto chunks = wire::render::chunk_counts(item);
                    uint32_t covered = 0, records = 0;
                    for (uint32_t kind = 0; kind < wire::render::kChunkKinds; ++kind) {
                        covered += chunks[kind] * wire::render::chunk_kind_bands(kind);
                        records += chunks[kind];
                        if (kind >= 2) {
                            EXPECT_LE(chunks[kind], 1u);
                        }
                    }
                    EXPECT_EQ(covered, bands) << count << " rings";
                    EXPECT_EQ(chunks[1], bands / wire::render::kChunkBands);
                    EXPECT_EQ(chunks[0], !closed && caps && sides > 2 ? 1u : 0u);
                    EXPECT_EQ(wire::render::chunk_count(item), records);
                    EXPECT_GE(records, 1u);
                }
            }
        }
    }
}

}  // namespace
