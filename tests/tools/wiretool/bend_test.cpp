// `wiretool bend` end to end: runs the built binary on a generated glb with valid and invalid inputs and checks
// the exit status, the message, that nothing is written on failure, and the output against the CPU reference.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <engine/assets/gltf.hpp>

#include "curved_space/chain.hpp"
#include "curved_space/segments_json.hpp"

#ifndef WIRETOOL_PATH
#error "WIRETOOL_PATH must name the wiretool binary"
#endif

namespace {

namespace fs = std::filesystem;
using engine::assets::MeshData;

// A fresh directory per test (every test builds its own world).
class BendCommand : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        dir_ = fs::temp_directory_path() / ("curved_space_bend_" + std::string(info->name()) + "_" +
                                            std::to_string(static_cast<long>(::getpid())));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    void write_text(const std::string& name, const std::string& text) const {
        std::ofstream(path(name), std::ios::binary) << text;
    }

    struct Run {
        int status = -1;
        std::string err;
    };
    // Runs wiretool with the arguments (already quoted as needed); captures stderr.
    Run wiretool(const std::string& args) const {
        const std::string err_file = path("stderr.txt");
        const std::string command = std::string("\"") + WIRETOOL_PATH + "\" " + args + " > \"" + path("stdout.txt") +
                                    "\" 2> \"" + err_file + "\"";
        const int raw = std::system(command.c_str());
        Run run;
        run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
        std::ifstream in(err_file);
        std::stringstream text;
        text << in.rdbuf();
        run.err = text.str();
        return run;
    }

    fs::path dir_;
};

// A tube of radius 0.5 along z in [-1, 11] (12 sides x 49 rings) with uvs, and a small box, as two meshes.
std::vector<MeshData> make_meshes() {
    std::vector<MeshData> meshes(2);
    MeshData& tube = meshes[0];
    tube.name = "tube";
    const int sides = 12;
    const int rings = 49;
    for (int r = 0; r < rings; ++r) {
        const float z = -1.0f + 12.0f * static_cast<float>(r) / static_cast<float>(rings - 1);
        for (int s = 0; s <= sides; ++s) {
            const float phi = 2.0f * std::numbers::pi_v<float> * static_cast<float>(s) / sides;
            tube.positions.insert(tube.positions.end(), {0.5f * std::cos(phi), 0.5f * std::sin(phi), z});
            tube.normals.insert(tube.normals.end(), {std::cos(phi), std::sin(phi), 0.0f});
            tube.uvs.insert(tube.uvs.end(), {static_cast<float>(s) / sides, z});
        }
    }
    for (int r = 0; r + 1 < rings; ++r)
        for (int s = 0; s < sides; ++s) {
            const auto a = static_cast<uint32_t>(r * (sides + 1) + s);
            const auto b = a + static_cast<uint32_t>(sides + 1);
            tube.indices.insert(tube.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
        }
    MeshData& quad = meshes[1];
    quad.name = "floor";
    quad.positions = {-0.4f, -0.45f, 2.0f, 0.4f, -0.45f, 2.0f, 0.4f, -0.45f, 6.0f, -0.4f, -0.45f, 6.0f};
    quad.normals = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    quad.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
    quad.indices = {0, 2, 1, 0, 3, 2};
    return meshes;
}

const char* good_segments =
    R"({"segments": [{"length": 4.0, "angle": 0.5, "direction": 0.0},
                     {"length": 3.0, "angle": -0.8, "direction": 1.2},
                     {"length": 2.0, "angle": 1.0}]})";

TEST_F(BendCommand, BakesTheCpuReferenceIntoEveryMesh) {
    const std::vector<MeshData> input = make_meshes();
    ASSERT_TRUE(engine::assets::write_glb(path("in.glb"), input).ok());
    write_text("segs.json", good_segments);
    const Run run = wiretool("bend \"" + path("in.glb") + "\" --segments \"" + path("segs.json") + "\" -o \"" +
                             path("out.glb") + "\"");
    ASSERT_EQ(run.status, 0) << run.err;

    // The reference: the input as any reader sees it, bent by the CPU reference.
    std::vector<MeshData> expected;
    ASSERT_TRUE(engine::assets::read_gltf(path("in.glb"), expected).ok());
    std::vector<curved_space::Segment> segments;
    ASSERT_TRUE(curved_space::read_segments_json(path("segs.json"), segments).ok());
    curved_space::Chain chain;
    ASSERT_TRUE(curved_space::make_chain(segments, chain).ok());
    ASSERT_EQ(segments.size(), 3u);
    EXPECT_EQ(segments[2].direction_rad, 0.0);  // optional key, default 0

    std::vector<MeshData> output;
    ASSERT_TRUE(engine::assets::read_gltf(path("out.glb"), output).ok());
    ASSERT_EQ(output.size(), expected.size());
    double worst = 0.0;
    for (std::size_t m = 0; m < output.size(); ++m) {
        MeshData& e = expected[m];
        EXPECT_EQ(curved_space::bend_vertices(chain, e.positions, e.normals, e.origin), 0u);
        ASSERT_EQ(output[m].positions.size(), e.positions.size());
        ASSERT_EQ(output[m].normals.size(), e.normals.size());
        for (std::size_t i = 0; i < e.positions.size(); ++i) {
            worst = std::max(worst, static_cast<double>(std::abs(output[m].positions[i] - e.positions[i])));
            EXPECT_NEAR(output[m].positions[i], e.positions[i], 1e-6) << "mesh " << m << " value " << i;
            EXPECT_NEAR(output[m].normals[i], e.normals[i], 1e-6) << "mesh " << m << " value " << i;
        }
        EXPECT_EQ(output[m].uvs, e.uvs);
        EXPECT_EQ(output[m].indices, e.indices);
        EXPECT_EQ(output[m].indices, input[m].indices);
        EXPECT_EQ(output[m].uvs, input[m].uvs);
    }
    std::printf("[ measure  ] wiretool bend vs CPU reference: max position difference %.3g m\n", worst);
    // And the bend really happened: the tube's far end is off the z axis.
    EXPECT_GT(std::abs(output[0].positions[output[0].positions.size() - 3]), 1.0f);
}

struct BadCase {
    const char* label;
    const char* segments_json;  // nullptr: no file written (missing)
    bool garbage_glb = false;
    bool missing_glb = false;
    const char* expect;         // a substring of the message
};

TEST_F(BendCommand, BadInputExitsTwoWithAClearMessageAndWritesNothing) {
    const std::vector<BadCase> cases{
        {"missing glb", good_segments, false, true, "missing.glb"},
        {"garbage glb", good_segments, true, false, "in.glb"},
        {"malformed JSON", R"({"segments": [{"length": 4.0, "angle": 0.5,}]})", false, false, "segs.json: invalid JSON"},
        {"NaN", R"({"segments": [{"length": NaN, "angle": 0.5}]})", false, false, "segs.json: invalid JSON"},
        {"overflow", R"({"segments": [{"length": 1e999, "angle": 0.5}]})", false, false, "segs.json: invalid JSON"},
        {"missing key", R"({"segments": [{"length": 4.0, "angle": 0.5}, {"length": 1.0}]})", false, false,
         "segs.json: segment 1: missing key \"angle\""},
        {"missing segments", R"({"segment": []})", false, false, "segs.json: missing key \"segments\""},
        {"empty list", R"({"segments": []})", false, false, "segs.json: \"segments\" is empty"},
        {"negative length", R"({"segments": [{"length": 4.0, "angle": 0.5}, {"length": -1, "angle": 0.1}]})", false,
         false, "segs.json: segment 1: length must be positive, got -1"},
        {"zero length", R"({"segments": [{"length": 0, "angle": 0.5}]})", false, false,
         "segs.json: segment 0: length must be positive, got 0"},
        {"string value", R"({"segments": [{"length": 2, "angle": "0.5"}]})", false, false,
         "segs.json: segment 0: angle must be a number, got string"},
        {"unknown key", R"({"segments": [{"length": 2, "angle": 0.5, "directon": 1}]})", false, false,
         "segs.json: segment 0: unknown key \"directon\""},
        {"not an object", R"({"segments": [3]})", false, false, "segs.json: segment 0: expected an object"},
        {"missing segments file", nullptr, false, false, "segs.json: cannot open"},
    };
    for (const BadCase& c : cases) {
        SCOPED_TRACE(c.label);
        fs::remove(path("in.glb"));
        fs::remove(path("segs.json"));
        if (c.garbage_glb) {
            write_text("in.glb", "glTF this is not a binary glTF file at all");
        } else {
            ASSERT_TRUE(engine::assets::write_glb(path("in.glb"), make_meshes()).ok());
        }
        if (c.segments_json) write_text("segs.json", c.segments_json);
        const std::string in = c.missing_glb ? path("missing.glb") : path("in.glb");
        const Run run =
            wiretool("bend \"" + in + "\" --segments \"" + path("segs.json") + "\" -o \"" + path("out.glb") + "\"");
        EXPECT_EQ(run.status, 2) << run.err;
        EXPECT_NE(run.err.find(c.expect), std::string::npos) << "stderr: " << run.err;
        // Nothing at the output path, and no temporary left beside it.
        EXPECT_FALSE(fs::exists(path("out.glb")));
        for (const auto& entry : fs::directory_iterator(dir_))
            EXPECT_EQ(entry.path().filename().string().find("out.glb"), std::string::npos) << entry.path();
    }
    // A usage error (no --segments) is bad input too.
    ASSERT_TRUE(engine::assets::write_glb(path("in.glb"), make_meshes()).ok());
    const Run usage = wiretool("bend \"" + path("in.glb") + "\" -o \"" + path("out.glb") + "\"");
    EXPECT_EQ(usage.status, 2);
    EXPECT_NE(usage.err.find("--segments"), std::string::npos) << usage.err;
    EXPECT_FALSE(fs::exists(path("out.glb")));
}

TEST(SegmentsJson, ParsesAndRejectsWithoutTouchingTheOutput) {
    std::vector<curved_space::Segment> out{{9.0, 9.0, 9.0}};
    ASSERT_TRUE(curved_space::parse_segments_json(R"({"segments": [{"length": 2, "angle": 0.25, "direction": -1}]})",
                                                  "s.json", out)
                    .ok());
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].length_m, 2.0);
    EXPECT_EQ(out[0].angle_rad, 0.25);
    EXPECT_EQ(out[0].direction_rad, -1.0);
    const engine::Status bad =
        curved_space::parse_segments_json(R"({"segments": [{"length": 2, "angle": 0.25}, {"length": -3, "angle": 0}]})",
                                          "s.json", out);
    EXPECT_FALSE(bad.ok());
    EXPECT_EQ(bad.message, "s.json: segment 1: length must be positive, got -3");
    EXPECT_EQ(bad.index, 1);
    EXPECT_EQ(out.size(), 1u);
    EXPECT_EQ(curved_space::parse_segments_json("[1, 2]", "s.json", out).message,
              "s.json: expected an object {\"segments\": [...]}, got array");
}

}  // namespace
