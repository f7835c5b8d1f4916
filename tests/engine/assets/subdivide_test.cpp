// Catmull-Clark refinement (counts, finiteness, uvs, watertightness, errors), the screen-error level choice
// measured against a finely refined bent reference, and the tunnel assets (load, quads, bytes = tool output).
#include <engine/assets/gltf.hpp>
#include <engine/assets/mesh_building.hpp>
#include <engine/assets/subdivide.hpp>

#include <curved_space/chain.hpp>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <unordered_map>

namespace fs = std::filesystem;
using engine::assets::ControlMesh;
using engine::assets::MeshData;

namespace {

constexpr double kPi = 3.14159265358979323846;

fs::path temp_dir() {
    fs::path p = fs::temp_directory_path() /
                 ("subdivide_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
}

// A quad (a, b, c, d counter-clockwise seen from the front) with its own four vertices, flat normal, given uvs.
void add_quad(MeshData& m, std::array<glm::vec3, 4> p, std::array<glm::vec2, 4> uv) {
    engine::assets::add_quad(m, {.corners = p, .uvs = uv});
}

// A strip of `n` unit quads in the z = 0 plane along +x, uv = (x / n, y).
MeshData quad_strip(int n) {
    MeshData m;
    m.name = "strip";
    for (int i = 0; i < n; ++i) {
        const auto x0 = static_cast<float>(i), x1 = static_cast<float>(i + 1);
        const float u0 = x0 / static_cast<float>(n), u1 = x1 / static_cast<float>(n);
        add_quad(m, {glm::vec3(x0, 0, 0), {x1, 0, 0}, {x1, 1, 0}, {x0, 1, 0}}, {glm::vec2(u0, 0), {u1, 0}, {u1, 1}, {u0, 1}});
    }
    return m;
}

// A closed cube of half size 1; each face has its own vertices (hard edges, 24 vertices).
MeshData hard_cube() {
    MeshData m;
    m.name = "cube";
    const std::array<glm::vec2, 4> uv{glm::vec2(0, 0), {1, 0}, {1, 1}, {0, 1}};
    for (int axis = 0; axis < 3; ++axis)
        for (int sign = -1; sign <= 1; sign += 2) {
            glm::vec3 n(0), t(0), b(0);
            n[axis] = static_cast<float>(sign);
            t[(axis + 1) % 3] = 1;
            b[(axis + 2) % 3] = 1;
            if (sign < 0) std::swap(t, b);  // keep counter-clockwise seen from outside
            add_quad(m, {n - t - b, n + t - b, n + t + b, n - t + b}, uv);
        }
    return m;
}

// The same cube with shared vertices and averaged normals: no hard edges, refines toward a rounded shape.
MeshData smooth_cube() {
    MeshData hard = hard_cube();
    MeshData m;
    m.name = "smooth_cube";
    std::map<std::array<float, 3>, std::uint32_t> index;
    for (std::uint32_t i : hard.indices) {
        const std::array<float, 3> p{hard.positions[3 * i], hard.positions[3 * i + 1], hard.positions[3 * i + 2]};
        auto [it, inserted] = index.try_emplace(p, static_cast<std::uint32_t>(m.vertex_count()));
        if (inserted) {
            m.positions.insert(m.positions.end(), p.begin(), p.end());
            const glm::vec3 n = glm::normalize(glm::vec3(p[0], p[1], p[2]));
            m.normals.insert(m.normals.end(), {n.x, n.y, n.z});
        }
        m.indices.push_back(it->second);
    }
    return m;
}

// An open tube along +z seen from inside (normals point to the axis): `around` segments, `along` rings of
// quads over length_m, uv = (i / around, z), seam at i = 0. Vertices at angles (i + 0.5) 2 pi / around.
MeshData inner_tube(int around, int along, float radius_m, float length_m) {
    MeshData m;
    m.name = "tube";
    for (int j = 0; j <= along; ++j)
        for (int i = 0; i <= around; ++i) {
            const double a = (i + 0.5) * 2.0 * kPi / around;
            const float z = length_m * static_cast<float>(j) / static_cast<float>(along);
            m.positions.insert(m.positions.end(), {radius_m * static_cast<float>(std::cos(a)),
                                                   radius_m * static_cast<float>(std::sin(a)), z});
            m.normals.insert(m.normals.end(), {-static_cast<float>(std::cos(a)), -static_cast<float>(std::sin(a)), 0.0f});
            m.uvs.insert(m.uvs.end(), {static_cast<float>(i) / static_cast<float>(around), z});
        }
    const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (around + 1) + i); };
    for (int j = 0; j < along; ++j)
        for (int i = 0; i < around; ++i) {
            // Seen from inside (from the axis) counter-clockwise: (i, j), (i, j+1), (i+1, j+1), (i+1, j).
            const std::uint32_t a = at(i, j), b = at(i, j + 1), c = at(i + 1, j + 1), d = at(i + 1, j);
            m.indices.insert(m.indices.end(), {a, b, c, a, c, d});
        }
    return m;
}

bool all_finite(const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x); });
}

// Welds by exact position and counts how often each directed edge is used.
struct EdgeCensus {
    std::size_t boundary_edges = 0;   // directed edges without a twin
    std::size_t repeated_edges = 0;   // directed edges used more than once
};
EdgeCensus edge_census(const MeshData& m) {
    std::map<std::array<float, 3>, std::uint32_t> weld;
    std::vector<std::uint32_t> id(m.vertex_count());
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const std::array<float, 3> p{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
        id[v] = weld.try_emplace(p, static_cast<std::uint32_t>(weld.size())).first->second;
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
        for (int k = 0; k < 3; ++k)
            ++directed[{id[m.indices[3 * t + k]], id[m.indices[3 * t + (k + 1) % 3]]}];
    EdgeCensus census;
    for (const auto& [e, count] : directed) {
        if (count > 1) ++census.repeated_edges;
        if (!directed.count({e.second, e.first})) ++census.boundary_edges;
    }
    return census;
}

// ---- distance from points to a triangle soup (grid accelerated) ----

glm::dvec3 closest_on_triangle(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    // Ericson, Real-Time Collision Detection 5.1.5.
    const glm::dvec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

class TriangleGrid {
  public:
    TriangleGrid(const MeshData& m, double cell_m) : mesh_(m), cell_(cell_m) {
        for (std::uint32_t t = 0; t < m.triangle_count(); ++t) {
            glm::dvec3 lo(1e300), hi(-1e300);
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 v = vertex(m.indices[3 * t + k]);
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
            const glm::ivec3 a = cell_of(lo), b = cell_of(hi);
            for (int x = a.x; x <= b.x; ++x)
                for (int y = a.y; y <= b.y; ++y)
                    for (int z = a.z; z <= b.z; ++z) cells_[key(x, y, z)].push_back(t);
        }
    }
    // Exact distance from p to the nearest triangle.
    double distance(const glm::dvec3& p) const {
        const glm::ivec3 c = cell_of(p);
        double best = 1e300;
        for (int r = 1; r < 64; ++r) {
            for (int x = c.x - r; x <= c.x + r; ++x)
                for (int y = c.y - r; y <= c.y + r; ++y)
                    for (int z = c.z - r; z <= c.z + r; ++z) {
                        if (std::max({std::abs(x - c.x), std::abs(y - c.y), std::abs(z - c.z)}) < r - 1) continue;
                        const auto it = cells_.find(key(x, y, z));
                        if (it == cells_.end()) continue;
                        for (std::uint32_t t : it->second) {
                            const glm::dvec3 q = closest_on_triangle(p, vertex(mesh_.indices[3 * t]),
                                                                     vertex(mesh_.indices[3 * t + 1]),
                                                                     vertex(mesh_.indices[3 * t + 2]));
                            best = std::min(best, glm::length(q - p));
                        }
                    }
            if (best <= (r - 1) * cell_) return best;  // nothing outside the searched cube can be closer
        }
        return best;
    }

  private:
    glm::dvec3 vertex(std::uint32_t i) const {
        return {mesh_.positions[3 * i], mesh_.positions[3 * i + 1], mesh_.positions[3 * i + 2]};
    }
    glm::ivec3 cell_of(const glm::dvec3& p) const { return glm::ivec3(glm::floor(p / cell_)); }
    static std::int64_t key(int x, int y, int z) {
        return (static_cast<std::int64_t>(x + 100000) * 200000 + (y + 100000)) * 200000 + (z + 100000);
    }
    const MeshData& mesh_;
    double cell_;
    std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells_;
};

// Points of the rendered (piecewise linear) surface: vertices, edge midpoints, triangle centroids.
std::vector<glm::dvec3> surface_samples(const MeshData& m) {
    std::vector<glm::dvec3> out;
    const auto v = [&](std::uint32_t i) { return glm::dvec3(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]); };
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const glm::dvec3 a = v(m.indices[3 * t]), b = v(m.indices[3 * t + 1]), c = v(m.indices[3 * t + 2]);
        out.insert(out.end(), {a, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5, (a + b + c) / 3.0});
    }
    return out;
}

// Two-sided maximum distance (metres) between a mesh and a (much finer) reference whose grid is given:
// every sample of `a` to the reference, and every 3rd reference vertex to `a` (catches parts `a` misses).
double hausdorff_m(const MeshData& a, const MeshData& reference, const TriangleGrid& reference_grid) {
    const TriangleGrid grid_a(a, 0.1);
    double worst = 0.0;
    for (const glm::dvec3& p : surface_samples(a)) worst = std::max(worst, reference_grid.distance(p));
    for (std::size_t v = 0; v < reference.vertex_count(); v += 3)
        worst = std::max(worst, grid_a.distance({reference.positions[3 * v], reference.positions[3 * v + 1],
                                                 reference.positions[3 * v + 2]}));
    return worst;
}

MeshData refined_and_bent(const ControlMesh& control, int level, const curved_space::Chain& chain) {
    MeshData m;
    const auto s = engine::assets::subdivide(control, level, m);
    EXPECT_TRUE(s.ok()) << s.message;
    curved_space::bend_vertices(chain, m.positions, m.normals, m.origin);
    return m;
}

}  // namespace

// ---- refinement ----

TEST(Subdivide, QuadsArePairedFromTriangles) {
    ControlMesh c;
    ASSERT_TRUE(engine::assets::make_control_mesh(quad_strip(3), c).ok());
    EXPECT_EQ(c.face_sizes.size(), 3u);
    EXPECT_EQ(c.quad_count(), 3u);
    EXPECT_EQ(c.positions.size() / 3, 8u);  // 12 glTF vertices welded to 8
    EXPECT_TRUE(c.crease_vertices.empty());  // one flat normal everywhere: no hard edge

    ControlMesh cube;
    ASSERT_TRUE(engine::assets::make_control_mesh(hard_cube(), cube).ok());
    EXPECT_EQ(cube.quad_count(), 6u);
    EXPECT_EQ(cube.positions.size() / 3, 8u);
    EXPECT_EQ(cube.crease_vertices.size() / 2, 12u);  // every cube edge is hard
}

TEST(Subdivide, FaceCountsGrowFourfoldPerLevel) {
    for (int level = 0; level <= 4; ++level) {
        MeshData strip, cube;
        ASSERT_TRUE(engine::assets::subdivide(quad_strip(3), level, strip).ok());
        ASSERT_TRUE(engine::assets::subdivide(hard_cube(), level, cube).ok());
        const std::size_t quads = std::size_t{1} << (2 * level);
        EXPECT_EQ(strip.triangle_count(), 2 * 3 * quads) << "level " << level;
        EXPECT_EQ(cube.triangle_count(), 2 * 6 * quads) << "level " << level;
        EXPECT_TRUE(all_finite(strip.positions) && all_finite(strip.normals) && all_finite(strip.uvs));
        EXPECT_TRUE(all_finite(cube.positions) && all_finite(cube.normals));
        // Strip: (3 * 2^L + 1) x (2^L + 1) grid points, one uv each (no seam).
        const std::size_t n = std::size_t{1} << level;
        EXPECT_EQ(strip.vertex_count(), (3 * n + 1) * (n + 1)) << "level " << level;
        EXPECT_EQ(strip.name, "strip");
    }
}

TEST(Subdivide, ClosedInputStaysWatertightAndHardEdgesStaySharp) {
    MeshData cube;
    ASSERT_TRUE(engine::assets::subdivide(hard_cube(), 3, cube).ok());
    const EdgeCensus census = edge_census(cube);
    EXPECT_EQ(census.boundary_edges, 0u);
    EXPECT_EQ(census.repeated_edges, 0u);
    // All edges creased: the cube keeps its faces (every point on the surface of [-1, 1]^3).
    for (std::size_t v = 0; v < cube.vertex_count(); ++v) {
        const float m = std::max({std::abs(cube.positions[3 * v]), std::abs(cube.positions[3 * v + 1]),
                                  std::abs(cube.positions[3 * v + 2])});
        EXPECT_NEAR(m, 1.0f, 1e-5f);
    }
    // Hard edges keep split normals: each refined corner appears with three different normals.
    EXPECT_EQ(cube.vertex_count(), 6u * 9u * 9u);

    MeshData round;
    ASSERT_TRUE(engine::assets::subdivide(smooth_cube(), 3, round).ok());
    EXPECT_EQ(edge_census(round).boundary_edges, 0u);
    // No creases: the surface shrinks inside the cube and every vertex has one smooth normal.
    double max_coord = 0.0;
    for (float x : round.positions) max_coord = std::max(max_coord, double(std::abs(x)));
    EXPECT_LT(max_coord, 0.9);
    EXPECT_EQ(round.vertex_count(), 6u * 64u + 2u);  // V - E + F = 2 for the refined quad sphere
}

TEST(Subdivide, OpenEndsAreSharpBoundariesAndUvSeamsSplit) {
    MeshData tube;
    const MeshData coarse = inner_tube(12, 4, 2.5f, 4.0f);
    ASSERT_TRUE(engine::assets::subdivide(coarse, 2, tube).ok());
    const EdgeCensus census = edge_census(tube);
    EXPECT_EQ(census.repeated_edges, 0u);
    EXPECT_EQ(census.boundary_edges, 2u * 12u * 4u);  // the two end rings only: the uv seam is welded
    // The open ends stay in their planes (sharp boundary) and the uv seam has both u = 0 and u = 1.
    bool seam0 = false, seam1 = false;
    for (std::size_t v = 0; v < tube.vertex_count(); ++v) {
        const float z = tube.positions[3 * v + 2];
        EXPECT_GE(z, -1e-5f);
        EXPECT_LE(z, 4.0f + 1e-5f);
        const float u = tube.uvs[2 * v], w = tube.uvs[2 * v + 1];
        EXPECT_GE(u, -1e-6f);
        EXPECT_LE(u, 1.0f + 1e-6f);
        EXPECT_NEAR(w, z, 1e-4f);  // v = z is linear along the tube and stays so
        const float angle = std::atan2(tube.positions[3 * v + 1], tube.positions[3 * v]);
        if (std::abs(angle - static_cast<float>(kPi / 12)) < 1e-4f) {
            seam0 = seam0 || u == 0.0f;
            seam1 = seam1 || u == 1.0f;
        }
        // Normals point inward (toward the axis).
        const float nr = tube.normals[3 * v] * tube.positions[3 * v] + tube.normals[3 * v + 1] * tube.positions[3 * v + 1];
        EXPECT_LT(nr, 0.0f);
    }
    EXPECT_TRUE(seam0);
    EXPECT_TRUE(seam1);
}

TEST(Subdivide, FacePointUvIsTheAverageOfTheCornerUvs) {
    MeshData strip;
    ASSERT_TRUE(engine::assets::subdivide(quad_strip(3), 1, strip).ok());
    // The face point of the middle quad sits at its centre (1.5, 0.5) with uv (0.5, 0.5).
    bool found = false;
    for (std::size_t v = 0; v < strip.vertex_count(); ++v)
        if (std::abs(strip.positions[3 * v] - 1.5f) < 1e-6f && std::abs(strip.positions[3 * v + 1] - 0.5f) < 1e-6f) {
            EXPECT_NEAR(strip.uvs[2 * v], 0.5f, 1e-6f);
            EXPECT_NEAR(strip.uvs[2 * v + 1], 0.5f, 1e-6f);
            found = true;
        }
    EXPECT_TRUE(found);
}

TEST(Subdivide, BadInputIsASpecificErrorNamingTheMesh) {
    MeshData out;
    auto status = engine::assets::subdivide(quad_strip(2), -1, out);
    EXPECT_EQ(status.message, "mesh 'strip': subdivision level -1 out of range [0, 6]");
    status = engine::assets::subdivide(quad_strip(2), 7, out);
    EXPECT_EQ(status.message, "mesh 'strip': subdivision level 7 out of range [0, 6]");

    MeshData empty;
    empty.name = "void";
    EXPECT_EQ(engine::assets::subdivide(empty, 1, out).message, "mesh 'void': no triangles to subdivide");

    MeshData fin = quad_strip(1);
    fin.positions[4] = std::nanf("");
    EXPECT_EQ(engine::assets::subdivide(fin, 1, out).message, "mesh 'strip': vertex 1 has a non-finite position");

    // Three triangles on one edge (a fin): non-manifold.
    MeshData fan;
    fan.name = "fan";
    fan.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1};
    fan.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4};
    status = engine::assets::subdivide(fan, 1, out);
    EXPECT_NE(status.message.find("mesh 'fan': non-manifold edge between vertices"), std::string::npos)
        << status.message;

    MeshData degenerate = quad_strip(1);
    degenerate.indices = {0, 1, 1};
    EXPECT_NE(engine::assets::subdivide(degenerate, 1, out).message.find("mesh 'strip': degenerate face"),
              std::string::npos);
    EXPECT_EQ(out.vertex_count(), 0u);  // never written on failure
}

// ---- level choice ----

TEST(SubdivisionLevel, StraightFarGetsZeroBentNearGetsMore) {
    const MeshData tube = inner_tube(12, 4, 2.5f, 4.0f);
    engine::assets::LevelQuery far{.curvature_per_m = 0.0, .distance_m = 400.0, .focal_px = 1000.0, .tolerance_px = 0.5};
    EXPECT_EQ(engine::assets::choose_subdivision_level(tube, far), 0);
    engine::assets::LevelQuery near = far;
    near.curvature_per_m = (kPi / 2) / 4.0;
    near.distance_m = 3.0;
    const int bent_near = engine::assets::choose_subdivision_level(tube, near);
    EXPECT_GE(bent_near, 3);
    // Monotone: more bend or closer never lowers the level; the clamp holds.
    engine::assets::LevelQuery straight_near = near;
    straight_near.curvature_per_m = 0.0;
    EXPECT_LE(engine::assets::choose_subdivision_level(tube, straight_near), bent_near);
    engine::assets::LevelQuery touching = near;
    touching.distance_m = 0.0;
    touching.max_level = 2;
    EXPECT_EQ(engine::assets::choose_subdivision_level(tube, touching), 2);
}

// The chosen level meets the tolerance when measured: refine, bend with curved_space, compare with a level-5
// reference bent the same way (two-sided distance over vertices, edge midpoints and centroids).
TEST(SubdivisionLevel, MeasuredErrorOfTheChosenLevelIsWithinTolerance) {
    ControlMesh control;
    ASSERT_TRUE(engine::assets::make_control_mesh(inner_tube(12, 4, 2.5f, 4.0f), control).ok());
    const engine::assets::RefinementErrorModel model = engine::assets::refinement_error_model(control);
    const double kappa = (kPi / 3) / 4.0;  // 60 degrees over the 4 m piece
    curved_space::Chain chain;
    const curved_space::Segment segment{.length_m = 4.0, .angle_rad = kPi / 3, .direction_rad = 0.0};
    ASSERT_TRUE(curved_space::make_chain(std::span(&segment, 1), chain).ok());
    const MeshData reference = refined_and_bent(control, 5, chain);
    const TriangleGrid reference_grid(reference, 0.05);

    std::array<double, 4> measured{};
    for (int level = 0; level < 4; ++level) {
        measured[level] = hausdorff_m(refined_and_bent(control, level, chain), reference, reference_grid);
        const double predicted = engine::assets::predicted_error_m(model, kappa, level);
        std::printf("level %d: predicted %.5f m, measured %.5f m\n", level, predicted, measured[level]);
        EXPECT_LE(measured[level], predicted) << "level " << level;  // the model is an upper bound
        EXPECT_GE(measured[level], predicted / 6.0) << "level " << level;  // and not a wild one
    }
    for (double distance_m : {2.0, 5.0, 20.0, 80.0}) {
        const engine::assets::LevelQuery q{.curvature_per_m = kappa, .distance_m = distance_m, .focal_px = 1000.0,
                                           .tolerance_px = 1.0, .max_level = 3};
        const int level = engine::assets::choose_subdivision_level(model, q);
        const double error_px = measured[level] * q.focal_px / distance_m;
        std::printf("distance %.0f m: level %d, measured %.3f px\n", distance_m, level, error_px);
        if (level < q.max_level) {
            EXPECT_LE(error_px, q.tolerance_px) << "distance " << distance_m;
        }
        if (level > 0) {  // one level less would not have been enough (within the model's slack)
            EXPECT_GT(measured[level - 1] * q.focal_px / distance_m, q.tolerance_px / 6.0);
        }
    }
}

// ---- tunnel assets ----

namespace {
const fs::path kTunnelDir = fs::path(WIRE_ASSET_DIR) / "tunnel";
const std::array<const char*, 3> kPieces{"straight_section.glb", "wall_details.glb", "cable_hooks.glb"};
}  // namespace

TEST(TunnelAssets, EveryPieceLoadsAndIsQuadDominant) {
    std::uintmax_t total_bytes = 0;
    for (const char* piece : kPieces) {
        const fs::path path = kTunnelDir / piece;
        total_bytes += fs::file_size(path);
        std::vector<MeshData> meshes;
        const auto status = engine::assets::read_gltf(path.string(), meshes);
        ASSERT_TRUE(status.ok()) << status.message;
        ASSERT_FALSE(meshes.empty()) << piece;
        for (const MeshData& m : meshes) {
            EXPECT_FALSE(m.uvs.empty()) << m.name;
            ControlMesh control;
            const auto s = engine::assets::make_control_mesh(m, control);
            ASSERT_TRUE(s.ok()) << s.message;
            EXPECT_EQ(control.quad_count(), control.face_sizes.size()) << piece << " " << m.name;
            MeshData refined;
            ASSERT_TRUE(engine::assets::subdivide(control, 2, refined).ok()) << m.name;
            EXPECT_EQ(edge_census(refined).repeated_edges, 0u) << m.name;
        }
    }
    EXPECT_LT(total_bytes, 200u * 1024u);
    // The anchors sidecar exists and names anchor_0.
    std::ifstream anchors(kTunnelDir / "anchors.json");
    const std::string text((std::istreambuf_iterator<char>(anchors)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("\"anchor_0\""), std::string::npos);
}

TEST(TunnelAssets, MissingOrCorruptPieceNamesTheFile) {
    std::vector<MeshData> meshes;
    const std::string missing = (kTunnelDir / "no_such_piece.glb").string();
    auto status = engine::assets::read_gltf(missing, meshes);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message.find(missing), std::string::npos) << status.message;

    const fs::path dir = temp_dir();
    const fs::path corrupt = dir / "straight_section.glb";
    {
        // The real piece cut in half: a truncated download.
        std::ifstream in(kTunnelDir / "straight_section.glb", std::ios::binary);
        std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        bytes.resize(bytes.size() / 2);
        std::ofstream(corrupt, std::ios::binary) << bytes;
    }
    status = engine::assets::read_gltf(corrupt.string(), meshes);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message.find(corrupt.string()), std::string::npos) << status.message;
    fs::remove_all(dir);
}

TEST(TunnelAssets, CommittedFilesEqualTheToolOutput) {
    const fs::path dir = temp_dir();
    const std::string command = std::string(MAKE_TUNNEL_ASSETS_EXE) + " --out " + dir.string();
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    std::size_t compared = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
        const fs::path committed = kTunnelDir / entry.path().filename();
        ASSERT_TRUE(fs::exists(committed)) << committed << " is written by the tool but not committed";
        std::ifstream a(entry.path(), std::ios::binary), b(committed, std::ios::binary);
        const std::string x((std::istreambuf_iterator<char>(a)), std::istreambuf_iterator<char>());
        const std::string y((std::istreambuf_iterator<char>(b)), std::istreambuf_iterator<char>());
        EXPECT_TRUE(x == y) << committed
                            << " differs from the tool's output; regenerate with: make_tunnel_assets --out assets/tunnel";
        ++compared;
    }
    EXPECT_EQ(compared, kPieces.size() + 1);  // the pieces and anchors.json
    fs::remove_all(dir);
}
