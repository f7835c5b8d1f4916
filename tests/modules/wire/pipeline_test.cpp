// WirePipeline (modules/wire/src/pipeline.cpp): the stages driven for one wire. A first state is exactly the stage
// functions run by hand; a bad state names its node and leaves every output as it was; a change of spline settings
// starts a new history (no blend from an incomparable curve); inserted nodes blend in (the pop-free state carries
// over between states) while ring 0's frame moves with the wire.
#include "wire/motion.hpp"
#include "wire/pipeline.hpp"
#include "wire/spline.hpp"

#include <gtest/gtest.h>

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <cstring>
#include <vector>

namespace wire {
namespace {

WireNodes sagging_cable(int n, double sag) {
    WireNodes w;
    for (int i = 0; i < n; ++i) {
        const double x = static_cast<double>(i) / (n - 1);
        w.positions.push_back({4.0 * x, -sag * 4.0 * x * (1.0 - x), 0.3 * std::sin(3.0 * x)});
        w.ids.push_back(static_cast<uint32_t>(10 * i));
    }
    return w;
}

bool same_bytes(const std::vector<TubeVertex>& a, const std::vector<TubeVertex>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(TubeVertex)) == 0);
}

TEST(WirePipeline, FirstStateIsTheStagesRunByHand) {
    PipelineSettings settings;
    settings.spline.kind = SplineKind::automatic;
    settings.tessellate.rings_per_segment = 5;
    settings.tube.sides = 9;
    const WireNodes nodes = sagging_cable(12, 0.6);
    WirePipeline pipe;
    ASSERT_TRUE(pipe.update(nodes, settings).ok());

    Curve curve;
    ASSERT_TRUE(build_curve(nodes, settings.spline, curve).ok());
    std::vector<uint32_t> counts;
    std::vector<RingParam> params;
    segment_ring_counts(curve, settings.tessellate, counts);
    place_rings(curve, counts, params);
    RingSet rings;
    build_rings(curve, params, RingSettings{}, rings);
    TubeMesh mesh;
    build_tube(rings, settings.tube, mesh);

    ASSERT_EQ(pipe.rings().rings.size(), rings.rings.size());
    EXPECT_EQ(std::memcmp(pipe.rings().rings.data(), rings.rings.data(), rings.rings.size() * sizeof(Ring)), 0);
    EXPECT_TRUE(same_bytes(pipe.mesh().vertices, mesh.vertices));
    EXPECT_EQ(pipe.mesh().indices, mesh.indices);
    EXPECT_EQ(pipe.states(), 1u);
}

TEST(WirePipeline, BadStateNamesTheNodeAndKeepsTheOutputs) {
    PipelineSettings settings;
    WirePipeline pipe;
    ASSERT_TRUE(pipe.update(sagging_cable(8, 0.4), settings).ok());
    const std::vector<TubeVertex> before = pipe.mesh().vertices;
    const std::size_t rings_before = pipe.rings().rings.size();
    WireNodes bad = sagging_cable(8, 0.4);
    bad.positions[5].y = std::nan("");
    const Status st = pipe.update(bad, settings);
    ASSERT_FALSE(st.ok());
    EXPECT_EQ(st.index, 5);
    EXPECT_NE(st.message.find("node 5"), std::string::npos) << st.message;
    EXPECT_TRUE(same_bytes(pipe.mesh().vertices, before));
    EXPECT_EQ(pipe.rings().rings.size(), rings_before);
    EXPECT_EQ(pipe.states(), 1u);
}

TEST(WirePipeline, NewNodesBlendInAndSettingsChangesStartOver) {
    PipelineSettings settings;
    settings.tessellate.rings_per_segment = 4;
    WirePipeline pipe;
    const WireNodes coarse = sagging_cable(7, 0.8);
    ASSERT_TRUE(pipe.update(coarse, settings).ok());
    // A node inserted off the old curve (an id that was not there): the drawn curve still shows the old one.
    WireNodes finer = coarse;
    finer.positions.insert(finer.positions.begin() + 3, 0.5 * (coarse.positions[2] + coarse.positions[3]) +
                                                            glm::dvec3(0.0, -0.05, 0.0));
    finer.ids.insert(finer.ids.begin() + 3, 999u);
    ASSERT_TRUE(pipe.update(finer, settings).ok());
    EXPECT_TRUE(pipe.pop_free().blending());
    // Another spline: a new history, the new curve at once.
    settings.spline.kind = SplineKind::c2;
    ASSERT_TRUE(pipe.update(finer, settings).ok());
    EXPECT_FALSE(pipe.pop_free().blending());
    Curve exact;
    ASSERT_TRUE(build_curve(finer, settings.spline, exact).ok());
    ASSERT_EQ(pipe.curve().segments.size(), exact.segments.size());
    for (std::size_t i = 0; i < exact.segments.size(); ++i) EXPECT_EQ(pipe.curve().segments[i].b1, exact.segments[i].b1);
}

TEST(WirePipeline, FirstFrameMovesWithTheWire) {
    PipelineSettings settings;
    settings.tessellate.rings_per_segment = 3;
    WirePipeline pipe;
    WireNodes nodes = sagging_cable(10, 0.7);
    ASSERT_TRUE(pipe.update(nodes, settings).ok());
    const glm::dvec3 before = pipe.rings().frames.front().r;
    const glm::dquat q = glm::angleAxis(0.05, glm::normalize(glm::dvec3(0.3, 1.0, -0.2)));
    for (glm::dvec3& p : nodes.positions) p = q * p + glm::dvec3(2.0, 0.0, 1.0);
    ASSERT_TRUE(pipe.update(nodes, settings).ok());
    EXPECT_LT(glm::length(pipe.rings().frames.front().r - q * before), 1e-9);
}

}  // namespace
}  // namespace wire
