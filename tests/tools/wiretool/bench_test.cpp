// `wiretool bench` against its contract: file names, exact CSV headers, row counts, finite numbers, and the
// accuracy figures the bench exists to show. Timings are never checked (the machine is shared and loaded).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

using Rows = std::vector<std::map<std::string, std::string>>;

struct Csv {
    std::string header;
    std::vector<std::string> columns;
    Rows rows;
};

Csv read_csv(const fs::path& file) {
    Csv csv;
    std::ifstream in(file);
    std::getline(in, csv.header);
    std::stringstream hs(csv.header);
    for (std::string c; std::getline(hs, c, ',');) csv.columns.push_back(c);
    for (std::string line; std::getline(in, line);) {
        std::stringstream ss(line);
        std::map<std::string, std::string> row;
        std::size_t i = 0;
        for (std::string c; std::getline(ss, c, ','); ++i)
            row[i < csv.columns.size() ? csv.columns[i] : "?"] = c;
        EXPECT_EQ(i, csv.columns.size()) << file << ": " << line;
        csv.rows.push_back(row);
    }
    return csv;
}

double number(const std::map<std::string, std::string>& row, const std::string& key) {
    const auto it = row.find(key);
    if (it == row.end()) {
        ADD_FAILURE() << "missing column " << key;
        return NAN;
    }
    char* end = nullptr;
    const double v = std::strtod(it->second.c_str(), &end);
    EXPECT_TRUE(end != it->second.c_str() && *end == '\0')
        << key << " = '" << it->second << "' is not a number";
    return v;
}

const std::map<std::string, std::string>* find(const Rows& rows,
                                               const std::map<std::string, std::string>& keys) {
    for (const auto& r : rows) {
        bool ok = true;
        for (const auto& [k, v] : keys) ok = ok && r.count(k) && r.at(k) == v;
        if (ok) return &r;
    }
    return nullptr;
}

// The bench's outputs in a fresh directory (one run serves every check below: ctest runs each TEST in its own
// process, so the checks are one TEST rather than a suite sharing a fixture).
const fs::path& out_dir() {
    static const fs::path dir =
        fs::temp_directory_path() / ("wiretool_bench_test_" + std::to_string(::getpid()));
    return dir;
}

void check_bench_csv(const fs::path& dir) {
    const Csv csv = read_csv(dir / "bench.csv");
    EXPECT_EQ(
        csv.header,
        "scene,method,mode,tolerance_px,wires,visible_wires,rings,vertices,bytes_uploaded,cpu_ms_per_frame,"
        "ns_per_vertex,max_screen_error_px");
    EXPECT_TRUE(fs::exists(dir / "bench.md"));
    ASSERT_EQ(csv.rows.size(), 6u) << "2 scenes x {cpu-mesh, gpu-nodes, uniform}";
    for (const auto& r : csv.rows) {
        for (const std::string& c : csv.columns) {
            if (c == "scene" || c == "method" || c == "mode") continue;
            const double v = number(r, c);
            EXPECT_TRUE(std::isfinite(v) && v >= 0.0) << c << " in " << r.at("scene") << "/" << r.at("mode");
        }
        EXPECT_TRUE(r.at("mode") == "cpu-mesh" || r.at("mode") == "gpu-nodes" || r.at("mode") == "uniform");
        EXPECT_EQ(number(r, "wires"), 1000.0);
    }
    for (const char* scene : {"standard", "offscreen"})
        for (const char* mode : {"cpu-mesh", "gpu-nodes", "uniform"})
            EXPECT_NE(find(csv.rows, {{"scene", scene}, {"mode", mode}}), nullptr) << scene << " " << mode;

    const auto* cpu = find(csv.rows, {{"scene", "standard"}, {"mode", "cpu-mesh"}});
    const auto* gpu = find(csv.rows, {{"scene", "standard"}, {"mode", "gpu-nodes"}});
    const auto* uni = find(csv.rows, {{"scene", "standard"}, {"mode", "uniform"}});
    ASSERT_TRUE(cpu && gpu && uni);
    // The nodes path: the camera moves, the wires do not, so a frame sends at most the list of visible wires'
    // slots (4 bytes each; the aim: at least 20x fewer bytes than cpu-mesh). Bytes are exact counts.
    EXPECT_LE(number(*gpu, "bytes_uploaded"), 4.0 * number(*gpu, "visible_wires"));
    EXPECT_LE(20.0 * number(*gpu, "bytes_uploaded"), number(*cpu, "bytes_uploaded"));
    EXPECT_GT(number(*gpu, "visible_wires"), 0.0);
    EXPECT_GT(number(*cpu, "visible_wires"), 0.0);
    // Adaptive: fewer vertices than the uniform tessellation that reaches no better error.
    EXPECT_LT(number(*cpu, "vertices"), number(*uni, "vertices"));
    EXPECT_LE(number(*uni, "max_screen_error_px"), number(*cpu, "max_screen_error_px") + 1e-9);
    EXPECT_LE(number(*cpu, "max_screen_error_px"), number(*cpu, "tolerance_px"));
    EXPECT_EQ(number(*gpu, "rings"), 0.0) << "the nodes path's rings are the GPU's (bench --gl)";

    for (const char* mode : {"cpu-mesh", "gpu-nodes"}) {
        const auto* off = find(csv.rows, {{"scene", "offscreen"}, {"mode", mode}});
        ASSERT_TRUE(off);
        // The nodes path lists the automatic spline's wires (no sphere to cull by on the CPU) and the GPU culls
        // them; still wires send nothing after their first frame either way.
        if (std::string(mode) == "cpu-mesh") {
            EXPECT_EQ(number(*off, "visible_wires"), 0.0);
        }
        EXPECT_EQ(number(*off, "rings"), 0.0);
        EXPECT_EQ(number(*off, "bytes_uploaded"), 0.0);
    }
}

void check_accuracy_csv(const fs::path& dir) {
    const Csv csv = read_csv(dir / "accuracy.csv");
    EXPECT_EQ(
        csv.header,
        "scene,method,tolerance_px,rings,sides,vertices,bytes_cpu_mesh,bytes_gpu_nodes,ns_per_vertex,"
        "us_per_wire_cpu_mesh,us_per_wire_gpu_nodes,max_world_error_m,max_screen_error_px,max_twist_deg,"
        "max_pop_m,max_pop_blended_m,max_pop_remedy_m");
    EXPECT_TRUE(fs::exists(dir / "accuracy.md"));
    EXPECT_TRUE(fs::exists(dir / "stability.md"));
    const std::vector<std::string> scenes = {"catenary", "helix", "stretched_bend", "churn"};
    const std::vector<std::string> methods = {"linear",
                                              "uniform",
                                              "centripetal",
                                              "chordal",
                                              "c2",
                                              "auto",
                                              "curvature_tension",
                                              "centripetal+rotation",
                                              "centripetal+projection"};
    const std::vector<std::string> tolerances = {"0.1", "0.25", "0.5", "1", "2"};
    ASSERT_EQ(csv.rows.size(), scenes.size() * methods.size() * tolerances.size());
    for (const auto& scene : scenes)
        for (const auto& method : methods)
            for (const auto& tol : tolerances)
                EXPECT_NE(find(csv.rows, {{"scene", scene}, {"method", method}, {"tolerance_px", tol}}),
                          nullptr)
                    << scene << " " << method << " " << tol;
    for (const auto& r : csv.rows) {
        for (const std::string& c : csv.columns) {
            if (c == "scene" || c == "method") continue;
            const double v = number(r, c);
            EXPECT_TRUE(std::isfinite(v) && v >= 0.0)
                << c << " in " << r.at("scene") << "/" << r.at("method");
        }
        EXPECT_GT(number(r, "rings"), 0.0);
        EXPECT_LT(number(r, "bytes_gpu_nodes"), number(r, "bytes_cpu_mesh"));
        EXPECT_GT(number(r, "bytes_gpu_nodes"), 64.0) << "a header and the nodes";
        // The LOD's promise, measured: the drawn centre line is within the tolerance on screen.
        EXPECT_LE(number(r, "max_screen_error_px"), number(r, "tolerance_px") * (1.0 + 1e-9))
            << r.at("scene") << "/" << r.at("method") << " at " << r.at("tolerance_px");
    }
}

// The figures, as accuracy bounds: double reflection's twist error is at least 100x below the
// rotation method's at equal rings (helix), the pop-free blend keeps every frame's pop under 1 mm on the 20
// m cable while nodes come and go, and the automatic spline keeps a stretched run on its straight line.
void check_accuracy_figures(const fs::path& dir) {
    const Csv csv = read_csv(dir / "accuracy.csv");
    for (const char* tol : {"0.1", "0.25", "0.5", "1", "2"}) {
        const auto* dr =
            find(csv.rows, {{"scene", "helix"}, {"method", "centripetal"}, {"tolerance_px", tol}});
        const auto* rot =
            find(csv.rows, {{"scene", "helix"}, {"method", "centripetal+rotation"}, {"tolerance_px", tol}});
        const auto* proj =
            find(csv.rows, {{"scene", "helix"}, {"method", "centripetal+projection"}, {"tolerance_px", tol}});
        ASSERT_TRUE(dr && rot && proj);
        EXPECT_EQ(number(*dr, "rings"), number(*rot, "rings")) << "equal rings";
        EXPECT_LE(100.0 * number(*dr, "max_twist_deg"), number(*rot, "max_twist_deg"))
            << "at " << tol << " px";
        EXPECT_LT(number(*rot, "max_twist_deg"), number(*proj, "max_twist_deg")) << "at " << tol << " px";
    }
    // churn: nodes inserted on the curve and removed again over 60 frames; catenary: one node inserted on the
    // curve, then an original node removed. The blend keeps each frame under 1/10 of the event's offset and
    // under PopFreeSettings::max_step_m (1 mm) unless the change exceeds what 1 mm a frame carries within the
    // longest blend (4 s: 16 cm; pop_free.hpp); these events stay below that.
    for (const char* scene : {"churn", "catenary"}) {
        for (const char* method :
             {"linear", "uniform", "centripetal", "chordal", "c2", "auto", "curvature_tension"}) {
            const auto* r = find(csv.rows, {{"scene", scene}, {"method", method}, {"tolerance_px", "0.5"}});
            ASSERT_TRUE(r);
            EXPECT_LT(number(*r, "max_pop_blended_m"), 1e-3) << scene << " " << method;
            EXPECT_LE(number(*r, "max_pop_blended_m"), 0.2 * number(*r, "max_pop_m") * (1.0 + 1e-3) + 1e-12)
                << scene << " " << method;
            if (std::string(method) !=
                "linear") {  // a node inserted on a polyline changes nothing: no pop to pop-free blend
                EXPECT_LT(number(*r, "max_pop_blended_m"), number(*r, "max_pop_m")) << scene << " " << method;
            }
            // The old column name, kept for one release, repeats the new one.
            EXPECT_EQ(r->at("max_pop_remedy_m"), r->at("max_pop_blended_m")) << scene << " " << method;
        }
    }
    for (const char* method : {"auto", "curvature_tension", "linear"}) {
        const auto* r =
            find(csv.rows, {{"scene", "stretched_bend"}, {"method", method}, {"tolerance_px", "0.1"}});
        ASSERT_TRUE(r);
        EXPECT_LT(number(*r, "max_world_error_m"), 1e-4) << method << ": the stretched run leaves its line";
    }
    // Splines beat the node polyline on the hanging cable.
    const auto* lin = find(csv.rows, {{"scene", "catenary"}, {"method", "linear"}, {"tolerance_px", "0.1"}});
    const auto* c2 = find(csv.rows, {{"scene", "catenary"}, {"method", "c2"}, {"tolerance_px", "0.1"}});
    ASSERT_TRUE(lin && c2);
    EXPECT_LT(number(*c2, "max_world_error_m"), number(*lin, "max_world_error_m"));
}

void check_stability_and_plot(const fs::path& dir) {
    std::ifstream in(dir / "stability.md");
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string md = ss.str();
    for (const char* c : {"| coincident nodes (exact) | ok", "| NaN in a node | error: node 2",
                          "| 0 nodes | error:", "| 100,000-node wire", "| closed loop of 3 nodes | ok",
                          "| 1,000 chained bend segments closing a full circle | ok"})
        EXPECT_NE(md.find(c), std::string::npos) << c;
    EXPECT_EQ(md.find("NON-FINITE"), std::string::npos);
    if (std::system("gnuplot --version > /dev/null 2>&1") == 0) {
        EXPECT_TRUE(fs::exists(dir / "speed_vs_error.png"));
        EXPECT_GT(fs::file_size(dir / "speed_vs_error.png"), 1000u);
    }
}

// The pop-free blend over random node-event families: one row per method, the distributions finite, every blend
// settled exactly, and the issue-17 ratios (per-frame jump <= 1/5 of the running events' pops, lag <= those pops)
// held. Uniform Catmull-Rom is the known exception (docs/speed_vs_error.md): its parameter speed varies so much
// inside a segment that the parameter-to-parameter correspondence of a few events slides far along the curve.
void check_pop_free_csv(const fs::path& dir) {
    const Csv csv = read_csv(dir / "pop_free_families.csv");
    EXPECT_EQ(csv.header,
              "family,method,events,closed_events,overlapped_events,frames,pop_median_m,pop_p90_m,pop_max_m,"
              "jump_median_m,jump_p90_m,jump_max_m,lag_median_m,lag_p90_m,lag_max_m,settle_median_s,settle_p90_s,"
              "settle_max_s,max_jump_over_pop,max_lag_over_pop,max_settled_gap_m,large_events");
    EXPECT_TRUE(fs::exists(dir / "pop_free_families.md"));
    // The old names, kept for one release: the same files.
    const auto text = [](const fs::path& file) {
        std::ifstream in(file);
        return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    EXPECT_EQ(text(dir / "remedy_families.csv"), text(dir / "pop_free_families.csv"));
    EXPECT_EQ(text(dir / "remedy_families.md"), text(dir / "pop_free_families.md"));
    ASSERT_EQ(csv.rows.size(), 6u);
    for (const auto& r : csv.rows) {
        const std::string& m = r.at("method");
        for (const std::string& c : csv.columns) {
            if (c == "family" || c == "method") continue;
            const double v = number(r, c);
            EXPECT_TRUE(std::isfinite(v) && v >= 0.0) << c << " in " << m;
        }
        EXPECT_GE(number(r, "events"), 130.0) << m;
        EXPECT_GT(number(r, "closed_events"), 40.0) << m;
        EXPECT_LE(number(r, "max_settled_gap_m"), 1e-6) << m;
        EXPECT_LE(number(r, "settle_max_s"), 4.0 + 1e-9) << m;
        if (m != "uniform") {
            EXPECT_LE(number(r, "max_jump_over_pop"), 0.2) << m;
            EXPECT_LE(number(r, "max_lag_over_pop"), 1.0 + 1e-3) << m;  // (printed to 4 digits)
        }
    }
}

// `--gl` rows (bench_gl.csv): every selected scene on both paths (cpu-mesh, gpu-nodes) at
// 1, 2 and all threads, then strips and lines off with the one-draw baseline; the bytes draw() sent equal the computed plan on every frame, the baseline is one
// command over exactly the triangles of the tube-only rows.
TEST(WiretoolBench, GlRowsAtScale) {
    const fs::path dir = out_dir().string() + "_gl";
    fs::remove_all(dir);
    const std::string cmd = std::string(WIRETOOL_PATH) +
                            " bench --quick --gl --no-systems --no-accuracy --scenes standard,swaying --wires 40 "
                            "--size 320x180 --out " + dir.string() + " > " + (dir.string() + ".log") + " 2>&1";
    const int raw = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << "see " << dir.string() << ".log";
    ASSERT_TRUE(fs::exists(dir / "bench_gl.md"));
    if (!fs::exists(dir / "bench_gl.csv")) GTEST_SKIP() << "no headless GL here (bench_gl.md says why)";
    const Csv csv = read_csv(dir / "bench_gl.csv");
    for (const char* c : {"scene", "wires", "width", "height", "threads", "path", "thin_wires", "systems_wall_ms",
                          "draw_ms", "gpu_ms", "end_to_end_ms", "draw_commands", "draw_calls", "bytes_per_frame",
                          "bytes_mismatch_frames", "wire_memory_bytes", "gpu_buffer_bytes", "gpu_vs_one_draw"})
        EXPECT_NE(std::find(csv.columns.begin(), csv.columns.end(), c), csv.columns.end()) << c;
    std::set<std::string> threads;
    for (const auto& r : csv.rows) threads.insert(r.at("threads"));
    EXPECT_TRUE(threads.count("1") && threads.count("2"));
    ASSERT_EQ(csv.rows.size(), 2 * (2 * threads.size() + 3)) << "2 scenes x (2 paths x threads + 3 tube-only rows)";
    for (const char* scene : {"standard", "swaying"}) {
        const auto* base = find(csv.rows, {{"scene", scene}, {"path", "one-draw baseline"}});
        ASSERT_TRUE(base) << scene;
        EXPECT_EQ(number(*base, "draw_commands"), 1.0);
        EXPECT_EQ(number(*base, "draw_calls"), 1.0);
        EXPECT_GT(number(*base, "triangles"), 1000.0);
        {
            const auto* tubes = find(csv.rows, {{"scene", scene}, {"path", "cpu-mesh"}, {"thin_wires", "off"}});
            ASSERT_TRUE(tubes) << scene;
            EXPECT_EQ(number(*tubes, "triangles"), number(*base, "triangles")) << scene;
            EXPECT_GT(number(*tubes, "gpu_vs_one_draw"), 0.0);
        }
        // The nodes path draws the GPU's LOD at node resolution (its triangles are counted on the GPU, not here).
        for (const char* thin : {"on", "off"})
            EXPECT_TRUE(find(csv.rows, {{"scene", scene}, {"path", "gpu-nodes"}, {"thin_wires", thin}})) << scene << " " << thin;
    }
    {
        std::ifstream md(dir / "bench_gl.md");
        const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
        EXPECT_NE(text.find("## The nodes path against cpu-mesh"), std::string::npos);
    }
    for (const auto& r : csv.rows) {
        EXPECT_EQ(number(r, "bytes_mismatch_frames"), 0.0) << r.at("scene") << " " << r.at("path");
        EXPECT_EQ(number(r, "wires"), 40.0);
        EXPECT_EQ(number(r, "width"), 320.0);
        EXPECT_EQ(number(r, "height"), 180.0);
        EXPECT_GT(number(r, "visible"), 0.0);
        if (r.at("path") == "gpu-nodes" && r.at("scene") == "standard") {
            // Still wires under a moving camera: at most their slots, and only in frames where that list changes.
            EXPECT_LE(number(r, "bytes_per_frame"), 4.0 * number(r, "visible"));
        } else {
            EXPECT_GT(number(r, "bytes_per_frame"), 0.0) << r.at("scene") << " " << r.at("path");
        }
    }
    // A size that is not WxH is a usage error (exit 2).
    const int bad = std::system((std::string(WIRETOOL_PATH) + " bench --gl --size 12by7 --out " + dir.string() +
                                 "_bad > /dev/null 2>&1").c_str());
    EXPECT_TRUE(WIFEXITED(bad) && WEXITSTATUS(bad) == 2);
    if (!::testing::Test::HasFailure()) {
        fs::remove_all(dir);
        fs::remove(dir.string() + ".log");
    }
}

}  // namespace

// `wiretool bench --quick` on a subset of scenes (keeps the test well under a minute), then every check.
TEST(WiretoolBench, QuickRunHonoursTheContract) {
    const fs::path& dir = out_dir();
    fs::remove_all(dir);
    const std::string cmd =
        std::string(WIRETOOL_PATH) +
        " bench --quick --scenes standard,offscreen,catenary,helix,stretched_bend,churn,pop_free_families --out " +
        dir.string() + " > " + (dir.string() + ".log") + " 2>&1";
    const int raw = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << "see " << dir.string() << ".log";
    {
        SCOPED_TRACE("bench.csv");
        check_bench_csv(dir);
    }
    {
        SCOPED_TRACE("accuracy.csv");
        check_accuracy_csv(dir);
    }
    {
        SCOPED_TRACE("accuracy figures");
        check_accuracy_figures(dir);
    }
    {
        SCOPED_TRACE("stability.md and plot");
        check_stability_and_plot(dir);
    }
    {
        SCOPED_TRACE("pop_free_families.csv");
        check_pop_free_csv(dir);
    }
    if (!::testing::Test::HasFailure()) {
        fs::remove_all(dir);
        fs::remove(dir.string() + ".log");
    }
}

// The `far` scene (10,000 cables over a 2 km landscape): the same rows as the other scenes, the uniform baseline
// included, and the adaptive LOD below the node resolution drawing far fewer vertices within the tolerance.
TEST(WiretoolBench, FarSceneRows) {
    const fs::path dir = out_dir().string() + "_far";
    fs::remove_all(dir);
    const std::string cmd = std::string(WIRETOOL_PATH) + " bench --quick --no-accuracy --scenes far --out " +
                            dir.string() + " > " + (dir.string() + ".log") + " 2>&1";
    const int raw = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << "see " << dir.string() << ".log";
    const Csv csv = read_csv(dir / "bench.csv");
    ASSERT_EQ(csv.rows.size(), 3u) << "far x {cpu-mesh, gpu-nodes, uniform}";
    const auto* cpu = find(csv.rows, {{"scene", "far"}, {"mode", "cpu-mesh"}});
    const auto* gpu = find(csv.rows, {{"scene", "far"}, {"mode", "gpu-nodes"}});
    const auto* uni = find(csv.rows, {{"scene", "far"}, {"mode", "uniform"}});
    ASSERT_TRUE(cpu && gpu && uni);
    for (const auto* r : {cpu, gpu, uni}) EXPECT_EQ(number(*r, "wires"), 10000.0);
    EXPECT_GT(number(*cpu, "visible_wires"), 1000.0);
    EXPECT_LT(number(*cpu, "visible_wires"), 10000.0) << "some cables are out of view";
    EXPECT_LE(number(*cpu, "max_screen_error_px"), number(*cpu, "tolerance_px"));
    EXPECT_LE(number(*uni, "max_screen_error_px"), number(*cpu, "max_screen_error_px") + 1e-9);
    EXPECT_LT(number(*cpu, "rings"), number(*uni, "rings") / 3.0) << "spans below the node resolution";
    EXPECT_GT(number(*gpu, "visible_wires"), 1000.0);
    EXPECT_LE(number(*gpu, "bytes_uploaded"), 4.0 * number(*gpu, "visible_wires")) << "still cables: slots only";
    std::ifstream md(dir / "bench.md");
    const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("Per-system CPU ms per frame, `far`"), std::string::npos);
    EXPECT_NE(text.find("adaptive vs uniform at equal max screen error (`far`"), std::string::npos);
    if (!::testing::Test::HasFailure()) {
        fs::remove_all(dir);
        fs::remove(dir.string() + ".log");
    }
}
