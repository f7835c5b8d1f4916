// `wiretool bench`, random families (issue 17): every spline method on the random families of wire/families.hpp
// (the same seed and counts as tests/modules/wire/curve_family_test.cpp), reported as distributions of the
// per-case maximum deviation from the exact curve. Writes families.csv and families.md, a Markdown section for
// accuracy.md, and one panel of speed_vs_error.png.
#include "bench/accuracy/families.hpp"

#include <wire/testing/families.hpp>
#include <wire/spline.hpp>

#include <cstdio>
#include <string>
#include <vector>

namespace wiretool::bench {
namespace {

constexpr uint64_t kSeed = 20261124;  // = curve_family_test.cpp

struct SplineMethod {
    const char* name;
    wire::SplineSettings settings;
};

const SplineMethod kMethods[] = {
    {"linear", {.kind = wire::SplineKind::linear}},
    {"uniform", {.kind = wire::SplineKind::catmull_rom, .alpha = 0.0}},
    {"centripetal", {.kind = wire::SplineKind::catmull_rom, .alpha = 0.5}},
    {"chordal", {.kind = wire::SplineKind::catmull_rom, .alpha = 1.0}},
    {"c2", {.kind = wire::SplineKind::c2}},
    {"auto", {.kind = wire::SplineKind::automatic}},
};

}  // namespace

FamilyResults run_family_accuracy(const Options& o) {
    FamilyResults res;
    if (!selected(o, "families")) return res;
    using namespace wire::families;
    struct Family {
        const char* name;
        const char* what;
        std::vector<Case> cases;
    };
    std::vector<Family> families;
    families.push_back({"catenary", "exact catenaries, span 5-60 m, slack 0.5-40%, 5-40 nodes, uniform/end-dense/jittered, any orientation", catenaries(kSeed, 300)});
    families.push_back({"zigzag", "taut zig-zags: 2-5 collinear nodes between corners of 20-120 deg, stretch 1.02-1.10 (truth: the node polyline)", zigzags(kSeed, 100)});
    families.push_back({"helix", "exact helices, radius 0.2-2 m, 5-24 nodes per turn, uniform/jittered", helices(kSeed, 100)});
    families.push_back({"wrapped", "taut cables around sheaves/drums, radius 0.05-1.5 m, wrap 30-180 deg over 1.5-6 elements, stretch 1-5%", wrapped(kSeed, 120)});
    for (const Family& f : families) {
        std::fprintf(stderr, "bench: family %s (%zu cases)\n", f.name, f.cases.size());
        std::vector<double> chordal;
        for (const SplineMethod& m : kMethods) {
            FamilyRow row;
            row.family = f.name;
            row.method = m.name;
            row.cases = f.cases.size();
            std::vector<double> dev;
            for (const Case& c : f.cases) {
                wire::Curve curve;
                if (!wire::build_curve(c.nodes, m.settings, curve).ok()) {
                    dev.push_back(NAN);
                    continue;
                }
                dev.push_back(max_deviation_m(c, curve));
            }
            const Stats s = stats(dev);
            row.mean = s.mean, row.median = s.median, row.p90 = s.p90, row.max = s.max;
            row.worst = std::string("#").append(std::to_string(s.worst)).append(" ").append(f.cases[s.worst].label);
            if (std::string(m.name) == "chordal") chordal = dev;
            if (!chordal.empty() && std::string(m.name) == "auto") {
                double worst_ratio = 0.0;
                for (std::size_t i = 0; i < dev.size(); ++i) worst_ratio = std::max(worst_ratio, dev[i] / chordal[i]);
                res.auto_vs_chordal.push_back({f.name, worst_ratio});
            }
            res.rows.push_back(row);
        }
        res.descriptions.push_back(std::string("- `") + f.name + "` (" + std::to_string(f.cases.size()) + " cases): " + f.what);
    }
    return res;
}

std::string write_family_outputs(const Options& o, const FamilyResults& r) {
    if (r.rows.empty()) return "";
    Table csv;
    csv.header = {"family", "method", "cases", "mean_max_dev_m", "median_max_dev_m", "p90_max_dev_m", "max_max_dev_m", "worst_case"};
    for (const FamilyRow& f : r.rows)
        csv.add({f.family, f.method, num(f.cases), num(f.mean), num(f.median), num(f.p90), num(f.max), f.worst});
    if (!csv.write_csv(o.out_dir / "families.csv")) return "";
    std::string md = "## Random families (issue 17)\n\n";
    md += "Per case the largest distance from the spline through the nodes to the exact curve (the spline "
          "itself, no tessellation: 24 samples per segment, foot points by golden-section search on the exact "
          "curve, or the exact distance to the node polyline for the zig-zags); "
          "per family and method the distribution over the cases (fixed seed 20261124, the cases of "
          "tests/modules/wire/curve_family_test.cpp). `chordal` is three.js's chordal Catmull-Rom.\n\n";
    for (const std::string& d : r.descriptions) md += d + "\n";
    md += "\n" + csv.markdown() + "\n";
    for (const auto& [family, ratio] : r.auto_vs_chordal) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "- `%s`: auto / chordal, worst case %.3g\n", family.c_str(), ratio);
        md += buf;
    }
    if (!write_text(o.out_dir / "families.md", "# wiretool bench: random families\n\n" + md)) return "";
    return md;
}

std::string family_plot_panel(const std::filesystem::path& dat, const FamilyResults& r) {
    if (r.rows.empty()) return "";
    // x: family index + a small offset per method; y: median with a bar from the median to the max, p90 marked.
    std::vector<std::string> fams;
    for (const FamilyRow& f : r.rows)
        if (fams.empty() || fams.back() != f.family) fams.push_back(f.family);
    std::string data, plots;
    const std::size_t nm = std::size(kMethods);
    for (std::size_t m = 0; m < nm; ++m) {
        std::string lines;
        for (const FamilyRow& f : r.rows) {
            if (f.method != kMethods[m].name) continue;
            std::size_t fi = 0;
            while (fams[fi] != f.family) ++fi;
            const double x = static_cast<double>(fi) + (static_cast<double>(m) - 0.5 * static_cast<double>(nm - 1)) * 0.12;
            lines += num(x, 6) + " " + num(std::max(f.median, 1e-7), 6) + " " + num(std::max(f.median, 1e-7), 6) + " " +
                     num(std::max(f.max, 1e-7), 6) + " " + num(std::max(f.p90, 1e-7), 6) + "\n";
        }
        data += "# " + std::string(kMethods[m].name) + "\n" + lines + "\n\n";
        plots += std::string(plots.empty() ? "plot " : ", ") + "'" + dat.string() + "' index " + std::to_string(m) +
                 " using 1:2:3:4 with yerrorbars linecolor " + std::to_string(m + 1) + " pointtype 7 title \"" +
                 kMethods[m].name + "\", '' index " + std::to_string(m) + " using 1:5 with points linecolor " +
                 std::to_string(m + 1) + " pointtype 2 notitle";
    }
    if (!write_text(dat, data)) return "";
    std::string xtics = "set xtics (";
    for (std::size_t i = 0; i < fams.size(); ++i) xtics += (i ? ", \"" : "\"") + fams[i] + "\" " + std::to_string(i);
    xtics += ")\n";
    return "set title \"random families: max deviation per case (dot median, x p90, bar to max; floor 1e-7 m)\"\n"
           "unset logscale x\nset logscale y\nset format y \"%g\"\nset yrange [1e-7:*]\nset xrange [-0.6:" + std::to_string(fams.size() - 1) + ".6]\n" + xtics +
           "set xlabel \"family\"\nset ylabel \"max deviation from the exact curve (m)\"\n" + plots + "\n";
}

}  // namespace wiretool::bench
