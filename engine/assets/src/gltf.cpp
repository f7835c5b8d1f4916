// glTF reading and writing; the only translation unit that compiles tinygltf's implementation.
#define TINYGLTF_IMPLEMENTATION
// Geometry only: no image is ever decoded (no stb_image on untrusted bytes, see the image loader below) nor
// written, and an image's external URI is never opened.
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include <engine/assets/gltf.hpp>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>

namespace engine::assets {
namespace {

void append_bytes(std::vector<unsigned char>& buffer, const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), p, p + bytes);
    while (buffer.size() % 4 != 0) buffer.push_back(0);  // keep every view 4-byte aligned
}

int add_view_and_accessor(tinygltf::Model& model, std::vector<unsigned char>& buffer, const void* data,
                          std::size_t bytes, int component_type, int type, std::size_t count, int target) {
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = bytes;
    view.target = target;
    append_bytes(buffer, data, bytes);
    model.bufferViews.push_back(view);

    tinygltf::Accessor accessor;
    accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
    accessor.byteOffset = 0;
    accessor.componentType = component_type;
    accessor.type = type;
    accessor.count = count;
    model.accessors.push_back(accessor);
    return static_cast<int>(model.accessors.size()) - 1;
}

Status check_mesh(const MeshData& m, std::size_t index) {
    const std::string who = "mesh " + std::to_string(index) + (m.name.empty() ? "" : " '" + m.name + "'");
    if (m.positions.size() % 3 != 0) return Status::error(who + ": positions are not xyz triples");
    if (!m.normals.empty() && m.normals.size() != m.positions.size())
        return Status::error(who + ": normals count differs from positions");
    if (!m.uvs.empty() && m.uvs.size() / 2 != m.positions.size() / 3)
        return Status::error(who + ": uv count differs from vertex count");
    if (m.indices.size() % 3 != 0) return Status::error(who + ": indices are not triangles");
    const std::size_t n = m.vertex_count();
    for (std::size_t i = 0; i < m.indices.size(); ++i)
        if (m.indices[i] >= n)
            return Status::error(who + ": index " + std::to_string(i) + " = " + std::to_string(m.indices[i]) +
                                   " out of range (" + std::to_string(n) + " vertices)");
    return {};
}

}  // namespace

Status write_glb(const std::string& path, std::span<const MeshData> meshes) {
    for (std::size_t i = 0; i < meshes.size(); ++i)
        if (Status s = check_mesh(meshes[i], i); !s.ok()) return Status::error(path + ": " + s.message);

    tinygltf::Model model;
    model.asset.version = "2.0";
    model.asset.generator = "wires runtime";
    std::vector<unsigned char> buffer;
    tinygltf::Scene scene;

    for (const MeshData& m : meshes) {
        tinygltf::Primitive prim;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        const std::size_t n = m.vertex_count();
        const int pos = add_view_and_accessor(model, buffer, m.positions.data(), m.positions.size() * 4,
                                              TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n,
                                              TINYGLTF_TARGET_ARRAY_BUFFER);
        // POSITION requires min and max.
        std::vector<double> lo(3, n ? std::numeric_limits<double>::infinity() : 0.0);
        std::vector<double> hi(3, n ? -std::numeric_limits<double>::infinity() : 0.0);
        for (std::size_t v = 0; v < n; ++v)
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], double(m.positions[3 * v + k]));
                hi[k] = std::max(hi[k], double(m.positions[3 * v + k]));
            }
        model.accessors[pos].minValues = lo;
        model.accessors[pos].maxValues = hi;
        prim.attributes["POSITION"] = pos;
        if (!m.normals.empty())
            prim.attributes["NORMAL"] =
                add_view_and_accessor(model, buffer, m.normals.data(), m.normals.size() * 4,
                                      TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n,
                                      TINYGLTF_TARGET_ARRAY_BUFFER);
        if (!m.uvs.empty())
            prim.attributes["TEXCOORD_0"] =
                add_view_and_accessor(model, buffer, m.uvs.data(), m.uvs.size() * 4,
                                      TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n,
                                      TINYGLTF_TARGET_ARRAY_BUFFER);
        prim.indices = add_view_and_accessor(model, buffer, m.indices.data(), m.indices.size() * 4,
                                             TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                             m.indices.size(), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        tinygltf::Mesh mesh;
        mesh.name = m.name;
        mesh.primitives.push_back(prim);
        model.meshes.push_back(mesh);

        tinygltf::Node node;
        node.name = m.name;
        node.mesh = static_cast<int>(model.meshes.size()) - 1;
        if (m.origin != glm::dvec3(0.0)) node.translation = {m.origin.x, m.origin.y, m.origin.z};
        model.nodes.push_back(node);
        scene.nodes.push_back(static_cast<int>(model.nodes.size()) - 1);
    }
    tinygltf::Buffer b;
    b.data = std::move(buffer);
    model.buffers.push_back(std::move(b));
    model.scenes.push_back(scene);
    model.defaultScene = 0;

    std::ostringstream stream;
    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToStream(&model, stream, false, true))
        return Status::error(path + ": tinygltf could not serialize the model");

    const std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return Status::error(path + ": cannot open '" + tmp + "' for writing: " + std::strerror(errno));
        const std::string bytes = stream.str();
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        out.flush();
        if (!out) {
            out.close();
            std::remove(tmp.c_str());
            return Status::error(path + ": write failed: " + std::strerror(errno));
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string why = std::strerror(errno);
        std::remove(tmp.c_str());
        return Status::error(path + ": cannot rename temporary file: " + why);
    }
    return {};
}

namespace {

/// Reads `count` elements of `components` floats from a float accessor (honours byteStride).
Status read_float_accessor(const tinygltf::Model& model, int index, int components, std::vector<float>& out,
                           const std::string& who) {
    if (index < 0 || index >= static_cast<int>(model.accessors.size()))
        return Status::error(who + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model.accessors[index];
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
        return Status::error(who + ": accessor " + std::to_string(index) + " is not float");
    if (tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type)) != components)
        return Status::error(who + ": accessor " + std::to_string(index) + " has " +
                               std::to_string(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type))) +
                               " components, expected " + std::to_string(components));
    if (a.bufferView < 0 || a.bufferView >= static_cast<int>(model.bufferViews.size()))
        return Status::error(who + ": accessor " + std::to_string(index) + " has no buffer view (sparse or "
                               "empty accessors are not supported)");
    const tinygltf::BufferView& v = model.bufferViews[a.bufferView];
    if (v.buffer < 0 || v.buffer >= static_cast<int>(model.buffers.size()))
        return Status::error(who + ": buffer view " + std::to_string(a.bufferView) + " names no buffer");
    const std::vector<unsigned char>& data = model.buffers[v.buffer].data;
    const std::size_t elem = std::size_t(components) * 4;
    const std::size_t stride = v.byteStride ? v.byteStride : elem;
    // Overflow-safe (counts and offsets come from the file): the last element, [start + stride * (count - 1),
    // + elem), lies within the view, and the view within the buffer.
    const std::size_t view_begin = std::min(v.byteOffset, data.size());
    const std::size_t view_end = v.byteLength > data.size() - view_begin ? data.size() : view_begin + v.byteLength;
    const std::size_t room = view_end - view_begin;
    if (a.count > 0 && (stride < elem || a.byteOffset > room || room - a.byteOffset < elem ||
                        a.count - 1 > (room - a.byteOffset - elem) / stride))
        return Status::error(who + ": accessor " + std::to_string(index) + " reads past its buffer");
    const std::size_t start = view_begin + a.byteOffset;
    out.resize(a.count * components);
    for (std::size_t i = 0; i < a.count; ++i) std::memcpy(&out[i * components], &data[start + i * stride], elem);
    return {};
}

Status read_indices(const tinygltf::Model& model, int index, std::vector<uint32_t>& out, const std::string& who) {
    if (index < 0 || index >= static_cast<int>(model.accessors.size()))
        return Status::error(who + ": index accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model.accessors[index];
    if (a.type != TINYGLTF_TYPE_SCALAR) return Status::error(who + ": index accessor is not scalar");
    std::size_t size = 0;
    switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
        default: return Status::error(who + ": index component type " + std::to_string(a.componentType) +
                                        " is not an unsigned integer type");
    }
    if (a.bufferView < 0 || a.bufferView >= static_cast<int>(model.bufferViews.size()))
        return Status::error(who + ": index accessor has no buffer view");
    const tinygltf::BufferView& v = model.bufferViews[a.bufferView];
    if (v.buffer < 0 || v.buffer >= static_cast<int>(model.buffers.size()))
        return Status::error(who + ": index buffer view names no buffer");
    const std::vector<unsigned char>& data = model.buffers[v.buffer].data;
    const std::size_t stride = v.byteStride ? v.byteStride : size;
    // Overflow-safe, as in read_float_accessor.
    const std::size_t begin = std::min(v.byteOffset, data.size());
    const std::size_t room = data.size() - begin;
    if (a.count > 0 && (stride < size || a.byteOffset > room || room - a.byteOffset < size ||
                        a.count - 1 > (room - a.byteOffset - size) / stride))
        return Status::error(who + ": index accessor reads past its buffer");
    const std::size_t start = begin + a.byteOffset;
    out.resize(a.count);
    for (std::size_t i = 0; i < a.count; ++i) {
        const unsigned char* p = &data[start + i * stride];
        uint32_t value = 0;
        if (size == 1) value = p[0];
        else if (size == 2) { uint16_t s; std::memcpy(&s, p, 2); value = s; }
        else std::memcpy(&value, p, 4);
        out[i] = value;
    }
    return {};
}

glm::dmat4 local_matrix(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3) m = glm::translate(m, glm::make_vec3(node.translation.data()));
    if (node.rotation.size() == 4) {
        const glm::dquat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        m = m * glm::mat4_cast(glm::normalize(q));
    }
    if (node.scale.size() == 3) m = glm::scale(m, glm::make_vec3(node.scale.data()));
    return m;
}

Status convert_mesh(const tinygltf::Model& model, int mesh_index, const glm::dmat4& world, const std::string& file,
                    std::vector<MeshData>& out) {
    const tinygltf::Mesh& mesh = model.meshes[mesh_index];
    for (std::size_t p = 0; p < mesh.primitives.size(); ++p) {
        const tinygltf::Primitive& prim = mesh.primitives[p];
        const std::string who = file + ": mesh " + std::to_string(mesh_index) +
                                (mesh.name.empty() ? "" : " '" + mesh.name + "'") + " primitive " + std::to_string(p);
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;  // points/lines: not meshes
        auto it = prim.attributes.find("POSITION");
        if (it == prim.attributes.end()) return Status::error(who + ": no POSITION attribute");
        MeshData m;
        m.name = mesh.name;
        if (Status s = read_float_accessor(model, it->second, 3, m.positions, who); !s.ok()) return s;
        if (auto n = prim.attributes.find("NORMAL"); n != prim.attributes.end())
            if (Status s = read_float_accessor(model, n->second, 3, m.normals, who); !s.ok()) return s;
        if (auto t = prim.attributes.find("TEXCOORD_0"); t != prim.attributes.end())
            if (Status s = read_float_accessor(model, t->second, 2, m.uvs, who); !s.ok()) return s;
        const std::size_t n = m.vertex_count();
        if (!m.normals.empty() && m.normals.size() != m.positions.size())
            return Status::error(who + ": NORMAL count differs from POSITION count");
        if (!m.uvs.empty() && m.uvs.size() / 2 != n)
            return Status::error(who + ": TEXCOORD_0 count differs from POSITION count");
        if (prim.indices >= 0) {
            if (Status s = read_indices(model, prim.indices, m.indices, who); !s.ok()) return s;
        } else {
            m.indices.resize(n);
            for (std::size_t i = 0; i < n; ++i) m.indices[i] = static_cast<uint32_t>(i);
        }
        if (m.indices.size() % 3 != 0) return Status::error(who + ": index count is not a multiple of 3");
        for (std::size_t i = 0; i < m.indices.size(); ++i)
            if (m.indices[i] >= n)
                return Status::error(who + ": index " + std::to_string(i) + " = " +
                                       std::to_string(m.indices[i]) + " is out of range (" + std::to_string(n) +
                                       " vertices)");
        for (float f : m.positions)
            if (!std::isfinite(f)) return Status::error(who + ": POSITION holds a NaN or infinite value");
        for (float f : m.normals)
            if (!std::isfinite(f)) return Status::error(who + ": NORMAL holds a NaN or infinite value");
        for (float f : m.uvs)
            if (!std::isfinite(f)) return Status::error(who + ": TEXCOORD_0 holds a NaN or infinite value");
        if (m.normals.empty()) {  // area-weighted face normals
            std::vector<glm::dvec3> acc(n, glm::dvec3(0.0));
            auto P = [&](uint32_t i) { return glm::dvec3(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]); };
            for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
                const glm::dvec3 fn = glm::cross(P(m.indices[t + 1]) - P(m.indices[t]), P(m.indices[t + 2]) - P(m.indices[t]));
                for (int k = 0; k < 3; ++k) acc[m.indices[t + k]] += fn;
            }
            m.normals.resize(3 * n);
            for (std::size_t i = 0; i < n; ++i) {
                const double len = glm::length(acc[i]);
                const glm::dvec3 d = len > 0 ? acc[i] / len : glm::dvec3(0, 0, 1);
                for (int k = 0; k < 3; ++k) m.normals[3 * i + k] = float(d[k]);
            }
        }
        if (world != glm::dmat4(1.0)) {
            const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(world)));
            for (std::size_t i = 0; i < n; ++i) {
                const glm::dvec4 q = world * glm::dvec4(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2], 1.0);
                glm::dvec3 nn = normal_matrix * glm::dvec3(m.normals[3 * i], m.normals[3 * i + 1], m.normals[3 * i + 2]);
                const double len = glm::length(nn);
                if (len > 0) nn /= len;
                for (int k = 0; k < 3; ++k) {
                    m.positions[3 * i + k] = float(q[k]);
                    m.normals[3 * i + k] = float(nn[k]);
                }
            }
        }
        // Huge (finite) positions or node scales overflow the float results or the computed normals.
        for (std::size_t i = 0; i < m.positions.size(); ++i)
            if (!std::isfinite(m.positions[i]) || !std::isfinite(m.normals[i]))
                return Status::error(who + ": a position or normal is not finite after the node transforms "
                                             "(values too large)");
        out.push_back(std::move(m));
    }
    return {};
}

Status visit_node(const tinygltf::Model& model, int node_index, const glm::dmat4& parent, const std::string& file,
                  std::vector<MeshData>& out, int depth) {
    if (node_index < 0 || node_index >= static_cast<int>(model.nodes.size()))
        return Status::error(file + ": node " + std::to_string(node_index) + " does not exist");
    if (depth > 64) return Status::error(file + ": node hierarchy deeper than 64 (a cycle?)");
    const tinygltf::Node& node = model.nodes[node_index];
    const glm::dmat4 world = parent * local_matrix(node);
    if (node.mesh >= 0) {
        if (node.mesh >= static_cast<int>(model.meshes.size()))
            return Status::error(file + ": node " + std::to_string(node_index) + " names mesh " +
                                   std::to_string(node.mesh) + " which does not exist");
        if (Status s = convert_mesh(model, node.mesh, world, file, out); !s.ok()) return s;
    }
    for (int child : node.children)
        if (Status s = visit_node(model, child, world, file, out, depth + 1); !s.ok()) return s;
    return {};
}

}  // namespace

namespace {

/// Meshes of a loaded model (default scene, or every mesh when there is no scene); `file` names it in errors.
Status convert_model(const tinygltf::Model& model, const std::string& file, std::vector<MeshData>& out) {
    Status s;
    const glm::dmat4 identity(1.0);
    if (!model.scenes.empty()) {
        const int scene = model.defaultScene >= 0 && model.defaultScene < static_cast<int>(model.scenes.size())
                              ? model.defaultScene
                              : 0;
        for (int n : model.scenes[scene].nodes)
            if (s = visit_node(model, n, identity, file, out, 0); !s.ok()) break;
    } else {
        for (int m = 0; m < static_cast<int>(model.meshes.size()) && s.ok(); ++m)
            s = convert_mesh(model, m, identity, file, out);
    }
    if (!s.ok()) {
        out.clear();
        return s;
    }
    if (out.empty()) return Status::error(file + ": contains no triangle mesh");
    return {};
}

// ---- untrusted input: the GLB container, the JSON's buffers and images, external URIs ----

constexpr uint32_t kChunkJson = 0x4E4F534Au;  // "JSON" little-endian
constexpr uint32_t kChunkBin = 0x004E4942u;   // "BIN\0"
constexpr std::size_t kMaxBytes = std::numeric_limits<unsigned int>::max();  // tinygltf takes an unsigned int size

uint32_t le32(const unsigned char* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

std::string chunk_name(uint32_t type) {
    if (type == kChunkJson) return "JSON";
    if (type == kChunkBin) return "BIN";
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%08x", type);
    return std::string("of unknown type ") + hex;
}

/// The GLB container as validated by check_glb.
struct Glb {
    uint32_t length = 0;     ///< bytes of the GLB (the header's length; trailing bytes after it are ignored)
    std::size_t json_offset = 0, json_size = 0;
    bool has_bin = false;
    std::size_t bin_size = 0;
};

/// Checks the binary glTF container before tinygltf sees it (tinygltf 2.7.0 trusts the BIN chunk's length:
/// a BIN chunk claiming more bytes than the file holds is read past the end). Returns what is wrong, or nothing.
/// Layout: 12-byte header (magic "glTF", version 2, total length), then chunks of [length, type, data], each
/// length a multiple of 4; the first chunk is JSON, the second (if any) BIN, later chunks of unknown types are
/// skipped (glTF 2.0 spec), and the chunks fill the length exactly.
std::optional<std::string> check_glb(const unsigned char* data, std::size_t size, Glb& glb) {
    if (size < 12) return "shorter than the 12-byte GLB header (" + std::to_string(size) + " bytes)";
    if (std::memcmp(data, "glTF", 4) != 0) return std::string("the magic is not 'glTF'");
    const uint32_t version = le32(data + 4);
    if (version != 2) return "GLB version " + std::to_string(version) + " is not supported (only version 2)";
    const uint32_t length = le32(data + 8);
    if (length > size)
        return "the header's length " + std::to_string(length) + " exceeds the " + std::to_string(size) +
               " bytes given (truncated file?)";
    if (length % 4 != 0) return "the header's length " + std::to_string(length) + " is not a multiple of 4";
    if (length < 20) return "the header's length " + std::to_string(length) + " leaves no room for the JSON chunk";
    glb.length = length;
    std::size_t offset = 12;
    for (std::size_t k = 0; offset < length; ++k) {
        const std::string at = "chunk " + std::to_string(k) + " at byte " + std::to_string(offset);
        if (length - offset < 8)
            return at + ": its 8-byte header runs past the GLB length " + std::to_string(length);
        const uint32_t chunk_length = le32(data + offset);
        const uint32_t type = le32(data + offset + 4);
        const std::string what = "chunk " + std::to_string(k) + " (" + chunk_name(type) + ") at byte " +
                                 std::to_string(offset);
        const std::size_t left = length - offset - 8;
        if (chunk_length > left)
            return what + " claims " + std::to_string(chunk_length) + " bytes but only " + std::to_string(left) +
                   " follow its header (GLB length " + std::to_string(length) + ")";
        if (chunk_length % 4 != 0)
            return what + ": length " + std::to_string(chunk_length) + " is not a multiple of 4 (4-byte alignment)";
        if (k == 0 && type != kChunkJson) return "the first chunk is not JSON: " + what;
        if (k > 0 && type == kChunkJson) return what + " is a second JSON chunk";
        if (type == kChunkBin && glb.has_bin) return what + " is a second BIN chunk";
        if (type == kChunkBin && k != 1) return what + ": the BIN chunk must directly follow the JSON chunk";
        if (k == 1 && type != kChunkBin) return what + ": the second chunk must be BIN";
        if (chunk_length == 0) return what + " is empty";
        if (k == 0) {
            glb.json_offset = offset + 8;
            glb.json_size = chunk_length;
        } else if (type == kChunkBin) {
            glb.has_bin = true;
            glb.bin_size = chunk_length;
        }
        offset += 8 + std::size_t(chunk_length);
    }
    return std::nullopt;
}

/// A non-negative integer member of a JSON object (absent: `fallback`; present but not one: nothing).
std::optional<uint64_t> unsigned_member(const nlohmann::json& o, const char* key, std::optional<uint64_t> fallback) {
    const auto it = o.find(key);
    if (it == o.end()) return fallback;
    if (it->is_number_unsigned()) return it->get<uint64_t>();
    if (it->is_number_integer() && it->get<int64_t>() >= 0) return static_cast<uint64_t>(it->get<int64_t>());
    return std::nullopt;
}

/// What tinygltf 2.7.0 does not check on its own, in the parsed JSON: a GLB's BIN-chunk buffers (every buffer
/// without a uri reads the BIN chunk: its byteLength must be 1..BIN size) and the byte range of an image's buffer
/// view (tinygltf takes a pointer at the view's offset into the buffer without checking it). Returns what is wrong.
std::optional<std::string> check_json(const nlohmann::json& root, const Glb* glb) {
    std::vector<uint64_t> buffer_bytes;
    if (const auto b = root.find("buffers"); b != root.end() && b->is_array()) {
        for (std::size_t i = 0; i < b->size(); ++i) {
            const nlohmann::json& buffer = (*b)[i];
            const std::string who = "buffer " + std::to_string(i);
            if (!buffer.is_object()) return who + " is not a JSON object";
            const std::optional<uint64_t> bytes = unsigned_member(buffer, "byteLength", std::nullopt);
            if (!bytes || *bytes == 0) return who + ": byteLength must be a positive integer";
            buffer_bytes.push_back(*bytes);
            if (glb == nullptr || buffer.contains("uri")) continue;
            if (!glb->has_bin) return who + " has no uri and the GLB has no BIN chunk";
            if (*bytes > glb->bin_size)
                return who + ": byteLength " + std::to_string(*bytes) + " exceeds the BIN chunk (" +
                       std::to_string(glb->bin_size) + " bytes)";
        }
    }
    const auto views = root.find("bufferViews");
    if (const auto images = root.find("images"); images != root.end() && images->is_array()) {
        for (std::size_t i = 0; i < images->size(); ++i) {
            const nlohmann::json& image = (*images)[i];
            if (!image.is_object() || !image.contains("bufferView")) continue;  // tinygltf reports those
            const std::string who = "image " + std::to_string(i);
            const std::optional<uint64_t> v = unsigned_member(image, "bufferView", std::nullopt);
            if (!v || views == root.end() || !views->is_array() || *v >= views->size())
                return who + ": bufferView does not exist";
            const nlohmann::json& view = (*views)[*v];
            bool in_range = false;
            if (view.is_object()) {
                const uint64_t buffer = unsigned_member(view, "buffer", std::nullopt).value_or(UINT64_MAX);
                const uint64_t offset = unsigned_member(view, "byteOffset", 0).value_or(UINT64_MAX);
                const uint64_t bytes = unsigned_member(view, "byteLength", std::nullopt).value_or(UINT64_MAX);
                in_range = buffer < buffer_bytes.size() && offset <= buffer_bytes[buffer] &&
                           bytes <= buffer_bytes[buffer] - offset;
            }
            if (!in_range)
                return who + ": buffer view " + std::to_string(*v) + " is not a byte range of an existing buffer";
        }
    }
    return std::nullopt;
}

// Images are never decoded (geometry only): the loader keeps nothing and succeeds, so a file with textures loads.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
    return true;
}

// Filesystem callbacks. In memory there is no directory, so an external URI is an error. From a file, an
// external buffer must be a regular file inside the glTF file's directory (no absolute path, no '..' out of it,
// no device or pipe): a hostile file cannot make the loader read /etc/..., block on a FIFO, or pick up files
// from the working directory (tinygltf also searches '.').
struct FileScope {
    std::filesystem::path dir;  // canonical directory of the glTF file
};

std::optional<std::filesystem::path> inside(const std::string& path, const FileScope& scope) {
    std::error_code ec;
    const std::filesystem::path p = std::filesystem::weakly_canonical(path, ec);
    if (ec) return std::nullopt;
    const std::filesystem::path rel = p.lexically_relative(scope.dir);
    if (rel.empty() || *rel.begin() == "..") return std::nullopt;
    return p;
}

bool scoped_file_exists(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::exists(path, ec);  // reported (or refused) by scoped_read with a clear reason
}

bool scoped_read(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    const FileScope& scope = *static_cast<const FileScope*>(user);
    const std::optional<std::filesystem::path> p = inside(path, scope);
    std::error_code ec;
    if (!p) {
        if (err) *err += "external file '" + path + "' is outside the directory of the glTF file\n";
        return false;
    }
    if (!std::filesystem::is_regular_file(*p, ec)) {
        if (err) *err += "external file '" + path + "' is not a regular file\n";
        return false;
    }
    const auto bytes = std::filesystem::file_size(*p, ec);
    if (ec || bytes > kMaxBytes) {
        if (err) *err += "external file '" + path + "' cannot be sized or is larger than 4 GiB\n";
        return false;
    }
    std::ifstream in(*p, std::ios::binary);
    out->resize(static_cast<std::size_t>(bytes));
    if (!in || !in.read(reinterpret_cast<char*>(out->data()), static_cast<std::streamsize>(out->size()))) {
        if (err) *err += "external file '" + path + "' cannot be read\n";
        return false;
    }
    return true;
}

bool no_file_exists(const std::string&, void*) { return false; }
std::string same_path(const std::string& path, void*) { return path; }
bool no_read(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
    if (err) *err += "external file '" + path + "' cannot be read from memory\n";
    return false;
}
bool no_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is not supported\n";
    return false;
}

/// Every read: the container and JSON checks, then tinygltf (geometry only), then the conversion. `scope` null:
/// in memory (no external file); otherwise the directory external buffers may come from.
Status load(const unsigned char* data, std::size_t size, const std::string& name, FileScope* scope,
            std::vector<MeshData>& out) {
    out.clear();
    if (size > kMaxBytes) return Status::error(name + ": larger than 4 GiB");
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    Glb glb;
    if (size == 0) data = reinterpret_cast<const unsigned char*>("");
    const char* json_text = reinterpret_cast<const char*>(data);
    std::size_t json_size = size;
    if (binary) {
        if (const auto bad = check_glb(data, size, glb))
            return Status::error(name + ": not a valid GLB file: " + *bad);
        json_text += glb.json_offset;
        json_size = glb.json_size;
    }
    // tinygltf converts extras and extensions to its Value recursively: a deeply nested array overflowed the stack
    // (100,000 levels in a 200 kB file). glTF itself nests about 6 levels; 128 leaves room for any extras.
    constexpr int kMaxDepth = 128;
    struct TooDeep {};
    nlohmann::json root;
    try {
        root = nlohmann::json::parse(json_text, json_text + json_size,
                                     [](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
                                         if (depth > kMaxDepth) throw TooDeep{};
                                         return true;
                                     });
    } catch (const TooDeep&) {
        return Status::error(name + ": not a readable glTF file: JSON nested deeper than " +
                               std::to_string(kMaxDepth) + " levels");
    } catch (const std::exception& e) {
        return Status::error(name + ": not a readable glTF file: " + e.what());
    }
    if (root.is_object())  // otherwise tinygltf says what is wrong
        if (const auto bad = check_json(root, binary ? &glb : nullptr))
            return Status::error(name + ": not a readable glTF file: " + *bad);

    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    if (scope != nullptr)
        loader.SetFsCallbacks(tinygltf::FsCallbacks{&scoped_file_exists, &same_path, &scoped_read, &no_write, scope});
    else
        loader.SetFsCallbacks(tinygltf::FsCallbacks{&no_file_exists, &same_path, &no_read, &no_write, nullptr});
    loader.SetImageLoader(&skip_image, nullptr);
    const std::string base_dir = scope != nullptr ? scope->dir.string() : std::string();
    std::string err, warn;
    bool ok = false;
    try {  // tinygltf 2.7.0 throws std::out_of_range on some inputs (.at(0) of an empty vector)
        ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, glb.length, base_dir)
                    : loader.LoadASCIIFromString(&model, &err, &warn, json_text, static_cast<unsigned int>(size),
                                                 base_dir);
    } catch (const std::exception& e) {
        return Status::error(name + ": not a readable glTF file: " + e.what());
    }
    if (!ok) return Status::error(name + ": not a readable glTF file: " + (err.empty() ? "unknown error" : err));
    return convert_model(model, name, out);
}

}  // namespace

Status read_gltf(const std::string& path, std::vector<MeshData>& out) {
    out.clear();
    std::ifstream in(path, std::ios::binary);
    if (!in) return Status::error(path + ": cannot open: " + std::strerror(errno));
    std::vector<unsigned char> bytes;
    char block[1 << 16];
    while (in.read(block, sizeof block) || in.gcount() > 0) {
        bytes.insert(bytes.end(), block, block + in.gcount());
        if (bytes.size() > kMaxBytes) return Status::error(path + ": larger than 4 GiB");
    }
    if (in.bad()) return Status::error(path + ": read error: " + std::strerror(errno));
    FileScope scope;
    std::error_code ec;
    scope.dir = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec).parent_path(), ec);
    return load(bytes.data(), bytes.size(), path, &scope, out);
}

Status read_gltf_memory(std::span<const std::byte> bytes, const std::string& name, std::vector<MeshData>& out) {
    return load(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), name, nullptr, out);
}

}  // namespace engine::assets
