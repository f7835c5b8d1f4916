// Headless system test of the tunnel level (game/tunnel, target tunnel_level): runs frames in-process on Mesa
// llvmpipe at a fixed step and checks
//   - walls: points on the bent wall (chain.transform_point, between the ribs) project onto concrete-coloured
//     pixels, and an empty frame (pieces and wires off) is pure background there;
//   - cables: the rendered curve of the nearest cable across the tunnel and of a fixed wall cable, projected,
//     covers pixels that change when the wires are switched off;
//   - stats: every per-frame record is finite and counts are plausible;
//   - ropes: the hanging cables insert and remove nodes (new stable ids, placed on the current curve);
//   - determinism: two runs give byte-equal images;
//   - issue 14, on the default run (120 frames at 1280x720, 1/30 s): every frame's largest turn between rope
//     elements <= 20 deg, deepest rope penetration <= rope radius / 4, worst predicted piece error <= the
//     subdivision tolerance, and close-ups within 0.5 m of a rope and of a wall cable; the same rope bounds
//     over other bend seeds and scales; the wall cables clear the refined ribs (geometry read from the
//     asset).
// If no EGL context can be created the test fails: CI machines have Mesa.
#include "tunnel/level.hpp"
#include "tunnel/rope.hpp"
#include "tunnel/stats_json.hpp"

#include <engine/assets/gltf.hpp>
#include <engine/assets/subdivide.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <wire/curve.hpp>
#include <wire/spline.hpp>

#include <gtest/gtest.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace platform = engine::platform;

namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 360;
constexpr double kDt = 1.0 / 30.0;
constexpr double kPi = 3.14159265358979323846;

std::unique_ptr<platform::Context> make_context() {
    auto ctx = platform::create_headless_context({.width = kWidth, .height = kHeight, .quiet = true});
    if (!ctx) {
        ADD_FAILURE() << "no headless GL context: " << ctx.error().message;
        return nullptr;
    }
    return std::move(ctx).value();
}

std::unique_ptr<tunnel::Level> make_level() {
    auto level = tunnel::Level::create({.asset_dir = WIRE_ASSET_DIR "/tunnel"});
    if (!level) {
        ADD_FAILURE() << "Level::create: " << level.error().message;
        return nullptr;
    }
    level.value()->set_viewport(kWidth, kHeight);
    return std::move(level).value();
}

// Pixel of a world point, or nothing when it is behind the camera or outside the image (with a margin).
struct Pixel {
    int x = 0;
    int y = 0;
    double depth_m = 0.0;
    bool ok = false;
};

Pixel project(const engine::scene::Camera& camera, const glm::dvec3& p, int margin = 4) {
    const glm::vec4 clip = camera.view_projection() * glm::vec4(glm::vec3(p), 1.0f);
    Pixel px;
    if (clip.w <= camera.near_m) return px;
    const double nx = clip.x / clip.w;
    const double ny = clip.y / clip.w;
    px.x = static_cast<int>(std::floor((nx * 0.5 + 0.5) * kWidth));
    px.y = static_cast<int>(std::floor((1.0 - (ny * 0.5 + 0.5)) * kHeight));
    px.depth_m = clip.w;
    px.ok = px.x >= margin && px.x < kWidth - margin && px.y >= margin && px.y < kHeight - margin;
    return px;
}

int difference(const platform::Image& a, const platform::Image& b, int x, int y) {
    const std::uint8_t* p = a.pixel(x, y);
    const std::uint8_t* q = b.pixel(x, y);
    return std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]);
}

// Largest difference in the 3x3 block around (x, y): tolerant of a one-pixel projection offset.
int block_difference(const platform::Image& a, const platform::Image& b, int x, int y) {
    int best = 0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) best = std::max(best, difference(a, b, x + dx, y + dy));
    return best;
}

// Dense samples of the curve the wire systems draw (while a rope node blends in, it differs from the curve
// through the current nodes by up to a few centimetres).
std::vector<glm::dvec3> rendered_curve(const wire::Curve& curve) {
    std::vector<glm::dvec3> out;
    for (const wire::CubicBezier& segment : curve.segments)
        for (int i = 0; i < 16; ++i) out.push_back(wire::position(segment, i / 16.0));
    return out;
}

struct Frames {
    platform::Image full;      // pieces and wires
    platform::Image no_wires;  // pieces only
    platform::Image empty;     // neither
};

// Runs `frames` frames, then renders the last state three ways.
Frames run(platform::Context& ctx, tunnel::Level& level, int frames) {
    for (int f = 0; f < frames; ++f) {
        ctx.begin_frame();
        level.frame(kDt);
        ctx.end_frame();
    }
    Frames out;
    ctx.begin_frame();
    level.render();
    out.full = platform::read_pixels(ctx);
    level.options().draw_wires = false;
    level.render();
    out.no_wires = platform::read_pixels(ctx);
    level.options().draw_pieces = false;
    level.render();
    out.empty = platform::read_pixels(ctx);
    level.options().draw_wires = true;
    level.options().draw_pieces = true;
    ctx.end_frame();
    return out;
}

TEST(TunnelSystem, WallsAndCablesWhereExpected) {
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    auto level = make_level();
    ASSERT_TRUE(level);
    const Frames img = run(*ctx, *level, 20);
    const engine::scene::Camera& camera = level->camera();
    const curved_space::Chain& chain = level->chain();

    // The empty frame is the clear colour everywhere.
    const std::uint8_t* bg = img.empty.pixel(0, 0);
    int background_pixels = 0;
    for (int y = 0; y < kHeight; y += 4)
        for (int x = 0; x < kWidth; x += 4) {
            const std::uint8_t* c = img.empty.pixel(x, y);
            background_pixels += c[0] == bg[0] && c[1] == bg[1] && c[2] == bg[2];
        }
    EXPECT_EQ(background_pixels, (kHeight / 4) * (kWidth / 4));

    // Wall probes: upper half of the wall (clear of walkway and hooks), between the ribs, 3..7 m ahead of the
    // camera along the unbent axis.
    const double camera_z = level->flight_z_m();
    int probes = 0;
    int wall_coloured = 0;
    for (double ahead = 3.0; ahead <= 7.0; ahead += 1.0) {
        const double z = std::floor(camera_z + ahead) + 0.6;
        for (double deg : {25.0, 50.0, 75.0, 105.0, 130.0, 155.0}) {
            const double a = deg * kPi / 180.0;
            const glm::dvec3 p = chain.transform_point({2.3 * std::cos(a), 2.3 * std::sin(a), z});
            const Pixel px = project(camera, p);
            if (!px.ok) continue;
            ++probes;
            const std::uint8_t* c = img.no_wires.pixel(px.x, px.y);
            const int lum = c[0] + c[1] + c[2];
            // Concrete: a warm grey, clearly brighter than the background, red >= blue.
            const bool concrete = difference(img.no_wires, img.empty, px.x, px.y) > 60 && lum > 120 &&
                                  c[0] + 4 >= c[2] && std::abs(c[0] - c[2]) < 80;
            wall_coloured += concrete;
            if (!concrete)
                std::printf("wall probe at %d,%d (z %.1f, %.0f deg): rgb %d %d %d\n", px.x, px.y, z, deg,
                            c[0], c[1], c[2]);
        }
    }
    EXPECT_GE(probes, 20);
    EXPECT_GE(wall_coloured, probes * 9 / 10)
        << wall_coloured << " of " << probes << " wall probes are concrete";

    // Cables: the nearest cable across the tunnel in front of the camera, and the high fixed cables.
    auto coverage = [&](std::size_t cable, int& samples) {
        int covered = 0;
        samples = 0;
        // The curve the systems drew with; the nodes path builds it on the GPU only: then the same spline of the
        // cable's nodes on the CPU (within float rounding of the GPU's, and of a pop-free blend's for a rope).
        wire::Curve built;
        const wire::Curve* curve = &level->cable_curve(cable);
        if (curve->segments.empty() && level->options().upload_path == wire::UploadPath::gpu_nodes) {
            wire::SplineSettings spline;
            spline.kind = level->options().spline;
            if (wire::build_curve(level->cable_nodes(cable), spline, built).ok()) curve = &built;
        }
        for (const glm::dvec3& p : rendered_curve(*curve)) {
            const Pixel px = project(camera, p, 6);
            if (!px.ok || px.depth_m > 14.0) continue;
            ++samples;
            covered += block_difference(img.full, img.no_wires, px.x, px.y) > 24;
        }
        return samples > 0 ? static_cast<double>(covered) / samples : 0.0;
    };
    int checked_across = 0;
    int checked_fixed = 0;
    for (std::size_t c = 0; c < level->cables().size(); ++c) {
        const tunnel::CableInfo& info = level->cables()[c];
        int samples = 0;
        const double cov = coverage(c, samples);
        if (samples < 30) continue;
        if (info.hanging && info.across) {
            EXPECT_GE(cov, 0.85) << "cable " << c << " across the tunnel: " << samples << " samples";
            ++checked_across;
        }
        std::printf("cable %zu (%s): coverage %.2f of %d samples\n", c,
                    info.hanging ? (info.across ? "across" : "festoon") : "fixed", cov, samples);
        if (!info.hanging) {
            // Fixed cables run through the ribs (20% of the length) and past the hooks.
            EXPECT_GE(cov, 0.5) << "fixed cable " << c << ": " << samples << " samples";
            ++checked_fixed;
        }
    }
    EXPECT_GE(checked_across, 1) << "no cable across the tunnel in view";
    EXPECT_GE(checked_fixed, 2) << "fixed wall cables not in view";
}

TEST(TunnelSystem, StatsFiniteAndPlausible) {
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    auto level = make_level();
    ASSERT_TRUE(level);
    for (int f = 0; f < 12; ++f) {
        ctx->begin_frame();
        level->frame(kDt);
        ctx->end_frame();
        int non_finite = 0;
        const nlohmann::json record = tunnel::frame_record(level->stats(), level->system_stats(), non_finite);
        EXPECT_EQ(non_finite, 0);
        EXPECT_TRUE(tunnel::all_finite(record)) << record.dump();
        const tunnel::LevelFrameStats& s = level->stats();
        EXPECT_EQ(s.frame, static_cast<uint64_t>(f));
        EXPECT_GT(s.wires_drawn, 10u);
        EXPECT_LE(s.wires_drawn, s.wires);
        if (level->options().upload_path == wire::UploadPath::gpu_nodes) {
            // The GPU counts what it drew: triangles, read back 3 frames late.
            if (f >= 3) {
                EXPECT_GT(s.wire_triangles, 1000u);
            }
        } else {
            EXPECT_GT(s.wire_vertices, 1000u);
        }
        EXPECT_GT(s.wire_bytes_uploaded, 0u);
        EXPECT_GT(s.segment_bytes_uploaded, 0u);
        EXPECT_GT(s.piece_triangles, 1000u);
        EXPECT_GT(s.rope_nodes, 0u);
        // GPU timer results: from an earlier frame (or none yet), never negative.
        EXPECT_LT(s.gpu_ms_frame, static_cast<int64_t>(f) + 1);
        EXPECT_GE(s.wires_gpu_ms, 0.0);
        EXPECT_GE(s.pieces_gpu_ms, 0.0);
        if (f >= 8) {
            EXPECT_GE(s.gpu_ms_frame, 0) << "results arrive within a few frames";
        }
        EXPECT_TRUE(record.contains("gpu_ms") && record["gpu_ms"].contains("wire.render"));
        int pieces_drawn = 0;
        for (int n : s.piece_levels) pieces_drawn += n;
        EXPECT_GT(pieces_drawn, 3);
        EXPECT_LE(pieces_drawn, level->piece_count());
        EXPECT_GT(pieces_drawn - s.piece_levels[0], 0) << "no piece refined";  // near bent pieces refine
        for (const engine::ecs::SystemStats& st : level->system_stats()) {
            EXPECT_TRUE(std::isfinite(st.last_ms)) << st.name;
            EXPECT_GE(st.last_ms, 0.0) << st.name;
        }
    }
    EXPECT_EQ(level->system_stats().size(), 11u);
}

TEST(TunnelSystem, RopesInsertAndRemoveNodesWithNewIds) {
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    auto level = make_level();
    ASSERT_TRUE(level);
    level->options().draw_pieces = false;  // simulation only: fast
    level->options().draw_wires = false;
    std::vector<std::set<uint32_t>> seen(level->ropes().size());
    std::vector<uint32_t> max_id(level->ropes().size(), 0);
    for (std::size_t r = 0; r < level->ropes().size(); ++r) {
        const auto& ids = level->ropes()[r].ids();
        seen[r].insert(ids.begin(), ids.end());
        max_id[r] = *std::max_element(ids.begin(), ids.end());
    }
    int inserted = 0;
    int removed = 0;
    for (int f = 0; f < 150; ++f) {
        ctx->begin_frame();
        level->frame(kDt);
        ctx->end_frame();
        inserted += level->stats().nodes_inserted;
        removed += level->stats().nodes_removed;
        for (std::size_t r = 0; r < level->ropes().size(); ++r) {
            const tunnel::Rope& rope = level->ropes()[r];
            const std::set<uint32_t> ids(rope.ids().begin(), rope.ids().end());
            ASSERT_EQ(ids.size(), rope.size()) << "rope " << r << " has repeated ids";
            for (uint32_t id : ids) {
                // An id that appears now is either known or brand new (larger than any seen): never reused.
                if (seen[r].count(id) == 0) {
                    EXPECT_GT(id, max_id[r]) << "rope " << r << " reused id " << id;
                }
            }
            for (uint32_t id : ids) {
                seen[r].insert(id);
                max_id[r] = std::max(max_id[r], id);
            }
            for (const glm::dvec3& p : rope.positions()) ASSERT_TRUE(std::isfinite(p.x + p.y + p.z));
        }
    }
    EXPECT_GT(inserted, 10) << "the gusts should bend the ropes enough to refine them";
    EXPECT_GT(removed, 10) << "the ropes should coarsen again as they straighten";
}

TEST(TunnelSystem, RopeInsertsNodesOnTheCurrentCurve) {
    // A slack rope pulled into a V: adapt() refines the bend; every new node lies on the curve the wire
    // systems built through the nodes before the insertion.
    tunnel::Rope rope({0.0, 0.0, 0.0}, {3.0, 0.0, 0.0}, 4.5, 5, {.max_changes_per_adapt = 1});
    for (int i = 0; i < 20; ++i) rope.step(1.0 / 60.0);
    int insertions = 0;
    for (int round = 0; round < 20; ++round) {
        wire::WireNodes before;
        rope.write_nodes(before);
        wire::Curve curve;
        ASSERT_TRUE(wire::build_curve(before, wire::SplineSettings{}, curve).ok());
        const std::vector<uint32_t> old_ids = rope.ids();
        const tunnel::AdaptResult r = rope.adapt(wire::SplineSettings{});
        if (r.inserted == 0) continue;
        ++insertions;
        for (std::size_t i = 0; i < rope.size(); ++i) {
            if (std::find(old_ids.begin(), old_ids.end(), rope.ids()[i]) != old_ids.end()) continue;
            EXPECT_GT(rope.ids()[i], *std::max_element(old_ids.begin(), old_ids.end()));
            double best = 1e30;
            for (const wire::CubicBezier& seg : curve.segments)
                for (int k = 0; k <= 2000; ++k)
                    best = std::min(best, glm::length(wire::position(seg, k / 2000.0) - rope.positions()[i]));
            EXPECT_LT(best, 2e-3) << "new node " << rope.ids()[i] << " is off the curve";
        }
    }
    EXPECT_GT(insertions, 0);
}

TEST(TunnelSystem, TwoRunsRenderByteEqualImages) {
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    std::vector<platform::Image> images;
    for (int run_index = 0; run_index < 2; ++run_index) {
        auto level = make_level();
        ASSERT_TRUE(level);
        for (int f = 0; f < 8; ++f) {
            ctx->begin_frame();
            level->frame(kDt);
            if (f == 7) images.push_back(platform::read_pixels(*ctx));
            ctx->end_frame();
        }
    }
    ASSERT_EQ(images.size(), 2u);
    ASSERT_EQ(images[0].rgba.size(), images[1].rgba.size());
    EXPECT_TRUE(images[0].rgba == images[1].rgba) << "the tunnel is not reproducible at a fixed step";
}

// Per-frame figures of a simulation-only run (the wire systems, rope simulation and the piece level choice
// run; nothing is rasterised) at the default run's viewport.
struct RunFigures {
    std::vector<double> turn_deg, penetration_m, error_px;
    int close_ups = 0;
    double tolerance_px = 0.0;
    double rope_radius_m = 1e30;
    int max_level_used = 0;
    double drawn_vs_fresh_m =
        0.0;  // after the run: drawn (pop-free) rope curves vs the curves of their nodes
};

RunFigures run_figures(platform::Context& ctx, tunnel::LevelSettings settings, int frames, int width_px = 1280,
                       int height_px = 720) {
    RunFigures out;
    settings.asset_dir = WIRE_ASSET_DIR "/tunnel";
    auto created = tunnel::Level::create(settings);
    if (!created) {
        ADD_FAILURE() << "Level::create: " << created.error().message;
        return out;
    }
    tunnel::Level& level = *created.value();
    level.set_viewport(width_px, height_px);
    level.options().draw_pieces = false;
    level.options().draw_wires = false;
    out.tolerance_px = level.options().subdivision_tolerance_px;
    for (const tunnel::CableInfo& c : level.cables())
        if (c.hanging) out.rope_radius_m = std::min(out.rope_radius_m, static_cast<double>(c.radius_m));
    for (int f = 0; f < frames; ++f) {
        ctx.begin_frame();
        level.frame(kDt);
        ctx.end_frame();
        const tunnel::LevelFrameStats& s = level.stats();
        out.turn_deg.push_back(s.rope_max_turn_deg);
        out.penetration_m.push_back(s.rope_penetration_m);
        out.error_px.push_back(s.piece_max_error_px);
        out.close_ups += s.camera_rope_m <= 0.5 && s.camera_cable_m <= 0.5;
        for (int l = 0; l < static_cast<int>(s.piece_levels.size()); ++l)
            if (s.piece_levels[static_cast<std::size_t>(l)] > 0)
                out.max_level_used = std::max(out.max_level_used, l);
    }
    // Reported, not asserted (the wire module's blend, issue 17): how far the drawn rope curves lag behind
    // the curves through their current nodes.
    for (std::size_t c = 0; c < level.cables().size(); ++c) {
        if (!level.cables()[c].hanging) continue;
        wire::Curve fresh;
        if (!wire::build_curve(level.cable_nodes(c), wire::SplineSettings{}, fresh).ok()) continue;
        std::vector<glm::dvec3> q;
        for (const wire::CubicBezier& seg : fresh.segments)
            for (int i = 0; i < 32; ++i) q.push_back(wire::position(seg, i / 32.0));
        for (const wire::CubicBezier& seg : level.cable_curve(c).segments)
            for (int i = 0; i < 8; ++i) {
                const glm::dvec3 p = wire::position(seg, i / 8.0);
                double best = 1e30;
                for (const glm::dvec3& x : q) best = std::min(best, glm::length(x - p));
                out.drawn_vs_fresh_m = std::max(out.drawn_vs_fresh_m, best);
            }
    }
    return out;
}

void print_distribution(const char* name, std::vector<double> v) {
    std::sort(v.begin(), v.end());
    if (v.empty()) return;
    std::printf("%s: median %.4g, p90 %.4g, max %.4g\n", name, v[v.size() / 2], v[v.size() * 9 / 10],
                v.back());
}

TEST(TunnelSystem, DefaultRunRopesSmoothAndClearPiecesWithinTolerance) {
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    const RunFigures r = run_figures(*ctx, {}, 120);  // the default `tunnel --headless` run
    ASSERT_EQ(r.turn_deg.size(), 120u);
    EXPECT_DOUBLE_EQ(r.tolerance_px, 0.5);
    for (std::size_t f = 0; f < r.turn_deg.size(); ++f) {
        EXPECT_LE(r.turn_deg[f], 20.0) << "frame " << f;
        EXPECT_LE(r.penetration_m[f], r.rope_radius_m / 4.0) << "frame " << f;
        EXPECT_LE(r.error_px[f], r.tolerance_px) << "frame " << f;
    }
    print_distribution("rope_max_turn_deg", r.turn_deg);
    print_distribution("rope_penetration_m", r.penetration_m);
    print_distribution("piece_max_error_px", r.error_px);
    std::printf("after the run, drawn rope curves vs the curves of their nodes: %.4f m (pop-free blend lag)\n",
                r.drawn_vs_fresh_m);
    // The figures are alive: ropes rest on something (a contact is measured), the close-up needs the lifted
    // cap, and the flight has its close-ups.
    EXPECT_GT(*std::max_element(r.penetration_m.begin(), r.penetration_m.end()), 0.0);
    EXPECT_EQ(r.max_level_used, 4) << "no piece needed the lifted cap";
    EXPECT_GE(r.close_ups, 10) << "frames within 0.5 m of a rope and of a wall cable";
}

// The piece tolerance at any screen size (issue 31): at 1920x1080 and 3840x2160 the predicted error on screen is
// 1.5x and 3x what it is at 720 p for the same level; the level caches the levels the viewport needs (one more: the
// error falls 4x a level), so every frame of the default flight stays within 0.5 px there too.
TEST(TunnelSystem, PiecesWithinToleranceAtLargeViewports) {
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    for (const auto& [w, h] : {std::pair{1920, 1080}, std::pair{3840, 2160}}) {
        const RunFigures r = run_figures(*ctx, {}, 120, w, h);
        ASSERT_EQ(r.error_px.size(), 120u);
        for (std::size_t f = 0; f < r.error_px.size(); ++f)
            EXPECT_LE(r.error_px[f], r.tolerance_px) << w << "x" << h << ", frame " << f;
        EXPECT_GT(r.max_level_used, 4) << w << "x" << h << ": the close-up needs a level beyond 720 p's cap";
        std::printf("%dx%d: ", w, h);
        print_distribution("piece_max_error_px", r.error_px);
    }
}

TEST(TunnelSystem, RopeBoundsHoldOverBendSeedsAndScales) {
    // A family: other bend animations (seeds) and stronger bends (the rope's gravity tilts and the contact
    // metric stretches with the bend); 60 frames: the first gust swings the ropes of the first pieces.
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    std::vector<double> turns, penetrations;
    double worst_turn = 0.0, worst_penetration = 0.0;
    std::string worst_case;
    for (uint32_t seed : {2u, 3u})
        for (double scale : {1.0, 1.6}) {
            const RunFigures r = run_figures(*ctx, {.seed = seed, .bend_scale = scale}, 60);
            for (std::size_t f = 0; f < r.turn_deg.size(); ++f) {
                EXPECT_LE(r.turn_deg[f], 20.0) << "seed " << seed << " scale " << scale << " frame " << f;
                EXPECT_LE(r.penetration_m[f], r.rope_radius_m / 4.0)
                    << "seed " << seed << " scale " << scale << " frame " << f;
                if (r.turn_deg[f] > worst_turn) {
                    worst_turn = r.turn_deg[f];
                    worst_case = "seed " + std::to_string(seed) + " scale " + std::to_string(scale) +
                                 " frame " + std::to_string(f);
                }
                worst_penetration = std::max(worst_penetration, r.penetration_m[f]);
            }
            turns.insert(turns.end(), r.turn_deg.begin(), r.turn_deg.end());
            penetrations.insert(penetrations.end(), r.penetration_m.begin(), r.penetration_m.end());
        }
    print_distribution("family rope_max_turn_deg", turns);
    print_distribution("family rope_penetration_m", penetrations);
    std::printf("worst turn %.2f deg at %s; worst penetration %.4f m\n", worst_turn, worst_case.c_str(),
                worst_penetration);
}

// Distance in the plane from q to the triangle abc.
double point_triangle_distance_2d(const glm::dvec2& q, const glm::dvec2& a, const glm::dvec2& b,
                                  const glm::dvec2& c) {
    auto cross = [](const glm::dvec2& u, const glm::dvec2& v) { return u.x * v.y - u.y * v.x; };
    const double d1 = cross(b - a, q - a), d2 = cross(c - b, q - b), d3 = cross(a - c, q - c);
    const bool neg = d1 < 0 || d2 < 0 || d3<0, pos = d1> 0 || d2 > 0 || d3 > 0;
    if (!(neg && pos)) return 0.0;  // inside (or on an edge)
    auto seg = [](const glm::dvec2& p, const glm::dvec2& u, const glm::dvec2& v) {
        const glm::dvec2 e = v - u;
        const double t = std::clamp(glm::dot(p - u, e) / std::max(glm::dot(e, e), 1e-300), 0.0, 1.0);
        return glm::length(p - (u + t * e));
    };
    return std::min({seg(q, a, b), seg(q, b, c), seg(q, c, a)});
}

TEST(TunnelSystem, WallCablesClearTheRibs) {
    // The wall cables run along z at fixed (x, y) in the unbent space; the bend carries cross-sections
    // rigidly, so a cable clears a rib if its axis is at least its radius away from the rib's triangles
    // projected on (x, y). Ribs read from the asset and refined here (level 5, finer than the level cache),
    // and the level's own refined ribs.
    auto ctx = make_context();
    ASSERT_TRUE(ctx);
    auto level = make_level();
    ASSERT_TRUE(level);
    std::vector<engine::assets::MeshData> meshes;
    const std::string path = std::string(WIRE_ASSET_DIR) + "/tunnel/wall_details.glb";
    ASSERT_TRUE(engine::assets::read_gltf(path, meshes).ok()) << path;
    std::vector<engine::assets::MeshData> ribs;
    for (const engine::assets::MeshData& m : meshes) {
        if (m.name.rfind("rib_", 0) != 0) continue;
        engine::assets::MeshData refined;
        ASSERT_TRUE(engine::assets::subdivide(m, 5, refined).ok()) << m.name;
        ribs.push_back(std::move(refined));
    }
    ASSERT_EQ(ribs.size(), 4u);
    ribs.push_back(level->refined_mesh(1));
    int cables = 0;
    for (const tunnel::CableInfo& c : level->cables()) {
        if (c.hanging) continue;
        ++cables;
        double nearest = 1e30;
        for (const engine::assets::MeshData& m : ribs)
            for (std::size_t i = 0; i + 2 < m.indices.size(); i += 3) {
                glm::dvec2 p[3];
                for (int k = 0; k < 3; ++k) {
                    const std::size_t v = m.indices[i + static_cast<std::size_t>(k)];
                    p[k] = glm::dvec2(m.origin.x + m.positions[3 * v], m.origin.y + m.positions[3 * v + 1]);
                }
                nearest = std::min(nearest, point_triangle_distance_2d(c.section_m, p[0], p[1], p[2]));
            }
        std::printf("wall cable at (%.3f, %.3f) radius %.3f: %.4f m from the nearest rib\n", c.section_m.x,
                    c.section_m.y, c.radius_m, nearest);
        EXPECT_GE(nearest, c.radius_m + 0.005) << "wall cable at " << c.section_m.x << ", " << c.section_m.y;
        // ... and on its clips: within 2 cm of the ribs' inner faces.
        EXPECT_LE(nearest, c.radius_m + 0.02);
    }
    EXPECT_EQ(cables, 6);
}

TEST(TunnelSystem, RopeDrapedOverARibStaysWithFriction) {
    // A slack rope lands on a bar (a rib seen end-on: a cylinder along z) and settles; then the world tilts
    // (a sideways acceleration of 2 m/s^2, tan = 0.2 < friction 0.7). With friction the rope stays where it
    // lies on the bar; without, it slides over it. The material point on the bar (the node resting on it) is
    // tracked.
    const glm::dvec2 bar(1.0, -0.1);
    const double bar_radius = 0.05;
    const tunnel::Collider collider = [&](const glm::dvec3& a, const glm::dvec3& b, double r,
                                          tunnel::ElementContact& out) {
        const glm::dvec2 a2(a.x, a.y), e(b.x - a.x, b.y - a.y);
        const double t = std::clamp(glm::dot(bar - a2, e) / std::max(glm::dot(e, e), 1e-18), 0.0, 1.0);
        const glm::dvec2 v = a2 + t * e - bar;
        const double d = glm::length(v);
        if (d >= bar_radius + r || d < 1e-12) return false;
        out = {t, glm::dvec3(v / d, 0.0), bar_radius + r - d};
        return true;
    };
    auto slide = [&](double friction) {
        tunnel::Rope rope({-0.2, 0.0, 0.0}, {2.2, 0.0, 0.0}, 2.4, 25, {.friction = friction});
        rope.set_ends({0.0, 0.0, 0.0}, {2.0, 0.0, 0.0});  // slack, still straight above the bar
        for (int i = 0; i < 120; ++i) rope.step(1.0 / 60.0, {}, collider);
        std::size_t k = 0;  // the node resting on the bar
        for (std::size_t i = 0; i < rope.size(); ++i)
            if (glm::length(glm::dvec2(rope.positions()[i]) - bar) <
                glm::length(glm::dvec2(rope.positions()[k]) - bar))
                k = i;
        const glm::dvec3 before = rope.positions()[k];
        for (int i = 0; i < 180; ++i)
            rope.step(
                1.0 / 60.0, [](const glm::dvec3&) { return glm::dvec3(2.0, 0.0, 0.0); }, collider);
        const glm::dvec3 after = rope.positions()[k];
        std::printf("friction %.2g: node %zu of %zu on the bar at %.3f %.3f\n", friction, k, rope.size(),
                    before.x, before.y);
        // On the bar before and after (not fallen off), and no turn above the limit.
        EXPECT_LT(glm::length(glm::dvec2(before) - bar), bar_radius + 0.02 + 0.02);
        for (std::size_t i = 1; i + 1 < rope.size(); ++i) EXPECT_LE(rope.turn_angle(i) * 180.0 / kPi, 20.0);
        return glm::length(after - before);
    };
    const double with = slide(0.7);
    const double without = slide(1e-9);
    std::printf("the node on the bar slid %.4f m with friction, %.4f m without\n", with, without);
    EXPECT_LT(with, 0.005);
    EXPECT_GT(without, 5.0 * std::max(with, 0.002));
}

}  // namespace
