// `wiretool bench --gl`, the node stream rows (issue 39): 64-node wires moving every frame, written through
// wire::render::NodeStream in double and in float offsets at 1,000, 10,000 and 100,000 wires (--wires: that count
// only; --quick: the first two) on 1 and 2 threads, beside the copy floor: the bytes the frame sends at this
// machine's copy bandwidth, measured once. Writes bench_gl_stream.csv and a section of bench_gl.md.
#pragma once

#include "bench/common.hpp"

#include <engine/platform/context.hpp>

#include <string>

namespace wiretool::bench {

/// Runs the rows on `context` (headless, current) and appends their section to `md`; false when the CSV could not
/// be written.
bool run_gl_stream_rows(const Options& o, engine::platform::Context& context, std::string& md);

}  // namespace wiretool::bench
