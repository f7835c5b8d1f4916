// wire::render::install: a frame is one Schedule::run (the wire systems, then "wire.render"), on either
// upload path, with nothing copied from the systems to the renderer by hand. Over a random family of wires,
// swaying for a few frames, drawn with a LOD far from the defaults: the nodes path's picture equals
// cpu-mesh's (the list carries the LOD the systems used), and the system draws exactly what a by-hand draw of
// the same list draws.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "engine/ecs/registry.hpp"
#include "engine/ecs/schedule.hpp"
#include "engine/gfx/lit_renderer.hpp"
#include "engine/platform/capture.hpp"
#include "engine/platform/context.hpp"
#include "wire/render/install.hpp"
#include "wire/systems/api.hpp"
#include "wire/systems/systems.hpp"

namespace {

namespace platform = engine::platform;
using wire::UploadPath;

constexpr int kWidth = 480, kHeight = 270;
constexpr uint32_t kFrames = 4;

struct FamilyWire {
    std::vector<glm::dvec3> rest;  // nodes at rest
    glm::dvec3 sway_axis{};        // direction the wire sways in
    float radius_m = 0.01f;
};

// A random realistic wire in front of the default camera (z = 5 looking at the origin): 3-40 nodes, spacing
// uniform, end-dense or jittered, spans 1.5-4.5 m sagging 0-35% of the span, any orientation, radius 4 mm - 8
// cm.
FamilyWire family_wire(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    FamilyWire w;
    const int n = 3 + static_cast<int>(u(rng) * 38.0);
    const double span = 1.5 + 3.0 * u(rng), sag = 0.35 * u(rng) * span;
    const double yaw = 2.0 * std::numbers::pi * u(rng), pitch = (u(rng) - 0.5) * 1.2;
    const glm::dvec3 along(std::cos(yaw) * std::cos(pitch), std::sin(pitch), std::sin(yaw) * std::cos(pitch));
    const glm::dvec3 centre((u(rng) - 0.5) * 4.0, (u(rng) - 0.5) * 2.4, (u(rng) - 0.5) * 3.0);
    const int spacing = static_cast<int>(u(rng) * 3.0);
    for (int i = 0; i < n; ++i) {
        double s = static_cast<double>(i) / (n - 1);
        if (spacing == 1) s = 0.5 - 0.5 * std::cos(std::numbers::pi * s);             // end-dense
        if (spacing == 2 && i > 0 && i < n - 1) s += (u(rng) - 0.5) * 0.6 / (n - 1);  // jittered
        w.rest.push_back(centre + (s - 0.5) * span * along - glm::dvec3(0.0, 4.0 * sag * s * (1.0 - s), 0.0));
    }
    w.sway_axis = glm::normalize(glm::cross(along, glm::dvec3(0.0, 1.0, 0.0)) + glm::dvec3(0.0, 0.0, 1e-3));
    w.radius_m = static_cast<float>(0.004 + 0.08 * u(rng));
    return w;
}

wire::WireNodes swayed(const FamilyWire& w, uint32_t frame) {
    wire::WireNodes nodes;
    const std::size_t n = w.rest.size();
    for (std::size_t i = 0; i < n; ++i) {
        const double s = static_cast<double>(i) / static_cast<double>(n - 1);
        nodes.positions.push_back(w.rest[i] +
                                  0.04 * std::sin(0.7 * frame + 3.0 * s) * s * (1.0 - s) * w.sway_axis);
    }
    return nodes;
}

// The LOD every run uses: far from LodSettings' defaults (0.5 px, 32 sides), so a renderer that evaluated its
// own defaults instead of the list's would draw other rings and sides than the CPU paths.
wire::LodSettings coarse_lod() {
    wire::LodSettings lod;
    lod.tolerance_px = 3.0;
    lod.max_sides = 6;
    return lod;
}

struct PathRun {
    platform::Image installed;    // the frame "wire.render" drew
    platform::Image by_hand;      // the same list drawn by hand afterwards
    platform::Image default_lod;  // the same list drawn with LodSettings' defaults in place of the systems'
    wire::render::DrawStats stats;
    std::size_t frames = 0;
};

PathRun run(platform::Context& ctx, UploadPath path, const std::vector<FamilyWire>& family) {
    PathRun out;
    auto renderer = wire::render::WireRenderer::create();
    EXPECT_TRUE(renderer.ok()) << renderer.error().message;
    if (!renderer.ok()) return out;
    engine::ecs::Registry registry;
    engine::ecs::Schedule schedule;
    wire::systems::WireContext context;
    context.viewport_width_px = kWidth;
    context.viewport_height_px = kHeight;
    context.path = path;
    context.lod = coarse_lod();
    wire::systems::install(schedule, context);
    const std::shared_ptr<wire::render::RenderStep> step =
        wire::render::install(schedule, *renderer, context);
    std::vector<engine::ecs::Entity> wires;
    for (const FamilyWire& w : family) {
        wires.push_back(wire::systems::spawn_wire(registry, swayed(w, 0), {.radius_m = w.radius_m}));
    }
    const glm::vec4 clear{0.1f, 0.1f, 0.12f, 1.0f};
    for (uint32_t f = 0; f < kFrames; ++f) {
        for (std::size_t i = 0; i < wires.size(); ++i)
            wire::systems::set_nodes(registry, wires[i], swayed(family[i], f));
        engine::gfx::clear(clear);
        schedule.run(registry, 1.0 / 60.0);
    }
    out.installed = platform::read_pixels(ctx);
    out.stats = step->stats;
    out.frames = step->frames;
    engine::gfx::clear(clear);
    renderer->draw(context.draw_list, context.camera, step->settings);
    out.by_hand = platform::read_pixels(ctx);
    wire::DrawList defaults = context.draw_list;
    defaults.lod = {};
    engine::gfx::clear(clear);
    renderer->draw(defaults, context.camera, {.view = 1});
    out.default_lod = platform::read_pixels(ctx);
    return out;
}

bool background(const uint8_t* p) {
    return p[0] < 40 && p[1] < 40 && p[2] < 45;
}

// Wire pixels (covered in either image) that differ by more than 24/255 in a channel, except on silhouettes
// (a pixel next to the background in either image: coverage anti-aliasing), as a fraction of the wire pixels.
double differing_fraction(const platform::Image& a, const platform::Image& b,
                          std::size_t* covered_out = nullptr) {
    std::size_t covered = 0, differ = 0;
    const auto at = [&](const platform::Image& im, int x, int y) {
        return &im.rgba[4 * (std::size_t(y) * im.width + x)];
    };
    for (int y = 1; y + 1 < a.height; ++y) {
        for (int x = 1; x + 1 < a.width; ++x) {
            if (background(at(a, x, y)) && background(at(b, x, y))) continue;
            ++covered;
            bool silhouette = false;
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    silhouette |= background(at(a, x + dx, y + dy)) || background(at(b, x + dx, y + dy));
                }
            }
            int d = 0;
            for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(int(at(a, x, y)[c]) - int(at(b, x, y)[c])));
            differ += (d > 24 && !silhouette) ? 1 : 0;
        }
    }
    if (covered_out != nullptr) *covered_out = covered;
    return covered == 0 ? 1.0 : static_cast<double>(differ) / static_cast<double>(covered);
}

TEST(WireRenderInstall, EitherPathDrawsTheSystemsPictureWithNothingCopiedByHand) {
    auto made = platform::create_headless_context(
        {.backend = platform::Backend::headless, .width = kWidth, .height = kHeight, .quiet = true});
    ASSERT_TRUE(made.ok()) << made.error().message;
    platform::Context& ctx = **made;
    std::vector<double> same_path, default_lod;
    for (uint32_t scene = 0; scene < 12; ++scene) {
        std::vector<FamilyWire> family;
        for (uint32_t i = 0; i < 8; ++i) family.push_back(family_wire(1000 * (scene + 1) + i));
        const PathRun cpu = run(ctx, UploadPath::cpu_mesh, family);
        const PathRun nodes = run(ctx, UploadPath::gpu_nodes, family);
        for (const PathRun* r : {&cpu, &nodes}) {
            EXPECT_TRUE(r->stats.status.ok()) << r->stats.status.message;
            EXPECT_EQ(r->frames, kFrames);
            EXPECT_EQ(r->installed.rgba, r->by_hand.rgba)
                << "scene " << scene << ": the system draws what a draw by hand does";
        }
        EXPECT_GT(cpu.stats.draw_items, 0u);
        std::size_t covered = 0;
        const double fraction = differing_fraction(cpu.installed, nodes.installed, &covered);
        same_path.push_back(fraction);
        default_lod.push_back(differing_fraction(cpu.installed, nodes.default_lod));
        EXPECT_GT(covered, 500u) << "scene " << scene << ": the wires should cover the view";
        EXPECT_LE(fraction, 0.01) << "scene " << scene
                                  << ": the nodes path's picture differs from cpu-mesh's";
        if (scene == 0) {
            (void)platform::write_png("wire_render_install_cpu.png", cpu.installed);
            (void)platform::write_png("wire_render_install_nodes.png", nodes.installed);
            (void)platform::write_png("wire_render_install_nodes_default_lod.png", nodes.default_lod);
        }
    }
    std::sort(same_path.begin(), same_path.end());
    std::sort(default_lod.begin(), default_lod.end());
    std::printf(
        "differing wire pixels, nodes vs cpu-mesh: median %.4f max %.4f; with the default LOD instead of the "
        "systems': median %.4f min %.4f\n",
        same_path[same_path.size() / 2], same_path.back(), default_lod[default_lod.size() / 2],
        default_lod.front());
    // The comparison can fail: the nodes path drawing the list with LodSettings' defaults (what a renderer
    // that did not read the list's LOD would do) differs from the CPU's picture in every scene.
    EXPECT_GT(default_lod.front(), 0.01);
}

}  // namespace
