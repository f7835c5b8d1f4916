// The accuracy bench's rows: one reference scene, one method, one LOD tolerance through curve -> lod -> rings
// -> mesh, timed, with its sizes and errors (pops are filled in by the caller: they do not depend on the
// tolerance).
#pragma once

#include "bench/accuracy/methods.hpp"
#include "bench/scenes/reference_scenes.hpp"

#include <wire/nodes.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace wiretool::bench {

/// The LOD tolerances of every scene and method, px.
constexpr double kTolerancesPx[] = {0.1, 0.25, 0.5, 1.0, 2.0};

/// One row of accuracy.csv (sizes of one frame, CPU us per wire, errors, pops).
struct Row {
    std::string scene, method;
    double tolerance_px = 0.0;
    std::size_t rings = 0, sides = 0, vertices = 0, bytes_cpu = 0, bytes_gpu = 0;
    double ns_per_vertex = 0.0, us_cpu = 0.0, us_gpu = 0.0;
    double world_m = 0.0, screen_px = 0.0, twist_deg = 0.0, pop_m = 0.0, pop_blended_m = 0.0;
};

/// A static scene's row; CPU times are medians of 3 trials of at least `min_ms` each.
Row measure_row(const ReferenceScene& s, const Method& m, const wire::WireNodes& nodes, double tol,
                double min_ms);

/// Churn rows: every frame's state through the pop-free curve stage, then lod/rings/mesh; time per frame,
/// errors as the worst over the frames (world error against the catenary, which the inserted nodes lie near,
/// not on).
Row measure_churn_row(const ReferenceScene& s, const Method& m, const std::vector<wire::WireNodes>& states,
                      double tol);

}  // namespace wiretool::bench
