// Headless system test: renders known lit shapes through the real pipeline (EGL surfaceless, Mesa llvmpipe,
// engine::gfx::LitRenderer), reads the pixels back and compares them with the analytic image computed on the
// CPU by casting a ray through every pixel center (the rasterizer covers a pixel when its center is inside):
//   - coverage: mismatches only within kBandPx of the analytic outline;
//   - background: every other uncovered pixel is exactly the clear color;
//   - shading: away from edges each pixel matches albedo * (ambient + (1 - ambient) * max(0, n.l)) of the
//     analytic surface normal, and the lit side is measurably brighter than the shadowed one.
// If no EGL context can be created the test fails: CI machines have Mesa.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "engine/gfx/lit_renderer.hpp"
#include "engine/gfx/mesh.hpp"
#include "engine/platform/capture.hpp"
#include "engine/platform/context.hpp"
#include "engine/scene/camera.hpp"

namespace gfx = engine::gfx;
namespace platform = engine::platform;
namespace scene = engine::scene;

namespace {

constexpr int kWidth = 320;
constexpr int kHeight = 240;
constexpr int kBandPx = 2;          // coverage may differ from the analytic outline only this close to it
constexpr int kShadeTolerance = 4;  // 8-bit levels
const glm::vec4 kBackground(0.05f, 0.08f, 0.15f, 1.0f);
const glm::vec3 kAlbedo(0.9f, 0.6f, 0.3f);

// What a pixel-center ray sees: which part of the surface (0 = nothing) and its world normal.
struct Hit {
    int part = 0;
    glm::dvec3 normal_world{0.0};
};

// Ray in model space; returns part > 0 and the model-space normal on a hit.
using LocalRayCast = std::function<Hit(const glm::dvec3& origin, const glm::dvec3& dir)>;

Hit cast_cylinder(const glm::dvec3& o, const glm::dvec3& d, double r, double h) {
    double best_t = 1e300;
    Hit hit;
    const double a = d.x * d.x + d.z * d.z;
    if (a > 1e-15) {
        const double b = 2.0 * (o.x * d.x + o.z * d.z);
        const double c = o.x * o.x + o.z * o.z - r * r;
        const double disc = b * b - 4.0 * a * c;
        if (disc >= 0.0) {
            for (double sign : {-1.0, 1.0}) {
                const double t = (-b + sign * std::sqrt(disc)) / (2.0 * a);
                const glm::dvec3 p = o + t * d;
                if (t > 0.0 && std::abs(p.y) <= h && t < best_t) {
                    best_t = t;
                    hit = {1, glm::dvec3(p.x, 0.0, p.z) / r};
                }
            }
        }
    }
    if (std::abs(d.y) > 1e-15) {
        for (double y : {h, -h}) {
            const double t = (y - o.y) / d.y;
            const glm::dvec3 p = o + t * d;
            if (t > 0.0 && p.x * p.x + p.z * p.z <= r * r && t < best_t) {
                best_t = t;
                hit = {y > 0.0 ? 2 : 3, glm::dvec3(0.0, y > 0.0 ? 1.0 : -1.0, 0.0)};
            }
        }
    }
    return hit;
}

Hit cast_sphere(const glm::dvec3& o, const glm::dvec3& d, double r) {
    const double a = glm::dot(d, d);
    const double b = 2.0 * glm::dot(o, d);
    const double c = glm::dot(o, o) - r * r;
    const double disc = b * b - 4.0 * a * c;
    if (disc < 0.0) return {};
    const double t = (-b - std::sqrt(disc)) / (2.0 * a);
    if (t <= 0.0) return {};
    return {1, (o + t * d) / r};
}

struct Scene {
    scene::Camera camera;
    gfx::DirectionalLight light;
    gfx::PrimitiveMesh mesh;
    glm::mat4 world_from_model{1.0f};
    LocalRayCast cast;
};

// The analytic image: per pixel, the part hit by the ray through the pixel center.
std::vector<Hit> analytic_hits(const Scene& s) {
    const glm::dmat4 world_from_clip = glm::inverse(glm::dmat4(s.camera.view_projection()));
    const glm::dmat4 model_from_world = glm::inverse(glm::dmat4(s.world_from_model));
    const glm::dmat3 normal_to_world =
        glm::transpose(glm::inverse(glm::dmat3(glm::dmat4(s.world_from_model))));
    std::vector<Hit> hits(static_cast<std::size_t>(kWidth) * kHeight);
    for (int py = 0; py < kHeight; ++py) {
        for (int px = 0; px < kWidth; ++px) {
            const double nx = (px + 0.5) / kWidth * 2.0 - 1.0;
            const double ny = 1.0 - (py + 0.5) / kHeight * 2.0;  // image rows run top to bottom
            glm::dvec4 near = world_from_clip * glm::dvec4(nx, ny, -1.0, 1.0);
            glm::dvec4 far = world_from_clip * glm::dvec4(nx, ny, 1.0, 1.0);
            near /= near.w;
            far /= far.w;
            const glm::dvec3 o = glm::dvec3(model_from_world * near);
            const glm::dvec3 d = glm::dvec3(model_from_world * far) - o;
            Hit hit = s.cast(o, d);
            if (hit.part != 0) hit.normal_world = glm::normalize(normal_to_world * hit.normal_world);
            hits[static_cast<std::size_t>(py) * kWidth + px] = hit;
        }
    }
    return hits;
}

// True when some pixel within `band` (Chebyshev distance) sees a different part than (x, y).
bool near_edge(const std::vector<Hit>& hits, int x, int y, int band, bool coverage_only) {
    const Hit& h = hits[static_cast<std::size_t>(y) * kWidth + x];
    for (int dy = -band; dy <= band; ++dy) {
        for (int dx = -band; dx <= band; ++dx) {
            const int xx = std::clamp(x + dx, 0, kWidth - 1);
            const int yy = std::clamp(y + dy, 0, kHeight - 1);
            const Hit& o = hits[static_cast<std::size_t>(yy) * kWidth + xx];
            if (coverage_only ? ((o.part != 0) != (h.part != 0)) : (o.part != h.part)) return true;
        }
    }
    return false;
}

int to_level(double v) {
    return static_cast<int>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
}

platform::Image render(const Scene& s, const std::string& name) {
    auto ctx = platform::create_headless_context({.width = kWidth, .height = kHeight});
    if (!ctx) {
        ADD_FAILURE() << "no headless GL context (Mesa EGL surfaceless is required): " << ctx.error().message;
        return {};
    }
    std::printf("GL_VERSION=%s GL_RENDERER=%s\n", (*ctx)->gl_version().c_str(),
                (*ctx)->gl_renderer().c_str());
    auto renderer = gfx::LitRenderer::create();
    if (!renderer) {
        ADD_FAILURE() << renderer.error().message;
        return {};
    }
    auto mesh = gfx::upload_mesh(s.mesh, name);
    if (!mesh) {
        ADD_FAILURE() << mesh.error().message;
        return {};
    }
    (*ctx)->begin_frame();
    gfx::clear(kBackground);
    renderer->begin(s.camera.view_projection(), s.light);
    renderer->draw(*mesh, s.world_from_model, kAlbedo);
    (*ctx)->end_frame();
    platform::Image image = platform::read_pixels(**ctx);
    const auto path = std::filesystem::temp_directory_path() / "system_render_test" / (name + ".png");
    if (platform::write_png(path, image)) std::printf("wrote %s\n", path.string().c_str());
    return image;
}

void check_against_analytic(const Scene& s, const std::string& name) {
    const platform::Image image = render(s, name);
    ASSERT_EQ(image.width, kWidth);
    ASSERT_EQ(image.height, kHeight);
    const std::vector<Hit> hits = analytic_hits(s);
    const glm::dvec3 to_light = glm::normalize(glm::dvec3(s.light.to_light));
    const int bg[3] = {to_level(kBackground.r), to_level(kBackground.g), to_level(kBackground.b)};

    int covered_expected = 0;
    int mismatches_in_band = 0;
    int mismatches_outside_band = 0;
    int background_wrong = 0;
    int shade_checked = 0;
    int shade_wrong = 0;
    double lit_sum = 0.0;
    double shadow_sum = 0.0;
    int lit_count = 0;
    int shadow_count = 0;
    for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
            const Hit& hit = hits[static_cast<std::size_t>(y) * kWidth + x];
            const std::uint8_t* p = image.pixel(x, y);
            const bool is_background =
                std::abs(p[0] - bg[0]) <= 1 && std::abs(p[1] - bg[1]) <= 1 && std::abs(p[2] - bg[2]) <= 1;
            const bool covered = !is_background;
            covered_expected += hit.part != 0 ? 1 : 0;
            if (covered != (hit.part != 0)) {
                if (near_edge(hits, x, y, kBandPx, true)) {
                    ++mismatches_in_band;
                } else {
                    ++mismatches_outside_band;
                    if (mismatches_outside_band <= 5)
                        ADD_FAILURE() << name << ": pixel (" << x << ", " << y << ") covered=" << covered
                                      << " but the analytic image says " << (hit.part != 0);
                }
                continue;
            }
            if (hit.part == 0) {
                if (!is_background) ++background_wrong;
                continue;
            }
            if (near_edge(hits, x, y, kBandPx, false)) continue;
            // Interior pixel: predict its shade from the analytic normal.
            const double n_dot_l = glm::dot(hit.normal_world, to_light);
            const double k = s.light.ambient + (1.0 - s.light.ambient) * std::max(0.0, n_dot_l);
            ++shade_checked;
            bool ok = true;
            for (int c = 0; c < 3; ++c)
                ok = ok && std::abs(p[c] - to_level(kAlbedo[c] * k)) <= kShadeTolerance;
            if (!ok && ++shade_wrong <= 5) {
                ADD_FAILURE() << name << ": pixel (" << x << ", " << y << ") = " << int(p[0]) << ","
                              << int(p[1]) << "," << int(p[2]) << " expected " << to_level(kAlbedo[0] * k)
                              << "," << to_level(kAlbedo[1] * k) << "," << to_level(kAlbedo[2] * k);
            }
            const double luminance = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            if (n_dot_l > 0.5) {
                lit_sum += luminance;
                ++lit_count;
            } else if (n_dot_l < 0.0) {
                shadow_sum += luminance;
                ++shadow_count;
            }
        }
    }
    std::printf(
        "%s: %d px expected covered, %d mismatches within %d px of the outline, %d interior px shaded\n",
        name.c_str(), covered_expected, mismatches_in_band, kBandPx, shade_checked);
    EXPECT_GT(covered_expected, 2000) << "scene too small to test anything";
    EXPECT_EQ(mismatches_outside_band, 0);
    // The outline is about 2 * pi * 50 px long; a systematic half-pixel offset would show up as hundreds.
    EXPECT_LT(mismatches_in_band, covered_expected / 50);
    EXPECT_EQ(background_wrong, 0);
    EXPECT_EQ(shade_wrong, 0);
    ASSERT_GT(lit_count, 200);
    ASSERT_GT(shadow_count, 200);
    const double lit_mean = lit_sum / lit_count;
    const double shadow_mean = shadow_sum / shadow_count;
    std::printf("%s: mean luminance lit %.1f, shadowed %.1f\n", name.c_str(), lit_mean, shadow_mean);
    EXPECT_GT(lit_mean, 2.5 * shadow_mean);
}

scene::Camera test_camera() {
    return {.position = {0.0f, 1.0f, 6.0f},
            .target = {0.2f, 0.0f, 0.0f},
            .fov_y_rad = glm::radians(40.0f),
            .aspect = static_cast<float>(kWidth) / static_cast<float>(kHeight),
            .near_m = 0.1f,
            .far_m = 100.0f};
}

TEST(SystemRender, LitCylinderMatchesAnalyticSilhouette) {
    constexpr double kRadius = 0.8;
    constexpr double kHalfHeight = 1.0;
    Scene s;
    s.camera = test_camera();
    s.light = {.to_light = {1.0f, 0.3f, 0.4f}, .ambient = 0.15f};
    // 256 sides: the inscribed polygon is within r * (1 - cos(pi/256)) = 6e-5 m of the circle, ~0.004 px
    // here.
    s.mesh = gfx::make_cylinder_mesh({.radius_m = static_cast<float>(kRadius),
                                      .half_height_m = static_cast<float>(kHalfHeight),
                                      .sides = 256});
    s.world_from_model = glm::translate(glm::mat4(1.0f), glm::vec3(0.3f, -0.1f, 0.0f)) *
                         glm::rotate(glm::mat4(1.0f), glm::radians(15.0f), glm::vec3(0, 0, 1)) *
                         glm::rotate(glm::mat4(1.0f), glm::radians(25.0f), glm::vec3(1, 0, 0));
    s.cast = [](const glm::dvec3& o, const glm::dvec3& d) {
        return cast_cylinder(o, d, kRadius, kHalfHeight);
    };
    check_against_analytic(s, "cylinder");
}

TEST(SystemRender, LitSphereMatchesAnalyticSilhouette) {
    constexpr double kRadius = 1.1;
    Scene s;
    s.camera = test_camera();
    s.light = {.to_light = {-1.0f, 0.5f, 0.3f}, .ambient = 0.1f};
    // A UV sphere is a polyhedron inside the sphere: 256 x 128 keeps it within 1.1 * (1 - cos(pi/128)) m
    // (about 0.1 px here) of the true surface.
    s.mesh = gfx::make_sphere_mesh(static_cast<float>(kRadius), 256, 128);
    s.world_from_model = glm::translate(glm::mat4(1.0f), glm::vec3(-0.4f, 0.2f, -0.5f));
    s.cast = [](const glm::dvec3& o, const glm::dvec3& d) { return cast_sphere(o, d, kRadius); };
    check_against_analytic(s, "sphere");
}

}  // namespace
