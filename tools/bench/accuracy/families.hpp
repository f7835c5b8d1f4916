// `wiretool bench`: the random-family part (families.cpp). Runs when the scene `families` is selected
// (every run without --scenes); writes families.csv / families.md and adds a section and a plot panel.
#pragma once

#include "bench/common.hpp"

#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace wiretool::bench {

struct FamilyRow {
    std::string family, method;
    std::size_t cases = 0;
    double mean = 0.0, median = 0.0, p90 = 0.0, max = 0.0;  ///< of the per-case max deviation, metres
    std::string worst;                                        ///< "#index label" of the case with the max
};

struct FamilyResults {
    std::vector<FamilyRow> rows;
    std::vector<std::string> descriptions;
    std::vector<std::pair<std::string, double>> auto_vs_chordal;  ///< per family: worst per-case ratio
};

/// Every spline method on every family (empty when `families` is not selected).
FamilyResults run_family_accuracy(const Options& o);
/// Writes families.csv and families.md; returns the Markdown section for accuracy.md ("" if nothing to write
/// or a file could not be written).
std::string write_family_outputs(const Options& o, const FamilyResults& r);
/// Writes the panel's data to `dat` and returns its gnuplot commands ("" when there is nothing to plot).
std::string family_plot_panel(const std::filesystem::path& dat, const FamilyResults& r);

}  // namespace wiretool::bench
