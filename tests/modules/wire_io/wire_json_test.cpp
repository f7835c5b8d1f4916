// Wire JSON reader: the three file shapes, settings, and located error messages.
#include <wire/io/wire_json.hpp>

#include <gtest/gtest.h>

using wire::io::SceneSpec;

namespace {
SceneSpec parse_ok(const std::string& text) {
    SceneSpec s;
    const engine::Status st = wire::io::parse_wire_json(text, "in.json", s);
    EXPECT_TRUE(st.ok()) << st.message;
    return s;
}
std::string parse_error(const std::string& text) {
    SceneSpec s;
    const engine::Status st = wire::io::parse_wire_json(text, "in.json", s);
    EXPECT_FALSE(st.ok()) << "accepted: " << text;
    EXPECT_TRUE(s.frames.empty());
    return st.message;
}
}  // namespace

TEST(WireJson, SingleWireWithPlainNodes) {
    const SceneSpec s = parse_ok(R"({"radius": 0.05, "closed": false, "spline": {"type": "centripetal"},
                                    "nodes": [[0,0,0],[1,0,0],[2,1,0]]})");
    ASSERT_EQ(s.frames.size(), 1u);
    ASSERT_EQ(s.frames[0].wires.size(), 1u);
    const auto& w = s.frames[0].wires[0];
    ASSERT_EQ(w.positions.size(), 3u);
    EXPECT_EQ(w.positions[2], glm::dvec3(2, 1, 0));
    EXPECT_EQ(w.ids, (std::vector<uint32_t>{0, 1, 2}));
    EXPECT_EQ(*w.radius_m, 0.05);
    EXPECT_EQ(*w.closed, false);
    EXPECT_EQ(*w.spline_type, "centripetal");
    EXPECT_FALSE(w.alpha.has_value());
    EXPECT_EQ(w.stretch, (std::vector<float>{1, 1, 1}));
}

TEST(WireJson, NodeObjectsCarryIdStretchRadiusPhysics) {
    const SceneSpec s = parse_ok(R"({"nodes": [{"p": [0,0,0], "id": 7, "stretch": 1.2, "radius": 0.04},
        {"p": [1,0,0], "id": 9, "physics": {"theta": 0.1, "Iz": 2, "L": 1, "dL": 0.1, "A": 0.5}}]})");
    const auto& w = s.frames[0].wires[0];
    EXPECT_EQ(w.ids, (std::vector<uint32_t>{7, 9}));
    EXPECT_FLOAT_EQ(w.stretch[0], 1.2f);
    EXPECT_FLOAT_EQ(w.radius[0], 0.04f);
    EXPECT_FLOAT_EQ(w.radius[1], -1.0f);
    ASSERT_EQ(w.physics.size(), 2u);
    EXPECT_DOUBLE_EQ(w.physics[1].Iz, 2.0);
    EXPECT_FALSE(w.radius_m.has_value());
}

TEST(WireJson, WireListAndFrames) {
    EXPECT_EQ(parse_ok(R"({"wires": [{"nodes": [[0,0,0],[1,0,0]]}, {"nodes": [[0,1,0],[1,1,0]]}]})")
                  .frames[0].wires.size(), 2u);
    const SceneSpec f = parse_ok(R"({"frames": [{"wires": [{"nodes": [[0,0,0],[1,0,0]]}]},
                                              {"wires": [{"nodes": [[0,0,0],[2,0,0]]}]}]})");
    ASSERT_EQ(f.frames.size(), 2u);
    EXPECT_EQ(f.frames[1].wires[0].positions[1].x, 2.0);
}

TEST(WireJson, ErrorsNameWhereAndWhat) {
    EXPECT_NE(parse_error("{\"nodes\": [[0,0,0], [1,0").find("in.json: malformed JSON"), std::string::npos);
    EXPECT_EQ(parse_error(R"({"wires": [{"nodes": [[0,0,0]]}, {"nodes": [[0,0,0],[1,0]]}]})"),
              "in.json: wire 1, node 1: position has 2 coordinates, expected 3");
    EXPECT_EQ(parse_error(R"({"nodes": [[0,0,0],[1,"a",0]]})"),
              "in.json: node 1: coordinate y must be a number, got string");
    EXPECT_NE(parse_error(R"({"nodes": [[0,0,0],[1,1e999,0]]})").find("in.json: malformed JSON: "
                                                                       "[json.exception.out_of_range.406] number overflow"),
              std::string::npos);
    EXPECT_EQ(parse_error(R"({"radius": -1, "nodes": [[0,0,0],[1,0,0]]})"),
              "in.json: radius must be positive, got -1");
    EXPECT_EQ(parse_error(R"({"nodes": [{"p": [0,0,0], "radius": -0.5}, [1,0,0]]})"),
              "in.json: node 0: radius must be positive, got -0.5");
    EXPECT_EQ(parse_error(R"({"frames": [{"wires": [{"nodes": [[0,0,0],[1,0,0]]}]}, {"wires": [{"nodes": [{"p": [0,0,0], "id": 1}, {"p": [0,0,1], "id": 1}]}]}]})"),
              "in.json: frame 1, wire 0, node 1: id 1 is used twice");
    EXPECT_EQ(parse_error(R"({"nodes": [[0,0,0],[1,0,0]], "colour": 3})"), "in.json: unknown key 'colour' in wire");
    EXPECT_EQ(parse_error(R"({"spline": {"type": 3}, "nodes": []})"), "in.json: spline type must be a string");
    EXPECT_EQ(parse_error("[1,2]"),
              "in.json: the top level must be an object (a wire, {\"wires\": [...]} or {\"frames\": [...]}), got array");
    EXPECT_EQ(parse_error(R"({"wires": []})"), "in.json: contains no wire");
}

TEST(WireJson, MissingFileIsNamed) {
    SceneSpec s;
    const engine::Status st = wire::io::load_wire_json("/no/such/cable.json", s);
    EXPECT_FALSE(st.ok());
    EXPECT_NE(st.message.find("/no/such/cable.json: cannot open"), std::string::npos) << st.message;
}

TEST(WireJson, FrameCameraIsReadAndChecked) {
    const SceneSpec f = parse_ok(R"({"frames": [
        {"wires": [{"nodes": [[0,0,0],[1,0,0]]}], "camera": {"eye": [0,1,5], "target": [0,0,0]}},
        {"wires": [{"nodes": [[0,0,0],[1,0,0]]}]},
        {"wires": [{"nodes": [[0,0,0],[1,0,0]]}], "camera": {"eye": [0,9,0], "target": [0,0,0], "up": [0,0,-1],
                                                               "fov_deg": 45}}]})");
    ASSERT_EQ(f.frames.size(), 3u);
    ASSERT_TRUE(f.frames[0].camera.has_value());
    EXPECT_EQ(f.frames[0].camera->eye_m, glm::dvec3(0, 1, 5));
    EXPECT_FALSE(f.frames[0].camera->up.has_value());
    EXPECT_FALSE(f.frames[0].camera->fov_deg.has_value());
    EXPECT_FALSE(f.frames[1].camera.has_value());
    EXPECT_EQ(*f.frames[2].camera->up, glm::dvec3(0, 0, -1));
    EXPECT_EQ(*f.frames[2].camera->fov_deg, 45.0);

    const std::string wires = R"("wires": [{"nodes": [[0,0,0],[1,0,0]]}])";
    auto with_camera = [&](const std::string& camera) {
        return R"({"frames": [{)" + wires + R"(}, {)" + wires + R"(, "camera": )" + camera + "}]}";
    };
    EXPECT_EQ(parse_error(with_camera(R"({"eye": [0,0,5], "target": [0,0,0], "fov": 40})")),
              "in.json: frame 1: unknown key 'fov' in camera");
    EXPECT_EQ(parse_error(with_camera(R"({"eye": [0,0,5]})")), "in.json: frame 1: camera lacks \"target\"");
    EXPECT_EQ(parse_error(with_camera(R"({"eye": [1,2,3], "target": [1,2,3]})")),
              "in.json: frame 1: camera eye and target must differ");
    EXPECT_EQ(parse_error(with_camera(R"({"eye": [0,5,0], "target": [0,0,0], "up": [0,1,0]})")),
              "in.json: frame 1: camera up must be non-zero and not parallel to target - eye");
    EXPECT_EQ(parse_error(with_camera(R"({"eye": [0,0,5], "target": [0,0,0], "fov_deg": 180})")),
              "in.json: frame 1: camera fov_deg must be in (0, 180), got 180");
    EXPECT_EQ(parse_error(with_camera(R"({"eye": [0,"a",5], "target": [0,0,0]})")),
              "in.json: frame 1: camera eye y must be a number, got string");
    EXPECT_EQ(parse_error(with_camera(R"([0,0,5])")),
              "in.json: frame 1: \"camera\" must be an object {\"eye\", \"target\", \"up\", \"fov_deg\"}, got array");
    // Only frames carry a camera.
    EXPECT_EQ(parse_error(R"({)" + wires + R"(, "camera": {"eye": [0,0,5], "target": [0,0,0]}})"),
              "in.json: unknown key 'camera' in the top level");
}

TEST(WireJson, DefaultSplineIsAutomaticAndAnAlphaAloneMeansCatmullRom) {
    // Issue 17: the default spline is the best measured one (automatic); a file or override that gives only an
    // alpha still gets Catmull-Rom with that alpha, as before.
    wire::PipelineSettings p;
    SceneSpec s = parse_ok(R"({"nodes": [[0,0,0],[1,0,0],[2,1,0]]})");
    ASSERT_TRUE(wire::io::resolve_settings(s.frames[0].wires[0], {}, p).ok());
    EXPECT_EQ(p.spline.kind, wire::SplineKind::automatic);
    s = parse_ok(R"({"spline": {"alpha": 0.7}, "nodes": [[0,0,0],[1,0,0],[2,1,0]]})");
    ASSERT_TRUE(wire::io::resolve_settings(s.frames[0].wires[0], {}, p).ok());
    EXPECT_EQ(p.spline.kind, wire::SplineKind::catmull_rom);
    EXPECT_EQ(p.spline.alpha, 0.7);
    s = parse_ok(R"({"nodes": [[0,0,0],[1,0,0],[2,1,0]]})");
    wire::io::SettingsOverrides o;
    o.alpha = 0.25;
    ASSERT_TRUE(wire::io::resolve_settings(s.frames[0].wires[0], o, p).ok());
    EXPECT_EQ(p.spline.kind, wire::SplineKind::catmull_rom);
    EXPECT_EQ(p.spline.alpha, 0.25);
}
