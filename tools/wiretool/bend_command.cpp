// `wiretool bend`: bakes the curved-space bend (a chain of arc segments, SEGS.json) into every mesh of a glTF
// file, positions and normals, with the CPU reference. A contract: see docs/wiretool.md.
#include "commands.hpp"

#include <curved_space/chain.hpp>
#include <curved_space/segments_json.hpp>
#include <engine/assets/gltf.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace wiretool {
namespace {

struct BendOptions {
    std::string input;
    std::string segments;
    std::string output;
};

bool finite(const std::vector<float>& values, std::size_t& bad) {
    for (std::size_t i = 0; i < values.size(); ++i)
        if (!std::isfinite(values[i])) {
            bad = i;
            return false;
        }
    return true;
}

int run_bend(const BendOptions& o) {
    std::vector<curved_space::Segment> segments;
    if (engine::Status s = curved_space::read_segments_json(o.segments, segments); !s) {
        std::fprintf(stderr, "wiretool bend: %s\n", s.message.c_str());
        return exit_bad_input;
    }
    curved_space::Chain chain;
    if (engine::Status s = curved_space::make_chain(segments, chain); !s) {  // validated already; kept for safety
        std::fprintf(stderr, "wiretool bend: %s: %s\n", o.segments.c_str(), s.message.c_str());
        return exit_bad_input;
    }

    std::vector<engine::assets::MeshData> meshes;
    if (engine::Status s = engine::assets::read_gltf(o.input, meshes); !s.ok()) {
        std::fprintf(stderr, "wiretool bend: %s\n", s.message.c_str());
        return exit_bad_input;
    }
    if (meshes.empty()) {
        std::fprintf(stderr, "wiretool bend: %s: no triangle meshes to bend\n", o.input.c_str());
        return exit_bad_input;
    }

    std::size_t vertices = 0;
    std::size_t folded = 0;
    for (std::size_t m = 0; m < meshes.size(); ++m) {
        engine::assets::MeshData& mesh = meshes[m];
        std::size_t bad = 0;
        if (!finite(mesh.positions, bad) || !finite(mesh.normals, bad)) {
            std::fprintf(stderr, "wiretool bend: %s: mesh %zu ('%s'), vertex %zu: position or normal is not finite\n",
                         o.input.c_str(), m, mesh.name.c_str(), bad / 3);
            return exit_bad_input;
        }
        if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size()) {
            std::fprintf(stderr, "wiretool bend: %s: mesh %zu ('%s'): normal count differs from position count\n",
                         o.input.c_str(), m, mesh.name.c_str());
            return exit_bad_input;
        }
        folded += curved_space::bend_vertices(chain, mesh.positions, mesh.normals, mesh.origin);
        vertices += mesh.vertex_count();
    }
    if (folded > 0)
        std::fprintf(stderr,
                     "wiretool bend: warning: %zu of %zu vertices lie past a bend's centre of curvature (the mesh "
                     "folds there: use a larger length or smaller angle)\n",
                     folded, vertices);

    if (engine::Status s = engine::assets::write_glb(o.output, meshes); !s.ok()) {
        std::fprintf(stderr, "wiretool bend: %s\n", s.message.c_str());
        return exit_failure;
    }
    std::printf("bent %zu mesh(es), %zu vertices, along %zu segment(s) (%.6g m) -> %s\n", meshes.size(), vertices,
                chain.segment_count(), chain.total_length_m(), o.output.c_str());
    return exit_ok;
}

}  // namespace

Action add_bend_command(CLI::App& app) {
    auto o = std::make_shared<BendOptions>();
    CLI::App* cmd = app.add_subcommand(
        "bend",
        "Bend every mesh of a glTF file along a chain of circular-arc segments (positions and normals baked). "
        "The mesh's +z axis runs along the chain, starting at the origin. SEGS.json: {\"segments\": "
        "[{\"length\": metres, \"angle\": radians, \"direction\": radians (optional, 0 = toward +x)}, ...]}.");
    cmd->add_option("input", o->input, "Input mesh (.glb or .gltf)")->required();
    cmd->add_option("--segments", o->segments, "Segment list (JSON)")->required();
    cmd->add_option("-o,--output", o->output, "Output binary glTF (written atomically)")->required();
    return [o] { return run_bend(*o); };
}

}  // namespace wiretool
