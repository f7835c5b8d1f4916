// `wiretool bench`: standard scenes through the wire systems (bench.csv, bench.md) and speed against error on
// reference scenes (accuracy.csv, accuracy.md, stability.md, speed_vs_error.png). A contract: see
// docs/speed_vs_error.md.
#include "bench/common.hpp"
#include "commands.hpp"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>

namespace wiretool {
namespace {

int run_bench(const bench::Options& o) {
    std::error_code ec;
    std::filesystem::create_directories(o.out_dir, ec);
    if (ec || !std::filesystem::is_directory(o.out_dir)) {
        std::fprintf(stderr, "wiretool bench: cannot create output directory %s\n", o.out_dir.c_str());
        return exit_failure;
    }
    if (!o.skip_systems) {
        if (const int st = bench::run_systems_bench(o); st != exit_ok) return st;
    }
    if (o.gl) {
        if (const int st = bench::run_gl_scale_bench(o); st != exit_ok) return st;
    }
    if (!o.skip_accuracy) {
        if (const int st = bench::run_accuracy_bench(o); st != exit_ok) return st;
        if (bench::selected(o, "pop_free_families") || bench::selected(o, "remedy_families")) {
            if (const int st = bench::run_pop_free_bench(o); st != exit_ok) return st;
        }
    }
    std::fprintf(stderr, "wiretool bench: wrote %s\n", o.out_dir.c_str());
    return exit_ok;
}

}  // namespace

Action add_bench_command(CLI::App& app) {
    auto o = std::make_shared<bench::Options>();
    CLI::App* cmd = app.add_subcommand(
        "bench",
        "Runs the standard and reference scenes; writes DIR/bench.csv, bench.md, accuracy.csv, accuracy.md, "
        "stability.md, speed_vs_error.png, pop_free_families.csv and pop_free_families.md (also as remedy_families.*, "
        "their old name, for one release; see docs/speed_vs_error.md).");
    cmd->add_option("--out", o->out_dir, "Output directory (created if missing)")->required();
    cmd->add_flag("--quick", o->quick, "Fewer frames (finishes in under a minute); the CSV keeps its layout");
    cmd->add_option("--threads", o->threads, "Worker threads for the bench rows (tbb::global_control)")
        ->check(CLI::Range(1, 64));
    cmd->add_option("--scenes", o->scenes, "Only these scenes, comma-separated")
        ->delimiter(',')
        ->check(CLI::IsMember({"standard", "offscreen", "swaying", "far", "catenary", "helix", "stretched_bend",
                               "hairpin", "random_walk", "churn", "families", "pop_free_families", "remedy_families",
                               "stream", "views"}));
    cmd->add_flag("--no-accuracy", o->skip_accuracy, "Skip accuracy.csv/md, stability.md and the plot");
    cmd->add_flag(
        "--gl", o->gl,
        "Draw with the real WireRenderer (headless EGL: llvmpipe, or a GPU's EGL device): `standard`, `swaying` "
        "and `far` at --size with --wires wires on cpu-mesh and gpu-nodes at 1, 2 and all threads, plus strips "
        "and lines off with the one-draw baseline (bench_gl.csv, bench_gl.md): systems, draw() and GPU ms, draw "
        "commands, bytes, memory; with `swaying` or `stream` selected, the node stream's rows at 1,000, 10,000 "
        "and 100,000 moving wires (--wires: that count) beside this machine's copy floor (bench_gl_stream.csv)");
    cmd->add_option_function<std::string>(
           "--size",
           [o](const std::string& text) {
               const auto size = parse_size_wxh(text);
               if (!size) throw CLI::ValidationError("--size", "expected WxH with whole numbers in [1, 16384], got '" + text + "'");
               o->width_px = size->first, o->height_px = size->second;
           },
           "--gl rows: viewport WxH in pixels (default 1920x1080)");
    cmd->add_option("--wires", o->wires, "--gl rows: wires per scene (default: the scene's, 1,000; far 10,000)")
        ->check(CLI::Range(1, 10000000));
    cmd->add_flag("--no-systems", o->skip_systems, "Skip bench.csv/md (the ECS scenes)");
    cmd->add_option("--spline", o->spline,
                    "Spline of the ECS scenes' wires (bench.csv's method column): "
                    "uniform|centripetal|chordal|c2|auto|linear; default auto (the runtime's default)")
        ->check(CLI::IsMember({"uniform", "centripetal", "chordal", "c2", "auto", "linear"}));
    return [o] { return run_bench(*o); };
}

}  // namespace wiretool
