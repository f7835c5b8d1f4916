// glTF 2.0 reading and writing of plain triangle meshes through tinygltf.
#pragma once

#include <engine/assets/mesh_data.hpp>

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace engine::assets {

/// Writes binary glTF (.glb): one glTF mesh (one triangle primitive) and one node per MeshData, the
/// node translated by the mesh's origin. Attributes: POSITION (with min/max), NORMAL, TEXCOORD_0 when
/// uvs are present; uint32 indices. Writes to a temporary file and renames it, so a failure leaves no
/// partial file at `path`.
Status write_glb(const std::string& path, std::span<const MeshData> meshes);

/// Reads a .gltf or .glb file: every TRIANGLES primitive of every mesh reached from the default scene
/// (or from every node when there is no scene) becomes one MeshData with node transforms applied to
/// positions and normals (origin stays 0). Accepts any index component type and float vertex
/// attributes; a missing NORMAL is computed from the faces. Errors name the file and what is wrong.
Status read_gltf(const std::string& path, std::vector<MeshData>& out);

/// read_gltf for a .glb or .gltf already in memory; `name` stands for the file in every message. Buffers and
/// images must be embedded (GLB chunk or data: URI): an external URI is an error, nothing is read from disk.
Status read_gltf_memory(std::span<const std::byte> bytes, const std::string& name, std::vector<MeshData>& out);

}  // namespace engine::assets
