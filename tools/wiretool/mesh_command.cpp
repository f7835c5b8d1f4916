// `wiretool mesh`: wire JSON -> tube meshes (binary glTF) and ring records (CSV). A contract: docs/wiretool.md.
#include "commands.hpp"
#include "ring_csv.hpp"

#include <engine/assets/gltf.hpp>
#include <wire/io/wire_json.hpp>
#include <wire/pipeline.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

namespace wiretool {
namespace {

struct MeshOptions {
    std::string input;
    std::string glb_out;
    std::string csv_out;
    wire::io::SettingsOverrides overrides;
    uint32_t repeat = 0;
    bool no_caps = false;
};

std::string where(const std::string& file, std::size_t frame, std::size_t frames, std::size_t wire_index) {
    std::string s = file + ": ";
    if (frames > 1) s += "frame " + std::to_string(frame) + ", ";
    return s + "wire " + std::to_string(wire_index);
}

/// Everything one generation produces: CSV rows (all frames) and the last frame's meshes.
struct Output {
    std::string csv;
    std::vector<engine::assets::MeshData> meshes;
    std::size_t vertices = 0;
};

engine::assets::MeshData to_mesh_data(const wire::TubeMesh& tube, std::size_t wire_index) {
    engine::assets::MeshData m;
    m.name = "wire_" + std::to_string(wire_index);
    m.origin = tube.origin_m;
    m.positions.reserve(tube.vertices.size() * 3);
    m.normals.reserve(tube.vertices.size() * 3);
    m.uvs.reserve(tube.vertices.size() * 2);
    for (const wire::TubeVertex& v : tube.vertices) {
        m.positions.insert(m.positions.end(), {v.position.x, v.position.y, v.position.z});
        m.normals.insert(m.normals.end(), {v.normal.x, v.normal.y, v.normal.z});
        m.uvs.insert(m.uvs.end(), {v.uv.x, v.uv.y});
    }
    m.indices = tube.indices;
    return m;
}

/// One generation: every frame in order, every wire, from parsed input to finished vertex and index arrays.
/// Wires keep their pipeline state (pop-free blend, carried-over first frame) across frames.
engine::Status generate(const wire::io::SceneSpec& scene, const std::vector<std::vector<wire::PipelineSettings>>& settings,
                      const MeshOptions& o, bool want_outputs, Output& out) {
    const std::size_t wires = scene.frames.front().wires.size();
    std::vector<wire::WirePipeline> pipelines(wires);
    out = Output{};
    for (std::size_t f = 0; f < scene.frames.size(); ++f) {
        const bool last = f + 1 == scene.frames.size();
        for (std::size_t w = 0; w < wires; ++w) {
            const wire::io::WireSpec& spec = scene.frames[f].wires[w];
            engine::Status st = pipelines[w].update(wire::io::to_wire_nodes(spec), settings[f][w]);
            if (!st.ok()) return engine::Status::error(where(o.input, f, scene.frames.size(), w) + ": " + st.message, st.index);
            out.vertices += pipelines[w].mesh().vertices.size();
            if (want_outputs) {
                if (!o.csv_out.empty()) append_ring_rows(out.csv, f, w, pipelines[w].rings());
                if (last) out.meshes.push_back(to_mesh_data(pipelines[w].mesh(), w));
            }
        }
    }
    return engine::Status::success();
}

bool write_atomically(const std::string& path, const std::string& bytes, std::string& error) {
    const std::string tmp = path + ".tmp";
    std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
    if (!file) {
        error = path + ": cannot open for writing";
        return false;
    }
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    file.close();
    if (!file || std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        error = path + ": write failed";
        return false;
    }
    return true;
}

int run_mesh(MeshOptions o) {
    if (o.no_caps) o.overrides.caps = false;
    wire::io::SceneSpec scene;
    if (engine::Status st = wire::io::load_wire_json(o.input, scene); !st.ok()) {
        std::cerr << "wiretool mesh: " << st.message << "\n";
        return exit_bad_input;
    }
    std::vector<std::vector<wire::PipelineSettings>> settings(scene.frames.size());
    for (std::size_t f = 0; f < scene.frames.size(); ++f)
        for (std::size_t w = 0; w < scene.frames[f].wires.size(); ++w) {
            wire::PipelineSettings s;
            if (engine::Status st = wire::io::resolve_settings(scene.frames[f].wires[w], o.overrides, s); !st.ok()) {
                std::cerr << "wiretool mesh: " << where(o.input, f, scene.frames.size(), w) << ": " << st.message
                          << "\n";
                return exit_bad_input;
            }
            settings[f].push_back(s);
        }

    Output out;
    if (engine::Status st = generate(scene, settings, o, true, out); !st.ok()) {
        std::cerr << "wiretool mesh: " << st.message << "\n";
        return exit_bad_input;
    }
    if (o.repeat > 0) {
        Output scratch;
        double total_ms = 0.0;
        for (uint32_t k = 0; k < o.repeat; ++k) {
            const auto t0 = std::chrono::steady_clock::now();
            (void)generate(scene, settings, o, false, scratch);
            total_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        }
        std::fprintf(stderr, "vertices=%zu mean_ms=%.6f\n", out.vertices, total_ms / o.repeat);
    }

    // Outputs last, each written atomically; if the second fails the first is removed: nothing partial stays.
    std::string error;
    if (!o.csv_out.empty()) {
        if (!write_atomically(o.csv_out, std::string(kRingCsvHeader) + "\n" + out.csv, error)) {
            std::cerr << "wiretool mesh: " << error << "\n";
            return exit_failure;
        }
    }
    if (!o.glb_out.empty()) {
        if (auto st = engine::assets::write_glb(o.glb_out, out.meshes); !st.ok()) {
            std::cerr << "wiretool mesh: " << st.message << "\n";
            if (!o.csv_out.empty()) std::remove(o.csv_out.c_str());
            return exit_failure;
        }
    }
    return exit_ok;
}

}  // namespace

Action add_mesh_command(CLI::App& app) {
    auto o = std::make_shared<MeshOptions>();
    CLI::App* cmd = app.add_subcommand(
        "mesh",
        "Turn wires (JSON) into tube meshes. IN.json is one wire {\"radius\", \"closed\", \"spline\", \"nodes\"}, "
        "{\"wires\": [...]} or {\"frames\": [{\"wires\": [...]}, ...]} (successive states; nodes matched by id).");
    cmd->add_option("input", o->input, "Wire JSON file")->required();
    cmd->add_option("-o,--output", o->glb_out, "Write binary glTF: one mesh per wire (the last frame)");
    cmd->add_option("--csv", o->csv_out, "Write one row per ring (every frame)");
    cmd->add_option("--spline", o->overrides.spline_type, "uniform|centripetal|chordal|c2|auto (also catmull-rom, linear); default auto")
        ->check(CLI::IsMember({"uniform", "centripetal", "chordal", "c2", "auto", "automatic", "catmull-rom", "linear"}));
    cmd->add_option("--alpha", o->overrides.alpha, "Catmull-Rom knot exponent (0 uniform, 0.5 centripetal, 1 chordal)")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--tension", o->overrides.tension, "Cardinal tension (0 = Catmull-Rom, 1 = straight)")
        ->check(CLI::Range(-1.0, 1.0));
    auto* rps = cmd->add_option("--rings-per-segment", o->overrides.rings_per_segment,
                                "Rings per node interval at t = k/N (default 8)")
                    ->check(CLI::Range(1u, 4096u));
    auto* tol = cmd->add_option("--tolerance", o->overrides.tolerance_m,
                                "Adaptive rings: no point of the curve farther than METRES from the ring polyline")
                    ->check(CLI::PositiveNumber);
    rps->excludes(tol);
    cmd->add_option("--sides", o->overrides.sides, "Radial sides (default 12, or the file's \"sides\")")->check(CLI::Range(3u, 1024u));
    cmd->add_flag("--no-caps", o->no_caps, "Leave the ends of open wires open");
    cmd->add_option("--repeat", o->repeat,
                    "Generate R times and print 'vertices=<N> mean_ms=<X>' to stderr (one generation)")
        ->check(CLI::Range(1u, 1000000u));
    return [o] { return run_mesh(*o); };
}

}  // namespace wiretool
