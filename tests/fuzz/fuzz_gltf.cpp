// libFuzzer target: read_gltf_memory on arbitrary bytes (GLB or glTF JSON); every accepted mesh goes through
// make_control_mesh and subdivide (level 1). Property: errors carry a message naming the input; accepted meshes
// are well-formed (finite, indices in range) and so is their subdivision.
#include "fuzz_checks.hpp"

#include <engine/assets/gltf.hpp>
#include <engine/assets/subdivide.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace {

void check_mesh(const engine::assets::MeshData& m, const char* stage) {
    const std::string where = std::string(stage) + ": ";
    wire_fuzz::require(m.positions.size() % 3 == 0, (where + "positions not xyz").c_str());
    wire_fuzz::require(m.normals.size() == m.positions.size(), (where + "normal count differs").c_str());
    wire_fuzz::require(m.uvs.empty() || m.uvs.size() / 2 == m.vertex_count(), (where + "uv count differs").c_str());
    wire_fuzz::require(m.indices.size() % 3 == 0, (where + "indices not triangles").c_str());
    for (float f : m.positions) wire_fuzz::require(std::isfinite(f), (where + "position not finite").c_str());
    for (float f : m.normals) wire_fuzz::require(std::isfinite(f), (where + "normal not finite").c_str());
    for (float f : m.uvs) wire_fuzz::require(std::isfinite(f), (where + "uv not finite").c_str());
    for (uint32_t i : m.indices) wire_fuzz::require(i < m.vertex_count(), (where + "index out of range").c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    std::vector<engine::assets::MeshData> meshes;
    const engine::Status st =
        engine::assets::read_gltf_memory(std::as_bytes(std::span(data, size)), "fuzz.glb", meshes);
    if (!st.ok()) {
        wire_fuzz::require(st.message.rfind("fuzz.glb: ", 0) == 0, "glTF error does not name the input");
        wire_fuzz::require(st.message.size() > 10, "glTF error without a message");
        wire_fuzz::require(meshes.empty(), "rejected glTF left meshes in the output");
        return 0;
    }
    wire_fuzz::require(!meshes.empty(), "accepted glTF without meshes");
    for (const engine::assets::MeshData& m : meshes) {
        check_mesh(m, "read_gltf");
        if (m.triangle_count() > 20000) continue;  // keep one run fast
        engine::assets::ControlMesh control;
        const engine::Status cs = engine::assets::make_control_mesh(m, control);
        if (!cs.ok()) {
            wire_fuzz::require(!cs.message.empty(), "make_control_mesh error without a message");
            continue;
        }
        for (float f : control.positions) wire_fuzz::require(std::isfinite(f), "control position not finite");
        engine::assets::MeshData fine;
        const engine::Status ss = engine::assets::subdivide(control, 1, fine);
        if (!ss.ok()) {
            wire_fuzz::require(!ss.message.empty(), "subdivide error without a message");
            continue;
        }
        check_mesh(fine, "subdivide");
    }
    return 0;
}
