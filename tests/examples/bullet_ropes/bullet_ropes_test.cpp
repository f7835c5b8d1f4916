#include "rope_scene.hpp"

#include <wire/systems/api.hpp>
#include <wire/systems/components.hpp>
#include <wire/systems/systems.hpp>

#include <engine/ecs/registry.hpp>
#include <engine/ecs/schedule.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>

#include <BulletSoftBody/btSoftBody.h>
#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <vector>

namespace {

constexpr int kWidth = 960;
constexpr int kHeight = 540;

struct Projected {
    int x = 0;
    int y = 0;
    bool on_screen = false;
};

Projected project(const glm::mat4& clip_from_world, const glm::dvec3& p) {
    const glm::vec4 clip = clip_from_world * glm::vec4(glm::vec3(p), 1.0f);
    if (clip.w <= 0.0f) return {};
    const float x = (clip.x / clip.w * 0.5f + 0.5f) * kWidth;
    const float y = (0.5f - clip.y / clip.w * 0.5f) * kHeight;
    Projected r{static_cast<int>(x), static_cast<int>(y), false};
    r.on_screen = r.x >= 3 && r.y >= 3 && r.x < kWidth - 3 && r.y < kHeight - 3;
    return r;
}

// Does the segment eye -> p pass through the box (shrunk by `shrink_m`, so nodes resting on it stay visible)?
bool hidden_by(const bullet_ropes::Box& box, const glm::dvec3& eye, const glm::dvec3& p, double shrink_m) {
    const glm::dvec3 lo = glm::dvec3(box.centre_m - box.half_m) + shrink_m;
    const glm::dvec3 hi = glm::dvec3(box.centre_m + box.half_m) - shrink_m;
    double t0 = 0.0;
    double t1 = 1.0;
    const glm::dvec3 d = p - eye;
    for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) {
            if (eye[a] < lo[a] || eye[a] > hi[a]) return false;
            continue;
        }
        double ta = (lo[a] - eye[a]) / d[a];
        double tb = (hi[a] - eye[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    return true;
}

// The pixel's colour direction matches the tint's (the weave texture and the lighting scale it, the
// background, floor and box are greys far from every rope colour).
bool matches(const std::uint8_t* px, const glm::vec3& tint) {
    const glm::vec3 c(px[0], px[1], px[2]);
    if (std::max({c.r, c.g, c.b}) < 30.0f) return false;
    return glm::dot(glm::normalize(c), glm::normalize(tint)) > 0.97f;
}

bool rope_pixel_near(const engine::platform::Image& image, const Projected& p, const glm::vec3& tint, int r) {
    for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
            if (matches(image.pixel(p.x + dx, p.y + dy), tint)) return true;
        }
    }
    return false;
}

class BulletRopes : public ::testing::Test {
protected:
    void SetUp() override {
        auto ctx =
            engine::platform::create_headless_context({.width = kWidth, .height = kHeight, .quiet = true});
        ASSERT_TRUE(ctx) << ctx.error().message;
        ctx_ = std::move(*ctx);
        wire::systems::install(schedule_, wires_);
        wires_.on_error = [](const wire::systems::ErrorReport& e) { ADD_FAILURE() << e.message; };
        scene_ = std::make_unique<bullet_ropes::RopeScene>(registry_);
        auto view = bullet_ropes::RopeView::create(*scene_);
        ASSERT_TRUE(view) << view.error().message;
        view_ = std::make_unique<bullet_ropes::RopeView>(std::move(*view));
        wires_.camera = bullet_ropes::default_camera(kWidth, kHeight);
        wires_.viewport_width_px = kWidth;
        wires_.viewport_height_px = kHeight;
    }

    // Steps Bullet + the wire systems `frames` times, then draws the last frame and reads it back.
    engine::platform::Image run(int frames) {
        for (int i = 0; i < frames; ++i) {
            scene_->step(1.0 / 60.0);
            schedule_.run(registry_, 1.0 / 60.0);
        }
        ctx_->begin_frame();
        view_->draw(*scene_, wires_.draw_list, wires_.camera);
        engine::platform::Image image = engine::platform::read_pixels(*ctx_);
        ctx_->end_frame();
        return image;
    }

    std::unique_ptr<engine::platform::Context> ctx_;
    engine::ecs::Registry registry_;
    engine::ecs::Schedule schedule_;
    wire::systems::WireContext wires_;
    std::unique_ptr<bullet_ropes::RopeScene> scene_;
    std::unique_ptr<bullet_ropes::RopeView> view_;
};

TEST_F(BulletRopes, RopesAreDrawnWhereBulletPutsThem) {
    std::vector<wire::WireNodes> start;
    for (const bullet_ropes::Rope& rope : scene_->ropes())
        start.push_back(bullet_ropes::wire_nodes(*rope.body));

    const engine::platform::Image image = run(90);  // 1.5 s: the hanging ropes have swung down
    if (const char* dir = std::getenv("BULLET_ROPES_TEST_PNG")) {
        (void)engine::platform::write_png(dir, image);
    }
    const glm::mat4 clip_from_world = wires_.camera.view_projection();
    const glm::dvec3 eye(wires_.camera.position);
    const bullet_ropes::Box& box = scene_->box();

    int checked_all = 0;
    int hits_all = 0;
    for (std::size_t r = 0; r < scene_->ropes().size(); ++r) {
        const bullet_ropes::Rope& rope = scene_->ropes()[r];
        const wire::WireNodes now = bullet_ropes::wire_nodes(*rope.body);
        // The wire entity holds exactly Bullet's nodes, ids stable.
        const auto& nodes = registry_.get<wire::systems::Nodes>(rope.wire);
        ASSERT_EQ(nodes.positions, now.positions) << rope.name;
        ASSERT_EQ(nodes.ids, start[r].ids) << rope.name;

        int checked = 0;
        int hits = 0;
        for (const glm::dvec3& p : now.positions) {
            const Projected q = project(clip_from_world, p);
            if (!q.on_screen || hidden_by(box, eye, p, 0.005)) continue;
            ++checked;
            hits += rope_pixel_near(image, q, rope.colour, 2) ? 1 : 0;
        }
        checked_all += checked;
        hits_all += hits;
        std::printf("%s: %d of %d visible nodes show its colour\n", rope.name.c_str(), hits, checked);
        EXPECT_GE(checked, static_cast<int>(now.size()) / 3)
            << rope.name << ": too few nodes visible to check";
        EXPECT_GE(hits, checked * 9 / 10) << rope.name << ": not drawn where Bullet put its nodes";

        // The picture follows the simulation: where the swinging ropes started (horizontal), their colour is
        // gone.
        if (rope.name == "red rope" || rope.name == "green rope") {
            int old_checked = 0;
            int old_hits = 0;
            for (std::size_t i = now.size() / 2; i < now.size(); ++i) {  // the free half moved most
                const Projected q = project(clip_from_world, start[r].positions[i]);
                if (!q.on_screen || glm::distance(start[r].positions[i], now.positions[i]) < 0.3) continue;
                ++old_checked;
                old_hits += rope_pixel_near(image, q, rope.colour, 2) ? 1 : 0;
            }
            std::printf("%s: %d of %d start positions still show its colour\n", rope.name.c_str(), old_hits,
                        old_checked);
            EXPECT_GE(old_checked, static_cast<int>(now.size()) / 4) << rope.name << " did not swing";
            EXPECT_LE(old_hits, old_checked / 5) << rope.name << ": drawn where it no longer is";
        }
    }
    EXPECT_GE(hits_all, checked_all * 95 / 100);
}

TEST_F(BulletRopes, RopesRestOnTheFloorAndTheBox) {
    // Gaps between the tube surface (node centre +- radius) and the floor / the box, worst over every frame
    // of 4 s (swinging into the box, falling onto it, lying still): negative = sunk in.
    const bullet_ropes::Box& box = scene_->box();
    double floor_gap = std::numeric_limits<double>::infinity();
    double box_gap = std::numeric_limits<double>::infinity();
    int on_floor = 0;
    int on_box = 0;
    for (int frame = 0; frame < 240; ++frame) {
        scene_->step(1.0 / 60.0);
        on_floor = 0;
        on_box = 0;
        for (const bullet_ropes::Rope& rope : scene_->ropes()) {
            for (const glm::dvec3& p : bullet_ropes::wire_nodes(*rope.body).positions) {
                floor_gap = std::min(floor_gap, p.y - rope.radius_m);
                if (p.y - rope.radius_m < 0.01) ++on_floor;
                const glm::dvec3 d = glm::abs(p - glm::dvec3(box.centre_m)) - glm::dvec3(box.half_m);
                const double distance =
                    glm::length(glm::max(d, 0.0)) + std::min(std::max({d.x, d.y, d.z}), 0.0);
                box_gap = std::min(box_gap, distance - rope.radius_m);
                if (d.x < 0.0 && d.z < 0.0 && std::abs(d.y - rope.radius_m) < 0.01) ++on_box;
            }
        }
    }
    std::printf(
        "worst gap to the floor %.4f m, to the box %.4f m; at 4 s %d nodes on the floor, %d on the box top\n",
        floor_gap, box_gap, on_floor, on_box);
    EXPECT_GE(floor_gap, -0.01) << "a rope sank more than 1 cm into the floor";
    EXPECT_GE(box_gap, -0.01) << "a rope sank more than 1 cm into the box";
    EXPECT_GE(on_floor, 5) << "no rope lies on the floor";
    EXPECT_GE(on_box, 3) << "nothing rests on the box";
}

}  // namespace

namespace {

// The ropes streamed (RopeScene::stream_to: Bullet's node records written straight into the renderer's mapped
// memory) draw the picture their wire entities draw on the nodes path, frame after frame (Bullet is deterministic).
TEST(BulletRopesStream, StreamedRopesDrawWhatTheirEntitiesDraw) {
    auto ctx = engine::platform::create_headless_context({.width = kWidth, .height = kHeight, .quiet = true});
    ASSERT_TRUE(ctx) << ctx.error().message;
    struct Run {
        engine::ecs::Registry registry;
        engine::ecs::Schedule schedule;
        wire::systems::WireContext wires;
        std::unique_ptr<bullet_ropes::RopeScene> scene;
        std::unique_ptr<bullet_ropes::RopeView> view;
    };
    Run runs[2];
    for (int r = 0; r < 2; ++r) {
        Run& run = runs[r];
        run.wires.path = wire::UploadPath::gpu_nodes;
        run.wires.on_error = [](const wire::systems::ErrorReport& e) { ADD_FAILURE() << e.message; };
        wire::systems::install(run.schedule, run.wires);
        run.scene = std::make_unique<bullet_ropes::RopeScene>(run.registry);
        auto view = bullet_ropes::RopeView::create(*run.scene);
        ASSERT_TRUE(view) << view.error().message;
        run.view = std::make_unique<bullet_ropes::RopeView>(std::move(*view));
        run.wires.camera = bullet_ropes::default_camera(kWidth, kHeight);
        run.wires.viewport_width_px = kWidth;
        run.wires.viewport_height_px = kHeight;
        if (r == 1) {
            ASSERT_TRUE(run.scene->stream_to(run.view->node_stream()).ok());
            EXPECT_EQ(run.view->node_stream().size(), run.scene->ropes().size());
        }
    }
    for (int frame = 0; frame < 90; ++frame) {
        engine::platform::Image images[2];
        for (int r = 0; r < 2; ++r) {
            Run& run = runs[r];
            run.scene->step(1.0 / 60.0);
            run.schedule.run(run.registry, 1.0 / 60.0);
            (*ctx)->begin_frame();
            run.view->draw(*run.scene, run.wires.draw_list, run.wires.camera);
            images[r] = engine::platform::read_pixels(**ctx);
            (*ctx)->end_frame();
        }
        if (frame % 30 != 29) continue;
        EXPECT_TRUE(runs[1].wires.draw_list.items.empty()) << "streamed ropes left wire entities";
        std::size_t differ = 0, rope = 0;
        for (std::size_t i = 0; i + 3 < images[0].rgba.size(); i += 4) {
            int d = 0;
            for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(images[0].rgba[i + c]) - int(images[1].rgba[i + c])));
            differ += d > 24;
        }
        for (const auto& n : runs[0].wires.draw_list.items) rope += n.nodes != nullptr ? n.nodes->size() : 0;
        EXPECT_GT(rope, 0u);
        EXPECT_LE(differ, images[0].rgba.size() / 4 / 500) << "frame " << frame << ": " << differ << " pixels differ";
    }
}

}  // namespace
