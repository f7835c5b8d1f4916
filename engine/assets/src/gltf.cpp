// glTF reading and writing; the only translation unit that compiles tinygltf's implementation.
#define TINYGLTF_IMPLEMENTATION
// stb's implementations come from Debian's libstb.so (see cmake/Dependencies.cmake).
#include <tiny_gltf.h>

#include <engine/assets/gltf.hpp>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
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
    if (m.positions.size() % 3 != 0) return Status::failure(who + ": positions are not xyz triples");
    if (!m.normals.empty() && m.normals.size() != m.positions.size())
        return Status::failure(who + ": normals count differs from positions");
    if (!m.uvs.empty() && m.uvs.size() / 2 != m.positions.size() / 3)
        return Status::failure(who + ": uv count differs from vertex count");
    if (m.indices.size() % 3 != 0) return Status::failure(who + ": indices are not triangles");
    const std::size_t n = m.vertex_count();
    for (std::size_t i = 0; i < m.indices.size(); ++i)
        if (m.indices[i] >= n)
            return Status::failure(who + ": index " + std::to_string(i) + " = " + std::to_string(m.indices[i]) +
                                   " out of range (" + std::to_string(n) + " vertices)");
    return {};
}

}  // namespace

Status write_glb(const std::string& path, std::span<const MeshData> meshes) {
    for (std::size_t i = 0; i < meshes.size(); ++i)
        if (Status s = check_mesh(meshes[i], i); !s.ok()) return Status::failure(path + ": " + s.message);

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
        return Status::failure(path + ": tinygltf could not serialize the model");

    const std::string tmp = path + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return Status::failure(path + ": cannot open '" + tmp + "' for writing: " + std::strerror(errno));
        const std::string bytes = stream.str();
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        out.flush();
        if (!out) {
            out.close();
            std::remove(tmp.c_str());
            return Status::failure(path + ": write failed: " + std::strerror(errno));
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string why = std::strerror(errno);
        std::remove(tmp.c_str());
        return Status::failure(path + ": cannot rename temporary file: " + why);
    }
    return {};
}

namespace {

/// Reads `count` elements of `components` floats from a float accessor (honours byteStride).
Status read_float_accessor(const tinygltf::Model& model, int index, int components, std::vector<float>& out,
                           const std::string& who) {
    if (index < 0 || index >= static_cast<int>(model.accessors.size()))
        return Status::failure(who + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model.accessors[index];
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT)
        return Status::failure(who + ": accessor " + std::to_string(index) + " is not float");
    if (tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type)) != components)
        return Status::failure(who + ": accessor " + std::to_string(index) + " has " +
                               std::to_string(tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type))) +
                               " components, expected " + std::to_string(components));
    if (a.bufferView < 0 || a.bufferView >= static_cast<int>(model.bufferViews.size()))
        return Status::failure(who + ": accessor " + std::to_string(index) + " has no buffer view (sparse or "
                               "empty accessors are not supported)");
    const tinygltf::BufferView& v = model.bufferViews[a.bufferView];
    if (v.buffer < 0 || v.buffer >= static_cast<int>(model.buffers.size()))
        return Status::failure(who + ": buffer view " + std::to_string(a.bufferView) + " names no buffer");
    const std::vector<unsigned char>& data = model.buffers[v.buffer].data;
    const std::size_t elem = std::size_t(components) * 4;
    const std::size_t stride = v.byteStride ? v.byteStride : elem;
    const std::size_t start = v.byteOffset + a.byteOffset;
    if (a.count > 0 && (stride < elem || start + stride * (a.count - 1) + elem > data.size() ||
                        start + stride * (a.count - 1) + elem > v.byteOffset + v.byteLength))
        return Status::failure(who + ": accessor " + std::to_string(index) + " reads past its buffer");
    out.resize(a.count * components);
    for (std::size_t i = 0; i < a.count; ++i) std::memcpy(&out[i * components], &data[start + i * stride], elem);
    return {};
}

Status read_indices(const tinygltf::Model& model, int index, std::vector<uint32_t>& out, const std::string& who) {
    if (index < 0 || index >= static_cast<int>(model.accessors.size()))
        return Status::failure(who + ": index accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model.accessors[index];
    if (a.type != TINYGLTF_TYPE_SCALAR) return Status::failure(who + ": index accessor is not scalar");
    std::size_t size = 0;
    switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
        default: return Status::failure(who + ": index component type " + std::to_string(a.componentType) +
                                        " is not an unsigned integer type");
    }
    if (a.bufferView < 0 || a.bufferView >= static_cast<int>(model.bufferViews.size()))
        return Status::failure(who + ": index accessor has no buffer view");
    const tinygltf::BufferView& v = model.bufferViews[a.bufferView];
    if (v.buffer < 0 || v.buffer >= static_cast<int>(model.buffers.size()))
        return Status::failure(who + ": index buffer view names no buffer");
    const std::vector<unsigned char>& data = model.buffers[v.buffer].data;
    const std::size_t stride = v.byteStride ? v.byteStride : size;
    const std::size_t start = v.byteOffset + a.byteOffset;
    if (a.count > 0 && (stride < size || start + stride * (a.count - 1) + size > data.size()))
        return Status::failure(who + ": index accessor reads past its buffer");
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
        if (it == prim.attributes.end()) return Status::failure(who + ": no POSITION attribute");
        MeshData m;
        m.name = mesh.name;
        if (Status s = read_float_accessor(model, it->second, 3, m.positions, who); !s.ok()) return s;
        if (auto n = prim.attributes.find("NORMAL"); n != prim.attributes.end())
            if (Status s = read_float_accessor(model, n->second, 3, m.normals, who); !s.ok()) return s;
        if (auto t = prim.attributes.find("TEXCOORD_0"); t != prim.attributes.end())
            if (Status s = read_float_accessor(model, t->second, 2, m.uvs, who); !s.ok()) return s;
        const std::size_t n = m.vertex_count();
        if (!m.normals.empty() && m.normals.size() != m.positions.size())
            return Status::failure(who + ": NORMAL count differs from POSITION count");
        if (!m.uvs.empty() && m.uvs.size() / 2 != n)
            return Status::failure(who + ": TEXCOORD_0 count differs from POSITION count");
        if (prim.indices >= 0) {
            if (Status s = read_indices(model, prim.indices, m.indices, who); !s.ok()) return s;
        } else {
            m.indices.resize(n);
            for (std::size_t i = 0; i < n; ++i) m.indices[i] = static_cast<uint32_t>(i);
        }
        if (m.indices.size() % 3 != 0) return Status::failure(who + ": index count is not a multiple of 3");
        for (std::size_t i = 0; i < m.indices.size(); ++i)
            if (m.indices[i] >= n)
                return Status::failure(who + ": index " + std::to_string(i) + " = " +
                                       std::to_string(m.indices[i]) + " is out of range (" + std::to_string(n) +
                                       " vertices)");
        for (float f : m.positions)
            if (!std::isfinite(f)) return Status::failure(who + ": POSITION holds a NaN or infinite value");
        for (float f : m.normals)
            if (!std::isfinite(f)) return Status::failure(who + ": NORMAL holds a NaN or infinite value");
        for (float f : m.uvs)
            if (!std::isfinite(f)) return Status::failure(who + ": TEXCOORD_0 holds a NaN or infinite value");
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
                return Status::failure(who + ": a position or normal is not finite after the node transforms "
                                             "(values too large)");
        out.push_back(std::move(m));
    }
    return {};
}

Status visit_node(const tinygltf::Model& model, int node_index, const glm::dmat4& parent, const std::string& file,
                  std::vector<MeshData>& out, int depth) {
    if (node_index < 0 || node_index >= static_cast<int>(model.nodes.size()))
        return Status::failure(file + ": node " + std::to_string(node_index) + " does not exist");
    if (depth > 64) return Status::failure(file + ": node hierarchy deeper than 64 (a cycle?)");
    const tinygltf::Node& node = model.nodes[node_index];
    const glm::dmat4 world = parent * local_matrix(node);
    if (node.mesh >= 0) {
        if (node.mesh >= static_cast<int>(model.meshes.size()))
            return Status::failure(file + ": node " + std::to_string(node_index) + " names mesh " +
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
    if (out.empty()) return Status::failure(file + ": contains no triangle mesh");
    return {};
}

// Filesystem callbacks for in-memory reading: there is no directory, so an external URI is an error.
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

}  // namespace

Status read_gltf(const std::string& path, std::vector<MeshData>& out) {
    out.clear();
    std::ifstream probe(path, std::ios::binary);
    if (!probe) return Status::failure(path + ": cannot open: " + std::strerror(errno));
    char magic[4] = {};
    probe.read(magic, 4);
    const bool binary = probe.gcount() == 4 && std::memcmp(magic, "glTF", 4) == 0;
    probe.close();

    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    const bool ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, path)
                           : loader.LoadASCIIFromFile(&model, &err, &warn, path);
    if (!ok) return Status::failure(path + ": not a readable glTF file: " + (err.empty() ? "unknown error" : err));
    return convert_model(model, path, out);
}

Status read_gltf_memory(std::span<const std::byte> bytes, const std::string& name, std::vector<MeshData>& out) {
    out.clear();
    if (bytes.size() > std::numeric_limits<unsigned int>::max())
        return Status::failure(name + ": larger than 4 GiB");
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    const auto size = static_cast<unsigned int>(bytes.size());
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;

    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks(tinygltf::FsCallbacks{&no_file_exists, &same_path, &no_read, &no_write, nullptr});
    std::string err, warn;
    const bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, size, "")
                           : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(data),
                                                        size, "");
    if (!ok) return Status::failure(name + ": not a readable glTF file: " + (err.empty() ? "unknown error" : err));
    return convert_model(model, name, out);
}

}  // namespace engine::assets
