// `wiretool bench`, part 1: the wire systems (curve -> lod -> rings -> mesh -> draw_list) on the scenes of
// scenes/field_scenes.hpp seen by a moving camera: CPU time per frame and per system, counts, upload bytes,
// measured screen error, and a uniform tessellation with the same maximum screen error as the baseline.
// Writes bench.csv and bench.md. The steps: resolve the spline, then per scene the adaptive runs on both
// upload paths (run_scene.hpp), the uniform baseline (uniform_baseline.hpp) and the thread scaling; then the
// report (systems_report.hpp). --gl's rows: gl_scale.hpp.
#include "bench/common.hpp"
#include "bench/scenes/field_scenes.hpp"
#include "bench/systems/run_scene.hpp"
#include "bench/systems/systems_report.hpp"
#include "bench/systems/uniform_baseline.hpp"
#include "wiretool/commands.hpp"

#include <wire/io/wire_json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace wiretool::bench {
namespace {

// How every scene of one bench invocation runs.
struct SystemsPlan {
    wire::SplineSettings spline;  ///< the wires' spline (--spline)
    int frames = 120;             ///< per scene run (--quick: 16; `swaying` --quick: 8)
    int error_samples = 3;        ///< sampled frames of the screen error per run
};

// The wires' spline (--spline; default auto, the runtime's Style default), resolved as `wiretool mesh` does.
bool resolve_spline(const Options& o, wire::SplineSettings& spline) {
    wire::PipelineSettings resolved;
    wire::io::SettingsOverrides overrides;
    overrides.spline_type = o.spline;
    if (engine::Status st = wire::io::resolve_settings(wire::io::WireSpec{}, overrides, resolved); !st.ok()) {
        std::fprintf(stderr, "wiretool bench: --spline: %s\n", st.message.c_str());
        return false;
    }
    spline = resolved.spline;
    return true;
}

int scene_frames(const Options& o, const SystemsPlan& plan, SceneKind kind) {
    return kind == SceneKind::swaying && o.quick ? 8 : plan.frames;
}

// The scene on one upload path with the bench's thread count.
SceneRun run_adaptive(const Options& o, const SystemsPlan& plan, SceneKind kind, wire::UploadPath path) {
    const std::string name = scene_name(kind);
    const bool cpu = path == wire::UploadPath::cpu_mesh;
    const int wires = scene_wire_count(kind);
    const int frames = scene_frames(o, plan, kind);
    std::fprintf(stderr, "bench: %s %s, %d wires, %d frames, %d thread(s)\n", name.c_str(),
                 cpu ? "cpu-mesh" : "gpu-nodes", wires, frames, o.threads);
    RunSpec spec{.kind = kind,
                 .path = path,
                 .threads = o.threads,
                 .frames = frames,
                 .wires = wires,
                 .sample_errors = cpu,  // the nodes path's LOD runs on the GPU (bench --gl measures it)
                 .error_samples = cpu ? plan.error_samples : 0,
                 .after_frame = {},
                 .spline = plan.spline};
    return run_scene(spec);
}

// 1 vs 2 threads (wall time: the point of threads is to finish sooner), on the cpu-mesh path. Both thread
// counts get runs of their own, alternated (1, 2, 1, 2) and at least 40 frames each, so that a short --quick
// scene or a moment of load on the machine does not decide the ratio; the median over the frames of both runs
// of a thread count. Not for `offscreen`; on --quick only for `standard` and `swaying`.
bool wants_thread_scaling(const Options& o, SceneKind kind) {
    return kind != SceneKind::offscreen &&
           (!o.quick || kind == SceneKind::standard || kind == SceneKind::swaying);
}

std::pair<double, double> thread_scaling_wall_ms(const Options& o, const SystemsPlan& plan, SceneKind kind) {
    const std::string name = scene_name(kind);
    std::vector<double> walls[2];
    for (int round = 0; round < 2; ++round) {
        for (int t : {1, 2}) {
            std::fprintf(stderr, "bench: %s cpu-mesh, %d thread(s) (thread scaling)\n", name.c_str(), t);
            const SceneRun r = run_scene({.kind = kind,
                                          .path = wire::UploadPath::cpu_mesh,
                                          .threads = t,
                                          .frames = std::max(scene_frames(o, plan, kind), 40),
                                          .wires = scene_wire_count(kind),
                                          .sample_errors = false,
                                          .error_samples = 0,
                                          .after_frame = {},
                                          .spline = plan.spline});
            walls[t - 1].insert(walls[t - 1].end(), r.frame_wall_ms.begin(), r.frame_wall_ms.end());
        }
    }
    return {median(walls[0]), median(walls[1])};
}

// The figures bench.md quotes for `standard`, `offscreen` and `far`.
void note_scene_figures(SystemsReport& report, SceneKind kind, const SceneRun& cpu_run,
                        const SceneRun& gpu_run, const Uniform& u, const std::array<double, kSystems>& staged) {
    if (kind == SceneKind::standard) {
        report.standard_cpu_ms = median(cpu_run.frame_cpu_ms);
        report.standard_systems = staged;
        report.bytes_cpu = median(cpu_run.bytes);
        report.bytes_gpu = median(gpu_run.bytes);
        add_vertices_at_samples(cpu_run, u, report.adaptive_vertices_at_samples,
                                report.uniform_vertices_at_samples);
    }
    if (kind == SceneKind::far) {
        report.far_cpu_ms = median(cpu_run.frame_cpu_ms);
        report.far_systems = staged;
        add_vertices_at_samples(cpu_run, u, report.far_adaptive_vertices, report.far_uniform_vertices);
    }
    if (kind == SceneKind::offscreen) report.offscreen_cpu_ms = median(cpu_run.frame_cpu_ms);
}

// One scene: adaptive on both paths, the uniform baseline at the cpu-mesh run's sampled frames, the threads.
void bench_scene(const Options& o, const SystemsPlan& plan, SceneKind kind,
                 SystemsReport& report) {
    const std::string name = scene_name(kind);
    const int wires = scene_wire_count(kind);
    const SceneRun cpu_run = run_adaptive(o, plan, kind, wire::UploadPath::cpu_mesh);
    const SceneRun gpu_run = run_adaptive(o, plan, kind, wire::UploadPath::gpu_nodes);
    report.add_adaptive(name, o.spline, wires, cpu_run, gpu_run);
    const Uniform u = search_uniform(cpu_run);
    // Stage by stage, for the per-system columns and the uniform baseline's curve stage (the adaptive rows run
    // fused: a changed wire's lod, rings and mesh are timed inside the curve system there).
    std::fprintf(stderr, "bench: %s cpu-mesh, stage by stage (per-system times)\n", name.c_str());
    const SceneRun staged = run_scene({.kind = kind,
                                       .path = wire::UploadPath::cpu_mesh,
                                       .threads = o.threads,
                                       .frames = scene_frames(o, plan, kind),
                                       .wires = wires,
                                       .sample_errors = false,
                                       .error_samples = 0,
                                       .after_frame = {},
                                       .spline = plan.spline,
                                       .fused_stages = false});
    const std::array<double, kSystems> staged_systems = system_medians(staged);
    report.add_uniform(name, o.spline, wires, cpu_run, u, staged_systems);
    note_scene_figures(report, kind, cpu_run, gpu_run, u, staged_systems);
    if (wants_thread_scaling(o, kind)) {
        const auto [wall_1, wall_2] = thread_scaling_wall_ms(o, plan, kind);
        report.add_threads(name, wall_1, wall_2);
    }
}

}  // namespace

int run_systems_bench(const Options& o) {
    SystemsPlan plan;
    if (!resolve_spline(o, plan.spline)) return 2;
    plan.frames = o.quick ? 16 : 120;
    plan.error_samples = o.quick ? 2 : 3;

    SystemsReport report;

    for (SceneKind kind : {SceneKind::standard, SceneKind::offscreen, SceneKind::swaying, SceneKind::far}) {
        if (selected(o, scene_name(kind))) bench_scene(o, plan, kind, report);
    }

    if (!report.csv.write_csv(o.out_dir / "bench.csv")) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench.csv").c_str());
        return exit_failure;
    }
    if (!write_text(o.out_dir / "bench.md", report.markdown(o, plan.frames))) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench.md").c_str());
        return exit_failure;
    }
    return exit_ok;
}

}  // namespace wiretool::bench
