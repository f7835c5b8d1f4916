// `wiretool bench --gl` (gl_check.hpp).
#include "bench/systems/gl_check.hpp"

#include "bench/common.hpp"

#include <engine/gfx/lit_renderer.hpp>
#include <engine/platform/capture.hpp>

#include <utility>

namespace wiretool::bench {

bool GlCheck::init() {
    auto created = engine::platform::create_context(
        {.backend = engine::platform::Backend::headless, .width = 480, .height = 270, .quiet = true});
    if (!created) {
        error = created.error().message;
        return false;
    }
    context = std::move(created).value();
    for (bool keep : {false, true}) {
        auto r = wire::render::WireRenderer::create({.retain_rings = keep});
        if (!r) {
            error = r.error().message;
            return false;
        }
        wire::render::WireRenderer& renderer = keep ? retained : streamed;
        renderer = std::move(r).value();
        for (int i = 1; i < 4; ++i) renderer.add_material({.tint = {0.3f * i, 0.5f, 1.0f - 0.2f * i}});
    }
    const char* names[3] = {"cpu-mesh", "gpu-rings", "gpu-retained"};
    for (int i = 0; i < 3; ++i) {
        paths[i].name = names[i];
        paths[i].timer = engine::gfx::GpuTimer::create();
    }
    return true;
}

void GlCheck::draw_one(GlPath& path, wire::render::WireRenderer& renderer,
                       const wire::systems::WireContext& ctx, std::size_t computed, bool measured,
                       const std::filesystem::path& png) {
    context->begin_frame();
    engine::gfx::clear({0.1f, 0.1f, 0.12f, 1.0f});
    const double t0 = wall_ms();
    path.timer.begin();
    const wire::render::DrawStats st = renderer.draw(ctx.draw_list, ctx.camera);
    path.timer.end();
    const double t1 = wall_ms();
    engine::gfx::finish_gpu();  // llvmpipe's threads finish the frame before the next path is timed
    const double t2 = wall_ms();
    context->end_frame();
    for (const auto& m : path.timer.poll()) path.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
    if (!measured) return;
    ++path.frames;
    path.mismatches += st.bytes_uploaded != computed;
    path.renderer_bytes.push_back(static_cast<double>(st.bytes_uploaded));
    path.computed_bytes.push_back(static_cast<double>(computed));
    path.draw_ms.push_back(t1 - t0);
    path.finish_ms.push_back(t2 - t0);
    if (!png.empty()) (void)engine::platform::capture_png(*context, png);
}

void GlCheck::draw(const wire::systems::WireContext& ctx, int frame, int frames,
                   const std::filesystem::path& dir) {
    const bool measured = frame > 0;  // frame 0 uploads everything: loading, not a frame
    const bool last = frame + 1 == frames;
    if (ctx.draw_list.path == wire::UploadPath::cpu_mesh) {
        draw_one(paths[0], streamed, ctx, upload_bytes(ctx.draw_list), measured,
                 last ? dir / "bench_gl_cpu_mesh.png" : std::filesystem::path{});
        return;
    }
    draw_one(paths[1], streamed, ctx, upload_bytes(ctx.draw_list), measured,
             last ? dir / "bench_gl_gpu_rings.png" : std::filesystem::path{});
    const std::size_t planned = wire::render::plan_retained_frame(ctx.draw_list, model).bytes;
    draw_one(paths[2], retained, ctx, planned, measured,
             last ? dir / "bench_gl_gpu_retained.png" : std::filesystem::path{});
}

void GlCheck::finish() {
    for (GlPath& p : paths)
        for (const auto& m : p.timer.finish()) p.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
    for (GlPath& p : paths) std::erase_if(p.gpu_ms, [](double v) { return v < 0.0; });  // frame 0
}

}  // namespace wiretool::bench
