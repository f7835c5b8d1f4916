// `wiretool bench --gl`, the scaling part: `standard`, `swaying` and `far` drawn by the real WireRenderer at
// --size (default 1920x1080) with --wires wires, on both paths (cpu-mesh, gpu-nodes) at 1, 2 and all hardware
// threads, plus a run with strips and lines off (every wire a tube) and the
// one-draw baseline of that run: the frame's triangles merged into one indexed mesh, drawn with one command by
// the same renderer (same shaders), so the GPU ms of the wire paths against it is the price of drawing per wire.
// Per row: systems wall ms, draw() wall ms, GPU ms (GL_TIME_ELAPSED), draw + glFinish ms, end to end ms, draw
// commands and GL draw calls, bytes per frame (checked against the computed plan), wire-system memory and the
// renderer's GPU buffers. Writes bench_gl.csv and bench_gl.md (docs/speed_vs_error.md).
#pragma once

#include "bench/common.hpp"

namespace wiretool::bench {

/// Runs the GL scaling rows for the selected scenes among standard, swaying and far; exit_ok, exit_failure when
/// a file could not be written, or exit_ok with a note in bench_gl.md when there is no headless GL.
int run_gl_scale_bench(const Options& o);

}  // namespace wiretool::bench
