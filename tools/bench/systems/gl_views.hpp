// `wiretool bench --gl --scenes views` (issue 40): the swaying scene (1,000 moving wires; --wires to change) drawn
// from 1, 2 and 4 views a frame on the nodes path and on cpu-mesh: the camera, then a directional light's shadow map
// (Output::shadow, 2048 px), a second camera, a spot lamp's shadow map. Per view count: the CPU ms of the frame's
// draws, the bytes they sent, and what each extra view adds. Writes bench_gl_views.csv and a section of bench_gl.md.
#pragma once

#include "bench/common.hpp"

#include <engine/platform/context.hpp>

#include <string>

namespace wiretool::bench {

/// Runs the rows on `context` (headless, current) and appends their section to `md`; false when the CSV could not
/// be written. Run only when --scenes names `views`.
bool run_gl_views_rows(const Options& o, engine::platform::Context& context, std::string& md);

}  // namespace wiretool::bench
