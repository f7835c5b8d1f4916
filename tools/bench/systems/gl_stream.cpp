// `wiretool bench --gl`, the node stream rows (gl_stream.hpp).
#include "bench/systems/gl_stream.hpp"

#include <engine/gfx/draw.hpp>
#include <engine/gfx/gpu_timer.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/platform/context.hpp>
#include <wire/render/node_stream.hpp>
#include <wire/render/wire_renderer.hpp>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace wiretool::bench {
namespace {

constexpr std::size_t kNodes = 64;

/// The physics' output for frame `frame`: wire k hangs between two anchors 1.6 m apart on a 2 m grid, sagging
/// 0.3 m, swinging about its chord by up to 0.5 rad (its own phase) and waving along its length. Not timed.
void simulate(std::size_t wires, int frame, std::vector<double>& xyz) {
    xyz.resize(wires * kNodes * 3);
    const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(wires))));
    const double t = 0.05 * frame;
    tbb::parallel_for(std::size_t{0}, wires, [&](std::size_t k) {
        const double x0 = 2.0 * static_cast<double>(k % side), z0 = 2.0 * static_cast<double>(k / side);
        const double swing = 0.5 * std::sin(t + 0.37 * static_cast<double>(k));
        const double c = std::cos(swing), s = std::sin(swing);
        double* p = xyz.data() + 3 * kNodes * k;
        for (std::size_t j = 0; j < kNodes; ++j) {
            const double u = static_cast<double>(j) / (kNodes - 1);
            const double sag = 0.3 * 4.0 * u * (1.0 - u) + 0.02 * std::sin(9.0 * u + 3.0 * t) * std::sin(3.14159 * u);
            p[3 * j] = x0 + 1.6 * u;
            p[3 * j + 1] = 3.0 - sag * c;
            p[3 * j + 2] = z0 + sag * s;
        }
    });
}

/// This machine's copy bandwidth, bytes a millisecond: the median of 7 memcpys of 64 MiB (past the caches).
double copy_bytes_per_ms() {
    const std::size_t n = std::size_t{64} << 20;
    std::vector<char> a(n, 1), b(n, 2);
    std::vector<double> ms;
    for (int i = 0; i < 7; ++i) {
        const double t0 = wall_ms();
        std::memcpy(b.data(), a.data(), n);
        ms.push_back(wall_ms() - t0);
        a[static_cast<std::size_t>(i)] = b[n - 1 - static_cast<std::size_t>(i)];
    }
    return static_cast<double>(n) / std::max(median(ms), 1e-6);
}

struct StreamRow {
    std::size_t wires = 0;
    int threads = 1;
    bool floats = false;
    std::vector<double> write_ms, draw_ms, gpu_ms, bytes;
    double state_bytes = 0, mapped_bytes = 0;
    std::size_t errors = 0;
};

void run_row(engine::platform::Context& context, StreamRow& row, int frames) {
    auto made = wire::render::WireRenderer::create();
    if (!made) {
        std::fprintf(stderr, "bench --gl: %s\n", made.error().message.c_str());
        return;
    }
    wire::render::WireRenderer renderer = std::move(made).value();
    std::fprintf(stderr, "bench --gl: node stream, %zu wires of %zu nodes, %s, %d thread(s)\n", row.wires, kNodes,
                 row.floats ? "float offsets" : "double", row.threads);
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(row.threads));
    wire::render::NodeStream& stream = renderer.node_stream();
    if (const auto st = stream.usable(); !st.ok()) {
        std::fprintf(stderr, "bench --gl: %s\n", st.message.c_str());
        return;
    }
    std::vector<wire::render::StreamWire> wires;
    wires.reserve(row.wires);
    for (std::size_t k = 0; k < row.wires; ++k) wires.push_back(stream.add({.radius_m = 0.02f, .max_sides = 8}).value());
    const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(row.wires))));
    engine::scene::Camera camera;
    const double extent = 2.0 * static_cast<double>(side);
    camera.target = glm::dvec3(0.5 * extent, 2.0, 0.5 * extent);
    camera.position = camera.target + glm::dvec3(0.0, 0.9 * extent + 4.0, 0.6 * extent + 4.0);
    camera.near_m = 0.5f, camera.far_m = static_cast<float>(4.0 * extent + 20.0);
    std::vector<double> xyz;
    std::vector<float> offsets;
    std::vector<glm::dvec3> origins(row.wires);
    engine::gfx::GpuTimer timer = engine::gfx::GpuTimer::create();
    wire::DrawList list;
    list.path = wire::UploadPath::gpu_nodes;
    for (int f = 0; f < frames; ++f) {
        simulate(row.wires, f, xyz);
        if (row.floats) {
            // A float engine's output: offsets from each wire's anchor (its first node, a float point).
            offsets.resize(xyz.size());
            for (std::size_t k = 0; k < row.wires; ++k) {
                const double* p = xyz.data() + 3 * kNodes * k;
                origins[k] = glm::dvec3(glm::vec3(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])));
                for (std::size_t j = 0; j < kNodes; ++j)
                    for (int a = 0; a < 3; ++a)
                        offsets[3 * (kNodes * k + j) + a] = static_cast<float>(p[3 * j + a] - origins[k][a]);
            }
        }
        context.begin_frame();
        engine::gfx::clear({0.1f, 0.1f, 0.12f, 1.0f});
        const double t0 = wall_ms();
        std::size_t written = 0;
        const bool begun = stream.begin(row.wires * kNodes).ok();
        if (begun) {
            written = row.floats ? stream.write_many(wires, origins, offsets.data(), kNodes)
                                 : stream.write_many(wires, xyz.data(), kNodes);
        }
        const double t1 = wall_ms();
        timer.begin();
        const wire::render::DrawStats st = renderer.draw(list, camera, {});
        timer.end();
        const double t2 = wall_ms();
        engine::gfx::finish_gpu();
        context.end_frame();
        for (const auto& m : timer.poll()) row.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
        row.errors += row.wires - written;
        if (f == 0) continue;  // frame 0 makes every wire's slot: loading, not a frame
        row.write_ms.push_back(t1 - t0);
        row.draw_ms.push_back(t2 - t1);
        row.bytes.push_back(static_cast<double>(st.bytes_uploaded));
    }
    for (const auto& m : timer.finish()) row.gpu_ms.push_back(m.frame == 0 ? -1.0 : m.ms);
    std::erase_if(row.gpu_ms, [](double v) { return v < 0.0; });
    row.state_bytes = static_cast<double>(stream.state_bytes());
    row.mapped_bytes = static_cast<double>(stream.mapped_bytes());
}

}  // namespace

bool run_gl_stream_rows(const Options& o, engine::platform::Context& context, std::string& md) {
    std::vector<std::size_t> counts;
    if (o.wires > 0) {
        counts = {static_cast<std::size_t>(o.wires)};
    } else if (o.quick) {
        counts = {1000, 10000};
    } else {
        counts = {1000, 10000, 100000};
    }
    const int frames = o.quick ? 9 : 41;
    const double bytes_per_ms = copy_bytes_per_ms();
    std::vector<StreamRow> rows;
    for (std::size_t n : counts) {
        for (int threads : {1, 2}) {
            for (bool floats : {false, true}) {
                StreamRow row;
                row.wires = n, row.threads = threads, row.floats = floats;
                run_row(context, row, frames);
                rows.push_back(std::move(row));
            }
        }
    }
    Table table;
    table.header = {"wires",         "nodes_per_wire", "input",       "threads",        "frames",
                    "write_ms",      "draw_ms",        "cpu_ms",      "us_per_wire",    "two_thread_speedup",
                    "bytes_per_frame", "copy_floor_ms", "cpu_over_floor", "gpu_ms",     "state_bytes_per_wire",
                    "mapped_bytes_per_wire", "refused_writes"};
    for (const StreamRow& r : rows) {
        const double write = median(r.write_ms), draw = median(r.draw_ms), cpu = write + draw;
        const double bytes = median(r.bytes), floor = bytes / bytes_per_ms;
        double speedup = std::nan("");
        for (const StreamRow& one : rows) {
            if (r.threads == 2 && one.threads == 1 && one.wires == r.wires && one.floats == r.floats) {
                speedup = (median(one.write_ms) + median(one.draw_ms)) / std::max(cpu, 1e-9);
            }
        }
        table.add({num(r.wires), num(kNodes), r.floats ? "float" : "double", num(static_cast<std::size_t>(r.threads)),
                   num(r.write_ms.size()), num(write), num(draw), num(cpu),
                   num(1000.0 * cpu / static_cast<double>(std::max<std::size_t>(r.wires, 1))), num(speedup, 3),
                   num(bytes), num(floor), num(floor > 0 ? cpu / floor : std::nan(""), 3), num(median(r.gpu_ms)),
                   num(r.state_bytes / static_cast<double>(r.wires)), num(r.mapped_bytes / static_cast<double>(r.wires)),
                   num(r.errors)});
    }
    char bw[128];
    std::snprintf(bw, sizeof bw, "%.2f GB/s", bytes_per_ms / 1e6);
    md += "\n## The node stream (issue 39)\n\nWires of " + std::to_string(kNodes) +
          " nodes swinging and waving every frame (the physics' output, not timed), written with "
          "NodeStream::write_many (in double, or as float offsets from each wire's anchor) into the renderer's mapped "
          "region and drawn with an empty draw list on the nodes path; medians over the frames after the first. "
          "cpu_ms = write_ms (begin + write_many: read, check, offset, write) + draw_ms (draw(): headers, slots, GL "
          "calls); run with GALLIUM_NOOP=1 for the CPU side alone. copy_floor_ms: bytes_per_frame at this machine's "
          "copy bandwidth, measured once here (" + std::string(bw) + ", memcpy of 64 MiB): one copy of what the "
          "GPU gets, the physical limit. state_bytes_per_wire: the stream's CPU records; mapped_bytes_per_wire: its "
          "mapped regions (3, for the frames in flight). The nodes path's GPU state per wire is not counted here.\n\n" +
          table.markdown();
    return table.write_csv(o.out_dir / "bench_gl_stream.csv");
}

}  // namespace wiretool::bench
