// `wiretool bench` against its contract: file names, exact CSV headers, row counts, finite numbers, and the
// accuracy figures the bench exists to show. Timings are never checked (the machine is shared and loaded).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <sys/wait.h>
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
        for (std::string c; std::getline(ss, c, ','); ++i) row[i < csv.columns.size() ? csv.columns[i] : "?"] = c;
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
    EXPECT_TRUE(end != it->second.c_str() && *end == '\0') << key << " = '" << it->second << "' is not a number";
    return v;
}

const std::map<std::string, std::string>* find(const Rows& rows, const std::map<std::string, std::string>& keys) {
    for (const auto& r : rows) {
        bool ok = true;
        for (const auto& [k, v] : keys) ok = ok && r.count(k) && r.at(k) == v;
        if (ok) return &r;
    }
    return nullptr;
}

// One quick run shared by the tests of this file (the bench is the expensive part; each test only reads).
class WiretoolBench : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        dir_ = new fs::path(fs::temp_directory_path() / "wiretool_bench_test");
        fs::remove_all(*dir_);
        const std::string cmd = std::string(WIRETOOL_PATH) + " bench --quick --scenes " + kScenes + " --out " +
                                dir_->string() + " > " + (fs::temp_directory_path() / "wiretool_bench_test.log").string() +
                                " 2>&1";
        const int raw = std::system(cmd.c_str());
        status_ = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    }
    static void TearDownTestSuite() {
        fs::remove_all(*dir_);
        delete dir_;
    }
    static constexpr const char* kScenes = "standard,offscreen,catenary,helix,stretched_bend,churn";
    static fs::path* dir_;
    static int status_;
};
fs::path* WiretoolBench::dir_ = nullptr;
int WiretoolBench::status_ = -1;

TEST_F(WiretoolBench, BenchCsvContract) {
    ASSERT_EQ(status_, 0);
    const Csv csv = read_csv(*dir_ / "bench.csv");
    EXPECT_EQ(csv.header,
              "scene,method,mode,tolerance_px,wires,visible_wires,rings,vertices,bytes_uploaded,cpu_ms_per_frame,"
              "ns_per_vertex,max_screen_error_px");
    EXPECT_TRUE(fs::exists(*dir_ / "bench.md"));
    ASSERT_EQ(csv.rows.size(), 6u) << "2 scenes x {cpu-mesh, gpu-rings, uniform}";
    for (const auto& r : csv.rows) {
        for (const std::string& c : csv.columns) {
            if (c == "scene" || c == "method" || c == "mode") continue;
            const double v = number(r, c);
            EXPECT_TRUE(std::isfinite(v) && v >= 0.0) << c << " in " << r.at("scene") << "/" << r.at("mode");
        }
        EXPECT_TRUE(r.at("mode") == "cpu-mesh" || r.at("mode") == "gpu-rings" || r.at("mode") == "uniform");
        EXPECT_EQ(number(r, "wires"), 1000.0);
    }
    for (const char* scene : {"standard", "offscreen"})
        for (const char* mode : {"cpu-mesh", "gpu-rings", "uniform"})
            EXPECT_NE(find(csv.rows, {{"scene", scene}, {"mode", mode}}), nullptr) << scene << " " << mode;

    const auto* cpu = find(csv.rows, {{"scene", "standard"}, {"mode", "cpu-mesh"}});
    const auto* gpu = find(csv.rows, {{"scene", "standard"}, {"mode", "gpu-rings"}});
    const auto* uni = find(csv.rows, {{"scene", "standard"}, {"mode", "uniform"}});
    ASSERT_TRUE(cpu && gpu && uni);
    EXPECT_GT(number(*cpu, "visible_wires"), 0.0);
    // Adaptive: fewer vertices than the uniform tessellation that reaches no better error.
    EXPECT_LT(number(*cpu, "vertices"), number(*uni, "vertices"));
    EXPECT_LE(number(*uni, "max_screen_error_px"), number(*cpu, "max_screen_error_px") + 1e-9);
    EXPECT_LE(number(*cpu, "max_screen_error_px"), number(*cpu, "tolerance_px"));
    EXPECT_LT(number(*gpu, "bytes_uploaded"), number(*cpu, "bytes_uploaded"));
    EXPECT_EQ(number(*gpu, "rings"), number(*cpu, "rings")) << "both paths draw the same tessellation";

    for (const char* mode : {"cpu-mesh", "gpu-rings"}) {
        const auto* off = find(csv.rows, {{"scene", "offscreen"}, {"mode", mode}});
        ASSERT_TRUE(off);
        EXPECT_EQ(number(*off, "visible_wires"), 0.0);
        EXPECT_EQ(number(*off, "rings"), 0.0);
        EXPECT_EQ(number(*off, "bytes_uploaded"), 0.0);
    }
}

}  // namespace
