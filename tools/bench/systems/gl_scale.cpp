// `wiretool bench --gl`, the scaling rows (gl_scale.hpp).
#include "bench/systems/gl_scale.hpp"
#include "bench/systems/gl_stream.hpp"
#include "bench/systems/gl_views.hpp"

#include "bench/scenes/field_scenes.hpp"
#include "bench/systems/run_scene.hpp"
#include "wiretool/commands.hpp"

#include <engine/gfx/draw.hpp>
#include <engine/gfx/gpu_timer.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <wire/io/wire_json.hpp>
#include <wire/render/upload_plan.hpp>
#include <wire/render/wire_renderer.hpp>

#include <algorithm>
#include <unordered_map>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace wiretool::bench {
namespace {

enum class GlPathKind { cpu_mesh, gpu_nodes, one_draw };

const char* path_name(GlPathKind k) {
    switch (k) {
        case GlPathKind::cpu_mesh: return "cpu-mesh";
        case GlPathKind::gpu_nodes: return "gpu-nodes";
        case GlPathKind::one_draw: return "one-draw baseline";
    }
    return "?";
}

// Per measured frame of one row.
struct RowFrames {
    std::vector<double> systems_ms, draw_ms, finish_ms, gpu_ms, commands, calls, bytes, triangles, visible, nodes;
    std::size_t mismatches = 0;
    engine::gfx::GpuTimer timer;
};

// The frame's cpu-mesh triangles as one item: vertices moved to the first item's origin (difference in double,
// then float), indices rebased. Strips and lines are not in it: the baseline rows run with them off.
struct MergedMesh {
    std::vector<wire::TubeVertex> vertices;
    std::vector<uint32_t> indices;
    wire::DrawList list;

    void build(const wire::DrawList& from) {
        vertices.clear();
        indices.clear();
        list.path = wire::UploadPath::cpu_mesh;
        list.items.clear();
        if (from.items.empty()) return;
        const glm::dvec3 origin = from.items.front().origin_m;
        for (const wire::DrawItem& item : from.items) {
            const glm::dvec3 shift = item.origin_m - origin;
            const auto first = static_cast<uint32_t>(vertices.size());
            for (wire::TubeVertex v : item.vertices) {
                v.position = glm::vec3(glm::dvec3(v.position) + shift);
                vertices.push_back(v);
            }
            for (uint32_t i : item.indices) indices.push_back(first + i);
        }
        wire::DrawItem one;
        one.origin_m = origin;
        one.vertices = vertices;
        one.indices = indices;
        list.items.push_back(one);
    }
};

struct Row {
    std::string scene;
    int wires = 0, threads = 0;
    GlPathKind path = GlPathKind::cpu_mesh;
    bool thin = true;
    RowFrames f;
    double wire_memory_bytes = 0.0, gpu_buffer_bytes = 0.0;
};

std::size_t visible_nodes(const wire::DrawList& list) {
    std::size_t n = 0;
    for (const wire::DrawItem& item : list.items) {
        if (item.nodes != nullptr) n += item.nodes->size();
        else if (item.curve != nullptr) n += item.curve->node_count();
    }
    return n;
}

class GlScale {
public:
    bool init(const Options& o) {
        auto created = engine::platform::create_context(
            {.backend = engine::platform::Backend::headless, .width = o.width_px, .height = o.height_px, .quiet = true});
        if (!created) {
            error_ = created.error().message;
            return false;
        }
        context_ = std::move(created).value();
        return true;
    }
    const std::string& error() const { return error_; }
    void set_spline(const wire::SplineSettings& spline) { spline_ = spline; }
    std::string gl_renderer() const { return context_ ? context_->gl_renderer() : std::string{}; }
    engine::platform::Context& context() { return *context_; }

    // One row: the scene run on `path` (the one-draw baseline rides on a cpu-mesh run with thin wires off).
    void run_row(const Options& o, SceneKind kind, int wires, int threads, GlPathKind path, bool thin,
                 int frames, std::vector<Row>& rows) {
        const bool cpu = path == GlPathKind::cpu_mesh || path == GlPathKind::one_draw;
        auto made = wire::render::WireRenderer::create();
        if (!made) {
            std::fprintf(stderr, "bench --gl: %s\n", made.error().message.c_str());
            return;
        }
        wire::render::WireRenderer renderer = std::move(made).value();
        for (int i = 1; i < 4; ++i) renderer.add_material({.tint = {0.3f * i, 0.5f, 1.0f - 0.2f * i}});
        Row row;
        row.scene = scene_name(kind), row.wires = wires, row.threads = threads, row.path = path, row.thin = thin;
        row.f.timer = engine::gfx::GpuTimer::create();
        wire::render::NodesPlan seen;  // gpu-nodes: what the renderer has on the GPU
        MergedMesh merged;
        std::fprintf(stderr, "bench --gl: %s, %d wires, %dx%d, %d thread(s), %s%s\n", row.scene.c_str(), wires,
                     o.width_px, o.height_px, threads, path_name(path), thin ? "" : ", strips and lines off");
        RunSpec spec{.kind = kind,
                     .path = cpu ? wire::UploadPath::cpu_mesh : wire::UploadPath::gpu_nodes,
                     .threads = threads,
                     .frames = frames,
                     .wires = wires,
                     .sample_errors = false,
                     .error_samples = 0,
                     .after_frame = {},
                     .spline = spline_,
                     .width_px = o.width_px,
                     .height_px = o.height_px,
                     .thin_wires = thin};
        spec.after_frame = [&](const wire::systems::WireContext& ctx, int frame) {
            const bool measured = frame > 0;  // frame 0 uploads everything: loading, not a frame
            std::size_t computed = 0;
            const wire::DrawList* list = &ctx.draw_list;
            if (path == GlPathKind::one_draw) {
                merged.build(ctx.draw_list);
                list = &merged.list;
                computed = upload_bytes(*list);
            } else if (path == GlPathKind::gpu_nodes) {
                computed = wire::render::plan_nodes_frame(ctx.draw_list, seen);
            } else {
                computed = upload_bytes(ctx.draw_list);
            }
            context_->begin_frame();
            engine::gfx::clear({0.1f, 0.1f, 0.12f, 1.0f});
            const double t0 = wall_ms();
            row.f.timer.begin();
            wire::render::DrawSettings settings;
            const wire::render::DrawStats st = renderer.draw(*list, ctx.camera, settings);
            row.f.timer.end();
            const double t1 = wall_ms();
            engine::gfx::finish_gpu();
            const double t2 = wall_ms();
            if (frame + 1 == frames) {
                // The last frame of each path, once per scene and thread-wire setting.
                std::string file = "bench_gl_" + row.scene + "_" +
                                   std::string(path_name(path)).substr(0, path == GlPathKind::one_draw ? 8 : 12) +
                                   (thin ? "" : "_tubes") + ".png";
                if (threads == 1 || !thin) (void)engine::platform::capture_png(*context_, o.out_dir / file);
            }
            context_->end_frame();
            for (const auto& m : row.f.timer.poll()) row.f.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
            if (!measured) return;
            row.f.draw_ms.push_back(t1 - t0);
            row.f.finish_ms.push_back(t2 - t0);
            row.f.commands.push_back(static_cast<double>(st.indirect_commands));
            row.f.calls.push_back(static_cast<double>(st.multi_draw_calls));
            row.f.bytes.push_back(static_cast<double>(st.bytes_uploaded));
            row.f.triangles.push_back(static_cast<double>(st.triangles));
            row.f.visible.push_back(static_cast<double>(ctx.stats.visible_wires));
            row.f.nodes.push_back(static_cast<double>(visible_nodes(ctx.draw_list)));
            row.f.mismatches += st.bytes_uploaded != computed;
        };
        const SceneRun run = run_scene(spec);
        for (const auto& m : row.f.timer.finish()) row.f.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
        std::erase_if(row.f.gpu_ms, [](double v) { return v < 0.0; });
        row.f.systems_ms = run.frame_wall_ms;  // per measured frame, the same frames as the draws
        row.wire_memory_bytes = static_cast<double>(run.memory.visible_bytes + run.memory.culled_bytes);
        row.gpu_buffer_bytes = static_cast<double>(3 * renderer.info().region_bytes);
        rows.push_back(std::move(row));
    }

private:
    std::unique_ptr<engine::platform::Context> context_;
    std::string error_;
    wire::SplineSettings spline_{.kind = wire::SplineKind::automatic};
};

std::vector<int> thread_counts() {
    const int all = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
    std::vector<int> t{1, 2, all};
    std::sort(t.begin(), t.end());
    t.erase(std::unique(t.begin(), t.end()), t.end());
    return t;
}

}  // namespace

int run_gl_scale_bench(const Options& o) {
    std::vector<SceneKind> scenes;
    for (SceneKind k : {SceneKind::standard, SceneKind::swaying, SceneKind::far})
        if (selected(o, scene_name(k))) scenes.push_back(k);
    const bool stream_rows = selected(o, "swaying") || selected(o, "stream");
    const bool views_rows = std::find(o.scenes.begin(), o.scenes.end(), "views") != o.scenes.end();
    Table table;
    table.header = {"scene", "wires", "width", "height", "threads", "path", "thin_wires", "frames", "visible",
                    "triangles", "systems_wall_ms", "draw_ms", "gpu_ms", "draw_finish_ms", "end_to_end_ms",
                    "draw_commands", "draw_calls", "bytes_per_frame", "bytes_mismatch_frames",
                    "wire_memory_bytes", "gpu_buffer_bytes", "gpu_vs_one_draw"};
    std::string md = "# wiretool bench --gl\n\n";
    GlScale gl;
    if (scenes.empty() && !stream_rows && !views_rows) return exit_ok;
    {
        // The wires' spline (--spline), resolved as `wiretool mesh` does (the systems rows do the same).
        wire::PipelineSettings resolved;
        wire::io::SettingsOverrides overrides;
        overrides.spline_type = o.spline;
        if (engine::Status st = wire::io::resolve_settings(wire::io::WireSpec{}, overrides, resolved); !st.ok()) {
            std::fprintf(stderr, "wiretool bench: --spline: %s\n", st.message.c_str());
            return 2;
        }
        gl.set_spline(resolved.spline);
    }
    if (!gl.init(o)) {
        std::fprintf(stderr, "wiretool bench: --gl: no headless GL context (%s): bench_gl.md says so, no rows\n",
                     gl.error().c_str());
        md += "No headless GL context (" + gl.error() + "): no rows.\n";
        return write_text(o.out_dir / "bench_gl.md", md) ? exit_ok : exit_failure;
    }
    const int frames = o.quick ? 9 : 61;  // frame 0 is not measured
    std::vector<Row> rows;
    std::string nodes_md;  // the nodes path against cpu-mesh, per scene and thread count
    for (SceneKind kind : scenes) {
        const int wires = o.wires > 0 ? o.wires : scene_wire_count(kind);
        const std::size_t first = rows.size();
        for (int threads : thread_counts())
            for (GlPathKind p : {GlPathKind::cpu_mesh, GlPathKind::gpu_nodes})
                gl.run_row(o, kind, wires, threads, p, true, frames, rows);
        // Strips and lines off, so that the one-draw baseline draws exactly the triangles the paths draw.
        const int all = thread_counts().back();
        for (GlPathKind p : {GlPathKind::cpu_mesh, GlPathKind::gpu_nodes, GlPathKind::one_draw})
            gl.run_row(o, kind, wires, all, p, false, frames, rows);
        double baseline_gpu = 0.0;
        for (std::size_t r = first; r < rows.size(); ++r)
            if (rows[r].path == GlPathKind::one_draw) baseline_gpu = median(rows[r].f.gpu_ms);
        for (std::size_t r = first; r < rows.size(); ++r) {
            if (rows[r].path != GlPathKind::gpu_nodes || !rows[r].thin) continue;
            for (std::size_t c = first; c < rows.size(); ++c) {
                const Row& cpu = rows[c];
                if (cpu.path != GlPathKind::cpu_mesh || !cpu.thin || cpu.threads != rows[r].threads) continue;
                const Row& n = rows[r];
                const double cpu_wall = median(cpu.f.systems_ms) + median(cpu.f.draw_ms);
                const double nodes_wall = median(n.f.systems_ms) + median(n.f.draw_ms);
                const double budget = 16.0 * median(n.f.nodes) + 64.0 * median(n.f.visible);
                char line[512];
                std::snprintf(line, sizeof line,
                              "| %s | %d | %.3f | %.3f | %.3f | %.3f | %.0f | %.0f | %.2f |\n", n.scene.c_str(),
                              n.threads, median(cpu.f.systems_ms) + median(cpu.f.draw_ms), nodes_wall,
                              cpu_wall > 0.0 ? nodes_wall / cpu_wall : 0.0, median(n.f.gpu_ms), median(n.f.bytes),
                              budget, budget > 0.0 ? median(n.f.bytes) / budget : 0.0);
                nodes_md += line;
            }
        }
        for (std::size_t r = first; r < rows.size(); ++r) {
            const Row& row = rows[r];
            const double systems = median(row.f.systems_ms), draw = median(row.f.draw_ms),
                         finish = median(row.f.finish_ms), gpu = median(row.f.gpu_ms);
            table.add({row.scene, num(static_cast<std::size_t>(row.wires)), num(static_cast<std::size_t>(o.width_px)),
                       num(static_cast<std::size_t>(o.height_px)), num(static_cast<std::size_t>(row.threads)),
                       path_name(row.path), row.thin ? "on" : "off",
                       num(static_cast<std::size_t>(row.f.draw_ms.size())), num(median(row.f.visible)),
                       num(median(row.f.triangles)), num(systems), num(draw), num(gpu), num(finish),
                       num(row.path == GlPathKind::one_draw ? finish : systems + finish), num(median(row.f.commands)),
                       num(median(row.f.calls)), num(median(row.f.bytes)), num(row.f.mismatches),
                       num(row.wire_memory_bytes), num(row.gpu_buffer_bytes),
                       !row.thin && baseline_gpu > 0.0 ? num(gpu / baseline_gpu, 3) : std::string("nan")});
        }
    }
    if (!table.write_csv(o.out_dir / "bench_gl.csv")) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench_gl.csv").c_str());
        return exit_failure;
    }
    md += "GL: " + gl.gl_renderer() + ", " + std::to_string(o.width_px) + "x" + std::to_string(o.height_px) +
          ", medians over " + std::to_string(frames - 1) +
          " measured frames per row (frame 0, which uploads everything, is not measured). systems_wall_ms: the "
          "five wire systems; draw_ms: WireRenderer::draw() wall (CPU: packing, memcpy, GL calls, no waiting); "
          "gpu_ms: GL_TIME_ELAPSED of the pass; draw_finish_ms: draw() + glFinish; end_to_end_ms: systems + draw "
          "+ finish (the one-draw baseline: its draw + finish only); draw_commands: indirect commands (or "
          "draws) the GPU processes; draw_calls: GL multi-draw/draw calls; bytes_per_frame: what draw() "
          "memcpy'd (bytes_mismatch_frames: frames where that differs from the computed plan, must be 0); "
          "wire_memory_bytes: the wire systems' state; gpu_buffer_bytes: the renderer's stream regions (3). Rows "
          "with thin_wires off draw every wire as a tube; the one-draw baseline "
          "draws the same frame's triangles merged into one indexed mesh with one command (same shaders), and "
          "gpu_vs_one_draw is each such row's GPU ms over the baseline's (nan in rows with thin wires on).\n\n";
    md += table.markdown();
    md += "\n## The nodes path against cpu-mesh (issue 30)\n\nCPU wall per frame = systems_wall_ms + draw_ms (what "
          "the CPU spends, without waiting for the GPU: run with GALLIUM_NOOP=1 on llvmpipe, where draw() would "
          "otherwise run the compute shaders on the CPU); bytes: gpu-nodes bytes_per_frame against 16 B per "
          "visible node + 64 B per visible wire (the issue's bound; nodes of the visible wires' items).\n\n"
          "| scene | threads | cpu-mesh CPU ms | gpu-nodes CPU ms | nodes / cpu-mesh (aim <= 0.2) | gpu-nodes GPU ms "
          "| gpu-nodes bytes | 16 B/node + 64 B/wire | bytes / bound (aim <= 1) |\n| --- | --- | --- | --- | --- | "
          "--- | --- | --- | --- |\n" +
          nodes_md;
    if (stream_rows && !run_gl_stream_rows(o, gl.context(), md)) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench_gl_stream.csv").c_str());
        return exit_failure;
    }
    if (views_rows && !run_gl_views_rows(o, gl.context(), md)) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench_gl_views.csv").c_str());
        return exit_failure;
    }
    if (!write_text(o.out_dir / "bench_gl.md", md)) {
        std::fprintf(stderr, "wiretool bench: cannot write %s\n", (o.out_dir / "bench_gl.md").c_str());
        return exit_failure;
    }
    return exit_ok;
}

}  // namespace wiretool::bench
