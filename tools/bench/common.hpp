// `wiretool bench`: what its parts share: options, clocks, medians, the exact upload size of a DrawList, and
// CSV/Markdown writing. The bench parts: systems/ (ECS scenes, bench.csv), accuracy/ (reference scenes,
// accuracy.csv, the plot; families, pop-free blend, DESIGN §5 hard cases). The subcommand's options:
// tools/wiretool/bench_command.cpp.
#pragma once

#include <wire/draw.hpp>

#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace wiretool::bench {

struct Options {
    bool quick = false;
    std::filesystem::path out_dir;
    int threads = 1;  ///< tbb::global_control for the bench rows (the 1-vs-2 thread run is separate)
    std::vector<std::string>
        scenes;                  ///< empty: all; else only these (bench.csv and accuracy.csv scene names)
    bool skip_accuracy = false;  ///< only bench.csv/bench.md
    bool skip_systems = false;   ///< only accuracy/stability outputs
    bool gl = false;             ///< also draw `standard` with the real WireRenderer (headless EGL)
    std::string spline = "auto";  ///< spline of the ECS scenes' wires (bench.csv's method column)
    int width_px = 1920, height_px = 1080;  ///< --gl rows: the viewport (--size WxH)
    int wires = 0;                          ///< --gl rows: wires per scene (--wires; 0: the scene's own count)
};

/// Process CPU time (all threads), milliseconds: robust against other load on a shared machine.
double cpu_ms();
/// Monotonic wall time, milliseconds.
double wall_ms();
/// Median of `v` (0 for an empty vector). Takes a copy.
double median(std::vector<double> v);

/// Bytes WireRenderer::draw() memcpy's into its mapped buffers for a cpu-mesh `list`
/// (wire::render::streamed_upload_bytes): per drawn item a 32-byte draw record, vertices (32 B) with a 4-byte
/// draw index each and indices (4 B); per frame 20 bytes a draw command (one per class and material). Items
/// without geometry are skipped. The nodes path: wire::render::plan_nodes_frame.
std::size_t upload_bytes(const wire::DrawList& list);
/// The same for a cpu-mesh upload of `items` meshes of one material with these totals.
std::size_t cpu_mesh_bytes(std::size_t items, std::size_t vertices, std::size_t indices);
/// The bytes the nodes path writes the first frame it draws one wire of these nodes (plan_nodes_frame: the
/// 64-byte header, the nodes as pack_nodes packs them, the 4-byte list entry); 0 when they cannot be packed.
std::size_t gpu_nodes_bytes(const wire::WireNodes& nodes, const wire::SplineSettings& spline);

/// Whether `scene` is selected by the options.
bool selected(const Options& o, const std::string& scene);

/// A table written both as CSV (exact header) and as a Markdown table.
struct Table {
    std::vector<std::string> header;
    std::vector<std::vector<std::string>> rows;
    void add(std::vector<std::string> row) { rows.push_back(std::move(row)); }
    [[nodiscard]] bool write_csv(const std::filesystem::path& file) const;
    [[nodiscard]] std::string markdown() const;
};

/// Number formatting for the tables: general format with `digits` significant digits; non-finite -> "nan".
std::string num(double v, int digits = 4);
std::string num(std::size_t v);

/// Writes `text` to `file`; false on failure.
[[nodiscard]] bool write_text(const std::filesystem::path& file, const std::string& text);

// The bench parts. Each writes its files into o.out_dir, prints progress to stderr and returns an exit status
// (exit_ok, or exit_failure when a file could not be written).
int run_systems_bench(const Options& o);   ///< bench.csv, bench.md
int run_accuracy_bench(const Options& o);  ///< accuracy.csv, accuracy.md, speed_vs_error.png (gnuplot)
int run_pop_free_bench(const Options& o);   ///< pop_free_families.csv/.md (and remedy_families.*: accuracy/pop_free.cpp)
int run_gl_scale_bench(const Options& o);   ///< bench_gl.csv, bench_gl.md (systems/gl_scale.cpp)
/// The DESIGN §5 hard cases as a Markdown section (case, result, max error).
std::string stability_report();

}  // namespace wiretool::bench
