// `wiretool bench --gl --scenes views` (gl_views.hpp).
#include "bench/systems/gl_views.hpp"

#include "bench/systems/run_scene.hpp"

#include <engine/gfx/draw.hpp>
#include <engine/gfx/gpu_timer.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/gfx/shadow.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <engine/scene/light_view.hpp>
#include <wire/render/wire_renderer.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace wiretool::bench {
namespace {

struct ViewsRow {
    wire::UploadPath path = wire::UploadPath::gpu_nodes;
    int views = 1;
    std::vector<double> draw_ms, finish_ms, bytes, gpu_ms, camera_bytes;
    std::size_t failures = 0;
};

void run_row(const Options& o, engine::platform::Context& context, ViewsRow& row, int wires, int frames) {
    auto made = wire::render::WireRenderer::create();
    if (!made) {
        std::fprintf(stderr, "bench views: %s\n", made.error().message.c_str());
        return;
    }
    wire::render::WireRenderer renderer = std::move(made).value();
    for (int i = 1; i < 4; ++i) renderer.add_material({.tint = {0.3f * i, 0.5f, 1.0f - 0.2f * i}});  // as the --gl rows
    auto sun = engine::gfx::ShadowMap::create(2048);
    auto lamp = engine::gfx::ShadowMap::create(2048);
    if (!sun || !lamp) return;
    engine::gfx::GpuTimer timer = engine::gfx::GpuTimer::create();
    std::fprintf(stderr, "bench views: swaying, %d wires, %s, %d view(s)\n", wires,
                 std::string(wire::upload_path_name(row.path)).c_str(), row.views);
    RunSpec spec{.kind = SceneKind::swaying,
                 .path = row.path,
                 .threads = 1,
                 .frames = frames,
                 .wires = wires,
                 .sample_errors = false,
                 .error_samples = 0,
                 .after_frame = {},
                 .width_px = o.width_px,
                 .height_px = o.height_px};
    spec.after_frame = [&](const wire::systems::WireContext& ctx, int frame) {
        const engine::scene::Camera& cam = ctx.camera;
        // The scene's sphere, seen from the camera: what the lights' maps cover.
        const glm::dvec3 centre = cam.target;
        const double radius = 0.6 * glm::length(cam.target - cam.position);
        context.begin_frame();
        engine::gfx::clear({0.1f, 0.1f, 0.12f, 1.0f});
        std::size_t bytes = 0, camera_bytes = 0;
        const double t0 = wall_ms();
        timer.begin();
        if (row.views >= 2) {  // a directional light's shadow map
            sun->light = engine::scene::directional_light_view({0.3, 1.0, 0.4}, centre, radius);
            sun->begin();
            const auto st = renderer.draw(ctx.draw_list, sun->light, {.output = wire::render::Output::shadow, .view = 1});
            sun->end();
            bytes += st.bytes_uploaded;
            row.failures += st.status.ok() ? 0 : 1;
        }
        if (row.views >= 4) {  // a spot lamp's shadow map
            lamp->light = engine::scene::spot_light_view(cam.position + glm::dvec3(0.0, 2.0, 0.0), centre - cam.position,
                                                         0.7f, static_cast<float>(4.0 * radius));
            lamp->begin();
            const auto st = renderer.draw(ctx.draw_list, lamp->light, {.output = wire::render::Output::shadow, .view = 2});
            lamp->end();
            bytes += st.bytes_uploaded;
            row.failures += st.status.ok() ? 0 : 1;
        }
        wire::render::DrawSettings settings;
        settings.shadow = row.views >= 2 ? &*sun : nullptr;
        const auto main = renderer.draw(ctx.draw_list, cam, settings);
        bytes += main.bytes_uploaded;
        camera_bytes = main.bytes_uploaded;
        row.failures += main.status.ok() ? 0 : 1;
        if (row.views >= 4) {  // a second camera (a monitor's view), into the same image for the bench
            engine::scene::Camera second = cam;
            second.position = centre + glm::dvec3(-1.0, 0.5, 1.0) * glm::length(cam.position - centre) * 0.6;
            const auto st = renderer.draw(ctx.draw_list, second, {.view = 3, .shadow = &*sun});
            bytes += st.bytes_uploaded;
            row.failures += st.status.ok() ? 0 : 1;
        }
        timer.end();
        const double t1 = wall_ms();
        engine::gfx::finish_gpu();
        const double t2 = wall_ms();
        if (frame + 1 == frames && row.views == 4) {
            (void)engine::platform::capture_png(context, o.out_dir / ("bench_gl_views_" +
                                                                      std::string(wire::upload_path_name(row.path)) + ".png"));
        }
        context.end_frame();
        for (const auto& m : timer.poll()) row.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
        if (frame == 0) return;  // frame 0 uploads everything: loading, not a frame
        row.draw_ms.push_back(t1 - t0);
        row.finish_ms.push_back(t2 - t0);
        row.bytes.push_back(static_cast<double>(bytes));
        row.camera_bytes.push_back(static_cast<double>(camera_bytes));
    };
    (void)run_scene(spec);
    for (const auto& m : timer.finish()) row.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
    std::erase_if(row.gpu_ms, [](double v) { return v < 0.0; });
}

}  // namespace

bool run_gl_views_rows(const Options& o, engine::platform::Context& context, std::string& md) {
    const int wires = o.wires > 0 ? o.wires : 1000;
    const int frames = o.quick ? 9 : 41;
    std::vector<ViewsRow> rows;
    for (const wire::UploadPath path : {wire::UploadPath::gpu_nodes, wire::UploadPath::cpu_mesh}) {
        for (const int views : {1, 2, 4}) {
            ViewsRow row;
            row.path = path, row.views = views;
            run_row(o, context, row, wires, frames);
            rows.push_back(std::move(row));
        }
    }
    Table table;
    table.header = {"path", "wires", "views", "frames", "draw_ms", "draw_ms_per_extra_view", "finish_ms", "gpu_ms",
                    "bytes_per_frame", "bytes_per_extra_view", "camera_view_bytes", "failed_draws"};
    for (const ViewsRow& r : rows) {
        double extra_ms = std::nan(""), extra_bytes = std::nan("");
        for (const ViewsRow& one : rows) {
            if (one.path == r.path && one.views == 1 && r.views > 1) {
                extra_ms = (median(r.draw_ms) - median(one.draw_ms)) / (r.views - 1);
                extra_bytes = (median(r.bytes) - median(one.bytes)) / (r.views - 1);
            }
        }
        table.add({std::string(wire::upload_path_name(r.path)), num(static_cast<std::size_t>(wires)),
                   num(static_cast<std::size_t>(r.views)), num(r.draw_ms.size()), num(median(r.draw_ms)), num(extra_ms),
                   num(median(r.finish_ms)), num(median(r.gpu_ms)), num(median(r.bytes)), num(extra_bytes),
                   num(median(r.camera_bytes)), num(r.failures)});
    }
    md += "\n## Several views a frame (issue 40)\n\nThe swaying scene (moving wires) drawn per frame from 1 view (the "
          "camera), 2 (a directional light's 2048 px shadow map first, Output::shadow, received by the camera's "
          "draw) or 4 (also a spot lamp's map and a second camera), each draw with its own DrawSettings::view: its "
          "own culling and LOD on the nodes path. draw_ms: CPU ms of the frame's draw() calls (GALLIUM_NOOP=1 for "
          "the CPU side alone); finish_ms: until the GPU is done; bytes_per_frame: DrawStats::bytes_uploaded summed "
          "over the views. The nodes path sends a moving wire's nodes once: an extra view of the same list sends a "
          "slot per visible wire; cpu-mesh draws the camera's meshes again and streams them again.\n\n" +
          table.markdown();
    return table.write_csv(o.out_dir / "bench_gl_views.csv");
}

}  // namespace wiretool::bench
