// `wiretool bench --gl`: the real WireRenderer on a headless EGL context (Mesa llvmpipe), drawing every frame
// of `standard` on three paths (cpu-mesh and gpu-rings streamed by one renderer, gpu-rings retained by
// another): checks that the computed upload size equals FrameStats::bytes_uploaded, and measures per frame
// the draw() call's wall time (CPU: packing, memcpy, GL calls), the GPU time of the pass (GL_TIME_ELAPSED
// through engine::gfx::GpuTimer, read back a few frames later) and draw + glFinish wall time. The framebuffer
// is small: the bytes do not depend on it, and llvmpipe's fill rate would dominate otherwise. The bench's
// only GL code.
#pragma once

#include <engine/gfx/gpu_timer.hpp>
#include <engine/platform/context.hpp>
#include <wire/render/upload_plan.hpp>
#include <wire/render/wire_renderer.hpp>
#include <wire/systems/context.hpp>

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace wiretool::bench {

/// One drawing path's measurements (medians are taken over frames 1..N).
struct GlPath {
    std::string name;
    std::size_t frames = 0, mismatches = 0;
    std::vector<double> renderer_bytes, computed_bytes, draw_ms, finish_ms, gpu_ms, systems_ms;
    engine::gfx::GpuTimer timer;
};

struct GlCheck {
    std::unique_ptr<engine::platform::Context> context;
    wire::render::WireRenderer streamed, retained;
    wire::render::RingResidency model;  ///< what the retained renderer should send
    GlPath paths[3];                    ///< cpu-mesh, gpu-rings, gpu-retained
    std::string error;

    /// Creates the context and both renderers; false (and `error`) when there is no headless GL.
    bool init();
    /// Draws the frame's DrawList on its path(s) (gpu-rings: streamed, then retained); frame 0 is not
    /// measured; the last frame of `frames` is captured to dir/bench_gl_<path>.png.
    void draw(const wire::systems::WireContext& ctx, int frame, int frames, const std::filesystem::path& dir);
    /// Reads back the outstanding GPU timers (frame 0's are dropped).
    void finish();

private:
    void draw_one(GlPath& path, wire::render::WireRenderer& renderer, const wire::systems::WireContext& ctx,
                  std::size_t computed, bool measured, const std::filesystem::path& png);
};

}  // namespace wiretool::bench
