// Exact error messages of every load and input path: each names the file (or mesh), the frame, wire, node or
// segment, and what is wrong. A changed message is a visible change for users (wiretool prints them as is).
#include <curved_space/segments_json.hpp>
#include <engine/assets/gltf.hpp>
#include <engine/assets/subdivide.hpp>
#include <wire/io/wire_json.hpp>
#include <wire/pipeline.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

std::string wire_json_error(const std::string& text) {
    wire::io::SceneSpec scene;
    const engine::Status st = wire::io::parse_wire_json(text, "cable.json", scene);
    EXPECT_FALSE(st.ok());
    EXPECT_TRUE(scene.frames.empty());
    return st.message;
}

std::string pipeline_error(const wire::WireNodes& nodes, const wire::PipelineSettings& settings = {}) {
    wire::WirePipeline pipeline;
    const engine::Status st = pipeline.update(nodes, settings);
    EXPECT_FALSE(st.ok());
    return st.message;
}

std::string segments_error(const std::string& text) {
    std::vector<curved_space::Segment> segments;
    const engine::Status st = curved_space::parse_segments_json(text, "segs.json", segments);
    EXPECT_FALSE(st.ok());
    EXPECT_TRUE(segments.empty());
    return st.message;
}

std::string gltf_memory_error(const std::string& bytes) {
    std::vector<engine::assets::MeshData> meshes;
    const engine::Status st =
        engine::assets::read_gltf_memory(std::as_bytes(std::span(bytes.data(), bytes.size())), "piece.gltf", meshes);
    EXPECT_FALSE(st.ok());
    EXPECT_TRUE(meshes.empty());
    return st.message;
}

engine::assets::MeshData quad(const std::string& name) {
    engine::assets::MeshData m;
    m.name = name;
    m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    m.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    m.uvs = {0, 0, 1, 0, 1, 1, 0, 1};
    m.indices = {0, 1, 2, 0, 2, 3};
    return m;
}

/// A one-quad glTF (JSON, buffer as a data: URI) whose index buffer holds `last_index` as its last index.
std::string quad_gltf(int last_index, const std::string& buffer_uri = "") {
    // 4 float3 positions (48 bytes) + 6 uint16 indices (12 bytes), base64 of the little-endian bytes.
    const float positions[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, static_cast<uint16_t>(last_index)};
    std::string raw(reinterpret_cast<const char*>(positions), sizeof positions);
    raw.append(reinterpret_cast<const char*>(indices), sizeof indices);
    static const char* kB64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string b64;
    for (std::size_t i = 0; i < raw.size(); i += 3) {
        const uint32_t n = (uint32_t(uint8_t(raw[i])) << 16) |
                           (i + 1 < raw.size() ? uint32_t(uint8_t(raw[i + 1])) << 8 : 0u) |
                           (i + 2 < raw.size() ? uint32_t(uint8_t(raw[i + 2])) : 0u);
        b64 += kB64[(n >> 18) & 63];
        b64 += kB64[(n >> 12) & 63];
        b64 += i + 1 < raw.size() ? kB64[(n >> 6) & 63] : '=';
        b64 += i + 2 < raw.size() ? kB64[n & 63] : '=';
    }
    const std::string uri = buffer_uri.empty() ? "data:application/octet-stream;base64," + b64 : buffer_uri;
    return R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":60,"uri":")" + uri +
           R"("}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}],)"
           R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},)"
           R"({"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}],)"
           R"("meshes":[{"name":"quad","primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
           R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
}

fs::path temp_dir() {
    const fs::path p = fs::temp_directory_path() /
                       ("reliability_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::create_directories(p);
    return p;
}

}  // namespace

// ---- wire JSON (wire::io::parse_wire_json / load_wire_json) ----

TEST(WireJsonErrors, CoordinateOfTheWrongTypeNamesWireAndNode) {
    EXPECT_EQ(wire_json_error(R"({"wires": [{"nodes": [[0,0,0],[1,0,0]]},
        {"nodes": [[0,0,0],[1,0,0],[2,0,0],[3,0,0],[4,"up",0]]}]})"),
              "cable.json: wire 1, node 4: coordinate y must be a number, got string");
}

TEST(WireJsonErrors, FrameIsNamedWhenThereAreFrames) {
    EXPECT_EQ(wire_json_error(R"({"frames": [{"wires": [{"nodes": [[0,0,0],[1,0,0]]}]},
        {"wires": [{"nodes": [[0,0,0],{"p": [1,0,0], "stretch": -2}]}]}]})"),
              "cable.json: frame 1, wire 0, node 1: stretch must be positive, got -2");
}

// A file holding one wire names no wire index (there is only one).
TEST(WireJsonErrors, NegativeRadius) {
    EXPECT_EQ(wire_json_error(R"({"radius": -0.5, "nodes": [[0,0,0],[1,0,0]]})"),
              "cable.json: radius must be positive, got -0.5");
    EXPECT_EQ(wire_json_error(R"({"wires": [{"nodes": [[0,0,0],[1,0,0]]}, {"radius": -1e-9, "nodes": [[0,0,0],[1,0,0]]}]})"),
              "cable.json: wire 1: radius must be positive, got -1e-09");
}

TEST(WireJsonErrors, UnknownKeyIsATypo) {
    EXPECT_EQ(wire_json_error(R"({"radius": 0.1, "node": [[0,0,0],[1,0,0]]})"),
              "cable.json: unknown key 'node' in wire");
}

TEST(WireJsonErrors, MissingNodes) {
    EXPECT_EQ(wire_json_error(R"({"radius": 0.1})"), "cable.json: missing \"nodes\"");
}

// nlohmann rejects the number while parsing, before any wire or node is known.
TEST(WireJsonErrors, OverflowingNumber) {
    EXPECT_EQ(wire_json_error(R"({"nodes": [[0,0,0],[1e999,0,0]]})"),
              "cable.json: malformed JSON: [json.exception.out_of_range.406] number overflow parsing '1e999'");
}

TEST(WireJsonErrors, PhysicsAreaNamesItsValue) {
    EXPECT_EQ(wire_json_error(R"({"nodes": [{"p": [0,0,0], "physics": {"theta": 0, "Iz": 1, "L": 1, "dL": 0, "A": 0}},
        [1,0,0]]})"),
              "cable.json: node 0: physics A must be positive, got 0");
}

TEST(WireJsonErrors, MalformedJsonNamesTheFileAndPosition) {
    EXPECT_EQ(wire_json_error(R"({"nodes": [[0,0,0],[1,0)"),
              "cable.json: malformed JSON: [json.exception.parse_error.101] parse error at line 1, column 24: "
              "syntax error while parsing array - unexpected end of input; expected ']'");
}

TEST(WireJsonErrors, DuplicateIdNamesBothTheNodeAndTheId) {
    EXPECT_EQ(wire_json_error(R"({"nodes": [{"p": [0,0,0], "id": 4}, {"p": [1,0,0], "id": 4}]})"),
              "cable.json: node 1: id 4 is used twice");
}

TEST(WireJsonErrors, MissingFileNamesThePath) {
    wire::io::SceneSpec scene;
    const engine::Status st = wire::io::load_wire_json("/nonexistent/cable.json", scene);
    EXPECT_EQ(st.message, "/nonexistent/cable.json: cannot open: No such file or directory");
}

// ---- curve stage through WirePipeline (wire::build_curve) ----

TEST(CurveErrors, NanCoordinateNamesNodeAndAxis) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, std::numeric_limits<double>::quiet_NaN(), 0}};
    wire::WirePipeline pipeline;
    const engine::Status st = pipeline.update(nodes, {});
    EXPECT_EQ(st.message, "node 3: position.y is NaN");
    EXPECT_EQ(st.index, 3);
}

TEST(CurveErrors, InfiniteCoordinate) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {0, 0, -std::numeric_limits<double>::infinity()}};
    EXPECT_EQ(pipeline_error(nodes), "node 1: position.z is -Inf");
}

TEST(CurveErrors, CoordinateBeyondTheSupportedRange) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {1, 0, -2.5e110}};
    EXPECT_EQ(pipeline_error(nodes), "node 1: position.z is -2.5e+110 (beyond the supported range of +-1e12 m)");
}

TEST(CurveErrors, TooFewDistinctNodes) {
    wire::WireNodes nodes;
    nodes.positions = {{1, 2, 3}, {1, 2, 3}};
    EXPECT_EQ(pipeline_error(nodes),
              "a wire needs at least 2 distinct nodes, got 2 node(s) and 1 after merging coincident ones");
}

TEST(CurveErrors, ClosedLoopOfTwoNodes) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {1, 0, 0}};
    wire::PipelineSettings s;
    s.spline.closed = true;
    EXPECT_EQ(pipeline_error(nodes, s), "a closed loop needs at least 3 distinct nodes, got 2 after merging coincident ones");
}

// A node id used twice in one state (ids key the pop-free blend across states): the node and the id, with or
// without the pop-free blend. (wiretool's JSON reader reports it earlier, naming the file and wire.)
TEST(CurveErrors, DuplicateNodeId) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 0}};
    nodes.ids = {7, 8, 9, 8};
    EXPECT_EQ(pipeline_error(nodes), "node 3: id 8 is used twice (also node 1)");
    wire::PipelineSettings raw;
    raw.pop_free = false;
    EXPECT_EQ(pipeline_error(nodes, raw), "node 3: id 8 is used twice (also node 1)");
}

TEST(CurveErrors, NegativeNodeRadius) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    nodes.radius_m = {0.01f, -0.02f, 0.01f};
    EXPECT_EQ(pipeline_error(nodes), "node 1: radius_m is -0.0199999996 (must be finite and >= 0; 0 uses the wire's radius)");
}

TEST(CurveErrors, ArrayOfTheWrongLength) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    nodes.stretch = {1.0f, 1.0f};
    EXPECT_EQ(pipeline_error(nodes), "stretch has 2 entries for 3 nodes (must be empty or one per node)");
}

TEST(CurveErrors, PipelineKeepsThePreviousStateOnError) {
    wire::WireNodes good;
    good.positions = {{0, 0, 0}, {1, 0, 0}, {2, 1, 0}};
    wire::WirePipeline pipeline;
    ASSERT_TRUE(pipeline.update(good, {}).ok());
    const std::size_t vertices = pipeline.mesh().vertices.size();
    wire::WireNodes bad = good;
    bad.positions[2].x = std::numeric_limits<double>::infinity();
    EXPECT_EQ(pipeline.update(bad, {}).message, "node 2: position.x is +Inf");
    EXPECT_EQ(pipeline.mesh().vertices.size(), vertices);
}

// Found by `tools/fuzz run fuzz_geometry 60` (tests/fuzz/corpus/fuzz_geometry/regression_denormal_radius.bin):
// a closed uniform Catmull-Rom wire of 28 nodes with 8.6e9 m jumps and a denormal tube radius (1.04e-42 m).
// Texture u = arc length / (2 pi radius stretch) overflowed float: the mesh had uv = Inf. Now the radius is
// below the contract's minimum and the curve stage says so.
TEST(CurveErrors, DenormalRadiusRegression) {
    wire::PipelineSettings s;
    s.spline.kind = wire::SplineKind::catmull_rom;
    s.spline.alpha = 1.8442538971087601e-165;
    s.spline.tension = 4.4001711491141884e-310;
    s.spline.closed = true;
    s.spline.radius_m = 1.04116476e-42f;
    s.spline.merge_epsilon_rel = 1.9285913728758249e-168;
    s.tessellate.tolerance_m = 1.9285913724732417e-168;
    s.tessellate.max_rings_per_segment = 7;
    s.tube.sides = 3;
    s.tube.caps = false;
    s.pop_free = false;
    const glm::dvec3 far{-1.9100168016818808e-23, 1.5231766383643548e-313, 8589935840.0470562};
    const glm::dvec3 tiny{8.0868664911295234e-320, 1.2132797677859884e-279, 1.2132797677859895e-279};
    const glm::dvec3 a{-0.058823529411764497, -0.058823529411764497, -0.058823529411764497};
    const glm::dvec3 b{-0.058823529411764497, -0.058823529411764497, -3.4705882352941178};
    const glm::dvec3 c{-6.9656775329448006, -8.0465278620169966e-213, -7.1018096169245837};
    wire::WireNodes nodes;
    nodes.positions = {{1.9285913724732417e-168, -7.6464255144538837, -4.2315673801155569},
                       {1.0000000000000001e-09, -7.6464255144538837, -4.2315673801155569},
                       {-1.0744871516639058, 1.9285913724732417e-168, -5.6862747669114624},
                       {-3.9924434147613677, -2.8431372549019605, -2.8431372549019605},
                       {-2.8455882352941178, -3.47058773041514, 4.9999999999999822},
                       {1.9285913724732417e-168, 3.2637615056148837e-43, 1.0410273767909543e-42},
                       {1.0410273767909543e-42, 1.0410273767909543e-42, 1.0410273767909543e-42},
                       far, tiny, far, tiny, far, tiny, far, tiny, far,
                       a, b, a, b, a, b, a, c, c, c,
                       {-4.6875, -5, 4.3850708007826356},
                       {-4.9999994039550364, -5, -5}};
    EXPECT_EQ(pipeline_error(nodes, s), "settings.radius_m is 1.04116476e-42 (below the smallest supported radius, 1e-6 m)");
    // At the smallest supported radius, and a node radius and stretch at their minimum too, the same wire's mesh
    // is finite, uv included.
    s.spline.radius_m = 1e-6f;
    nodes.radius_m.assign(nodes.positions.size(), 0.0f);
    nodes.radius_m[7] = 1e-6f;
    nodes.stretch.assign(nodes.positions.size(), 1e-6f);
    wire::WirePipeline pipeline;
    const engine::Status st = pipeline.update(nodes, s);
    ASSERT_TRUE(st.ok()) << st.message;
    ASSERT_FALSE(pipeline.mesh().vertices.empty());
    float max_u = 0.0f;
    for (const wire::TubeVertex& v : pipeline.mesh().vertices) {
        ASSERT_TRUE(std::isfinite(v.uv.x) && std::isfinite(v.uv.y) && std::isfinite(v.position.x) &&
                    std::isfinite(v.position.y) && std::isfinite(v.position.z));
        max_u = std::max(max_u, v.uv.x);
    }
    EXPECT_GT(max_u, 1e20f);  // the case is extreme: u is huge, but finite
}

TEST(CurveErrors, NodeRadiusAndStretchBelowTheMinimum) {
    wire::WireNodes nodes;
    nodes.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    nodes.radius_m = {0.01f, 1e-7f, 0.01f};
    EXPECT_EQ(pipeline_error(nodes), "node 1: radius_m is 1.00000001e-07 (below the smallest supported radius, 1e-6 m)");
    nodes.radius_m.clear();
    nodes.stretch = {1.0f, 1.0f, 5e-7f};
    EXPECT_EQ(pipeline_error(nodes), "node 2: stretch is 4.99999999e-07 (must be finite and >= 1e-6)");
}

// ---- glTF (engine::assets::read_gltf / read_gltf_memory) ----

TEST(GltfErrors, MissingFile) {
    std::vector<engine::assets::MeshData> meshes;
    EXPECT_EQ(engine::assets::read_gltf("/nonexistent/piece.glb", meshes).message,
              "/nonexistent/piece.glb: cannot open: No such file or directory");
}

TEST(GltfErrors, NotGltfAtAll) {
    EXPECT_EQ(gltf_memory_error("hello"),
              "piece.gltf: not a readable glTF file: [json.exception.parse_error.101] parse error at line 1, column 1: "
              "syntax error while parsing value - invalid literal; last read: 'h'");
}

TEST(GltfErrors, IndexOutOfRangeNamesMeshPrimitiveAndIndex) {
    EXPECT_EQ(gltf_memory_error(quad_gltf(9)),
              "piece.gltf: mesh 0 'quad' primitive 0: index 5 = 9 is out of range (4 vertices)");
}

TEST(GltfErrors, ExternalBufferFromMemoryIsAnError) {
    const std::string message = gltf_memory_error(quad_gltf(3, "quad.bin"));
    EXPECT_EQ(message.rfind("piece.gltf: not a readable glTF file: ", 0), 0u) << message;
    EXPECT_NE(message.find("quad.bin"), std::string::npos) << message;
}

TEST(GltfErrors, FileAndMemoryGiveTheSameMessage) {
    const fs::path dir = temp_dir();
    const std::string path = (dir / "piece.gltf").string();
    std::ofstream(path) << quad_gltf(9);
    std::vector<engine::assets::MeshData> meshes;
    EXPECT_EQ(engine::assets::read_gltf(path, meshes).message,
              path + ": mesh 0 'quad' primitive 0: index 5 = 9 is out of range (4 vertices)");
    fs::remove_all(dir);
}

TEST(GltfMemory, ReadsWhatWriteGlbWrote) {
    const fs::path dir = temp_dir();
    const std::string path = (dir / "quad.glb").string();
    std::vector<engine::assets::MeshData> written{quad("a")};
    written[0].origin = glm::dvec3(0.0, 0.0, 2.0);
    ASSERT_TRUE(engine::assets::write_glb(path, written).ok());
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::vector<engine::assets::MeshData> from_memory, from_file;
    const engine::Status st =
        engine::assets::read_gltf_memory(std::as_bytes(std::span(bytes.data(), bytes.size())), "quad.glb", from_memory);
    ASSERT_TRUE(st.ok()) << st.message;
    ASSERT_TRUE(engine::assets::read_gltf(path, from_file).ok());
    ASSERT_EQ(from_memory.size(), 1u);
    EXPECT_EQ(from_memory[0].name, "a");
    EXPECT_EQ(from_memory[0].positions, from_file[0].positions);
    EXPECT_EQ(from_memory[0].normals, from_file[0].normals);
    EXPECT_EQ(from_memory[0].uvs, from_file[0].uvs);
    EXPECT_EQ(from_memory[0].indices, from_file[0].indices);
    EXPECT_FLOAT_EQ(from_memory[0].positions[2], 2.0f);  // the origin, as a node translation
    fs::remove_all(dir);
}

TEST(GltfMemory, JsonWithEmbeddedBuffer) {
    const std::string text = quad_gltf(3);
    std::vector<engine::assets::MeshData> meshes;
    const engine::Status st =
        engine::assets::read_gltf_memory(std::as_bytes(std::span(text.data(), text.size())), "quad.gltf", meshes);
    ASSERT_TRUE(st.ok()) << st.message;
    ASSERT_EQ(meshes.size(), 1u);
    EXPECT_EQ(meshes[0].triangle_count(), 2u);
    EXPECT_EQ(meshes[0].normals.size(), meshes[0].positions.size());  // computed from the faces
}

// ---- untrusted GLB containers: rejected before tinygltf parses them ----

namespace {

void put32(std::string& s, uint32_t v) {
    for (int i = 0; i < 4; ++i) s += static_cast<char>((v >> (8 * i)) & 0xffu);
}

/// A GLB: header + chunks (each given as type and bytes, lengths as given unless `lengths` overrides one).
std::string glb(const std::vector<std::pair<uint32_t, std::string>>& chunks, uint32_t version = 2,
                int64_t length = -1) {
    std::string body;
    for (const auto& [type, bytes] : chunks) {
        put32(body, static_cast<uint32_t>(bytes.size()));
        put32(body, type);
        body += bytes;
    }
    std::string out = "glTF";
    put32(out, version);
    put32(out, length < 0 ? static_cast<uint32_t>(12 + body.size()) : static_cast<uint32_t>(length));
    return out + body;
}

constexpr uint32_t kJson = 0x4E4F534A, kBin = 0x004E4942;

/// The quad of quad_gltf with its buffer in the BIN chunk (60 bytes, padded to 60) and `buffers` as given.
std::string quad_glb_json(const std::string& buffers, const std::string& extra = "") {
    std::string json = R"({"asset":{"version":"2.0"},"buffers":)" + buffers +
                       R"(,"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12}],)"
                       R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},)"
                       R"({"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}],)"
                       R"("meshes":[{"name":"quad","primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
                       R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0)" + extra + "}";
    while (json.size() % 4 != 0) json += ' ';
    return json;
}

std::string quad_bin() {
    const float positions[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    std::string raw(reinterpret_cast<const char*>(positions), sizeof positions);
    raw.append(reinterpret_cast<const char*>(indices), sizeof indices);
    return raw;  // 60 bytes, a multiple of 4
}

std::string glb_error(const std::string& bytes) {
    std::vector<engine::assets::MeshData> meshes;
    const engine::Status st =
        engine::assets::read_gltf_memory(std::as_bytes(std::span(bytes.data(), bytes.size())), "piece.glb", meshes);
    EXPECT_FALSE(st.ok());
    EXPECT_TRUE(meshes.empty());
    return st.message;
}

}  // namespace

// Found by `tools/fuzz run fuzz_gltf 60`: tinygltf 2.7.0 read 3,233 bytes from a BIN chunk that claims 3,240
// bytes of which the file holds 3,232 (heap-buffer-overflow in ParseBuffer). Also in the fuzz_gltf corpus.
TEST(GlbErrors, BinChunkLongerThanTheFileRegression) {
    const std::string path = std::string(RELIABILITY_DATA_DIR) + "/glb-bin-chunk-overflow.glb";
    std::vector<engine::assets::MeshData> meshes;
    EXPECT_EQ(engine::assets::read_gltf(path, meshes).message,
              path + ": not a valid GLB file: chunk 1 (BIN) at byte 932 claims 3240 bytes but only 3232 follow its "
                     "header (GLB length 4172)");
    EXPECT_TRUE(meshes.empty());
}

TEST(GlbErrors, ValidQuadLoads) {
    const std::string bytes = glb({{kJson, quad_glb_json(R"([{"byteLength":60}])")}, {kBin, quad_bin()}});
    std::vector<engine::assets::MeshData> meshes;
    const engine::Status st =
        engine::assets::read_gltf_memory(std::as_bytes(std::span(bytes.data(), bytes.size())), "piece.glb", meshes);
    ASSERT_TRUE(st.ok()) << st.message;
    ASSERT_EQ(meshes.size(), 1u);
    EXPECT_EQ(meshes[0].triangle_count(), 2u);
}

TEST(GlbErrors, HeaderFields) {
    const auto json = quad_glb_json(R"([{"byteLength":60}])");
    EXPECT_EQ(glb_error("glTF\x02"), "piece.glb: not a valid GLB file: shorter than the 12-byte GLB header (5 bytes)");
    EXPECT_EQ(glb_error(glb({{kJson, json}, {kBin, quad_bin()}}, 1)),
              "piece.glb: not a valid GLB file: GLB version 1 is not supported (only version 2)");
    const std::string whole = glb({{kJson, json}, {kBin, quad_bin()}});
    EXPECT_EQ(glb_error(whole.substr(0, whole.size() - 4)),
              "piece.glb: not a valid GLB file: the header's length " + std::to_string(whole.size()) +
                  " exceeds the " + std::to_string(whole.size() - 4) + " bytes given (truncated file?)");
    EXPECT_EQ(glb_error(glb({{kJson, json}}, 2, 12 + 8 + json.size() - 2)),
              "piece.glb: not a valid GLB file: the header's length " + std::to_string(12 + 8 + json.size() - 2) +
                  " is not a multiple of 4");
}

TEST(GlbErrors, ChunkLayout) {
    const auto json = quad_glb_json(R"([{"byteLength":60}])");
    const std::string json_at = std::to_string(12 + 8 + json.size());  // byte of the chunk after the JSON chunk
    EXPECT_EQ(glb_error(glb({{kBin, quad_bin()}, {kJson, json}})),
              "piece.glb: not a valid GLB file: the first chunk is not JSON: chunk 0 (BIN) at byte 12");
    EXPECT_EQ(glb_error(glb({{kJson, json}, {kBin, quad_bin()}, {kBin, quad_bin()}})),
              "piece.glb: not a valid GLB file: chunk 2 (BIN) at byte " + std::to_string(12 + 8 + json.size() + 68) +
                  " is a second BIN chunk");
    EXPECT_EQ(glb_error(glb({{kJson, json}, {kJson, json}})),
              "piece.glb: not a valid GLB file: chunk 1 (JSON) at byte " + json_at + " is a second JSON chunk");
    EXPECT_EQ(glb_error(glb({{kJson, json}, {0x12345678u, "abcd"}, {kBin, quad_bin()}})),
              "piece.glb: not a valid GLB file: chunk 1 (of unknown type 0x12345678) at byte " + json_at +
                  ": the second chunk must be BIN");
    EXPECT_EQ(glb_error(glb({{kJson, json}, {kBin, quad_bin() + "xy"}}, 2, 12 + 8 + json.size() + 8 + 64) + "zw"),
              "piece.glb: not a valid GLB file: chunk 1 (BIN) at byte " + json_at +
                  ": length 62 is not a multiple of 4 (4-byte alignment)");
    EXPECT_EQ(glb_error(glb({{kJson, json}, {kBin, ""}})),
              "piece.glb: not a valid GLB file: chunk 1 (BIN) at byte " + json_at + " is empty");
    // A chunk header cut by the length: 4 bytes after the JSON chunk.
    EXPECT_EQ(glb_error(glb({{kJson, json}}, 2, 12 + 8 + json.size() + 4) + "abcd"),
              "piece.glb: not a valid GLB file: chunk 1 at byte " + json_at +
                  ": its 8-byte header runs past the GLB length " + std::to_string(12 + 8 + json.size() + 4));
    // Unknown chunks after the BIN chunk are skipped (glTF 2.0).
    const std::string extra = glb({{kJson, json}, {kBin, quad_bin()}, {0x12345678u, "abcd"}});
    std::vector<engine::assets::MeshData> meshes;
    EXPECT_TRUE(engine::assets::read_gltf_memory(std::as_bytes(std::span(extra.data(), extra.size())), "x.glb", meshes)
                    .ok());
}

TEST(GlbErrors, BuffersMustFitTheBinChunk) {
    EXPECT_EQ(glb_error(glb({{kJson, quad_glb_json(R"([{"byteLength":64}])")}, {kBin, quad_bin()}})),
              "piece.glb: not a readable glTF file: buffer 0: byteLength 64 exceeds the BIN chunk (60 bytes)");
    EXPECT_EQ(glb_error(glb({{kJson, quad_glb_json(R"([{"byteLength":60}])")}})),
              "piece.glb: not a readable glTF file: buffer 0 has no uri and the GLB has no BIN chunk");
    // byteLength 0 made tinygltf 2.7.0 throw std::out_of_range (data.at(0) of an empty buffer).
    EXPECT_EQ(glb_error(glb({{kJson, quad_glb_json(R"([{"byteLength":60},{"byteLength":0}])")}, {kBin, quad_bin()}})),
              "piece.glb: not a readable glTF file: buffer 1: byteLength must be a positive integer");
}

TEST(GlbErrors, ImagesAreNotDecodedButTheirByteRangeIsChecked) {
    // A texture image in the BIN chunk (not a decodable PNG: images are never decoded, the geometry loads).
    const std::string good = R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":60}],)"
                       R"("bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":12},{"buffer":0,"byteOffset":VIEW_OFFSET,"byteLength":8}],)"
                       R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},)"
                       R"({"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}],)"
                       R"("images":[{"bufferView":2,"mimeType":"image/png"}],)"
                       R"("meshes":[{"name":"quad","primitives":[{"attributes":{"POSITION":0},"indices":1}]}],)"
                       R"("nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}],"scene":0})";
    auto with_offset = [&](int offset) {
        std::string text = good;
        text.replace(text.find("VIEW_OFFSET"), 11, std::to_string(offset));
        while (text.size() % 4 != 0) text += ' ';
        return glb({{kJson, text}, {kBin, quad_bin()}});
    };
    const std::string ok = with_offset(52);
    std::vector<engine::assets::MeshData> meshes;
    const engine::Status st =
        engine::assets::read_gltf_memory(std::as_bytes(std::span(ok.data(), ok.size())), "piece.glb", meshes);
    EXPECT_TRUE(st.ok()) << st.message;
    EXPECT_EQ(glb_error(with_offset(4000)),
              "piece.glb: not a readable glTF file: image 0: buffer view 2 is not a byte range of an existing buffer");
}

TEST(GltfErrors, HugeAccessorCountIsOutOfRangeNotAnOverflow) {
    // count * stride wraps around 2^64 to a small number: the range check must not.
    std::string text = quad_gltf(3);
    text.replace(text.find(R"("count":4)"), 9, R"("count":4611686018427387905)");
    EXPECT_EQ(gltf_memory_error(text), "piece.gltf: mesh 0 'quad' primitive 0: accessor 0 reads past its buffer");
}

// tinygltf 2.7.0 converts extras recursively: 100,000 nested arrays (a 200 kB file) overflowed the stack.
TEST(GltfErrors, DeeplyNestedJsonIsRefused) {
    const std::string deep = R"({"asset":{"version":"2.0"},"extras":)" + std::string(100000, '[') +
                             std::string(100000, ']') + "}";
    EXPECT_EQ(gltf_memory_error(deep), "piece.gltf: not a readable glTF file: JSON nested deeper than 128 levels");
    // Within the limit: read as before (no mesh in it).
    const std::string fine = R"({"asset":{"version":"2.0"},"extras":)" + std::string(120, '[') + std::string(120, ']') + "}";
    EXPECT_EQ(gltf_memory_error(fine), "piece.gltf: contains no triangle mesh");
}

TEST(GltfErrors, ExternalBufferOutsideTheFilesDirectoryIsRefused) {
    const fs::path dir = temp_dir();
    fs::create_directories(dir / "level");
    {
        std::ofstream secret(dir / "secret.bin", std::ios::binary);
        const std::string bytes(60, '\0');
        secret << bytes;
    }
    fs::copy_file(dir / "secret.bin", dir / "level" / "quad.bin", fs::copy_options::overwrite_existing);
    std::vector<engine::assets::MeshData> meshes;
    // Beside the file: read.
    std::ofstream(dir / "level" / "inside.gltf") << quad_gltf(3, "quad.bin");
    const engine::Status st = engine::assets::read_gltf((dir / "level" / "inside.gltf").string(), meshes);
    EXPECT_TRUE(st.ok()) << st.message;
    // '..' out of the directory: refused, naming the file and the reason.
    const std::string path = (dir / "level" / "outside.gltf").string();
    std::ofstream(path) << quad_gltf(3, "../secret.bin");
    const std::string message = engine::assets::read_gltf(path, meshes).message;
    EXPECT_EQ(message.rfind(path + ": not a readable glTF file: ", 0), 0u) << message;
    EXPECT_NE(message.find("is outside the directory of the glTF file"), std::string::npos) << message;
    EXPECT_TRUE(meshes.empty());
    fs::remove_all(dir);
}

// ---- control mesh and subdivision (engine::assets::make_control_mesh / subdivide) ----

TEST(SubdivideErrors, NonFinitePositionNamesMeshAndVertex) {
    engine::assets::MeshData m = quad("hook");
    m.positions[7] = std::numeric_limits<float>::quiet_NaN();
    engine::assets::ControlMesh control;
    EXPECT_EQ(engine::assets::make_control_mesh(m, control).message, "mesh 'hook': vertex 2 has a non-finite position");
}

TEST(SubdivideErrors, DegenerateFace) {
    engine::assets::MeshData m = quad("hook");
    m.indices = {0, 1, 1};
    engine::assets::ControlMesh control;
    EXPECT_EQ(engine::assets::make_control_mesh(m, control).message, "mesh 'hook': degenerate face 0 (vertex 1 repeated)");
}

TEST(SubdivideErrors, IndexOutOfRange) {
    engine::assets::MeshData m = quad("hook");
    m.indices[4] = 40;
    engine::assets::ControlMesh control;
    EXPECT_EQ(engine::assets::make_control_mesh(m, control).message, "mesh 'hook': index 40 out of range");
}

TEST(SubdivideErrors, LevelOutOfRange) {
    engine::assets::MeshData out;
    EXPECT_EQ(engine::assets::subdivide(quad("hook"), 7, out).message,
              "mesh 'hook': subdivision level 7 out of range [0, 6]");
}

// ---- SEGS.json (curved_space::parse_segments_json) ----

TEST(SegmentsErrors, NegativeLength) {
    EXPECT_EQ(segments_error(R"({"segments": [{"length": 1, "angle": 0}, {"length": -1, "angle": 0.5}]})"),
              "segs.json: segment 1: length must be positive, got -1");
}

TEST(SegmentsErrors, CurvatureBeyondTheRange) {
    EXPECT_EQ(segments_error(R"({"segments": [{"length": 1e-300, "angle": 1e10}]})"),
              "segs.json: segment 0: curvature angle/length must be at most 1e12 per metre, got angle 10000000000 over "
              "length 1e-300");
}

TEST(SegmentsErrors, TotalLengthBeyondTheRange) {
    EXPECT_EQ(segments_error(R"({"segments": [{"length": 6e11, "angle": 0}, {"length": 6e11, "angle": 0}]})"),
              "segs.json: segment 1: the chain's total length exceeds 1e12 m (1200000000000)");
}

TEST(SegmentsErrors, MissingKey) {
    EXPECT_EQ(segments_error(R"({"segments": [{"length": 2}]})"), "segs.json: segment 0: missing key \"angle\"");
}

TEST(SegmentsErrors, UnknownKey) {
    EXPECT_EQ(segments_error(R"({"segments": [{"length": 2, "angle": 0, "twist": 1}]})"),
              "segs.json: segment 0: unknown key \"twist\" (expected length, angle, direction)");
}

TEST(SegmentsErrors, WrongType) {
    EXPECT_EQ(segments_error(R"({"segments": [{"length": "2", "angle": 0}]})"),
              "segs.json: segment 0: length must be a number, got string");
}

TEST(SegmentsErrors, EmptyList) {
    EXPECT_EQ(segments_error(R"({"segments": []})"),
              "segs.json: \"segments\" is empty (at least one segment is needed)");
}

TEST(SegmentsErrors, MissingFile) {
    std::vector<curved_space::Segment> segments;
    EXPECT_EQ(curved_space::read_segments_json("/nonexistent/segs.json", segments).message,
              "/nonexistent/segs.json: cannot open the file");
}
