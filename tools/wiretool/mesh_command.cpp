// `wiretool mesh`: wire JSON -> tube meshes (binary glTF) and ring records (CSV). A contract: see README.
#include "commands.hpp"

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
    std::optional<std::string> spline;
    std::optional<double> alpha;
    std::optional<double> tension;
    std::optional<uint32_t> rings_per_segment;
    std::optional<double> tolerance_m;
    std::optional<uint32_t> sides;
    uint32_t repeat = 0;
    bool no_caps = false;
};

/// Settings of one wire: command line over file over defaults, field by field.
wire::Status resolve(const wire::io::WireSpec& spec, const MeshOptions& o, wire::PipelineSettings& out) {
    wire::PipelineSettings s;  // defaults
    const std::string type = o.spline ? *o.spline : spec.spline_type.value_or("centripetal");
    if (type == "uniform" || type == "centripetal" || type == "chordal" || type == "catmull-rom") {
        s.spline.kind = wire::SplineKind::catmull_rom;
        const double implied = type == "uniform" ? 0.0 : type == "chordal" ? 1.0 : 0.5;
        // A type named on the command line implies its alpha unless --alpha is given too.
        s.spline.alpha = o.alpha ? *o.alpha : o.spline ? implied : spec.alpha.value_or(implied);
    } else if (type == "c2") {
        s.spline.kind = wire::SplineKind::c2;
    } else if (type == "auto" || type == "automatic") {
        s.spline.kind = wire::SplineKind::automatic;
    } else if (type == "linear") {
        s.spline.kind = wire::SplineKind::linear;
    } else {
        return wire::Status::error("unknown spline type '" + type +
                                   "' (expected uniform, centripetal, chordal, catmull-rom, c2, auto or linear)");
    }
    if (o.alpha && !(s.spline.kind == wire::SplineKind::catmull_rom))
        return wire::Status::error("--alpha applies to uniform/centripetal/chordal/catmull-rom, not '" + type + "'");
    s.spline.tension = o.tension ? *o.tension : spec.tension.value_or(0.0);
    s.spline.bias = spec.bias.value_or(0.0);
    s.spline.continuity = spec.continuity.value_or(0.0);
    s.spline.curvature_tension = spec.curvature_tension.value_or(!spec.physics.empty());
    s.spline.closed = spec.closed.value_or(false);
    if (spec.radius_m) s.spline.radius_m = static_cast<float>(*spec.radius_m);
    if (o.tolerance_m) {
        s.tessellate.tolerance_m = *o.tolerance_m;
    } else {
        s.tessellate.rings_per_segment = o.rings_per_segment.value_or(8);
    }
    s.tube.sides = o.sides ? *o.sides : static_cast<uint32_t>(spec.sides.value_or(12));
    s.tube.caps = o.no_caps ? false : spec.caps.value_or(true);
    out = s;
    return wire::Status::success();
}

wire::WireNodes to_nodes(const wire::io::WireSpec& spec) {
    wire::WireNodes n;
    n.positions = spec.positions;
    n.ids = spec.ids;
    n.stretch = spec.stretch;
    n.radius_m.resize(spec.radius.size());
    for (std::size_t i = 0; i < spec.radius.size(); ++i) n.radius_m[i] = spec.radius[i] > 0 ? spec.radius[i] : 0.0f;
    for (const wire::io::NodePhysics& p : spec.physics) {
        n.theta_rad.push_back(p.theta);
        n.iz_m4.push_back(p.Iz);
        n.length_m.push_back(p.L);
        n.delta_length_m.push_back(p.dL);
        n.area_m2.push_back(p.A);
    }
    for (const glm::dvec3& tcb : spec.tcb) {
        n.kb_tension.push_back(static_cast<float>(tcb.x));
        n.kb_bias.push_back(static_cast<float>(tcb.y));
        n.kb_continuity.push_back(static_cast<float>(tcb.z));
    }
    return n;
}

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

void append_csv(std::string& csv, std::size_t frame, std::size_t wire_index, const wire::RingSet& r) {
    char line[640];
    for (std::size_t i = 0; i < r.params.size(); ++i) {
        const glm::dvec3 c = r.origin_m + r.centre_m[i];
        const wire::Frame& f = r.frames[i];
        const int n = std::snprintf(
            line, sizeof line,
            "%zu,%zu,%zu,%u,%.17g,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.17g\n", frame,
            wire_index, i, r.params[i].segment, r.params[i].t, c.x, c.y, c.z, f.t.x, f.t.y, f.t.z, f.r.x, f.r.y,
            f.r.z, f.s.x, f.s.y, f.s.z, double(r.rings[i].radius_m), r.u[i]);
        csv.append(line, static_cast<std::size_t>(n));
    }
}

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
/// Wires keep their pipeline state (pop-free remedy, carried-over first frame) across frames.
wire::Status generate(const wire::io::SceneSpec& scene, const std::vector<std::vector<wire::PipelineSettings>>& settings,
                      const MeshOptions& o, bool want_outputs, Output& out) {
    const std::size_t wires = scene.frames.front().wires.size();
    std::vector<wire::WirePipeline> pipelines(wires);
    out = Output{};
    for (std::size_t f = 0; f < scene.frames.size(); ++f) {
        const bool last = f + 1 == scene.frames.size();
        for (std::size_t w = 0; w < wires; ++w) {
            const wire::io::WireSpec& spec = scene.frames[f].wires[w];
            wire::Status st = pipelines[w].update(to_nodes(spec), settings[f][w]);
            if (!st.ok) return wire::Status::error(where(o.input, f, scene.frames.size(), w) + ": " + st.message, st.node);
            out.vertices += pipelines[w].mesh().vertices.size();
            if (want_outputs) {
                if (!o.csv_out.empty()) append_csv(out.csv, f, w, pipelines[w].rings());
                if (last) out.meshes.push_back(to_mesh_data(pipelines[w].mesh(), w));
            }
        }
    }
    return wire::Status::success();
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

int run_mesh(const MeshOptions& o) {
    wire::io::SceneSpec scene;
    if (wire::Status st = wire::io::load_wire_json(o.input, scene); !st.ok) {
        std::cerr << "wiretool mesh: " << st.message << "\n";
        return exit_bad_input;
    }
    std::vector<std::vector<wire::PipelineSettings>> settings(scene.frames.size());
    for (std::size_t f = 0; f < scene.frames.size(); ++f)
        for (std::size_t w = 0; w < scene.frames[f].wires.size(); ++w) {
            wire::PipelineSettings s;
            if (wire::Status st = resolve(scene.frames[f].wires[w], o, s); !st.ok) {
                std::cerr << "wiretool mesh: " << where(o.input, f, scene.frames.size(), w) << ": " << st.message
                          << "\n";
                return exit_bad_input;
            }
            settings[f].push_back(s);
        }

    Output out;
    if (wire::Status st = generate(scene, settings, o, true, out); !st.ok) {
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
        const std::string header = "frame,wire,ring,segment,t,x,y,z,tx,ty,tz,nx,ny,nz,bx,by,bz,radius,u\n";
        if (!write_atomically(o.csv_out, header + out.csv, error)) {
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
    cmd->add_option("--spline", o->spline, "uniform|centripetal|chordal|c2|auto (also catmull-rom, linear)")
        ->check(CLI::IsMember({"uniform", "centripetal", "chordal", "c2", "auto", "automatic", "catmull-rom", "linear"}));
    cmd->add_option("--alpha", o->alpha, "Catmull-Rom knot exponent (0 uniform, 0.5 centripetal, 1 chordal)")
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--tension", o->tension, "Cardinal tension (0 = Catmull-Rom, 1 = straight)")
        ->check(CLI::Range(-1.0, 1.0));
    auto* rps = cmd->add_option("--rings-per-segment", o->rings_per_segment,
                                "Rings per node interval at t = k/N (default 8)")
                    ->check(CLI::Range(1u, 4096u));
    auto* tol = cmd->add_option("--tolerance", o->tolerance_m,
                                "Adaptive rings: no point of the curve farther than METRES from the ring polyline")
                    ->check(CLI::PositiveNumber);
    rps->excludes(tol);
    cmd->add_option("--sides", o->sides, "Radial sides (default 12, or the file's \"sides\")")->check(CLI::Range(3u, 1024u));
    cmd->add_flag("--no-caps", o->no_caps, "Leave the ends of open wires open");
    cmd->add_option("--repeat", o->repeat,
                    "Generate R times and print 'vertices=<N> mean_ms=<X>' to stderr (one generation)")
        ->check(CLI::Range(1u, 1000000u));
    return [o] { return run_mesh(*o); };
}

}  // namespace wiretool
