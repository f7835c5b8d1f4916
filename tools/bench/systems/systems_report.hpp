// The wire systems bench's report: bench.csv's rows and bench.md's sections, gathered scene by scene while
// the bench runs (systems_bench.cpp) and written at the end. No measuring here: figures in, text out.
#pragma once

#include "bench/common.hpp"
#include "bench/systems/run_scene.hpp"
#include "bench/systems/uniform_baseline.hpp"

#include <array>
#include <string>
#include <vector>

namespace wiretool::bench {

struct SystemsReport {
    Table csv;                 ///< bench.csv (header set by the constructor)
    std::string notes;         ///< per scene: the uniform baseline's choice
    std::string system_lines;  ///< per scene: per-system CPU table rows
    std::string memory_lines;  ///< per scene and path: memory table rows
    std::string scene_bytes;   ///< per scene: gpu-nodes bytes, cpu-mesh bytes, their ratio
    std::string thread_lines;  ///< per scene: 1 vs 2 threads
    std::string decision_lines;  ///< per scene: adaptive vs uniform CPU, lod share (issue 29's decisions)
    // The figures section (`standard`, `offscreen`, `far`; negative: the scene did not run).
    double standard_cpu_ms = 0.0, offscreen_cpu_ms = -1.0, far_cpu_ms = -1.0;
    double bytes_cpu = 0.0, bytes_gpu = 0.0;
    double adaptive_vertices_at_samples = 0.0, uniform_vertices_at_samples = 0.0;
    double far_adaptive_vertices = 0.0, far_uniform_vertices = 0.0;
    std::array<double, kSystems> standard_systems{}, far_systems{};

    SystemsReport();

    /// The rows of one scene's adaptive runs: memory (both paths), bench.csv (cpu-mesh, gpu-nodes)
    /// and bytes uploaded.
    void add_adaptive(const std::string& scene, const std::string& method, int wires, const SceneRun& cpu_run,
                      const SceneRun& gpu_run);
    /// The uniform baseline's bench.csv row and note, and the scene's per-system CPU row. `staged`: the
    /// per-system medians of a cpu-mesh run stage by stage (WireContext::fused_stages off), so that each system's
    /// column is its own work and the uniform baseline gets the curve stage alone.
    void add_uniform(const std::string& scene, const std::string& method, int wires, const SceneRun& cpu_run,
                     const Uniform& u, const std::array<double, kSystems>& staged);
    /// A scene's 1 vs 2 threads row (median wall ms per frame).
    void add_threads(const std::string& scene, double wall_1, double wall_2);

    /// bench.md. `frames`: frames per scene run.
    [[nodiscard]] std::string markdown(const Options& o, int frames) const;
};

}  // namespace wiretool::bench
