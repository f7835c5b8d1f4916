// Tube mesh: counts, watertight (welded) with caps and on closed loops, outward CCW winding, flat caps, seam and
// uv ranges, reuse without allocation, and a reference checksum.
#include "ring_test_curves.hpp"
#include "wire/detail/segment_soa.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <random>

namespace wire::test {
namespace {

/// Every non-degenerate triangle's geometric normal points along its vertex normals (outward, CCW from outside).
void expect_outward(const TubeMesh& mesh) {
    std::size_t bad = 0, checked = 0;
    for (std::size_t k = 0; k + 2 < mesh.indices.size(); k += 3) {
        const TubeVertex& a = mesh.vertices[mesh.indices[k]];
        const TubeVertex& b = mesh.vertices[mesh.indices[k + 1]];
        const TubeVertex& c = mesh.vertices[mesh.indices[k + 2]];
        const glm::vec3 face = glm::cross(b.position - a.position, c.position - a.position);
        if (glm::length(face) < 1e-12f) continue;
        ++checked;
        if (glm::dot(face, a.normal + b.normal + c.normal) <= 0.0f) ++bad;
    }
    EXPECT_GT(checked, 0u);
    EXPECT_EQ(bad, 0u) << "inward-facing triangles";
}

void expect_uv_ranges(const TubeMesh& mesh) {
    for (const TubeVertex& v : mesh.vertices) {
        ASSERT_TRUE(v.uv.y >= 0.0f && v.uv.y <= 1.0f);
        ASSERT_TRUE(std::isfinite(v.uv.x) && finite(v.position) && finite(v.normal));
        ASSERT_NEAR(glm::length(v.normal), 1.0f, 1e-5f);
    }
}

TEST(Tube, OpenWithCapsIsWatertightAndOutward) {
    Curve c = helix_curve(1.0, 0.3, 2, 8);
    c.radius_m[3] = 0.2f;  // varying radius: tilted normals
    const RingSet set = rings_for(c, 4);
    for (uint32_t sides : {3u, 8u, 12u}) {
        TubeMesh mesh;
        build_tube(set, TubeSettings{.sides = sides}, mesh);
        const TubeCounts counts = tube_counts(set.rings.size(), false, TubeSettings{.sides = sides});
        EXPECT_EQ(mesh.vertices.size(), set.rings.size() * (sides + 1) + 2 * (sides + 1));
        EXPECT_EQ(mesh.indices.size(), counts.indices);
        const WeldReport w = weld_check(mesh);
        EXPECT_EQ(w.bad_edges, 0u);
        EXPECT_EQ(w.inconsistent_edges, 0u);
        EXPECT_EQ(w.degenerate_triangles, 0u);
        expect_outward(mesh);
        expect_uv_ranges(mesh);
        // Caps are flat: every cap vertex has the end tangent as normal.
        const std::size_t cap0 = set.rings.size() * (sides + 1);
        for (std::size_t j = 0; j <= sides; ++j) {
            EXPECT_LT(glm::length(glm::dvec3(mesh.vertices[cap0 + j].normal) + set.frames.front().t), 1e-6);
            EXPECT_LT(glm::length(glm::dvec3(mesh.vertices[cap0 + sides + 1 + j].normal) - set.frames.back().t), 1e-6);
        }
        // Seam: the duplicated vertex sits on the first one with v = 1.
        for (std::size_t i = 0; i < set.rings.size(); ++i) {
            const TubeVertex& first = mesh.vertices[i * (sides + 1)];
            const TubeVertex& seam = mesh.vertices[i * (sides + 1) + sides];
            EXPECT_EQ(first.position, seam.position);
            EXPECT_EQ(first.uv.y, 0.0f);
            EXPECT_EQ(seam.uv.y, 1.0f);
            EXPECT_EQ(first.uv.x, seam.uv.x);
        }
    }
}

// A cone (radius 0.1 -> 0.2 over 1 m): side normals tilt against the radius slope, n.t = -slope / sqrt(1 + slope^2).
TEST(Tube, ConeNormalsTiltWithRadiusSlope) {
    Curve cone = polyline_curve({{0, 0, 0}, {0, 0, 1}}, 0.1f);
    cone.radius_m = {0.1f, 0.2f};
    const RingSet set = rings_for(cone, 8);
    EXPECT_NEAR(set.rings[4].radius_m, 0.15f, 1e-6f);  // two nodes: the monotone Hermite radius is linear
    TubeMesh mesh;
    build_tube(set, TubeSettings{.sides = 8, .caps = false}, mesh);
    const double expected = -0.1 / std::sqrt(1.0 + 0.01);
    for (const TubeVertex& v : mesh.vertices) {
        EXPECT_NEAR(v.normal.z, expected, 1e-5);
        EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-6f);
    }
    TubeMesh flat;
    build_tube(set, TubeSettings{.sides = 8, .caps = false, .tilt_normals = false}, flat);
    for (const TubeVertex& v : flat.vertices) EXPECT_NEAR(v.normal.z, 0.0f, 1e-7f);
}

// Found by fuzz_wire_systems (corpus: regression_radius_jump): a node radius of 1.1e38 m next to 0.02 m a few
// centimetres away. The slope dR/ds overflowed float, 1 + slope^2 with it, and the tilted normals became NaN. A
// cone that steep is a disc: its side normals lie along the tangent, unit and finite.
TEST(Tube, RadiusJumpBeyondFloatRangeKeepsNormalsFinite) {
    for (const float big : {1e20f, 1e30f, 1.1e38f, 3.4e38f}) {
        Curve c = polyline_curve({{0, 0, 0}, {0.05, 0, 0}, {0.1, 0, 0}}, 0.02f);
        c.radius_m = {big, 0.02f, 0.02f};
        const RingSet set = rings_for(c, 4);
        TubeMesh mesh;
        build_tube(set, TubeSettings{.sides = 8, .caps = false}, mesh);
        for (const TubeVertex& v : mesh.vertices) {
            ASSERT_TRUE(std::isfinite(v.normal.x) && std::isfinite(v.normal.y) && std::isfinite(v.normal.z)) << big;
            EXPECT_NEAR(glm::length(v.normal), 1.0f, 1e-5f) << big;
        }
    }
}

TEST(Tube, WithoutCapsHasTwoOpenEnds) {
    const RingSet set = rings_for(helix_curve(1.0, 0.3, 1, 8), 2);
    TubeMesh mesh;
    build_tube(set, TubeSettings{.sides = 8, .caps = false}, mesh);
    const WeldReport w = weld_check(mesh);
    EXPECT_EQ(w.bad_edges, 2u * 8u);  // the two boundary loops
    EXPECT_EQ(w.inconsistent_edges, 0u);
}

// A closed loop of 3 nodes joins its last ring to its first: no cap, watertight, u continues over the join.
TEST(Tube, ClosedLoopJoinsWithoutSeam) {
    const Curve loop = catmull_rom_curve({{1, 0, 0.2}, {-0.5, 0.866, -0.2}, {-0.5, -0.866, 0.3}}, 0.05f, true);
    const RingSet set = rings_for(loop, 8);
    expect_orthonormal(set);
    TubeMesh mesh;
    build_tube(set, TubeSettings{.sides = 10}, mesh);
    EXPECT_EQ(mesh.vertices.size(), (set.rings.size() + 1) * 11u);
    const WeldReport w = weld_check(mesh);
    EXPECT_EQ(w.bad_edges, 0u);
    EXPECT_EQ(w.inconsistent_edges, 0u);
    expect_outward(mesh);
    expect_uv_ranges(mesh);
    const TubeVertex& last_row = mesh.vertices[set.rings.size() * 11u];
    EXPECT_EQ(last_row.position, mesh.vertices[0].position);
    EXPECT_FLOAT_EQ(last_row.uv.x, static_cast<float>(set.u.back()));
    EXPECT_GT(last_row.uv.x, set.rings.back().u);
    EXPECT_NEAR(set.u.back() - set.u[0], set.length_m / (2 * kPi * 0.05), 1e-6 * set.u.back());
}

// Straight wire, zero-length segment, radius 1e-6, far origin: finite and watertight (after welding).
TEST(Tube, HardCasesStayWatertight) {
    std::vector<Curve> curves;
    curves.push_back(polyline_curve({{0, 0, 0}, {0, 0, 1}, {0, 0, 2}}, 0.1f));
    curves.push_back(make_curve({hermite({0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}),
                                 CubicBezier{{1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}},
                                 hermite({1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 1, 0})},
                                0.05f));
    curves.push_back(helix_curve(0.01, 0.003, 1, 8, {}, 1e-6f));
    curves.push_back(helix_curve(1.0, 0.3, 1, 8, {1e6, 1e6, -1e6}, 0.01f));
    for (std::size_t k = 0; k < curves.size(); ++k) {
        const RingSet set = rings_for(curves[k], 4);
        expect_orthonormal(set);
        expect_u_monotonic(set);
        TubeMesh mesh;
        build_tube(set, TubeSettings{.sides = 8}, mesh);
        expect_uv_ranges(mesh);
        const WeldReport w = weld_check(mesh);
        EXPECT_EQ(w.bad_edges, 0u) << "curve " << k;
        EXPECT_EQ(w.inconsistent_edges, 0u) << "curve " << k;
    }
}

TEST(Tube, ReusedBuffersAndArenaOffsets) {
    const RingSet set = rings_for(helix_curve(1.0, 0.3, 1, 8), 4);
    TubeMesh mesh;
    build_tube(set, TubeSettings{}, mesh);
    const TubeVertex* v = mesh.vertices.data();
    const uint32_t* i = mesh.indices.data();
    build_tube(set, TubeSettings{}, mesh);
    EXPECT_EQ(mesh.vertices.data(), v);
    EXPECT_EQ(mesh.indices.data(), i);
    // Writing into an arena at a vertex offset shifts the indices only.
    std::vector<TubeVertex> arena(mesh.vertices.size() + 100);
    std::vector<uint32_t> idx(mesh.indices.size());
    write_tube(set.rings, false, 0.0f, TubeSettings{}, std::span(arena).subspan(100), idx, 100);
    for (std::size_t k = 0; k < idx.size(); ++k) ASSERT_EQ(idx[k], mesh.indices[k] + 100);
}

constexpr double kReferenceChecksum = 55651.983067;
constexpr uint64_t kReferenceIndexChecksum = 7087155;

// Reference: counts and a checksum of a fixed mesh. Regenerate (after an intended change) by running this test and
// copying the printed values.
// write_strip computes its rings' frame quaternions in one vectorized pass (glm::quat_cast's candidates taken by
// selects, not a switch); each must be bit for bit ring_frame_quaternion_xyz() of the same ring, whichever of the
// four candidates is the largest, with either sign, on rotations near the switch points and in float rounding.
TEST(Tube, StripQuaternionsEqualTheOneRingFunction) {
    std::mt19937_64 rng(20261124);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    std::vector<Ring> rings;
    auto add = [&](glm::dvec3 r, glm::dvec3 s) {
        Ring ring;
        ring.normal = glm::vec3(glm::normalize(r));
        ring.binormal = glm::vec3(glm::normalize(s));
        ring.radius_m = 0.01f;
        rings.push_back(ring);
    };
    // Random rotations (all four largest-candidate cases occur), then half turns about each axis and about
    // diagonals, where two candidates tie.
    for (int k = 0; k < 4000; ++k) {
        const glm::dvec3 a(uni(rng), uni(rng), uni(rng)), b(uni(rng), uni(rng), uni(rng));
        if (glm::length(a) < 1e-3) continue;
        const glm::dvec3 r = glm::normalize(a);
        const glm::dvec3 s = b - glm::dot(b, r) * r;
        if (glm::length(s) < 1e-3) continue;
        add(r, s);
    }
    const double h = std::sqrt(0.5);
    add({1, 0, 0}, {0, 1, 0});
    add({1, 0, 0}, {0, -1, 0});
    add({-1, 0, 0}, {0, 1, 0});
    add({-1, 0, 0}, {0, -1, 0});
    add({0, 1, 0}, {1, 0, 0});
    add({0, 0, 1}, {0, 1, 0});
    add({h, h, 0}, {h, -h, 0});
    add({h, 0, h}, {0, 1, 0});
    add({0, h, h}, {1, 0, 0});
    for (int open = 0; open < 2; ++open) {
        const bool closed = open == 0;
        const TubeCounts c = strip_counts(rings.size(), closed);
        std::vector<TubeVertex> vertices(c.vertices);
        std::vector<uint32_t> indices(c.indices);
        (void)write_strip(rings, closed, 1.0f, vertices, indices);
        std::array<int, 4> largest{};  // which candidate was the largest, over the cases (coverage)
        for (std::size_t k = 0; k < vertices.size() / 2; ++k) {
            const Ring& ring = rings[k == rings.size() ? 0 : k];
            const glm::vec3 expected = ring_frame_quaternion_xyz(ring);
            for (int v = 0; v < 2; ++v) {
                ASSERT_EQ(std::memcmp(&vertices[2 * k + v].normal, &expected, sizeof expected), 0)
                    << "ring " << k << ": " << vertices[2 * k + v].normal.x << " vs " << expected.x;
            }
            const glm::dvec3 r(ring.normal), s(ring.binormal), t = glm::cross(r, s);
            const double f[4] = {r.x + s.y + t.z, r.x - s.y - t.z, s.y - r.x - t.z, t.z - r.x - s.y};
            ++largest[static_cast<std::size_t>(std::max_element(f, f + 4) - f)];
        }
        for (int i = 0; i < 4; ++i) EXPECT_GT(largest[static_cast<std::size_t>(i)], 10) << "candidate " << i;
    }
}

// write_strip works through its rings in chunks (stack buffers), four rows at a time with a one-by-one remainder:
// every vertex and index must be the layout tube.hpp documents, for ring counts around the block and chunk sizes,
// open and closed, with a vertex offset; the bytes are compared, so a sign or lane mix-up cannot hide.
TEST(Tube, StripEveryRowAcrossChunks) {
    std::mt19937_64 rng(20261124);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    for (std::size_t n : {0u, 1u, 2u, 3u, 4u, 5u, 7u, 8u, 63u, 64u, 65u, 67u, 128u, 131u, 200u}) {
        std::vector<Ring> rings(n);
        for (std::size_t k = 0; k < n; ++k) {
            Ring& ring = rings[k];
            ring.centre_m = {uni(rng) * 10.0f, uni(rng) * 10.0f, uni(rng) * 10.0f};
            ring.radius_m = 0.01f + 0.01f * uni(rng);
            const glm::dvec3 a(uni(rng), uni(rng), uni(rng) + 2.0f), b(uni(rng) + 2.0f, uni(rng), uni(rng));
            const glm::dvec3 r = glm::normalize(a);
            ring.normal = glm::vec3(r);
            ring.binormal = glm::vec3(glm::normalize(b - glm::dot(b, r) * r));
            ring.u = static_cast<float>(k) * 0.25f + uni(rng) * 0.1f;
            ring.segment = static_cast<uint32_t>(k);
        }
        for (bool closed : {false, true}) {
            const uint32_t base = 1000;
            const TubeCounts c = strip_counts(n, closed);
            std::vector<TubeVertex> vertices(c.vertices + 1);
            std::vector<uint32_t> indices(c.indices + 1, 7u);
            std::memset(static_cast<void*>(vertices.data()), 0x5a, vertices.size() * sizeof(TubeVertex));
            const TubeVertex guard = vertices.back();
            const TubeCounts w = write_strip(rings, closed, 99.5f, vertices, indices, base);
            ASSERT_EQ(w.vertices, c.vertices);
            ASSERT_EQ(w.indices, c.indices);
            const std::size_t rows = c.vertices / 2;
            for (std::size_t row = 0; row < rows; ++row) {
                const Ring& ring = rings[row == n ? 0 : row];
                const float u = row == n ? 99.5f : ring.u;
                const glm::vec3 q = ring_frame_quaternion_xyz(ring);
                const TubeVertex expected[2] = {{ring.centre_m, q, {u, -ring.radius_m}},
                                                {ring.centre_m, q, {u, ring.radius_m}}};
                ASSERT_EQ(std::memcmp(&vertices[2 * row], expected, sizeof expected), 0)
                    << "n " << n << (closed ? " closed" : " open") << " row " << row;
            }
            ASSERT_EQ(std::memcmp(&vertices.back(), &guard, sizeof guard), 0) << "n " << n << ": wrote past the end";
            for (std::size_t b = 0; b + 1 < rows; ++b) {
                const auto a = static_cast<uint32_t>(base + 2 * b);
                const uint32_t expected[6] = {a + 1, a + 3, a + 2, a + 1, a + 2, a};
                for (std::size_t j = 0; j < 6; ++j) ASSERT_EQ(indices[6 * b + j], expected[j]) << "band " << b;
            }
            ASSERT_EQ(indices.back(), 7u) << "n " << n << ": wrote past the end";
        }
    }
}

// The ring stage's structure-of-arrays copy of a curve's segments (four at a time by 4x4 transposes, the rest one
// by one): every double lands where the per-segment kernels read it, for counts around the block size.
TEST(SegmentSoa, TransposeMovesEveryControlPoint) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> uni(-1e3, 1e3);
    for (std::size_t n : {0u, 1u, 3u, 4u, 5u, 8u, 11u, 63u, 64u}) {
        std::vector<CubicBezier> segments(n);
        for (CubicBezier& c : segments) {
            for (glm::dvec3* p : {&c.b0, &c.b1, &c.b2, &c.b3}) *p = {uni(rng), uni(rng), uni(rng)};
        }
        std::vector<double> out(12 * n, -1.0);
        detail::transpose_segments(segments.data(), n, out.data());
        for (std::size_t k = 0; k < n; ++k) {
            const glm::dvec3* p[4] = {&segments[k].b0, &segments[k].b1, &segments[k].b2, &segments[k].b3};
            for (std::size_t j = 0; j < 4; ++j) {
                for (int a = 0; a < 3; ++a) {
                    ASSERT_EQ(out[(3 * j + static_cast<std::size_t>(a)) * n + k], (*p[j])[a])
                        << "n " << n << " segment " << k << " point " << j << " axis " << a;
                }
            }
        }
    }
}

TEST(Tube, ReferenceChecksum) {
    const RingSet set = rings_for(helix_curve(1.0, 0.3, 1, 4), 3);
    TubeMesh mesh;
    build_tube(set, TubeSettings{.sides = 6}, mesh);
    double sum = 0.0;
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
        const TubeVertex& v = mesh.vertices[k];
        const double w = 1.0 + static_cast<double>(k % 7);
        sum += w * (v.position.x + 2 * v.position.y + 3 * v.position.z + 5 * v.normal.x + 7 * v.normal.y +
                    11 * v.normal.z + 13 * v.uv.x + 17 * v.uv.y);
    }
    uint64_t isum = 0;
    for (std::size_t k = 0; k < mesh.indices.size(); ++k) isum += (k + 1) * mesh.indices[k];
    std::printf("  reference: %zu vertices, %zu indices, checksum %.6f, index checksum %llu\n", mesh.vertices.size(),
                mesh.indices.size(), sum, static_cast<unsigned long long>(isum));
    EXPECT_EQ(mesh.vertices.size(), 13u * 7u + 2u * 7u);
    EXPECT_EQ(mesh.indices.size(), 12u * 36u + 2u * 18u);
    EXPECT_NEAR(sum, kReferenceChecksum, 1e-3);
    EXPECT_EQ(isum, kReferenceIndexChecksum);
}

}  // namespace
}  // namespace wire::test
