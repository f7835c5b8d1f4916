// Wires in shadow maps (WireRenderer Output::depth from a light's view, engine::gfx::ShadowMap) and in G-buffers,
// against analytic answers over random families:
// - a straight wire between a light (directional, or a spot lamp) and a ground plane: the shadow's centre and width
//   (the darkening's centroid and integral across it, in camera pixels, where the wire does not hide the ground from
//   the top-down camera) equal the cylinder's projection from the light within max(1 px, the map's texel on the
//   ground): a thin caster's edges land on texel centres where it runs along the map's grid, the limit of any depth
//   map. On the nodes path and cpu-mesh, over random heights (touching the ground: a cable lying on a wall, the
//   peter-panning case, up to 2 m), radii (0.15 to 12 camera pixels across), directions, light elevations (40 to 85
//   degrees) or lamp places, and map texels (0.3 to 2.5 camera pixels: sub-pixel wires whose shadow is wide in the
//   map, and wires wide in the camera that are under a texel in the map); a cable touching the ground loses at most
//   the lookup's depth bias (in texels) of shadow beside it (its far side casts: the peter-panning bound); the ground
//   away from the shadow stays lit (no acne);
// - a wire receiving its own shadow: its lit side is never shadowed (no stripes);
// - the G-buffer output's normals equal the colour output's shading normals; its albedo the lit path's albedo.
#include <gtest/gtest.h>

#include <epoxy/gl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "engine/gfx/lit_renderer.hpp"
#include "engine/gfx/mesh.hpp"
#include "engine/gfx/shadow.hpp"
#include "engine/platform/capture.hpp"
#include "engine/platform/context.hpp"
#include "engine/scene/camera.hpp"
#include "engine/scene/light_view.hpp"
#include "wire/draw.hpp"
#include "wire/lod.hpp"
#include "wire/rings.hpp"
#include "wire/spline.hpp"
#include "wire/tube.hpp"
#include "wire/render/wire_renderer.hpp"

namespace {

namespace platform = engine::platform;
namespace gfx = engine::gfx;
using wire::DrawItem;
using wire::DrawList;
using wire::UploadPath;
using wire::render::DrawSettings;
using wire::render::Output;
using wire::render::WireRenderer;

constexpr int kSize = 400;            // the camera's image, square
constexpr double kHalfView_m = 1.0;   // the top-down camera sees +-1 m
constexpr double kPixel_m = 2.0 * kHalfView_m / kSize;
constexpr float kAlbedo = 0.8f, kAmbient = 0.2f;

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

/// One case of the family: a straight wire through (0, height, 0) along the horizontal `along`, the light.
struct ShadowCase {
    std::string name;
    glm::dvec3 along{1, 0, 0};
    double height_m = 0.5, radius_m = 0.01;
    glm::dvec3 to_light{0, 1, 0};
    int map_px = 1024;
    double texel_px = 1.0;  ///< a shadow-map texel over a camera pixel
    bool spot = false;      ///< a spot light at spot_m (e, y in the wire's cross-section) instead of the directional
    glm::dvec2 spot_m{0.0};
};

ShadowCase shadow_case(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    ShadowCase c;
    const double heading = 2.0 * std::numbers::pi * unit(rng);
    c.along = {std::cos(heading), 0.0, std::sin(heading)};
    const double width_px = 0.15 * std::pow(80.0, unit(rng));  // 0.15 .. 12 px across
    c.radius_m = 0.5 * width_px * kPixel_m;
    const int h = static_cast<int>(4 * unit(rng));
    c.height_m = h == 0 ? c.radius_m : std::array<double, 3>{0.05, 0.4, 1.5}[h - 1] * (0.7 + 0.6 * unit(rng));
    const double elevation = (40.0 + 45.0 * unit(rng)) * std::numbers::pi / 180.0;
    const double azimuth = 2.0 * std::numbers::pi * unit(rng);
    c.to_light = {std::cos(elevation) * std::cos(azimuth), std::sin(elevation), std::cos(elevation) * std::sin(azimuth)};
    c.texel_px = 0.3 * std::pow(2.5 / 0.3, unit(rng));
    c.spot = seed % 3 == 0;
    c.spot_m = {2.0 * (unit(rng) - 0.5), c.height_m + 1.0 + 2.0 * unit(rng)};
    char name[200];
    std::snprintf(name, sizeof name, "seed %u: width %.2f px, height %.3f m, %s %.2f, texel %.2f px", seed, width_px,
                  c.height_m, c.spot ? "spot light at height" : "directional, elevation (deg)",
                  c.spot ? c.spot_m.y : elevation * 180.0 / std::numbers::pi, c.texel_px);
    c.name = name;
    return c;
}

class ShadowTest : public ::testing::Test {
protected:
    void SetUp() override {
        auto made = platform::create_headless_context(
            {.backend = platform::Backend::headless, .width = kSize, .height = kSize, .quiet = true});
        ASSERT_TRUE(made.ok()) << made.error().message;
        ctx_ = std::move(made).value();
        auto renderer = WireRenderer::create();
        ASSERT_TRUE(renderer.ok()) << renderer.error().message;
        renderer_ = std::move(renderer).value();
        auto lit = gfx::LitRenderer::create();
        ASSERT_TRUE(lit.ok()) << lit.error().message;
        lit_ = std::move(lit).value();
        auto plane = gfx::upload_mesh(gfx::make_plane_mesh(1.0f), "ground");
        ASSERT_TRUE(plane.ok());
        plane_ = std::move(plane).value();
    }

    /// The top-down orthographic camera over the ground around `centre`.
    static engine::scene::Camera top_down(const glm::dvec3& centre) {
        engine::scene::Camera cam;
        cam.position = centre + glm::dvec3(0.0, 5.0, 0.0);
        cam.target = centre;
        cam.up = {0.0, 0.0, -1.0};
        cam.aspect = 1.0f;
        cam.near_m = 0.5f;
        cam.far_m = 10.0f;
        cam.ortho_half_height_m = static_cast<float>(kHalfView_m);
        return cam;
    }

    std::unique_ptr<platform::Context> ctx_;
    WireRenderer renderer_;
    gfx::LitRenderer lit_;
    gfx::GpuMesh plane_;
};

/// The wire's draw list on `path`: the nodes themselves (nodes path) or, for cpu-mesh, the mesh the CPU reference
/// builds at the LOD `view` asks for (what the systems give the camera).
struct WireLists {
    wire::WireNodes nodes;
    wire::SplineSettings spline;
    wire::Curve curve;
    wire::TubeMesh mesh;
    DrawItem item;
};

void make_list(WireLists& w, UploadPath path, const wire::LodView& camera_view, uint64_t id) {
    w.item = {};
    w.item.wire_id = id;
    if (path == UploadPath::gpu_nodes) {
        w.item.nodes = &w.nodes;
        w.item.spline = w.spline;
        w.item.nodes_generation = 1;
        w.item.sides = 32;
        return;
    }
    ASSERT_TRUE(wire::build_curve(w.nodes, w.spline, w.curve).ok());
    wire::WireLod lod;
    wire::update_lod(w.curve, camera_view, {}, lod, static_cast<const wire::BoundingSphere*>(nullptr));
    ASSERT_TRUE(lod.visible);
    std::vector<wire::RingParam> params;
    wire::place_rings(w.curve, lod.counts, params);
    wire::RingSet rings;
    wire::build_rings(w.curve, params, {}, rings);
    w.mesh = {};
    if (lod.drawn_sides <= 2) {
        wire::build_strip(rings, w.mesh);
    } else {
        wire::build_tube(rings, {.sides = lod.drawn_sides, .caps = true}, w.mesh);
    }
    w.item.origin_m = w.mesh.origin_m;
    w.item.vertices = w.mesh.vertices;
    w.item.indices = w.mesh.indices;
    w.item.sides = lod.drawn_sides;
    w.item.caps = true;
}

// The analytic shadow of a cylinder (axis `along`, horizontal, at height h, radius r) on y = 0 under a directional
// light: across the wire (e = up x along), in the plane of e and y, the light is L2 = (L.e, L.y); the shadow is the
// points x e with |L2n.y x + L2n.x h| <= r: centre -L.e h / L.y, width 2 r |L2| / L.y.
TEST_F(ShadowTest, WireShadowOnTheGroundIsTheAnalyticProjectionOverRandomPlacements) {
    constexpr uint32_t kCases = 96;
    // [2 path + fine]: per path, the cases whose map texel on the ground is over a camera pixel (0) or not (1).
    std::vector<double> centre_err[4], width_err[4], acne[2];
    double worst[2] = {0.0, 0.0};
    std::string worst_name[2];
    for (uint32_t seed = 1; seed <= kCases; ++seed) {
        const ShadowCase c = shadow_case(seed);
        const glm::dvec3 e = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), c.along));
        const double le = glm::dot(c.to_light, e), ly = c.to_light.y;
        glm::dvec3 lit_dir = c.to_light;  // the ground's (directional) lighting
        double centre_x = -le * c.height_m / ly;
        double width = 2.0 * c.radius_m * std::sqrt(le * le + ly * ly) / ly;
        if (c.spot) {
            // From the point S = spot_m, the rays tangent to the disc (centre (0, h), radius r) meet y = 0 at the
            // shadow's edges (an infinite cylinder's shadow from a point is a strip along its axis).
            const glm::dvec2 from_s = glm::dvec2(0.0, c.height_m) - c.spot_m;
            const double phi = std::atan2(from_s.y, from_s.x), alpha = std::asin(c.radius_m / glm::length(from_s));
            const auto meet = [&](double a) { return c.spot_m.x - c.spot_m.y * std::cos(a) / std::sin(a); };
            const double x1 = meet(phi - alpha), x2 = meet(phi + alpha);
            centre_x = 0.5 * (x1 + x2);
            width = std::abs(x2 - x1);
            lit_dir = glm::normalize(c.spot_m.x * e + glm::dvec3(0.0, c.spot_m.y, 0.0) - centre_x * e);  // from the shadow
        }
        // What the camera sees of it: the interval less the wire's own footprint |u| < r (seen from above, the wire
        // hides what lies under it): its length and centroid.
        double seen_width = 0.0, seen_moment = 0.0;
        for (const auto& [lo, hi] : {std::pair{centre_x - 0.5 * width, std::min(centre_x + 0.5 * width, -c.radius_m)},
                                     std::pair{std::max(centre_x - 0.5 * width, c.radius_m), centre_x + 0.5 * width}}) {
            if (hi <= lo) continue;
            seen_width += hi - lo;
            seen_moment += 0.5 * (hi * hi - lo * lo);
        }
        const double seen_centre = seen_width > 0.0 ? seen_moment / seen_width : centre_x;
        // The shadow's middle is under the camera: the wire passes over (0, h, 0) shifted back along the light.
        const glm::dvec3 shadow_mid = centre_x * e;
        const glm::dvec3 wire_mid = shadow_mid - centre_x * e;  // the wire's foot: x = 0 across
        WireLists w;
        w.spline.kind = wire::SplineKind::catmull_rom;
        w.spline.radius_m = static_cast<float>(c.radius_m);
        for (int i = 0; i < 9; ++i) {
            w.nodes.positions.push_back(wire_mid + glm::dvec3(0, c.height_m, 0) + (i - 4) * 0.5 * kHalfView_m * c.along);
        }
        const engine::scene::Camera cam = top_down(shadow_mid);
        const wire::LodView cam_view = wire::LodView::orthographic(cam.position, cam.target, cam.up, kHalfView_m, kSize,
                                                                   kSize, cam.near_m, cam.far_m);
        // The map: the sphere around the wire's middle 2.2 m, its texel c.texel_px camera pixels.
        const double radius = 1.1 * kHalfView_m + c.height_m;
        const int map_px = std::clamp(static_cast<int>(std::lround(2.0 * radius / (c.texel_px * kPixel_m))), 64, 8192);
        auto map = gfx::ShadowMap::create(map_px);
        ASSERT_TRUE(map.ok()) << map.error().message;
        map->light = engine::scene::directional_light_view(c.to_light, wire_mid + glm::dvec3(0, 0.5 * c.height_m, 0), radius);
        double texel_px = 2.0 * radius / map_px / kPixel_m;
        if (c.spot) {  // a cone over +-1.2 m of ground around the shadow, its texel there c.texel_px camera pixels
            const glm::dvec3 lamp = c.spot_m.x * e + glm::dvec3(0.0, c.spot_m.y, 0.0);
            const double reach = glm::length(lamp - shadow_mid);
            const auto half_angle = static_cast<float>(std::atan(1.2 * kHalfView_m / reach));
            const int px = std::clamp(static_cast<int>(std::lround(2.0 * 1.2 * kHalfView_m / (c.texel_px * kPixel_m))), 64, 8192);
            map = gfx::ShadowMap::create(px);
            ASSERT_TRUE(map.ok()) << map.error().message;
            map->light = engine::scene::spot_light_view(lamp, shadow_mid - lamp, half_angle, static_cast<float>(2.0 * reach));
            texel_px = 2.0 * 1.2 * kHalfView_m / px / kPixel_m;
        }
        for (const UploadPath path : {UploadPath::gpu_nodes, UploadPath::cpu_mesh}) {
            const int p = path == UploadPath::gpu_nodes ? 0 : 1;
            make_list(w, path, cam_view, 100 + seed);
            const DrawList list{.path = path, .items = {w.item}};
            ctx_->begin_frame();
            gfx::clear({0.0f, 0.0f, 0.0f, 1.0f});
            map->begin();
            const auto cast = renderer_.draw(list, map->light, {.output = Output::shadow, .view = 1});
            map->end();
            ASSERT_TRUE(cast.status.ok()) << cast.status.message;
            // The ground only (the wire would hide its shadow from above), eye-relative.
            const glm::mat4 model = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(glm::dvec3(0.0) - cam.position)),
                                               glm::vec3(3.0f));
            lit_.begin(cam.clip_from_relative(), {.to_light = glm::vec3(lit_dir), .color = glm::vec3(1.0f), .ambient = kAmbient},
                       &*map, cam.position);
            lit_.draw(plane_, model, glm::vec3(kAlbedo));
            const platform::Image image = platform::read_pixels(*ctx_);
            ctx_->end_frame();
            // Darkening per pixel: 0 lit, 1 in full shadow (ambient only).
            // A map texel on the ground across the shadow, in camera pixels: a caster's edges land on texel centres
            // where it runs along the map's grid, so the bound is a pixel or that texel, whichever is larger.
            const double ground_texel_px =
                texel_px * glm::length(glm::dvec2(glm::dot(lit_dir, e), lit_dir.y)) / lit_dir.y;
            // A cable touching the ground casts from its far side (Output::shadow), which meets the ground along
            // the contact: beside it the caster is within the lookup's depth bias (0.5 + 1.5 tan(angle to the
            // light) texels, ShadowMap's defaults) of the ground, so up to that many texels of shadow next to the
            // cable are lost: the stated peter-panning bound, on top of the texel bound.
            const double tan_light = glm::length(glm::dvec2(lit_dir.x, lit_dir.z)) / lit_dir.y;
            const bool touching = c.height_m <= 1.5 * c.radius_m;
            const double bound_px =
                std::max(1.0, ground_texel_px) + (touching ? (0.5 + 1.5 * tan_light) * ground_texel_px : 0.0);
            const int fine = ground_texel_px <= 1.0 ? 1 : 0;
            const double lit_value = 255.0 * kAlbedo * (kAmbient + (1.0 - kAmbient) * lit_dir.y);
            const double dark_value = 255.0 * kAlbedo * kAmbient;
            // Four windows 40 px long along the shadow; in each, the darkening's integral and centroid across it.
            double sum_centre = 0.0, sum_width = 0.0, worst_here = 0.0, acne_here = 0.0;
            std::array<double, 4> mass{}, moment{}, v0{};
            for (int win = 0; win < 4; ++win) v0[static_cast<std::size_t>(win)] = (-0.7 + 0.35 * win) * kHalfView_m;
            const double window_m = 40 * kPixel_m;
            for (int y = 0; y < kSize; ++y) {
                for (int x = 0; x < kSize; ++x) {
                    // Pixel centre in world x, z (top-down, up = -z: image right is +x, row 0 the top, at -z).
                    const double wx = shadow_mid.x + ((x + 0.5) * kPixel_m - kHalfView_m);
                    const double wz = shadow_mid.z + ((y + 0.5) * kPixel_m - kHalfView_m);
                    const glm::dvec3 q{wx, 0.0, wz};
                    const double u = glm::dot(q, e), v = glm::dot(q - shadow_mid, c.along);
                    std::size_t win = 4;
                    for (std::size_t w = 0; w < 4; ++w) win = v >= v0[w] && v < v0[w] + window_m ? w : win;
                    if (win == 4) continue;
                    const double value = image.pixel(x, y)[0];
                    const double d = std::clamp((lit_value - value) / (lit_value - dark_value), -1.0, 2.0);
                    if (std::abs(u - centre_x) > 0.5 * width + (4.0 * texel_px + 3.0) * kPixel_m) {
                        acne_here = std::max(acne_here, d);
                        continue;
                    }
                    if (std::abs(u) < c.radius_m) continue;  // under the wire: hidden from the camera by it
                    mass[win] += d;
                    moment[win] += d * u;
                }
            }
            for (std::size_t win = 0; win < 4; ++win) {
                const double measured_width = mass[win] * kPixel_m * kPixel_m / window_m;
                const double measured_centre = mass[win] > 0.0 ? moment[win] / mass[win] : 0.0;
                const double ce = mass[win] > 0.0 ? std::abs(measured_centre - seen_centre) / kPixel_m : 0.0;
                const double we = std::abs(measured_width - seen_width) / kPixel_m;
                // A shadow under a pixel wide has a centroid known only as well as its mass: compared when > 0.5 px.
                if (seen_width > 0.5 * kPixel_m) sum_centre = std::max(sum_centre, ce);
                sum_width = std::max(sum_width, we);
                worst_here = std::max({worst_here, we, seen_width > 0.5 * kPixel_m ? ce : 0.0});
                EXPECT_LE(we, bound_px) << (p == 0 ? "nodes" : "cpu") << " " << c.name << ", window " << win << ": width "
                                        << measured_width / kPixel_m << " px, analytic " << seen_width / kPixel_m << " px";
                if (seen_width > 0.5 * kPixel_m) {
                    EXPECT_LE(ce, bound_px) << (p == 0 ? "nodes" : "cpu") << " " << c.name << ", window " << win
                                            << ": centre off by " << ce << " px";
                }
            }
            EXPECT_LE(acne_here, 0.06) << (p == 0 ? "nodes" : "cpu") << " " << c.name << ": the lit ground darkens";
            centre_err[2 * p + fine].push_back(sum_centre);
            width_err[2 * p + fine].push_back(sum_width);
            acne[p].push_back(acne_here);
            if (worst_here / bound_px > worst[p]) worst[p] = worst_here / bound_px, worst_name[p] = c.name;
            if (worst_here / bound_px > 0.8) (void)platform::write_png("shadow_case_" + std::to_string(seed) + (p ? "_cpu" : "_nodes") + ".png", image);
        }
    }
    for (int p = 0; p < 2; ++p) {
        for (int fine = 1; fine >= 0; --fine) {
            const int k = 2 * p + fine;
            std::printf("%s, map texel on the ground %s 1 px (%zu cases): shadow centre error px median %.3f p90 %.3f "
                        "max %.3f; width error px median %.3f p90 %.3f max %.3f\n",
                        p == 0 ? "nodes" : "cpu-mesh", fine ? "<=" : ">", centre_err[k].size(),
                        quantile(centre_err[k], 0.5), quantile(centre_err[k], 0.9), quantile(centre_err[k], 1.0),
                        quantile(width_err[k], 0.5), quantile(width_err[k], 0.9), quantile(width_err[k], 1.0));
        }
        std::printf("%s: lit ground darkening max %.3f; worst error over its bound %.2f: %s\n", p == 0 ? "nodes" : "cpu-mesh",
                    quantile(acne[p], 1.0), worst[p], worst_name[p].c_str());
    }
}

}  // namespace

namespace {

/// A hanging cable seen from a random side, `radius_px` across in the camera (about), for the tests below.
struct Hanging {
    WireLists w;
    engine::scene::Camera camera;
    glm::dvec3 to_light{0, 1, 0};
    glm::dvec3 centre{0.0};
};

Hanging hanging(uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    Hanging h;
    const double span = 0.5 + 4.0 * unit(rng), sag = span * 0.4 * unit(rng);
    const int n = 5 + static_cast<int>(20 * unit(rng));
    const double heading = 2.0 * std::numbers::pi * unit(rng);
    const glm::dvec3 along{std::cos(heading), 0.0, std::sin(heading)};
    for (int i = 0; i < n; ++i) {
        const double t = static_cast<double>(i) / (n - 1);
        h.w.nodes.positions.push_back((t - 0.5) * span * along + glm::dvec3(0.0, -4.0 * sag * t * (1.0 - t), 0.0));
    }
    h.w.spline.kind = wire::SplineKind::catmull_rom;
    h.centre = glm::dvec3(0.0, -sag * 0.5, 0.0);
    const double yaw = 2.0 * std::numbers::pi * unit(rng), pitch = (unit(rng) - 0.3) * 1.2;
    const glm::dvec3 dir{std::cos(pitch) * std::cos(yaw), std::sin(pitch), std::cos(pitch) * std::sin(yaw)};
    const double away = span * (0.6 + 1.0 * unit(rng));
    h.camera.position = h.centre + away * dir;
    h.camera.target = h.centre;
    h.camera.fov_y_rad = static_cast<float>(glm::radians(50.0));
    h.camera.aspect = 1.0f;
    h.camera.near_m = static_cast<float>(0.02 * away);
    h.camera.far_m = static_cast<float>(3.0 * away + span);
    const double focal = 0.5 * kSize / std::tan(0.5 * h.camera.fov_y_rad);
    h.w.spline.radius_m = static_cast<float>(0.5 * (3.0 + 30.0 * unit(rng)) * away / focal);
    const double elevation = (20.0 + 65.0 * unit(rng)) * std::numbers::pi / 180.0, azimuth = 2.0 * std::numbers::pi * unit(rng);
    h.to_light = {std::cos(elevation) * std::cos(azimuth), std::sin(elevation), std::cos(elevation) * std::sin(azimuth)};
    return h;
}

wire::LodView lod_view_of(const engine::scene::Camera& c) {
    return wire::LodView::perspective(c.position, c.target, c.up, c.fov_y_rad, kSize, kSize, c.near_m, c.far_m);
}

// A wire in its own shadow map: where its surface faces the light (n.l > 0.25) the lookup says lit, everywhere
// (no stripes of self-shadowing along a curved tube, whatever the sides, radius and light angle).
TEST_F(ShadowTest, AWireLitSideIsNeverInItsOwnShadow) {
    // The shading hook shows what the default shading would use: visibility (red) and n.l (green).
    auto made = WireRenderer::create(
        {.shading_glsl = "vec3 shade(vec3 albedo, vec3 n, vec3 to_eye) { return vec3(wire_shadow, max(dot(n, "
                         "u_to_light), 0.0), 0.0); }\n"});
    ASSERT_TRUE(made.ok()) << made.error().message;
    WireRenderer& r = *made;
    std::vector<double> striped[2];
    for (uint32_t seed = 1; seed <= 32; ++seed) {
        Hanging h = hanging(seed);
        auto map = gfx::ShadowMap::create(1024);
        ASSERT_TRUE(map.ok());
        double reach = 0.0;
        for (const glm::dvec3& p : h.w.nodes.positions) reach = std::max(reach, glm::length(p - h.centre));
        map->light = engine::scene::directional_light_view(h.to_light, h.centre, reach + 2.0 * h.w.spline.radius_m);
        for (const UploadPath path : {UploadPath::gpu_nodes, UploadPath::cpu_mesh}) {
            const int p = path == UploadPath::gpu_nodes ? 0 : 1;
            make_list(h.w, path, lod_view_of(h.camera), 500 + seed);
            const DrawList list{.path = path, .items = {h.w.item}};
            ctx_->begin_frame();
            gfx::clear({0.0f, 0.0f, 1.0f, 1.0f});
            map->begin();
            ASSERT_TRUE(r.draw(list, map->light, {.output = Output::shadow, .view = 1}).status.ok());
            map->end();
            DrawSettings settings;
            settings.light.to_light = glm::vec3(h.to_light);
            settings.shadow = &*map;
            ASSERT_TRUE(r.draw(list, h.camera, settings).status.ok());
            const platform::Image image = platform::read_pixels(*ctx_);
            ctx_->end_frame();
            std::size_t facing = 0, dark = 0;
            for (int y = 0; y < kSize; ++y) {
                for (int x = 0; x < kSize; ++x) {
                    const uint8_t* px = image.pixel(x, y);
                    if (px[2] > 128 || px[1] < 64) continue;  // background, or not facing the light enough
                    ++facing;
                    dark += px[0] < 230 ? 1 : 0;
                }
            }
            if (facing < 50) continue;
            const double share = static_cast<double>(dark) / static_cast<double>(facing);
            striped[p].push_back(share);
            EXPECT_LE(share, 0.002) << (p == 0 ? "nodes" : "cpu") << " seed " << seed << ": " << dark << " of " << facing
                                    << " pixels facing the light read as shadowed";
            if (share > 0.002) (void)platform::write_png("shadow_self_" + std::to_string(seed) + (p ? "_cpu.png" : "_nodes.png"), image);
        }
    }
    for (int p = 0; p < 2; ++p) {
        EXPECT_GE(striped[p].size(), 24u);
        std::printf("%s: share of lit-facing wire pixels read as shadowed over %zu wires: median %.4f p90 %.4f max %.4f\n",
                    p == 0 ? "nodes" : "cpu-mesh", striped[p].size(), quantile(striped[p], 0.5),
                    quantile(striped[p], 0.9), quantile(striped[p], 1.0));
    }
}

// Output::gbuffer writes the normal and albedo the colour output shades: the default layout's attachment 0 equals a
// colour draw whose shading returns n * 0.5 + 0.5, attachment 1 one returning the albedo, pixel for pixel.
TEST_F(ShadowTest, GbufferNormalsAndAlbedoAreTheLitOutputs) {
    auto normals = WireRenderer::create({.shading_glsl = "vec3 shade(vec3 a, vec3 n, vec3 e) { return n * 0.5 + 0.5; }\n"});
    auto albedos = WireRenderer::create({.shading_glsl = "vec3 shade(vec3 a, vec3 n, vec3 e) { return a; }\n"});
    ASSERT_TRUE(normals.ok() && albedos.ok());
    GLuint fbo = 0, tex[4] = {0, 0, 0, 0};
    glCreateFramebuffers(1, &fbo);
    glCreateTextures(GL_TEXTURE_2D, 4, tex);
    for (int i = 0; i < 3; ++i) {
        glTextureStorage2D(tex[i], 1, GL_RGBA8, kSize, kSize);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0 + i, tex[i], 0);
    }
    glTextureStorage2D(tex[3], 1, GL_DEPTH_COMPONENT32F, kSize, kSize);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, tex[3], 0);
    const GLenum buffers[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glNamedFramebufferDrawBuffers(fbo, 3, buffers);
    ASSERT_EQ(glCheckNamedFramebufferStatus(fbo, GL_DRAW_FRAMEBUFFER), static_cast<GLenum>(GL_FRAMEBUFFER_COMPLETE));
    std::size_t compared = 0;
    int worst[2] = {0, 0};
    for (uint32_t seed = 1; seed <= 12; ++seed) {
        Hanging h = hanging(seed + 100);
        for (const UploadPath path : {UploadPath::gpu_nodes, UploadPath::cpu_mesh}) {
            make_list(h.w, path, lod_view_of(h.camera), 900 + seed);
            const DrawList list{.path = path, .items = {h.w.item}};
            ctx_->begin_frame();
            GLint frame_fbo = 0;  // the context's own (headless: not 0)
            glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &frame_fbo);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo);
            const float zero[4] = {0, 0, 0, 0};
            for (int i = 0; i < 3; ++i) glClearNamedFramebufferfv(fbo, GL_COLOR, i, zero);
            const float one = 1.0f;
            glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &one);
            const auto g = normals->draw(list, h.camera, {.output = Output::gbuffer});
            ASSERT_TRUE(g.status.ok()) << g.status.message;
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, static_cast<GLuint>(frame_fbo));
            std::vector<uint8_t> attachment[2];
            for (int i = 0; i < 2; ++i) {
                attachment[i].resize(std::size_t{kSize} * kSize * 4);
                glGetTextureImage(tex[i], 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(attachment[i].size()),
                                  attachment[i].data());
            }
            for (int i = 0; i < 2; ++i) {
                gfx::clear({0.0f, 0.0f, 0.0f, 0.0f});
                ASSERT_TRUE((i == 0 ? *normals : *albedos).draw(list, h.camera).status.ok());
                const platform::Image lit = platform::read_pixels(*ctx_);
                for (int y = 0; y < kSize; ++y) {
                    for (int x = 0; x < kSize; ++x) {
                        const uint8_t* a = lit.pixel(x, y);
                        const uint8_t* b = &attachment[i][(std::size_t(kSize - 1 - y) * kSize + x) * 4];  // GL rows: bottom up
                        if (a[3] == 0 && b[3] == 0) continue;
                        ++compared;
                        for (int k = 0; k < 3; ++k) worst[i] = std::max(worst[i], std::abs(int(a[k]) - int(b[k])));
                    }
                }
            }
            ctx_->end_frame();
        }
    }
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(4, tex);
    std::printf("G-buffer against the lit output: %zu pixels; largest difference normal %d/255, albedo %d/255\n", compared,
                worst[0], worst[1]);
    EXPECT_GT(compared, 10000u);
    EXPECT_LE(worst[0], 1);
    EXPECT_LE(worst[1], 1);
}

// A depth pre-pass (Output::depth) writes the depth the colour output writes, value for value, on both paths: an
// engine's later passes (an equal-depth test, occlusion of its own geometry) see the wires where the lit pass puts
// them. Phone-wire lines write no depth in either.
TEST_F(ShadowTest, ADepthPrePassWritesTheColourOutputsDepth) {
    std::size_t compared = 0, covered = 0, lines = 0;
    for (uint32_t seed = 1; seed <= 16; ++seed) {
        Hanging h = hanging(seed + 200);
        if (seed % 2 == 0) h.w.spline.radius_m *= 0.05f;  // 0.15 - 1.6 px: strips and phone-wire lines
        for (const UploadPath path : {UploadPath::gpu_nodes, UploadPath::cpu_mesh}) {
            make_list(h.w, path, lod_view_of(h.camera), 1300 + seed);
            const DrawList list{.path = path, .items = {h.w.item}};
            lines += path == UploadPath::cpu_mesh && h.w.item.sides == 1 ? 1 : 0;
            const auto depth_of = [&](Output output) {
                ctx_->begin_frame();
                gfx::clear({0.1f, 0.1f, 0.12f, 1.0f});
                EXPECT_TRUE(renderer_.draw(list, h.camera, {.output = output}).status.ok());
                std::vector<float> depth(std::size_t{kSize} * kSize);
                glReadPixels(0, 0, kSize, kSize, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
                ctx_->end_frame();
                return depth;
            };
            (void)depth_of(Output::color);  // the nodes path's LOD state settles on this view first
            const std::vector<float> lit = depth_of(Output::color), pre = depth_of(Output::depth);
            std::size_t differ = 0;
            for (std::size_t i = 0; i < lit.size(); ++i) {
                differ += lit[i] != pre[i] ? 1 : 0;
                covered += lit[i] < 1.0f ? 1 : 0;
            }
            compared += lit.size();
            EXPECT_EQ(differ, 0u) << (path == UploadPath::cpu_mesh ? "cpu" : "nodes") << " seed " << seed << ": "
                                  << differ << " depth values differ";
        }
    }
    EXPECT_GE(lines, 1u) << "the family should include phone-wire lines";
    EXPECT_GT(covered, 10000u);
    std::printf("depth pre-pass against the colour output's depth: %zu pixels (%zu covered), equal\n", compared, covered);
}

}  // namespace
