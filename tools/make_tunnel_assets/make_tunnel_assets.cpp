// Writes the coarse tunnel pieces: make_tunnel_assets --out assets/tunnel
// (straight_section.glb, wall_details.glb, cable_hooks.glb, anchors.json). Output is deterministic: the
// committed files must equal it byte for byte (tests/engine/assets/subdivide_test.cpp checks).
#include "tunnel_pieces.hpp"

#include <engine/assets/gltf.hpp>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
    std::string out_dir;
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
            out_dir = argv[++i];
        } else {
            std::fprintf(stderr, "usage: make_tunnel_assets --out DIR\n");
            return 2;
        }
    }
    if (out_dir.empty()) {
        std::fprintf(stderr, "usage: make_tunnel_assets --out DIR\n");
        return 2;
    }
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    const tunnel::TunnelSpec spec;
    const struct {
        const char* file;
        std::vector<engine::assets::MeshData> meshes;
    } pieces[] = {{"straight_section.glb", tunnel::straight_section(spec)},
                  {"wall_details.glb", tunnel::wall_details(spec)},
                  {"cable_hooks.glb", tunnel::cable_hooks(spec)}};
    for (const auto& piece : pieces) {
        const std::string path = (std::filesystem::path(out_dir) / piece.file).string();
        if (auto s = engine::assets::write_glb(path, piece.meshes); !s.ok()) {
            std::fprintf(stderr, "make_tunnel_assets: %s\n", s.message.c_str());
            return 1;
        }
    }
    const std::string json_path = (std::filesystem::path(out_dir) / "anchors.json").string();
    std::ofstream json(json_path, std::ios::binary | std::ios::trunc);
    json << tunnel::anchors_json(tunnel::anchors(spec));
    if (!json) {
        std::fprintf(stderr, "make_tunnel_assets: %s: write failed\n", json_path.c_str());
        return 1;
    }
    return 0;
}
