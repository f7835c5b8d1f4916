// The bulk node stream (wire/render/node_stream.hpp) against the draw list's nodes path: over a random family of
// wires (catenaries, taut zig-zags, helices, wrapped cables; every spline kind the GPU builds; 1e5 m from the
// origin) moving rigidly and waving for several frames, a streamed wire (written in double, in float offsets, one
// by one or many at once) is drawn with the rings the same wire gets as a DrawItem: same LOD counts, centres,
// frames (the first frame carried by the motion fitted on the GPU) and u. Bad nodes: one test per kind of error,
// the message the ECS path gives, the wire's last curve kept, the rest drawn, no GL object or slot leaked.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/gfx/lit_renderer.hpp"
#include "engine/platform/context.hpp"
#include "engine/scene/camera.hpp"
#include "wire/draw.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/render/node_stream.hpp"
#include "wire/render/wire_renderer.hpp"
#include "wire/spline.hpp"
#include "wire/testing/families.hpp"

namespace {

namespace platform = engine::platform;
using wire::DrawItem;
using wire::DrawList;
using wire::UploadPath;
using wire::render::DrawnRings;
using wire::render::NodeStream;
using wire::render::StreamStyle;
using wire::render::StreamWire;
using wire::render::WireRenderer;

constexpr int kWidth = 640;
constexpr int kHeight = 400;

DrawList nodes_list() {
    DrawList list;
    list.path = UploadPath::gpu_nodes;
    return list;
}

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}
double angle(const glm::dvec3& a, const glm::dvec3& b) { return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)); }

class NodeStreamTest : public ::testing::Test {
protected:
    void SetUp() override {
        auto made = platform::create_headless_context(
            {.backend = platform::Backend::headless, .width = kWidth, .height = kHeight, .quiet = true});
        ASSERT_TRUE(made.ok()) << made.error().message;
        ctx_ = std::move(made).value();
        for (WireRenderer* r : {&list_, &streamed_}) {
            auto renderer = WireRenderer::create();
            ASSERT_TRUE(renderer.ok()) << renderer.error().message;
            *r = std::move(renderer).value();
        }
        ASSERT_TRUE(streamed_.node_stream().usable().ok()) << streamed_.node_stream().usable().message;
    }
    wire::render::DrawStats draw(WireRenderer& r, const DrawList& list) {
        ctx_->begin_frame();
        engine::gfx::clear({0.1f, 0.1f, 0.1f, 1.0f});
        const wire::render::DrawStats stats = r.draw(list, camera_, {});
        ctx_->end_frame();
        return stats;
    }
    std::unique_ptr<platform::Context> ctx_;
    WireRenderer list_, streamed_;
    engine::scene::Camera camera_;
};

/// The family's wires, each placed in a grid cell around `centre` (positions only: the stream carries no ids,
/// stretch or per-node values), with a spline kind and a way of being written.
struct StreamCase {
    std::string name;
    wire::WireNodes nodes;  // frame 0, world
    StreamStyle style;
    int how = 0;  // 0 double one by one, 1 float offsets one by one, 2 double many, 3 float many
    glm::dvec3 axis{0, 0, 1};
    double wave = 0.0;
};

std::vector<StreamCase> stream_family(const glm::dvec3& centre) {
    std::vector<wire::families::Case> cases;
    for (auto&& part : {wire::families::catenaries(11, 10), wire::families::zigzags(12, 8), wire::families::helices(13, 8),
                        wire::families::wrapped(14, 6)}) {
        cases.insert(cases.end(), part.begin(), part.end());
    }
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const wire::SplineKind kinds[] = {wire::SplineKind::automatic, wire::SplineKind::catmull_rom, wire::SplineKind::c2,
                                      wire::SplineKind::linear};
    std::vector<StreamCase> out;
    for (std::size_t k = 0; k < cases.size(); ++k) {
        StreamCase c;
        c.name = cases[k].family + " " + cases[k].label;
        glm::dvec3 lo = cases[k].nodes.positions[0], hi = lo;
        for (const glm::dvec3& p : cases[k].nodes.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
        const double size = glm::length(hi - lo);
        const glm::dvec3 cell = centre + glm::dvec3(80.0 * double(k % 6), 80.0 * double(k / 6), 0.0);
        for (const glm::dvec3& p : cases[k].nodes.positions) c.nodes.positions.push_back(cell + (p - 0.5 * (lo + hi)) * (40.0 / size));
        c.style.kind = kinds[k % 4];
        c.style.radius_m = 0.05f + 0.1f * static_cast<float>(unit(rng));
        c.style.max_sides = 16;
        c.how = static_cast<int>((k / 4) % 4);
        c.axis = glm::normalize(glm::dvec3(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5));
        c.wave = 0.02 + 0.3 * unit(rng);
        c.name += std::string(" (") + (c.how == 0 ? "double" : c.how == 1 ? "float" : c.how == 2 ? "double many" : "float many") + ")";
        out.push_back(std::move(c));
    }
    return out;
}

/// Frame f's nodes: turned about the wire's centre by 0.06 f rad about its axis, moved, and waved.
wire::WireNodes at_frame(const StreamCase& c, int f) {
    glm::dvec3 mid(0.0);
    for (const glm::dvec3& p : c.nodes.positions) mid += p;
    mid /= double(c.nodes.positions.size());
    const glm::dquat q = glm::angleAxis(0.06 * f, c.axis);
    wire::WireNodes n;
    for (std::size_t j = 0; j < c.nodes.positions.size(); ++j) {
        const double s = double(j) / double(c.nodes.positions.size() - 1);
        const glm::dvec3 wave(0.0, 0.0, c.wave * std::sin(3.0 * s + 0.4 * f) * std::sin(3.14159 * s));
        n.positions.push_back(mid + glm::dvec3(0.3 * f, 0.0, 0.1 * f) + q * (c.nodes.positions[j] - mid) + wave);
    }
    return n;
}

TEST_F(NodeStreamTest, DrawsTheListsRingsOverRandomFamiliesWhileMoving) {
    const glm::dvec3 centre(1.0e5, -2.0e4, 3.0e4);
    const std::vector<StreamCase> cases = stream_family(centre);
    camera_.target = centre + glm::dvec3(200.0, 120.0, 0.0);
    camera_.position = camera_.target + glm::dvec3(40.0, -90.0, 520.0);
    camera_.near_m = 20.0f, camera_.far_m = 2000.0f;
    NodeStream& stream = streamed_.node_stream();
    std::vector<StreamWire> wires;
    for (const StreamCase& c : cases) {
        auto w = stream.add(c.style);
        ASSERT_TRUE(w.ok()) << w.error().message;
        wires.push_back(*w);
    }
    std::vector<double> centre_err, frame_err, u_err;
    std::size_t compared = 0, same = 0;
    double worst = 0.0, worst_frame = 0.0;
    std::string worst_name, worst_frame_name;
    constexpr int kFrames = 8;
    for (int f = 0; f < kFrames; ++f) {
        std::vector<wire::WireNodes> nodes;
        for (const StreamCase& c : cases) nodes.push_back(at_frame(c, f));
        // The list: one item a wire, the motion fitted on the GPU by index (as the systems ask when ids match),
        // its nodes packed as the stream writes them (float records).
        DrawList list = nodes_list();
        std::vector<wire::PackedNodes> packed(cases.size());
        for (std::size_t k = 0; k < cases.size(); ++k) {
            DrawItem item;
            item.wire_id = 1000 + k;
            item.nodes = &nodes[k];
            item.spline = wire::SplineSettings{.kind = cases[k].style.kind, .radius_m = cases[k].style.radius_m};
            ASSERT_TRUE(wire::pack_nodes(nodes[k], item.spline, packed[k], wire::NodeFormat::floats).ok());
            item.packed_nodes = &packed[k];
            item.nodes_generation = static_cast<uint64_t>(f + 1);
            item.fit_motion = f > 0;
            item.sides = cases[k].style.max_sides;
            list.items.push_back(item);
        }
        const auto a = draw(list_, list);
        ASSERT_TRUE(a.status.ok()) << a.status.message;
        std::vector<DrawnRings> want;
        ASSERT_TRUE(list_.read_drawn_rings(want).ok());

        // The stream: every way of writing, all into one frame's region.
        std::size_t total = 0;
        for (const auto& n : nodes) total += n.size();
        ASSERT_TRUE(stream.begin(total).ok());
        std::vector<StreamWire> many_double, many_float;
        std::vector<double> xyz_double;
        std::vector<float> xyz_float;
        std::vector<glm::dvec3> origins;
        std::size_t many_count = 0;
        for (std::size_t k = 0; k < cases.size(); ++k) {
            const auto& p = nodes[k].positions;
            const glm::dvec3 origin = wire::float_point(p[p.size() / 2]) + glm::dvec3(0.25, 0.0, 0.0);
            std::vector<float> offsets;
            for (const glm::dvec3& q : p) {
                const glm::vec3 o(q - origin);
                offsets.insert(offsets.end(), {o.x, o.y, o.z});
            }
            switch (cases[k].how) {
                case 0: ASSERT_TRUE(stream.write(wires[k], &p[0].x, p.size())) << cases[k].name; break;
                case 1: ASSERT_TRUE(stream.write(wires[k], origin, offsets.data(), p.size())) << cases[k].name; break;
                default: {
                    // write_many takes wires of one node count: the first count seen for each kind of input.
                    if (many_count == 0) many_count = p.size();
                    if (p.size() != many_count) {
                        ASSERT_TRUE(stream.write(wires[k], &p[0].x, p.size())) << cases[k].name;
                        break;
                    }
                    if (cases[k].how == 2) {
                        many_double.push_back(wires[k]);
                        for (const glm::dvec3& q : p) xyz_double.insert(xyz_double.end(), {q.x, q.y, q.z});
                    } else {
                        many_float.push_back(wires[k]);
                        origins.push_back(origin);
                        xyz_float.insert(xyz_float.end(), offsets.begin(), offsets.end());
                    }
                }
            }
        }
        EXPECT_EQ(stream.write_many(many_double, xyz_double.data(), many_count), many_double.size());
        EXPECT_EQ(stream.write_many(many_float, origins, xyz_float.data(), many_count), many_float.size());
        EXPECT_TRUE(stream.errors().empty()) << stream.errors()[0].message;
        const auto b = draw(streamed_, nodes_list());
        ASSERT_TRUE(b.status.ok()) << b.status.message;
        EXPECT_EQ(b.wires_uploaded, cases.size());
        std::vector<DrawnRings> got;
        ASSERT_TRUE(streamed_.read_drawn_rings(got).ok());
        ASSERT_EQ(got.size(), want.size()) << "frame " << f;

        for (const DrawnRings& g : got) {
            const auto k = static_cast<std::size_t>(g.wire_id & 0xffffffffu);
            const auto it = std::find_if(want.begin(), want.end(), [&](const DrawnRings& d) { return d.wire_id == 1000 + k; });
            ASSERT_NE(it, want.end()) << cases[k].name << " drawn by the stream only";
            ++compared;
            bool counts = it->rings.params.size() == g.rings.params.size() && it->sides == g.sides;
            for (std::size_t i = 0; counts && i < g.rings.params.size(); ++i)
                counts = it->rings.params[i].segment == g.rings.params[i].segment && it->rings.params[i].t == g.rings.params[i].t;
            if (!counts) continue;
            ++same;
            double e = 0.0;
            for (std::size_t i = 0; i < g.rings.params.size(); ++i) {
                const glm::dvec3 a_c = it->rings.origin_m + it->rings.centre_m[i];
                const glm::dvec3 b_c = g.rings.origin_m + g.rings.centre_m[i];
                e = std::max(e, glm::length(a_c - b_c) / 40.0);
                const double fa = std::max(angle(it->rings.frames[i].r, g.rings.frames[i].r),
                                           angle(it->rings.frames[i].t, g.rings.frames[i].t));
                frame_err.push_back(fa);
                if (fa > worst_frame) worst_frame = fa, worst_frame_name = cases[k].name + " frame " + std::to_string(f);
            }
            for (std::size_t i = 0; i < g.rings.u.size(); ++i)
                u_err.push_back(std::abs(g.rings.u[i] - it->rings.u[i]) / std::max(1.0, it->rings.u.back()));
            centre_err.push_back(e);
            if (e > worst) worst = e, worst_name = cases[k].name + " frame " + std::to_string(f);
        }
    }
    std::printf("stream vs list over %zu wire frames (%zu with the same LOD counts): centre error / 40 m median %.2e "
                "p90 %.2e max %.2e (%s); frame angle rad median %.2e p90 %.2e max %.2e (%s); u error max %.2e\n",
                compared, same, quantile(centre_err, 0.5), quantile(centre_err, 0.9), worst, worst_name.c_str(),
                quantile(frame_err, 0.5), quantile(frame_err, 0.9), worst_frame, worst_frame_name.c_str(),
                quantile(u_err, 1.0));
    EXPECT_EQ(compared, cases.size() * kFrames);
    EXPECT_GE(same * 50, compared * 49) << "LOD counts should differ only at float thresholds";
    // Both are float offsets from float origins of the same double nodes (the stream's origin differs): a few
    // float roundings of the wire's extent. The automatic spline reacts to 1e-7 rad turns of float-rounded taut
    // runs (DrawnRingsTest): bounded loosely at the worst, tightly at p90.
    EXPECT_LE(quantile(centre_err, 0.9), 1e-6);
    EXPECT_LE(worst, 2e-2);
    EXPECT_LE(quantile(frame_err, 0.9), 1e-5);
    EXPECT_LE(quantile(u_err, 1.0), 1e-3);
}

/// One wire's nodes that the stream must refuse, and what it must say (check_curve_input's message on the same
/// nodes in double).
struct BadCase {
    std::string what;
    wire::WireNodes nodes;
    bool closed = false;
};

TEST_F(NodeStreamTest, BadNodesAreRefusedWithTheEcsMessagesAndTheRestDraws) {
    camera_.target = glm::dvec3(0.0, 0.0, 0.0);
    camera_.position = glm::dvec3(0.0, -3.0, 30.0);
    camera_.near_m = 0.5f, camera_.far_m = 200.0f;
    const auto line = [](double y, std::size_t n) {
        wire::WireNodes w;
        for (std::size_t j = 0; j < n; ++j) w.positions.push_back({-4.0 + 8.0 * double(j) / double(n - 1), y, 0.1 * double(j % 2)});
        return w;
    };
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<BadCase> bad;
    bad.push_back({"NaN position", line(1.0, 6)});
    bad.back().nodes.positions[3].y = nan;
    bad.push_back({"infinite position", line(1.0, 6)});
    bad.back().nodes.positions[0].z = std::numeric_limits<double>::infinity();
    bad.push_back({"beyond 1e12 m", line(1.0, 6)});
    bad.back().nodes.positions[5].x = 2e12;
    bad.push_back({"all coincident", line(1.0, 6)});
    for (auto& p : bad.back().nodes.positions) p = glm::dvec3(1.0, 2.0, 3.0);
    bad.push_back({"one node", line(1.0, 2)});
    bad.back().nodes.positions.resize(1);
    bad.push_back({"closed with two distinct", line(1.0, 4), true});
    bad.back().nodes.positions[2] = bad.back().nodes.positions[1], bad.back().nodes.positions[3] = bad.back().nodes.positions[0];
    bad.push_back({"negative radius", line(1.0, 6)});
    bad.push_back({"denormal radius", line(1.0, 6)});
    for (std::size_t b = 0; b < bad.size(); ++b) {
        SCOPED_TRACE(bad[b].what);
        auto made = WireRenderer::create();
        ASSERT_TRUE(made.ok());
        WireRenderer renderer = std::move(made).value();
        NodeStream& stream = renderer.node_stream();
        // Three good wires and the one that goes bad on frame 1 (valid on frame 0: it keeps that curve).
        std::vector<StreamWire> wires;
        for (int k = 0; k < 4; ++k) {
            StreamStyle style;
            style.closed = k == 3 && bad[b].closed;
            wires.push_back(stream.add(style).value());
        }
        std::vector<wire::WireNodes> good = {line(-2.0, 7), line(-1.0, 9), line(0.0, 5), line(1.0, 6)};
        std::vector<float> radius(6, 0.0f);
        const wire::SplineSettings spline{.closed = bad[b].closed};
        std::size_t buffers = 0;
        for (int f = 0; f < 3; ++f) {
            ASSERT_TRUE(stream.begin(64).ok());
            for (int k = 0; k < 3; ++k) ASSERT_TRUE(stream.write(wires[k], &good[k].positions[0].x, good[k].size()));
            wire::WireNodes w = f == 0 ? good[3] : bad[b].nodes;
            if (f == 0 && bad[b].closed) w.positions = {{-1, 1, 0}, {1, 1, 0}, {0, 2, 0}};
            const float* r = nullptr;
            if (f > 0 && bad[b].what == "negative radius") radius[2] = -0.5f, r = radius.data();
            if (f > 0 && bad[b].what == "denormal radius") radius[4] = 1e-9f, r = radius.data();
            if (r != nullptr) w.radius_m.assign(radius.begin(), radius.end());
            const bool wrote = stream.write(wires[3], w.positions.empty() ? nullptr : &w.positions[0].x, w.size(), 24, r);
            const auto stats = draw(renderer, nodes_list());
            EXPECT_TRUE(stats.status.ok()) << stats.status.message;
            std::vector<DrawnRings> drawn;
            ASSERT_TRUE(renderer.read_drawn_rings(drawn).ok());
            // Every wire drawn: the bad one with its frame-0 curve.
            EXPECT_EQ(drawn.size(), 4u) << "frame " << f;
            if (f == 0) {
                EXPECT_TRUE(wrote);
                EXPECT_TRUE(stream.errors().empty());
                buffers = renderer.info().node_path_buffers;
                continue;
            }
            EXPECT_FALSE(wrote);
            const wire::Status want = wire::check_curve_input(w, spline);
            ASSERT_FALSE(want.ok()) << "the case is not bad on the CPU";
            const std::vector<wire::render::StreamError> errors = stream.errors();
            ASSERT_EQ(errors.size(), 1u);
            EXPECT_EQ(errors[0].wire, wires[3]);
            EXPECT_EQ(errors[0].message, "stream wire 3: " + want.message);
            EXPECT_EQ(errors[0].node, want.index);
            EXPECT_EQ(stats.wires_uploaded, 3u);  // the bad wire's last curve stays on the GPU
            EXPECT_EQ(renderer.info().node_path_buffers, buffers) << "GL buffers grew";
        }
        // Removed and added again: the slot comes back, nothing grows.
        stream.remove(wires[3]);
        EXPECT_FALSE(stream.live(wires[3]));
        auto again = stream.add({});
        ASSERT_TRUE(again.ok());
        EXPECT_EQ(again->index, wires[3].index);
        EXPECT_EQ(stream.size(), 4u);
    }
}

TEST_F(NodeStreamTest, CoincidentNodesMergeAsBuildCurveMergesThem) {
    camera_.target = glm::dvec3(0.0);
    camera_.position = glm::dvec3(0.0, -3.0, 30.0);
    camera_.near_m = 0.5f, camera_.far_m = 200.0f;
    NodeStream& stream = streamed_.node_stream();
    const StreamWire w = stream.add({.kind = wire::SplineKind::catmull_rom}).value();
    wire::WireNodes nodes;
    for (int j = 0; j < 8; ++j) nodes.positions.push_back({-4.0 + double(j), 0.3 * std::sin(double(j)), 0.0});
    nodes.positions.insert(nodes.positions.begin() + 4, nodes.positions[3] + glm::dvec3(1e-12, 0.0, 0.0));
    ASSERT_TRUE(stream.begin(nodes.size()).ok());
    ASSERT_TRUE(stream.write(w, &nodes.positions[0].x, nodes.size()));
    ASSERT_TRUE(draw(streamed_, nodes_list()).status.ok());
    std::vector<DrawnRings> drawn;
    ASSERT_TRUE(streamed_.read_drawn_rings(drawn).ok());
    ASSERT_EQ(drawn.size(), 1u);
    wire::Curve curve;
    ASSERT_TRUE(wire::build_curve(nodes, {.kind = wire::SplineKind::catmull_rom}, curve).ok());
    EXPECT_EQ(drawn[0].rings.params.back().segment + 1, curve.segment_count()) << "merged as build_curve merges";
}

TEST_F(NodeStreamTest, OutOfRoomAndStaleWritesAreRefusedNamingWhy) {
    NodeStream& stream = streamed_.node_stream();
    const StreamWire a = stream.add({}).value(), b = stream.add({}).value();
    const double xyz[] = {0, 0, 0, 1, 0, 0, 2, 1, 0, 3, 0, 0};
    EXPECT_FALSE(stream.write(a, xyz, 4));  // no frame begun
    ASSERT_TRUE(stream.begin(6).ok());
    EXPECT_TRUE(stream.write(a, xyz, 4));
    EXPECT_FALSE(stream.write(b, xyz, 4));  // 8 > 6
    const auto errors = stream.errors();
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_NE(errors[0].message.find("no room for its 4 nodes (begin() reserved 6"), std::string::npos) << errors[0].message;
    EXPECT_FALSE(stream.write(StreamWire{99}, xyz, 4));
    // A frame drawn with a list on another path: the stream's wires are not drawn, and draw() says why.
    ASSERT_TRUE(stream.begin(4).ok());
    ASSERT_TRUE(stream.write(a, xyz, 4));
    DrawList cpu;
    cpu.path = UploadPath::cpu_mesh;
    const auto stats = draw(streamed_, cpu);
    EXPECT_NE(stats.status.message.find("the node stream's wires draw on the nodes path; this draw list is on 'cpu'"),
              std::string::npos)
        << stats.status.message;
    const auto bad_style = stream.add({.alpha = std::numeric_limits<double>::quiet_NaN()});
    ASSERT_FALSE(bad_style.ok());
    EXPECT_EQ(bad_style.error().message, "style: settings.alpha is NaN");
    // Longer than one GPU invocation walks (kNodesPathMaxNodes): refused, naming the count; at the limit, written.
    std::vector<double> line;
    for (std::size_t j = 0; j <= wire::render::kNodesPathMaxNodes; ++j) line.insert(line.end(), {0.01 * j, 0.0, 0.0});
    const std::size_t n = wire::render::kNodesPathMaxNodes;
    ASSERT_TRUE(stream.begin(2 * n + 1).ok());
    EXPECT_FALSE(stream.write(b, line.data(), n + 1));
    const auto long_errors = stream.errors();
    ASSERT_EQ(long_errors.size(), 1u);
    EXPECT_NE(long_errors[0].message.find("8193 nodes; the nodes path draws at most 8192 a wire"), std::string::npos)
        << long_errors[0].message;
    EXPECT_TRUE(stream.write(a, line.data(), n));
}

}  // namespace

namespace {

// A random family of inputs, good and bad (fixed seed): open and closed wires of 1-80 nodes, 1e-3-1e3 m, up to 1e9 m
// from the origin, written in double and as float offsets; defects at random nodes: NaN, infinities, coordinates
// past 1e12 m, runs of coincident nodes, pairs at 0.3-30x the merge tolerance, bad radii. Every write is accepted
// exactly when check_curve_input accepts the same nodes (in double), a refusal carries its message, and an
// accepted wire is drawn with the segments of build_curve's merge.
TEST_F(NodeStreamTest, AcceptsExactlyWhatTheCurveStageAcceptsOverARandomFamily) {
    camera_.target = glm::dvec3(0.0);
    camera_.position = glm::dvec3(0.0, 0.0, 10.0);
    camera_.near_m = 0.01f, camera_.far_m = 1e4f;
    std::mt19937 rng(20261205);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    NodeStream& stream = streamed_.node_stream();
    constexpr int kPerFrame = 40, kFrames = 10;
    std::size_t accepted = 0, refused = 0, merged = 0;
    for (int f = 0; f < kFrames; ++f) {
        struct Case {
            StreamWire wire;
            wire::WireNodes nodes;
            bool closed = false;
            std::string want;  // empty: accepted
            std::size_t segments = 0;
        };
        std::vector<Case> cases(kPerFrame);
        std::size_t total = 0;
        for (Case& c : cases) {
            c.closed = unit(rng) < 0.2;
            const auto n = static_cast<std::size_t>(1 + std::pow(unit(rng), 2.0) * 80.0);
            const double size = std::pow(10.0, -3.0 + 6.0 * unit(rng));
            // Always in front of the camera at the origin's scale: offset far, but wires are not looked at there.
            const glm::dvec3 at = unit(rng) < 0.3 ? glm::dvec3(std::pow(10.0, 9.0 * unit(rng)), 0.0, 0.0) : glm::dvec3(0.0);
            for (std::size_t j = 0; j < n; ++j) {
                const double s = double(j) / double(std::max<std::size_t>(n - 1, 1));
                c.nodes.positions.push_back(at + size * glm::dvec3(s - 0.5, 0.3 * std::sin(6.0 * s) + 0.1 * unit(rng), 0.2 * std::cos(5.0 * s)));
            }
            const int defect = static_cast<int>(unit(rng) * 8.0);
            const std::size_t k = static_cast<std::size_t>(unit(rng) * double(n)) % n;
            auto& p = c.nodes.positions;
            if (defect == 1) p[k][static_cast<int>(unit(rng) * 3) % 3] = std::numeric_limits<double>::quiet_NaN();
            if (defect == 2) p[k][static_cast<int>(unit(rng) * 3) % 3] = -std::numeric_limits<double>::infinity();
            if (defect == 3) p[k].y = 2e12 * (unit(rng) < 0.5 ? 1 : -1);
            if (defect == 4) {
                for (std::size_t j = k; j < std::min(n, k + 1 + static_cast<std::size_t>(unit(rng) * 5)); ++j) p[j] = p[k];
            }
            if (defect == 5 && k + 1 < n) {
                // A pair near the merge tolerance (1e-9 of the box diagonal, or 64 ulps far out).
                glm::dvec3 lo = p[0], hi = p[0];
                for (const auto& q : p) lo = glm::min(lo, q), hi = glm::max(hi, q);
                const double eps = std::max(1e-9 * glm::length(hi - lo), 64.0 * 2.220446049250313e-16 * glm::length(at));
                p[k + 1] = p[k] + glm::dvec3(eps * std::pow(10.0, -0.5 + 2.0 * unit(rng)), 0.0, 0.0);
            }
            if (defect == 6) c.closed = true;  // closed, possibly with too few distinct nodes
            c.nodes.radius_m.clear();
            if (defect == 7) {
                c.nodes.radius_m.assign(n, 0.0f);
                c.nodes.radius_m[k] = unit(rng) < 0.5 ? -0.1f : 1e-8f;
            }
            StreamStyle style;
            style.closed = c.closed;
            style.kind = wire::SplineKind::catmull_rom;
            auto w = stream.add(style);
            ASSERT_TRUE(w.ok());
            c.wire = *w;
            const wire::SplineSettings spline{.closed = c.closed};
            const wire::Status st = wire::check_curve_input(c.nodes, spline);
            if (!st.ok()) {
                c.want = "stream wire " + std::to_string(c.wire.index) + ": " + st.message;
            } else {
                std::vector<glm::dvec3> curve;
                const std::size_t m = wire::curve_nodes(c.nodes, spline, curve);
                c.segments = c.closed ? m : m - 1;
                merged += m != n;
            }
            total += n;
        }
        ASSERT_TRUE(stream.begin(total).ok());
        for (std::size_t i = 0; i < cases.size(); ++i) {
            Case& c = cases[i];
            const auto& p = c.nodes.positions;
            const float* r = c.nodes.radius_m.empty() ? nullptr : c.nodes.radius_m.data();
            bool ok = false;
            if (i % 2 == 0) {
                ok = stream.write(c.wire, &p[0].x, p.size(), 24, r);
            } else {
                const glm::dvec3 origin = wire::float_point(p[0]);
                std::vector<float> o;
                for (const auto& q : p) o.insert(o.end(), {float(q.x - origin.x), float(q.y - origin.y), float(q.z - origin.z)});
                // The offsets' own positions in double are what the curve stage must judge.
                for (std::size_t j = 0; j < p.size(); ++j)
                    c.nodes.positions[j] = origin + glm::dvec3(o[3 * j], o[3 * j + 1], o[3 * j + 2]);
                const wire::SplineSettings spline{.closed = c.closed};
                const wire::Status st = wire::check_curve_input(c.nodes, spline);
                c.want = st.ok() ? "" : "stream wire " + std::to_string(c.wire.index) + ": " + st.message;
                if (st.ok()) {
                    std::vector<glm::dvec3> curve;
                    const std::size_t m = wire::curve_nodes(c.nodes, spline, curve);
                    c.segments = c.closed ? m : m - 1;
                }
                ok = stream.write(c.wire, origin, o.data(), p.size(), 12, r);
            }
            EXPECT_EQ(ok, c.want.empty()) << "case " << i << " frame " << f << ": " << c.want;
            accepted += ok, refused += !ok;
        }
        const std::vector<wire::render::StreamError> errors = stream.errors();
        for (const Case& c : cases) {
            if (c.want.empty()) continue;
            const auto it = std::find_if(errors.begin(), errors.end(), [&](const auto& e) { return e.wire == c.wire; });
            ASSERT_NE(it, errors.end()) << c.want;
            EXPECT_EQ(it->message, c.want);
        }
        // At node resolution every segment has a ring: the last ring's segment counts them.
        DrawList list = nodes_list();
        list.lod.keep_node_resolution = true;
        ASSERT_TRUE(draw(streamed_, list).status.ok());
        std::vector<DrawnRings> drawn;
        ASSERT_TRUE(streamed_.read_drawn_rings(drawn).ok());
        for (const DrawnRings& d : drawn) {
            const auto it = std::find_if(cases.begin(), cases.end(),
                                         [&](const Case& c) { return NodeStream::wire_id(c.wire) == d.wire_id; });
            ASSERT_NE(it, cases.end());
            EXPECT_TRUE(it->want.empty()) << "a refused wire was drawn";
            EXPECT_EQ(d.rings.params.back().segment + 1, it->segments) << "merged otherwise than build_curve";
        }
        for (const Case& c : cases) stream.remove(c.wire);
    }
    std::printf("stream checks over %d random inputs: %zu accepted (%zu merged), %zu refused, each as the curve stage "
                "decides\n", kPerFrame * kFrames, accepted, merged, refused);
    EXPECT_GT(refused, 100u);
    EXPECT_GT(accepted, 100u);
    EXPECT_GT(merged, 10u);
}

}  // namespace

namespace {

// One renderer drawing entities' items and streamed wires in the same frame (the curve passes of both, and wires
// of both that did not change, listed) draws each wire as the renderer that draws only that kind draws it: over 6
// frames where some wires of each kind move, some stay and some are not written.
TEST_F(NodeStreamTest, ListAndStreamInOneDrawAsEachAlone) {
    const glm::dvec3 centre(-3.0e4, 1.0e3, 2.0e4);
    const std::vector<StreamCase> cases = stream_family(centre);
    camera_.target = centre + glm::dvec3(200.0, 120.0, 0.0);
    camera_.position = camera_.target + glm::dvec3(40.0, -90.0, 520.0);
    camera_.near_m = 20.0f, camera_.far_m = 2000.0f;
    auto made = WireRenderer::create();
    ASSERT_TRUE(made.ok());
    WireRenderer both = std::move(made).value();
    NodeStream& mixed = both.node_stream();
    NodeStream& alone = streamed_.node_stream();
    // Even cases: list items (in `both` and `list_`); odd: streamed (in `both` and `streamed_`).
    std::vector<StreamWire> in_mixed(cases.size()), in_alone(cases.size());
    for (std::size_t k = 1; k < cases.size(); k += 2) {
        in_mixed[k] = mixed.add(cases[k].style).value();
        in_alone[k] = alone.add(cases[k].style).value();
    }
    std::size_t compared = 0;
    double worst = 0.0;
    for (int f = 0; f < 6; ++f) {
        std::vector<wire::WireNodes> nodes;
        for (const StreamCase& c : cases) nodes.push_back(at_frame(c, f < 2 ? f : (f % 3 == 0 ? f : f - 1)));
        DrawList list = nodes_list();
        std::size_t stream_nodes = 0;
        for (std::size_t k = 0; k < cases.size(); k += 2) {
            DrawItem item;
            item.wire_id = 1000 + k;
            item.nodes = &nodes[k];
            item.spline = wire::SplineSettings{.kind = cases[k].style.kind, .radius_m = cases[k].style.radius_m};
            // Every third wire keeps its generation from frame 1 on: unchanged, listed.
            item.nodes_generation = (k / 2) % 3 == 0 ? static_cast<uint64_t>(std::min(f, 1) + 1) : static_cast<uint64_t>(f + 1);
            if ((k / 2) % 3 == 0) nodes[k] = at_frame(cases[k], std::min(f, 1));
            item.fit_motion = f > 0;
            item.sides = cases[k].style.max_sides;
            list.items.push_back(item);
        }
        for (std::size_t k = 1; k < cases.size(); k += 2) stream_nodes += nodes[k].size();
        ASSERT_TRUE(mixed.begin(stream_nodes).ok());
        ASSERT_TRUE(alone.begin(stream_nodes).ok());
        for (std::size_t k = 1; k < cases.size(); k += 2) {
            if (f > 1 && (k / 2) % 3 == 0) continue;  // not written: drawn from its state on the GPU
            ASSERT_TRUE(mixed.write(in_mixed[k], &nodes[k].positions[0].x, nodes[k].size()));
            ASSERT_TRUE(alone.write(in_alone[k], &nodes[k].positions[0].x, nodes[k].size()));
        }
        ASSERT_TRUE(draw(both, list).status.ok());
        std::vector<DrawnRings> got;
        ASSERT_TRUE(both.read_drawn_rings(got).ok());
        ASSERT_TRUE(draw(list_, list).status.ok());
        ASSERT_TRUE(draw(streamed_, nodes_list()).status.ok());
        std::vector<DrawnRings> want, want_stream;
        ASSERT_TRUE(list_.read_drawn_rings(want).ok());
        ASSERT_TRUE(streamed_.read_drawn_rings(want_stream).ok());
        want.insert(want.end(), want_stream.begin(), want_stream.end());
        ASSERT_EQ(got.size(), want.size()) << "frame " << f;
        for (const DrawnRings& g : got) {
            const auto it = std::find_if(want.begin(), want.end(), [&](const DrawnRings& d) { return d.wire_id == g.wire_id; });
            ASSERT_NE(it, want.end()) << g.wire_id;
            ASSERT_EQ(it->rings.params.size(), g.rings.params.size()) << g.wire_id << " frame " << f;
            ++compared;
            for (std::size_t i = 0; i < g.rings.params.size(); ++i) {
                worst = std::max(worst, glm::length((g.rings.origin_m + g.rings.centre_m[i]) -
                                                    (it->rings.origin_m + it->rings.centre_m[i])));
                worst = std::max(worst, angle(g.rings.frames[i].r, it->rings.frames[i].r));
            }
        }
    }
    EXPECT_EQ(compared, 6 * cases.size());
    EXPECT_EQ(worst, 0.0) << "the same inputs through the same programs";
}

}  // namespace
