// The accuracy bench's report: accuracy.csv, accuracy.md (key figures, the families' section, every row) and
// the plot speed_vs_error.png (gnuplot, when installed; its data and script beside it). Figures in, files
// out.
#pragma once

#include "bench/accuracy/families.hpp"
#include "bench/accuracy/rows.hpp"
#include "bench/common.hpp"
#include "bench/scenes/reference_scenes.hpp"

#include <string>
#include <vector>

namespace wiretool::bench {

/// Writes accuracy.csv, the plot and accuracy.md into o.out_dir (families.csv/.md through
/// write_family_outputs). `plot_note`: the plot's one-sentence outcome. exit_ok, or exit_failure when a file
/// could not be written.
int write_accuracy_report(const Options& o, const std::vector<ReferenceScene>& scenes,
                          const std::vector<Row>& rows, const FamilyResults& families,
                          std::string& plot_note);

}  // namespace wiretool::bench
