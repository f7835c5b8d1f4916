// The wire systems bench's baseline: a uniform tessellation (one ring count per segment, one side count) with
// the same maximum screen error as the adaptive LOD at a run's sampled frames, and what it costs to build.
#pragma once

#include "bench/systems/run_scene.hpp"

#include <cstdint>
#include <vector>

namespace wiretool::bench {

/// Uniform baseline: k rings per segment on every visible wire, the same side count everywhere.
struct Uniform {
    uint32_t rings_per_segment = 1;
    uint32_t sides = 3;
    double max_error_px = 0.0;
    double rebuild_cpu_ms = 0.0;  ///< median over samples: rings + mesh of every visible wire
};

/// The smallest ring count per segment (up to 256) whose screen error over `run`'s samples is no worse than
/// the adaptive run's, the smallest side count no worse radially, and the CPU ms of building them.
Uniform search_uniform(const SceneRun& run);

/// Per measured frame of `run`: the uniform tessellation's rings, vertices and cpu-mesh upload bytes for the
/// same visible wires (open wires: one extra ring each, and caps).
struct UniformCounts {
    std::vector<double> rings, vertices, bytes;
};
UniformCounts uniform_counts(const SceneRun& run, const Uniform& u);

/// Adds the adaptive and the uniform vertex counts over `run`'s sampled frames (the same visible wires).
void add_vertices_at_samples(const SceneRun& run, const Uniform& u, double& adaptive, double& uniform);

}  // namespace wiretool::bench
