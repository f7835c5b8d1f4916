// Primitive mesh generators (plain math) and GpuMesh upload.
#include "engine/gfx/mesh.hpp"

#include <epoxy/gl.h>

#include <cassert>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace engine::gfx {
namespace {

void add_quad(PrimitiveMesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 n) {
    const auto base = static_cast<std::uint32_t>(m.vertices.size());
    m.vertices.insert(m.vertices.end(), {{a, n}, {b, n}, {c, n}, {d, n}});
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

}  // namespace

PrimitiveMesh make_cylinder_mesh(const CylinderDesc& desc) {
    assert(desc.sides >= 3 && "cylinder needs at least 3 sides");
    PrimitiveMesh m;
    const int n = desc.sides;
    const float r = desc.radius_m;
    const float h = desc.half_height_m;
    const float two_pi = 2.0f * std::numbers::pi_v<float>;
    // Side: two rings, seam duplicated. phi grows from +z toward +x so that (bottom i, bottom i+1, top i+1)
    // is CCW seen from outside.
    for (int i = 0; i <= n; ++i) {
        const float phi = two_pi * static_cast<float>(i) / static_cast<float>(n);
        const glm::vec3 dir(std::sin(phi), 0.0f, std::cos(phi));
        m.vertices.push_back({dir * r + glm::vec3(0, -h, 0), dir});
        m.vertices.push_back({dir * r + glm::vec3(0, h, 0), dir});
    }
    for (int i = 0; i < n; ++i) {
        const auto b0 = static_cast<std::uint32_t>(2 * i);
        const std::uint32_t t0 = b0 + 1;
        const std::uint32_t b1 = b0 + 2;
        const std::uint32_t t1 = b0 + 3;
        m.indices.insert(m.indices.end(), {b0, b1, t1, b0, t1, t0});
    }
    if (desc.caps) {
        for (int cap = 0; cap < 2; ++cap) {
            const float y = cap == 0 ? h : -h;
            const glm::vec3 normal(0.0f, cap == 0 ? 1.0f : -1.0f, 0.0f);
            const auto center = static_cast<std::uint32_t>(m.vertices.size());
            m.vertices.push_back({glm::vec3(0, y, 0), normal});
            for (int i = 0; i < n; ++i) {
                const float phi = two_pi * static_cast<float>(i) / static_cast<float>(n);
                m.vertices.push_back({glm::vec3(r * std::sin(phi), y, r * std::cos(phi)), normal});
            }
            for (int i = 0; i < n; ++i) {
                const std::uint32_t a = center + 1 + static_cast<std::uint32_t>(i);
                const std::uint32_t b = center + 1 + static_cast<std::uint32_t>((i + 1) % n);
                // Seen from +y, (center, a, b) runs counter-clockwise; the bottom cap is seen from -y, so
                // reverse it.
                if (cap == 0) {
                    m.indices.insert(m.indices.end(), {center, a, b});
                } else {
                    m.indices.insert(m.indices.end(), {center, b, a});
                }
            }
        }
    }
    return m;
}

PrimitiveMesh make_box_mesh(glm::vec3 e) {
    PrimitiveMesh m;
    using glm::vec3;
    add_quad(m, {-e.x, -e.y, e.z}, {e.x, -e.y, e.z}, {e.x, e.y, e.z}, {-e.x, e.y, e.z}, {0, 0, 1});
    add_quad(m, {e.x, -e.y, -e.z}, {-e.x, -e.y, -e.z}, {-e.x, e.y, -e.z}, {e.x, e.y, -e.z}, {0, 0, -1});
    add_quad(m, {e.x, -e.y, e.z}, {e.x, -e.y, -e.z}, {e.x, e.y, -e.z}, {e.x, e.y, e.z}, {1, 0, 0});
    add_quad(m, {-e.x, -e.y, -e.z}, {-e.x, -e.y, e.z}, {-e.x, e.y, e.z}, {-e.x, e.y, -e.z}, {-1, 0, 0});
    add_quad(m, {-e.x, e.y, e.z}, {e.x, e.y, e.z}, {e.x, e.y, -e.z}, {-e.x, e.y, -e.z}, {0, 1, 0});
    add_quad(m, {-e.x, -e.y, -e.z}, {e.x, -e.y, -e.z}, {e.x, -e.y, e.z}, {-e.x, -e.y, e.z}, {0, -1, 0});
    return m;
}

PrimitiveMesh make_plane_mesh(float s) {
    PrimitiveMesh m;
    add_quad(m, {-s, 0, s}, {s, 0, s}, {s, 0, -s}, {-s, 0, -s}, {0, 1, 0});
    return m;
}

PrimitiveMesh make_sphere_mesh(float radius_m, int slices, int stacks) {
    assert(slices >= 3 && stacks >= 2);
    PrimitiveMesh m;
    const float pi = std::numbers::pi_v<float>;
    for (int j = 0; j <= stacks; ++j) {
        const float theta = pi * static_cast<float>(j) / static_cast<float>(stacks);  // 0 at +y
        for (int i = 0; i <= slices; ++i) {
            const float phi = 2.0f * pi * static_cast<float>(i) / static_cast<float>(slices);
            const glm::vec3 n(std::sin(theta) * std::sin(phi), std::cos(theta),
                              std::sin(theta) * std::cos(phi));
            m.vertices.push_back({n * radius_m, n});
        }
    }
    const auto row = static_cast<std::uint32_t>(slices + 1);
    for (int j = 0; j < stacks; ++j) {
        for (int i = 0; i < slices; ++i) {
            const std::uint32_t a = static_cast<std::uint32_t>(j) * row + static_cast<std::uint32_t>(i);
            const std::uint32_t b = a + row;
            m.indices.insert(m.indices.end(), {a, b, b + 1, a, b + 1, a + 1});
        }
    }
    return m;
}

Expected<GpuMesh> upload_mesh(const PrimitiveMesh& mesh, std::string_view label) {
    if (mesh.vertices.empty() || mesh.indices.empty())
        return Error{"upload_mesh: mesh '" + std::string(label) + "' is empty"};
    GpuMesh gpu;
    Expected<Buffer> vb = make_buffer(std::span<const Vertex>(mesh.vertices), label);
    if (!vb) return vb.error();
    Expected<Buffer> ib = make_buffer(std::span<const std::uint32_t>(mesh.indices), label);
    if (!ib) return ib.error();
    gpu.vertices = std::move(vb).value();
    gpu.indices = std::move(ib).value();
    gpu.vertex_array = make_vertex_array({
        .vertex_buffer = &gpu.vertices,
        .stride_bytes = sizeof(Vertex),
        .attributes = {{.location = 0, .components = 3, .offset_bytes = offsetof(Vertex, position)},
                       {.location = 1, .components = 3, .offset_bytes = offsetof(Vertex, normal)}},
        .index_buffer = &gpu.indices,
        .label = label,
    });
    gpu.index_count = static_cast<int>(mesh.indices.size());
    return gpu;
}

void draw(const GpuMesh& mesh) {
    mesh.vertex_array.bind();
    glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
}

}  // namespace engine::gfx
