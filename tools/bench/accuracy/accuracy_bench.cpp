// `wiretool bench`, part 2: speed against error. Reference scenes whose exact answer is generated in code
// (catenary, helix, stretched run + tight bend, hairpin, smooth random curve, churn), every spline method,
// three frame methods and five LOD tolerances; per row time, size, world/screen/twist error and pops. Writes
// accuracy.csv, accuracy.md, stability.md and speed_vs_error.png (gnuplot, when installed).
// The steps: the random families (families.hpp), the reference scenes (scenes/reference_scenes.hpp), per
// scene and method the rows (rows.hpp) and pops (pops.hpp), then the report (accuracy_report.hpp) and
// stability.md.
#include "bench/accuracy/accuracy_report.hpp"
#include "bench/accuracy/families.hpp"
#include "bench/accuracy/methods.hpp"
#include "bench/accuracy/pops.hpp"
#include "bench/accuracy/rows.hpp"
#include "bench/common.hpp"
#include "bench/scenes/reference_scenes.hpp"
#include "wiretool/commands.hpp"

#include <cstdio>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace wiretool::bench {
namespace {

// Every method on one scene at every tolerance, with the scene's pops (per curve: frame variants share their
// spline's), appended to `rows`.
void measure_scene(const Options& o, const ReferenceScene& s, std::vector<Row>& rows) {
    const double min_ms = o.quick ? 0.3 : 3.0;
    const int churn_frames = o.quick ? 60 : 200;
    const int pop_samples = o.quick ? kQuickPopSamplesPerSegment : kPopSamplesPerSegment;
    std::fprintf(stderr, "bench: accuracy %s\n", s.name.c_str());
    std::map<std::string, Pops> pops;  // per curve (frame variants share their spline's)
    for (const Method& m : methods()) {
        wire::WireNodes nodes = s.nodes;
        if (m.physics) add_physics(nodes, s.stretch);
        if (s.churn) {
            const std::vector<wire::WireNodes> states = churn_states(nodes, m.spline, churn_frames);
            if (!pops.count(m.spline_key)) pops[m.spline_key] = churn_pops(states, m.spline, pop_samples);
            for (double tol : kTolerancesPx) rows.push_back(measure_churn_row(s, m, states, tol));
        } else {
            if (!pops.count(m.spline_key)) pops[m.spline_key] = event_pops(nodes, m.spline, pop_samples);
            for (double tol : kTolerancesPx) rows.push_back(measure_row(s, m, nodes, tol, min_ms));
        }
        for (std::size_t k = rows.size() - std::size(kTolerancesPx); k < rows.size(); ++k) {
            rows[k].pop_m = pops[m.spline_key].unblended_m;
            rows[k].pop_blended_m = pops[m.spline_key].blended_m;
        }
    }
}

}  // namespace

int run_accuracy_bench(const Options& o) {
    const FamilyResults families = run_family_accuracy(o);
    const std::vector<ReferenceScene> scenes = reference_scenes(o);
    std::vector<Row> rows;
    for (const ReferenceScene& s : scenes) measure_scene(o, s, rows);

    std::string plot_note;
    if (const int st = write_accuracy_report(o, scenes, rows, families, plot_note); st != exit_ok) return st;
    std::fprintf(stderr, "bench: stability cases\n");
    if (!write_text(o.out_dir / "stability.md", stability_report())) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "stability.md").c_str());
        return exit_failure;
    }
    std::fprintf(stderr, "bench: %s\n", plot_note.c_str());
    return exit_ok;
}

}  // namespace wiretool::bench
