// The wire systems bench's measuring loop: one scene, one upload path, one thread count, through the five
// wire systems (curve -> lod -> rings -> mesh -> draw_list) frame by frame, timed per system, with counts,
// upload bytes and the screen error at a few sampled frames.
#pragma once

#include "bench/scenes/field_scenes.hpp"

#include <wire/bezier.hpp>
#include <wire/draw.hpp>
#include <wire/lod.hpp>
#include <wire/systems/api.hpp>
#include <wire/systems/context.hpp>
#include <wire/systems/systems.hpp>

#include <array>
#include <cstddef>
#include <functional>
#include <vector>

namespace wiretool::bench {

constexpr double kTolerancePx = 0.5;
constexpr float kRadiusM = 0.015f;
constexpr int kSystems = 5;
constexpr const char* kSystemNames[kSystems] = {"curve", "lod", "rings", "mesh", "draw_list"};

/// What one frame at a sampled frame keeps for the uniform baseline: the view and the visible wires' curves.
struct Sample {
    wire::LodView view;
    std::vector<wire::Curve> curves;
    double adaptive_error_px = 0.0;
    double adaptive_radial_px = 0.0;
    double max_radial_scale_px = 0.0;  ///< max over visible wires of R_px = radius * focal / z_min
    std::size_t adaptive_vertices = 0;
};

/// Per measured frame (frame 0 excluded) figures of one run.
struct SceneRun {
    std::vector<std::array<double, kSystems>> system_cpu_ms;  ///< per measured frame
    std::vector<double> frame_cpu_ms, frame_wall_ms;
    /// bytes: cpu-mesh streamed_upload_bytes; nodes path plan_nodes_frame (rings and vertices are 0 there: the
    /// GPU computes them)
    std::vector<double> visible, rings, vertices, bytes;
    std::vector<double> visible_segments;  ///< per frame: segments of the visible wires (uniform counts)
    std::vector<Sample> samples;
    double max_error_px = 0.0;
    wire::systems::WireMemory memory{};  ///< after the last frame
    double rss_kb = 0.0;  ///< VmRSS of the process after the last frame (the scene still alive)
};

struct RunSpec {
    SceneKind kind = SceneKind::standard;
    wire::UploadPath path = wire::UploadPath::cpu_mesh;
    int threads = 1;
    int frames = 120;
    int wires = 1000;
    bool sample_errors = true;
    int error_samples = 3;  ///< frames at which the screen error is measured (spread over the run)
    /// Called after the systems of every frame, frame 0 included (untimed), e.g. to draw the DrawList with
    /// GL.
    std::function<void(const wire::systems::WireContext&, int frame)> after_frame;
    wire::SplineSettings spline{.kind =
                                    wire::SplineKind::automatic};  ///< the wires' Style::spline (--spline)
    int width_px = 1920, height_px = 1080;  ///< the viewport the LOD sees (the aspect follows)
    bool thin_wires = true;  ///< false: no camera-facing strips or phone-wire lines (every wire a tube)
    bool fused_stages = true;  ///< WireContext::fused_stages (false: stage by stage, for per-system times)
};

/// Runs the scene for spec.frames frames under a tbb::global_control of spec.threads.
SceneRun run_scene(const RunSpec& spec);

/// Median CPU ms of each system over the run's measured frames.
std::array<double, kSystems> system_medians(const SceneRun& r);

/// A /proc/self/status field in kB (VmRSS, VmHWM), or 0 where there is none.
double proc_status_kb(const char* field);

}  // namespace wiretool::bench
