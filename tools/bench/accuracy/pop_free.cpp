// `wiretool bench`: the pop-free blend over random node-event families (wire/testing/pop_free_family.hpp), per
// spline method: pop_free_families.csv and .md (distributions of the instant pop, the per-frame jump, the
// lag and the settling time; the worst ratios and the worst case).
#include "bench/common.hpp"
#include "wiretool/commands.hpp"

#include <wire/testing/pop_free_family.hpp>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace wiretool::bench {
namespace {

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5)];
}

struct PopFreeMethod {
    const char* name;
    wire::SplineSettings spline;
};

}  // namespace

int run_pop_free_bench(const Options& o) {
    using wire::SplineKind;
    const PopFreeMethod methods[] = {
        {"linear", {.kind = SplineKind::linear}},
        {"uniform", {.kind = SplineKind::catmull_rom, .alpha = 0.0}},
        {"centripetal", {.kind = SplineKind::catmull_rom, .alpha = 0.5}},
        {"chordal", {.kind = SplineKind::catmull_rom, .alpha = 1.0}},
        {"c2", {.kind = SplineKind::c2}},
        {"auto", {.kind = SplineKind::automatic}},
    };
    const wire::PopFreeSettings defaults{};
    Table csv;
    csv.header = {"family", "method", "events", "closed_events", "overlapped_events", "frames",
                  "pop_median_m", "pop_p90_m", "pop_max_m", "jump_median_m", "jump_p90_m", "jump_max_m",
                  "lag_median_m", "lag_p90_m", "lag_max_m", "settle_median_s", "settle_p90_s", "settle_max_s",
                  "max_jump_over_pop", "max_lag_over_pop", "max_settled_gap_m", "large_events"};
    std::string worst;
    for (std::size_t k = 0; k < std::size(methods); ++k) {
        std::fprintf(stderr, "bench: pop-free family %s\n", methods[k].name);
        wire::PopFreeFamilySettings s;
        s.spline = methods[k].spline;
        s.cables = o.quick ? 10 : 40;  // 130 or 520 events, half on closed loops
        s.seed = 17 + k;
        const wire::PopFreeFamilyResult r = wire::run_pop_free_family(s);
        if (!r.error.empty()) {
            std::fprintf(stderr, "wiretool bench: pop-free family %s: %s\n", methods[k].name, r.error.c_str());
            return exit_failure;
        }
        std::vector<double> pop, jump, lag, settle;
        std::size_t closed = 0, overlapped = 0;
        for (const wire::PopFreeEvent& e : r.events) {
            pop.push_back(e.pop_m), jump.push_back(e.jump_m), lag.push_back(e.lag_m);
            settle.push_back(e.frames * defaults.frame_s);
            closed += e.closed, overlapped += e.overlapped;
        }
        csv.add({"insert_remove", methods[k].name, num(r.events.size()), num(closed), num(overlapped), num(r.frames),
                 num(quantile(pop, 0.5)), num(quantile(pop, 0.9)), num(quantile(pop, 1.0)), num(quantile(jump, 0.5)),
                 num(quantile(jump, 0.9)), num(quantile(jump, 1.0)), num(quantile(lag, 0.5)), num(quantile(lag, 0.9)),
                 num(quantile(lag, 1.0)), num(quantile(settle, 0.5)), num(quantile(settle, 0.9)),
                 num(quantile(settle, 1.0)), num(r.max_jump_ratio), num(r.max_lag_ratio), num(r.max_settled_gap_m),
                 num(r.large_events)});
        worst += std::string("- `") + methods[k].name + "`: largest jump/pop at " + r.worst_jump + "; largest lag/pop at " +
                 r.worst_lag + "\n";
    }
    std::string md = "# wiretool bench: the pop-free blend over random node events\n\n";
    md += "Per method, " + std::string(o.quick ? "10" : "40") +
          " random 20-40 m cables (half hanging catenaries, half closed loops; 16-48 nodes), 13 events each: a node "
          "inserted exactly on the curve, a node removed anywhere (a loop's seam node included), an end node "
          "re-created under a new id; 0-40 frames apart, so most events overlap others. Per event: `pop` the instant "
          "pop (exact curves before and after), `jump` the largest per-frame jump of the drawn curve while it ran, "
          "`lag` the largest distance between the drawn and the exact curve while it ran, `settle` its geomorph's "
          "length. Ratios are per frame, against the sum of the pops of the events running then. Distances are "
          "symmetric Hausdorff distances with exact foot points (wire::curve_distance_m). `large_events`: changes "
          "whose offset exceeds what 2 mm a frame can carry within the longest geomorph (they move by up to "
          "1.5 max|D| / N_max a frame).\n\n";
    md += csv.markdown() + "\nWorst cases:\n\n" + worst;
    // pop_free_families.*, and the same files under their old name remedy_families.* for one release.
    for (const char* name : {"pop_free_families", "remedy_families"}) {
        const std::filesystem::path file = o.out_dir / (std::string(name) + ".csv");
        if (!csv.write_csv(file) || !write_text(o.out_dir / (std::string(name) + ".md"), md)) {
            std::fprintf(stderr, "wiretool bench: cannot write %s and its .md\n", file.c_str());
            return exit_failure;
        }
    }
    return exit_ok;
}

}  // namespace wiretool::bench
