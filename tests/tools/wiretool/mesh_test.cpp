// `wiretool mesh` against its contract: options, CSV layout, glTF output, errors and exit statuses.
#include <engine/assets/gltf.hpp>
#include <wire/bezier.hpp>
#include <wire/spline.hpp>

#include <gtest/gtest.h>

#include "tool_test.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/wait.h>

namespace fs = std::filesystem;

namespace {

using wiretool_test::ToolRun;

class WiretoolMesh : public wiretool_test::ToolTest {
protected:
    WiretoolMesh() : ToolTest("wiretool_mesh", "") {}
    static std::vector<std::vector<std::string>> read_csv(const std::string& file, std::string& header) {
        std::ifstream in(file);
        std::getline(in, header);
        std::vector<std::vector<std::string>> rows;
        for (std::string line; std::getline(in, line);) {
            std::vector<std::string> cells;
            std::stringstream ss(line);
            for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
            rows.push_back(cells);
        }
        return rows;
    }
};

/// A hanging cable: 12 nodes on y = cosh.
std::string cable_json(double radius = 0.05) {
    std::string nodes;
    for (int i = 0; i < 12; ++i) {
        const double x = i * 0.5;
        const double y = 2.0 * (std::cosh((x - 2.75) / 2.0) - std::cosh(2.75 / 2.0));
        if (i > 0) nodes += ',';
        nodes += '[';
        nodes += std::to_string(x);
        nodes += ',';
        nodes += std::to_string(y);
        nodes += ",0]";
    }
    return "{\"radius\": " + std::to_string(radius) + ", \"spline\": {\"type\": \"chordal\"}, \"nodes\": [" + nodes + "]}";
}

}  // namespace

TEST_F(WiretoolMesh, CsvHeaderAndFixedRingsAtKOverN) {
    const std::string in = write("cable.json", cable_json());
    const ToolRun r = run("mesh " + in + " --csv " + path("rings.csv") + " --rings-per-segment 5 --spline centripetal");
    ASSERT_EQ(r.status, 0) << r.err;
    std::string header;
    const auto rows = read_csv(path("rings.csv"), header);
    EXPECT_EQ(header, "frame,wire,ring,segment,t,x,y,z,tx,ty,tz,nx,ny,nz,bx,by,bz,radius,u");
    ASSERT_EQ(rows.size(), 11u * 5u + 1u);  // 11 segments x 5 rings + the last ring of an open wire
    double last_u = -1.0;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        ASSERT_EQ(rows[i].size(), 19u);
        EXPECT_EQ(std::stoul(rows[i][2]), i);
        const std::size_t seg = std::stoul(rows[i][3]);
        const double t = std::stod(rows[i][4]);
        if (i + 1 < rows.size()) {
            EXPECT_EQ(seg, i / 5);
            EXPECT_DOUBLE_EQ(t, double(i % 5) / 5.0);
        } else {
            EXPECT_EQ(seg, 10u);
            EXPECT_DOUBLE_EQ(t, 1.0);
        }
        // Frame orthonormal, radius as given, u increasing.
        const glm::dvec3 T(std::stod(rows[i][8]), std::stod(rows[i][9]), std::stod(rows[i][10]));
        const glm::dvec3 N(std::stod(rows[i][11]), std::stod(rows[i][12]), std::stod(rows[i][13]));
        const glm::dvec3 B(std::stod(rows[i][14]), std::stod(rows[i][15]), std::stod(rows[i][16]));
        EXPECT_NEAR(glm::length(T), 1.0, 1e-6);
        EXPECT_NEAR(glm::dot(T, N), 0.0, 1e-6);
        EXPECT_NEAR(glm::length(glm::cross(T, N) - B), 0.0, 1e-6);
        EXPECT_NEAR(std::stod(rows[i][17]), 0.05, 1e-7);
        const double u = std::stod(rows[i][18]);
        EXPECT_GT(u, last_u);
        last_u = u;
    }
}

TEST_F(WiretoolMesh, ToleranceBoundsTheDistanceFromCurveToRingPolyline) {
    const std::string in = write("cable.json", cable_json());
    const double tol = 1e-3;
    const ToolRun r = run("mesh " + in + " --csv " + path("rings.csv") + " --tolerance 0.001");
    ASSERT_EQ(r.status, 0) << r.err;
    std::string header;
    const auto rows = read_csv(path("rings.csv"), header);
    std::vector<glm::dvec3> polyline;
    for (const auto& row : rows) polyline.emplace_back(std::stod(row[5]), std::stod(row[6]), std::stod(row[7]));

    // The same curve, built by the library from the same nodes (the file says chordal).
    wire::WireNodes nodes;
    for (int i = 0; i < 12; ++i) {
        const double x = i * 0.5;
        nodes.positions.emplace_back(x, 2.0 * (std::cosh((x - 2.75) / 2.0) - std::cosh(2.75 / 2.0)), 0.0);
    }
    // Round the nodes as the file does (std::to_string keeps 6 decimals).
    for (auto& p : nodes.positions) p = glm::dvec3(std::stod(std::to_string(p.x)), std::stod(std::to_string(p.y)), 0.0);
    wire::Curve curve;
    ASSERT_TRUE(build_curve(nodes, wire::SplineSettings{.alpha = 1.0}, curve).ok());
    double worst = 0.0;
    for (const glm::dvec3& p : wire::sample_curve(curve, 400)) worst = std::max(worst, wire::distance_to_polyline(p, polyline));
    EXPECT_LE(worst, tol) << "rings: " << rows.size();
    EXPECT_GT(worst, tol / 50) << "far more rings than the tolerance needs: " << rows.size();
}

TEST_F(WiretoolMesh, GlbLoadsBackThroughTinygltf) {
    const std::string in =
        write("two.json", "{\"wires\": [" + cable_json() + ", {\"radius\": 0.02, \"closed\": true, \"nodes\": "
                          "[[0,0,0],[1,0,0],[1,1,0],[0,1,0]]}]}");
    const ToolRun r = run("mesh " + in + " -o " + path("out.glb") + " --sides 6 --rings-per-segment 4");
    ASSERT_EQ(r.status, 0) << r.err;
    std::vector<engine::assets::MeshData> meshes;
    const auto st = engine::assets::read_gltf(path("out.glb"), meshes);
    ASSERT_TRUE(st.ok()) << st.message;
    ASSERT_EQ(meshes.size(), 2u);
    // Open wire: 45 rings x 7 vertices + 2 caps x 7; closed: (16 + 1) rings x 7, no caps.
    EXPECT_EQ(meshes[0].vertex_count(), 45u * 7u + 14u);
    EXPECT_EQ(meshes[1].vertex_count(), 17u * 7u);
    for (const auto& m : meshes) {
        EXPECT_EQ(m.normals.size(), m.positions.size());
        EXPECT_EQ(m.uvs.size() / 2, m.vertex_count());
        for (float f : m.positions) ASSERT_TRUE(std::isfinite(f));
        for (std::size_t v = 0; v < m.vertex_count(); ++v) {
            const glm::dvec3 n(m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2]);
            EXPECT_NEAR(glm::length(n), 1.0, 1e-5);
        }
    }
}

TEST_F(WiretoolMesh, FramesAreProcessedInOrderAndTheLastIsWritten) {
    const std::string in = write("frames.json", R"({"frames": [
        {"wires": [{"nodes": [{"p": [0,0,0], "id": 1}, {"p": [1,0,0], "id": 2}, {"p": [2,0.5,0], "id": 3}]}]},
        {"wires": [{"nodes": [{"p": [0,0,0], "id": 1}, {"p": [1,0.1,0], "id": 2}, {"p": [1.5,0.3,0], "id": 9},
                              {"p": [2,0.5,0], "id": 3}]}]}]})");
    const ToolRun r = run("mesh " + in + " --csv " + path("r.csv") + " -o " + path("r.glb") + " --rings-per-segment 2");
    ASSERT_EQ(r.status, 0) << r.err;
    std::string header;
    const auto rows = read_csv(path("r.csv"), header);
    std::size_t frame0 = 0, frame1 = 0;
    for (const auto& row : rows) (row[0] == "0" ? frame0 : frame1)++;
    EXPECT_EQ(frame0, 2u * 2u + 1u);
    EXPECT_EQ(frame1, 3u * 2u + 1u);
    std::vector<engine::assets::MeshData> meshes;
    ASSERT_TRUE(engine::assets::read_gltf(path("r.glb"), meshes).ok());
    ASSERT_EQ(meshes.size(), 1u);
    EXPECT_EQ(meshes[0].vertex_count(), (3u * 2u + 1u) * 13u + 26u);  // default 12 sides, with caps
}

TEST_F(WiretoolMesh, RepeatPrintsVerticesAndMeanTime) {
    const std::string in = write("cable.json", cable_json());
    const ToolRun r = run("mesh " + in + " --repeat 3 --rings-per-segment 2 --sides 4");
    ASSERT_EQ(r.status, 0) << r.err;
    const std::size_t expected = (11u * 2u + 1u) * 5u + 10u;
    EXPECT_EQ(r.err.rfind("vertices=" + std::to_string(expected) + " mean_ms=", 0), 0u) << r.err;
}

TEST_F(WiretoolMesh, BadInputExitsTwoNamingWireAndNodeAndWritesNothing) {
    struct Case {
        std::string json, expect;
    };
    const std::vector<Case> cases = {
        {"{\"nodes\": [[0,0,0], [1,0", "malformed JSON"},
        {"{\"nodes\": [[0,0,0]]}", "wire 0: a wire needs at least 2 distinct nodes"},
        {R"({"wires": [{"nodes": [[0,0,0],[1,0,0]]}, {"nodes": [[0,0,0],[1,"nan",0]]}]})", "wire 1, node 1: coordinate y"},
        {R"({"radius": -0.1, "nodes": [[0,0,0],[1,0,0]]})", "radius must be positive"},
        {R"({"spline": {"type": "bezier"}, "nodes": [[0,0,0],[1,0,0]]})", "unknown spline type 'bezier'"},
    };
    for (const Case& c : cases) {
        const std::string in = write("bad.json", c.json);
        const ToolRun r = run("mesh " + in + " -o " + path("bad.glb") + " --csv " + path("bad.csv"));
        EXPECT_EQ(r.status, 2) << c.json;
        EXPECT_NE(r.err.find(c.expect), std::string::npos) << "message: " << r.err << " for " << c.json;
        EXPECT_NE(r.err.find("bad.json"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(path("bad.glb")));
        EXPECT_FALSE(fs::exists(path("bad.csv")));
    }
    EXPECT_EQ(run("mesh " + path("missing.json")).status, 2);
    EXPECT_EQ(run("mesh").status, 2);
    EXPECT_EQ(run("mesh " + write("c.json", cable_json()) + " --rings-per-segment 3 --tolerance 0.1").status, 2);
}

TEST_F(WiretoolMesh, CommandLineOverridesTheFile) {
    const std::string in = write("cable.json", cable_json(0.05));
    ASSERT_EQ(run("mesh " + in + " --csv " + path("a.csv") + " --rings-per-segment 1").status, 0);
    ASSERT_EQ(run("mesh " + in + " --csv " + path("b.csv") + " --rings-per-segment 1 --spline uniform").status, 0);
    std::string h;
    const auto a = read_csv(path("a.csv"), h), b = read_csv(path("b.csv"), h);
    ASSERT_EQ(a.size(), b.size());
    // Same nodes (ring centres at t = 0), different tangents: chordal (file) against uniform (command line).
    double max_tangent_diff = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i][5], b[i][5]);
        max_tangent_diff = std::max(max_tangent_diff, std::abs(std::stod(a[i][8]) - std::stod(b[i][8])));
    }
    EXPECT_GT(max_tangent_diff, 1e-3);
}
