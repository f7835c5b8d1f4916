// The wire systems bench's report (systems_report.hpp): bench.csv's rows and bench.md.
#include "bench/systems/systems_report.hpp"

#include "bench/scenes/field_scenes.hpp"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace wiretool::bench {
namespace {

std::vector<std::string> row(const std::string& scene, const std::string& method, const std::string& mode,
                             int wires, double visible, double rings, double vertices, double bytes,
                             double cpu_ms_frame, double error_px) {
    const double ns_per_vertex = vertices > 0 ? cpu_ms_frame * 1e6 / vertices : 0.0;
    return {scene,
            method,
            mode,
            num(kTolerancePx),
            std::to_string(wires),
            num(visible, 6),
            num(rings, 8),
            num(vertices, 9),
            num(bytes, 10),
            num(cpu_ms_frame),
            num(ns_per_vertex),
            num(error_px)};
}

std::string memory_line(const std::string& scene, const char* path, const SceneRun& r) {
    char buf[2048];
    const wire::systems::WireMemory& m = r.memory;
    auto per = [](std::size_t bytes, std::size_t n) { return n ? bytes / 1024.0 / n : 0.0; };
    std::snprintf(buf, sizeof buf, "| %s | %s | %zu | %.2f | %zu | %.2f | %.2f | %.2f | %.2f | %.1f |\n",
                  scene.c_str(), path, m.visible_wires, per(m.visible_bytes, m.visible_wires), m.culled_wires,
                  per(m.culled_bytes, m.culled_wires), per(m.mesh_bytes, m.visible_wires),
                  per(m.nodes_bytes, m.visible_wires + m.culled_wires),
                  (m.visible_bytes + m.culled_bytes) / 1048576.0, r.rss_kb / 1024.0);
    return buf;
}

}  // namespace

SystemsReport::SystemsReport() {
    csv.header = {"scene",          "method",           "mode",          "tolerance_px",
                  "wires",          "visible_wires",    "rings",         "vertices",
                  "bytes_uploaded", "cpu_ms_per_frame", "ns_per_vertex", "max_screen_error_px"};
}

void SystemsReport::add_adaptive(const std::string& scene, const std::string& method, int wires,
                                 const SceneRun& cpu_run, const SceneRun& gpu_run) {
    memory_lines += memory_line(scene, "cpu-mesh", cpu_run);
    memory_lines += memory_line(scene, "gpu-nodes", gpu_run);
    const SceneRun& c = cpu_run;
    const SceneRun& g = gpu_run;
    csv.add(row(scene, method, "cpu-mesh", wires, median(c.visible), median(c.rings), median(c.vertices),
                median(c.bytes), median(c.frame_cpu_ms), c.max_error_px));
    // Rings, vertices and the screen error are the GPU's on the nodes path (0 here; bench --gl reads them).
    csv.add(row(scene, method, "gpu-nodes", wires, median(g.visible), 0.0, 0.0, median(g.bytes),
                median(g.frame_cpu_ms), 0.0));
    scene_bytes += "| " + scene + " | " + num(median(g.bytes), 8) + " |";
    const double scene_bytes_cpu = median(c.bytes);
    if (scene_bytes_cpu > 0.0) {
        char buf[256];
        std::snprintf(buf, sizeof buf, " %.8g | %.1fx |\n", scene_bytes_cpu,
                      scene_bytes_cpu / std::max(1.0, median(g.bytes)));
        scene_bytes += buf;
    } else {
        scene_bytes += " 0 | - |\n";
    }
}

void SystemsReport::add_uniform(const std::string& scene, const std::string& method, int wires,
                                const SceneRun& cpu_run, const Uniform& u,
                                const std::array<double, kSystems>& staged) {
    char buf[2048];
    const UniformCounts counts = uniform_counts(cpu_run, u);
    const std::array<double, kSystems>& sys = staged;
    const double curve_ms = sys[0];
    double staged_total = 0.0;
    for (double v : sys) staged_total += v;
    std::snprintf(buf, sizeof buf, "| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f |\n", scene.c_str(),
                  sys[0], sys[1], sys[2], sys[3], sys[4], staged_total, median(cpu_run.frame_cpu_ms));
    system_lines += buf;
    csv.add(row(scene, method, "uniform", wires, median(cpu_run.visible), median(counts.rings),
                median(counts.vertices), median(counts.bytes), curve_ms + u.rebuild_cpu_ms, u.max_error_px));
    {
        // Issue 29's decisions: adaptive never costs more CPU than uniform at equal error, on any scene, and the
        // lod stage stays under 20% of the frame (the moving frame, `swaying`, is the one it is set for).
        const double adaptive_ms = median(cpu_run.frame_cpu_ms), uniform_ms = curve_ms + u.rebuild_cpu_ms;
        double total = 0.0;
        for (double v : sys) total += v;
        const double lod_share = total > 0.0 ? sys[1] / total : 0.0;
        std::snprintf(buf, sizeof buf, "| %s | %.3f | %.3f | %.2f | %s | %.1f%% | %s |\n", scene.c_str(), adaptive_ms,
                      uniform_ms, uniform_ms > 0.0 ? adaptive_ms / uniform_ms : 0.0,
                      adaptive_ms <= uniform_ms ? "yes" : "**no**", 100.0 * lod_share,
                      lod_share < 0.2 ? "yes" : "**no**");
        decision_lines += buf;
    }
    std::snprintf(buf, sizeof buf,
                  "- `%s` uniform baseline: %u rings per segment, %u sides (max centre-line error %.3f px "
                  "against the adaptive run's %.3f px over %zu sampled frames).\n",
                  scene.c_str(), u.rings_per_segment, u.sides, u.max_error_px, cpu_run.max_error_px,
                  cpu_run.samples.size());
    notes += buf;
}

void SystemsReport::add_threads(const std::string& scene, double wall_1, double wall_2) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "| %s | %.3f | %.3f | %.2fx |\n", scene.c_str(), wall_1, wall_2,
                  wall_2 > 0 ? wall_1 / wall_2 : 0.0);
    thread_lines += buf;
}

std::string SystemsReport::markdown(const Options& o, int frames) const {
    char buf[2048];
    std::string md = "# wiretool bench: wire systems\n\n";
    std::snprintf(
        buf, sizeof buf,
        "%d hanging wires of %d nodes (catenaries 10 m across; `far`: 10,000 cables over a 2 km landscape), "
        "1920x1080, 60 degree field of view, "
        "tolerance %.2f px, %d frames of a moving camera (medians exclude frame 0, which builds "
        "everything)%s; "
        "%d thread(s). `standard`: static nodes; `swaying`: every node moves every frame; `offscreen`: "
        "the same wires, all behind the camera; `far`: power lines (120-260 m spans) and rigging (12-45 m) "
        "over "
        "2 km x 2 km of rolling ground, a camera flying 45 m up. CPU time is process CPU time of the five "
        "systems "
        "(curve, lod, rings, mesh, draw_list) per frame. `bytes_uploaded` is computed exactly as "
        "WireRenderer::draw() would memcpy it from the frame's DrawList (no GL is run). `uniform`: a fixed "
        "ring count per segment and one side count, the smallest whose measured maximum screen error is "
        "no worse than the adaptive run's; its CPU time is the curve stage plus building its rings and "
        "mesh for every visible wire (what it costs whenever the wires move).\n\n",
        1000, kFieldNodes, kTolerancePx, frames, o.quick ? " (--quick; `swaying` runs 8 frames)" : "",
        o.threads);
    md += buf;
    md += csv.markdown();
    md += "\n" + notes;
    if (standard_cpu_ms > 0.0) {
        md += "\n## Figures\n\n";
        md += "Per-system CPU ms per frame, `standard`, cpu-mesh (median):";
        for (int i = 0; i < kSystems; ++i) {
            std::snprintf(buf, sizeof buf, " %s %.3f;", kSystemNames[i],
                          standard_systems[static_cast<std::size_t>(i)]);
            md += buf;
        }
        md += "\n\n";
        if (adaptive_vertices_at_samples > 0.0) {
            std::snprintf(
                buf, sizeof buf,
                "- adaptive vs uniform at equal max screen error (`standard`, same sampled frames): "
                "%.0f vs %.0f vertices, %.1fx fewer (aim >= 5x)\n",
                adaptive_vertices_at_samples, uniform_vertices_at_samples,
                uniform_vertices_at_samples / adaptive_vertices_at_samples);
            md += buf;
        }
        if (standard_systems[1] > 0.0) {
            double total = 0.0;
            for (double v : standard_systems) total += v;
            std::snprintf(buf, sizeof buf,
                          "- lod share of the five systems (`standard`, cpu-mesh): %.1f%% (aim <= 25%%)\n",
                          100.0 * standard_systems[1] / total);
            md += buf;
        }
        if (bytes_gpu > 0.0) {
            std::snprintf(buf, sizeof buf,
                          "- gpu-nodes vs cpu-mesh bytes per frame: %.0f vs %.0f, %.1fx fewer (aim >= 6x)\n",
                          bytes_gpu, bytes_cpu, bytes_cpu / bytes_gpu);
            md += buf;
        } else if (bytes_cpu > 0.0) {
            std::snprintf(buf, sizeof buf,
                          "- gpu-nodes vs cpu-mesh bytes per frame: 0 vs %.0f (still wires: the nodes path sends "
                          "nothing after their first frame; aim >= 6x fewer)\n",
                          bytes_cpu);
            md += buf;
        }
        if (offscreen_cpu_ms >= 0.0) {
            std::snprintf(buf, sizeof buf,
                          "- offscreen vs standard CPU per frame: %.4f vs %.4f ms = %.2f%% (aim < 2%%)\n",
                          offscreen_cpu_ms, standard_cpu_ms, 100.0 * offscreen_cpu_ms / standard_cpu_ms);
            md += buf;
        }
    }
    if (!system_lines.empty()) {
        md += "\n## Per-system CPU ms per frame (cpu-mesh, median; " + std::to_string(o.threads) +
              " thread(s))\n\nStage by stage (a run with `WireContext::fused_stages` off, so each column is that "
              "system's own work); `fused frame`: the adaptive row's frame, where a wire whose curve changed goes "
              "on through lod, rings and mesh right after its curve (the runtime's default).\n\n"
              "| scene | curve | lod | rings | mesh | draw_list | frame | fused frame |\n"
              "| --- | --- | --- | --- | --- | --- | --- | --- |\n" +
              system_lines;
    }
    if (!memory_lines.empty()) {
        std::snprintf(buf, sizeof buf, "%.1f", proc_status_kb("VmHWM") / 1024.0);
        md +=
            "\n## Memory the wire systems hold (after the last frame; wire::systems::wire_memory: capacity "
            "of "
            "their per-wire containers plus the components, KiB per wire; the mesh column is the cpu-mesh "
            "output, included in the visible figure; nodes are the game's input, not included)\n\n"
            "| scene | path | visible | KiB / visible wire | culled | KiB / culled wire | mesh KiB / visible "
            "| "
            "nodes KiB / wire | systems MiB | process RSS MiB |\n"
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n" +
            memory_lines + "\nProcess peak resident size (VmHWM) at the end of the bench: " + buf +
            " MiB.\n"
            "\nPer wire the systems keep the curve (double Bezier segments), the last valid nodes (they "
            "re-prime "
            "the pop-free state), the LOD state, the float ring records and, on cpu-mesh, the drawn mesh. A "
            "wire "
            "culled while it moves keeps none of curve, LOD counts, rings or mesh (the next frame rebuilds "
            "them; "
            "the curve comes back from the last valid nodes when the view turns to it); the LOD's span "
            "hierarchy "
            "(LodBounds) is kept only by wires whose curve did not change since their last LOD update "
            "(static "
            "wires: the coherence reuse). Aims (issue 18): <= 16 KB per visible and <= 4 KB per culled "
            "64-node "
            "wire on `swaying`.\n";
    }
    if (!scene_bytes.empty()) {
        md +=
            "\n## Bytes uploaded per frame (median)\n\n| scene | gpu-nodes | cpu-mesh | cpu-mesh / gpu-nodes |\n"
            "| --- | --- | --- | --- |\n" +
            scene_bytes + "\n(aims: gpu-nodes >= 20x fewer than cpu-mesh on `standard`, >= 6x on `swaying`)\n";
    }
    if (far_cpu_ms >= 0.0) {
        md += "\nPer-system CPU ms per frame, `far` (10,000 cables), cpu-mesh (median):";
        for (int i = 0; i < kSystems; ++i) {
            std::snprintf(buf, sizeof buf, " %s %.3f;", kSystemNames[i],
                          far_systems[static_cast<std::size_t>(i)]);
            md += buf;
        }
        md += "\n\n";
        if (far_adaptive_vertices > 0.0) {
            std::snprintf(
                buf, sizeof buf,
                "- adaptive vs uniform at equal max screen error (`far`, same sampled frames): %.0f vs %.0f "
                "vertices, %.1fx fewer (aim >= 10x)\n",
                far_adaptive_vertices, far_uniform_vertices, far_uniform_vertices / far_adaptive_vertices);
            md += buf;
        }
    }
    if (o.gl) md += "\n`--gl`: the renderer's rows at scale are in bench_gl.md (systems/gl_scale.hpp).\n";
    if (!thread_lines.empty()) {
        std::string load = "unknown";
        if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {  // other work on the machine skews wall times
            char text[128] = {};
            if (std::fgets(text, sizeof text, f)) load = std::string(text, std::strcspn(text, "\n"));
            std::fclose(f);
        }
        md +=
            "\n## 1 vs 2 threads (cpu-mesh, median wall ms per frame of the five systems over two runs of at "
            "least 40 "
            "frames each, alternated; /proc/loadavg at "
            "the "
            "end: " +
            load +
            ")\n\n"
            "| scene | 1 thread | 2 threads | speed-up |\n| --- | --- | --- | --- |\n" +
            thread_lines;
    }
    if (!decision_lines.empty()) {
        md +=
            "\n## Decisions (issue 29): adaptive never costlier than uniform, lod under 20% of the frame\n\n"
            "CPU ms per frame (cpu-mesh, median): the adaptive systems against the uniform baseline at the same "
            "maximum screen error (its curve stage plus rebuilding its rings and mesh, what it costs whenever "
            "the wires move); lod share: the lod system's CPU over the five systems'. The lod aim is set for the "
            "moving frame (`swaying`); on still scenes the other systems cost next to nothing, so the share "
            "there says little.\n\n"
            "| scene | adaptive ms | uniform ms | adaptive / uniform | adaptive <= uniform | lod share | lod < 20% "
            "|\n| --- | --- | --- | --- | --- | --- | --- |\n" +
            decision_lines;
    }
    return md;
}

}  // namespace wiretool::bench
