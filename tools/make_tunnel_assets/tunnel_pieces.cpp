// Coarse tunnel pieces: deliberately few quads (they are refined at run time for the bend they get).
#include "tunnel_pieces.hpp"

#include <engine/assets/mesh_building.hpp>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

#include <array>
#include <cmath>
#include <cstdio>

namespace tunnel {
namespace {

using engine::assets::add_quad;
using engine::assets::MeshData;
constexpr double kPi = 3.14159265358979323846;

// Ring direction i of `around` (vertex angles offset by half a segment so the floor is a flat face).
glm::vec3 radial(int i, int around) {
    const double a = (i + 0.5) * 2.0 * kPi / around - kPi / 2;
    return {static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.0f};
}

}  // namespace

std::vector<MeshData> straight_section(const TunnelSpec& spec) {
    MeshData wall;
    wall.name = "tunnel_wall";
    // Shared vertices along the smooth wall (one normal per vertex, pointing to the axis); the uv seam at
    // i = 0 / around duplicates a column. Quads (i, j), (i, j+1), (i+1, j+1), (i+1, j) face the axis.
    for (int j = 0; j <= spec.along; ++j)
        for (int i = 0; i <= spec.around; ++i) {
            const glm::vec3 r = radial(i % spec.around, spec.around);
            const float z = spec.length_m * static_cast<float>(j) / static_cast<float>(spec.along);
            wall.positions.insert(wall.positions.end(), {spec.radius_m * r.x, spec.radius_m * r.y, z});
            wall.normals.insert(wall.normals.end(), {-r.x, -r.y, 0.0f});
            wall.uvs.insert(wall.uvs.end(), {static_cast<float>(i) / static_cast<float>(spec.around), z / spec.length_m});
        }
    const auto at = [&](int i, int j) { return static_cast<std::uint32_t>(j * (spec.around + 1) + i); };
    for (int j = 0; j < spec.along; ++j)
        for (int i = 0; i < spec.around; ++i) {
            const std::uint32_t a = at(i, j), b = at(i, j + 1), c = at(i + 1, j + 1), d = at(i + 1, j);
            wall.indices.insert(wall.indices.end(), {a, b, c, a, c, d});
        }
    return {wall};
}

std::vector<MeshData> wall_details(const TunnelSpec& spec) {
    std::vector<MeshData> out;
    const float depth_m = 0.2f, width_m = 0.2f;
    for (int k = 0; k < static_cast<int>(spec.length_m); ++k) {
        MeshData rib;
        rib.name = "rib_" + std::to_string(k);
        const float z0 = static_cast<float>(k), z1 = z0 + width_m;
        const float r_out = spec.radius_m, r_in = spec.radius_m - depth_m;
        for (int i = 0; i < spec.around; ++i) {
            const glm::vec3 a = radial(i, spec.around), b = radial((i + 1) % spec.around, spec.around);
            const glm::vec3 mid = glm::normalize(a + b);
            const float u0 = static_cast<float>(i) / static_cast<float>(spec.around);
            const float u1 = static_cast<float>(i + 1) / static_cast<float>(spec.around);
            const std::array<glm::vec2, 4> uv{glm::vec2(u0, 0), {u1, 0}, {u1, 1}, {u0, 1}};
            const auto p = [](glm::vec3 dir, float r, float z) { return glm::vec3(r * dir.x, r * dir.y, z); };
            add_quad(rib, {.corners = {p(a, r_in, z0), p(b, r_in, z0), p(b, r_in, z1), p(a, r_in, z1)}, .uvs = uv, .facing = -mid});
            add_quad(rib, {.corners = {p(a, r_out, z0), p(b, r_out, z0), p(b, r_out, z1), p(a, r_out, z1)}, .uvs = uv, .facing = mid});
            add_quad(rib, {.corners = {p(a, r_in, z0), p(b, r_in, z0), p(b, r_out, z0), p(a, r_out, z0)}, .uvs = uv, .facing = {0, 0, -1}});
            add_quad(rib, {.corners = {p(a, r_in, z1), p(b, r_in, z1), p(b, r_out, z1), p(a, r_out, z1)}, .uvs = uv, .facing = {0, 0, 1}});
        }
        // Smooth around the ring, hard at its four corner circles: the inner and outer bands get radial
        // normals (equal where neighbouring quads meet), the flat end faces keep +-z, so only the corner
        // circles carry two normals per position and become creases in make_control_mesh.
        for (std::size_t v = 0; v < rib.vertex_count(); ++v) {
            float* n = &rib.normals[3 * v];
            if (std::abs(n[2]) > 0.5f) continue;  // the flat end faces keep +-z
            const float* q = &rib.positions[3 * v];
            const float len = std::hypot(q[0], q[1]);
            const float sign = (n[0] * q[0] + n[1] * q[1]) > 0.0f ? 1.0f : -1.0f;
            n[0] = sign * q[0] / len;
            n[1] = sign * q[1] / len;
        }
        out.push_back(std::move(rib));
    }
    MeshData walkway;
    walkway.name = "walkway";
    engine::assets::add_box_along_z(walkway, {-1.1f, spec.walkway_top_y_m - 0.1f, 0.0f}, {1.1f, spec.walkway_top_y_m, spec.length_m}, spec.along);
    out.push_back(std::move(walkway));
    return out;
}

std::vector<Anchor> anchors(const TunnelSpec& spec) {
    std::vector<Anchor> out;
    const float arm_m = 0.3f, thick_m = 0.04f, y_m = -0.3f;
    for (int side = 0; side < 2; ++side)
        for (int k = 0; k < static_cast<int>(spec.length_m); ++k) {
            const float sx = side == 0 ? -1.0f : 1.0f;
            const float wall_x = std::sqrt(spec.radius_m * spec.radius_m - y_m * y_m) - 0.05f;
            Anchor a;
            a.name = "anchor_" + std::to_string(out.size());
            a.x = sx * (wall_x - (arm_m - thick_m - 0.03f));
            a.y = y_m + thick_m;
            a.z = k + 0.5;
            out.push_back(a);
        }
    return out;
}

std::vector<MeshData> cable_hooks(const TunnelSpec& spec) {
    // A J-bracket: an arm from the wall toward the axis with a lip at its tip; profile in (s, y) with s the
    // distance from the wall, extruded 6 cm along z. 8 profile points, 8 side quads + 3 quads per cap.
    const float arm = 0.3f, t = 0.04f, lip = 0.1f, half_z = 0.03f;
    const std::array<glm::vec2, 8> profile{glm::vec2(0, 0), {arm - t, 0}, {arm, 0}, {arm, t},
                                           {arm, lip}, {arm - t, lip}, {arm - t, t}, {0, t}};
    std::vector<MeshData> out;
    for (const Anchor& a : anchors(spec)) {
        MeshData m;
        m.name = a.name;
        m.origin = glm::dvec3(a.x, a.y, a.z);
        const float in = a.x < 0 ? 1.0f : -1.0f;  // toward the axis
        // Anchor sits at s = arm - t - 0.03, y = t (on the arm, against the lip) in the profile.
        const auto P = [&](glm::vec2 q, float z) {
            return glm::vec3(in * (q.x - (arm - t - 0.03f)), q.y - t, z);
        };
        for (int i = 0; i < 8; ++i) {
            const glm::vec2 q0 = profile[static_cast<std::size_t>(i)], q1 = profile[static_cast<std::size_t>((i + 1) % 8)];
            const glm::vec2 e = q1 - q0;
            // Outward in the profile plane: the profile runs counter-clockwise in (s, y), so right of e.
            const glm::vec3 facing(in * e.y, -e.x, 0.0f);
            const float len = glm::length(e);
            add_quad(m, {.corners = {P(q0, -half_z), P(q1, -half_z), P(q1, half_z), P(q0, half_z)},
                         .uvs = {glm::vec2(0, 0), {len, 0}, {len, 2 * half_z}, {0, 2 * half_z}},
                         .facing = facing});
        }
        const std::array<std::array<int, 4>, 3> caps{{{0, 1, 6, 7}, {1, 2, 3, 6}, {6, 3, 4, 5}}};
        for (float z : {-half_z, half_z})
            for (const auto& cap : caps) {
                std::array<glm::vec3, 4> p;
                std::array<glm::vec2, 4> uv;
                for (int k = 0; k < 4; ++k) {
                    p[static_cast<std::size_t>(k)] = P(profile[static_cast<std::size_t>(cap[static_cast<std::size_t>(k)])], z);
                    uv[static_cast<std::size_t>(k)] = profile[static_cast<std::size_t>(cap[static_cast<std::size_t>(k)])];
                }
                add_quad(m, {.corners = p, .uvs = uv, .facing = {0, 0, z}});
            }
        out.push_back(std::move(m));
    }
    return out;
}

std::string anchors_json(const std::vector<Anchor>& anchors) {
    std::string s =
        "{\n  \"units\": \"m\",\n"
        "  \"space\": \"unbent piece space: +z along the tunnel (0..4), +y up, axis at x = y = 0\",\n"
        "  \"meshes\": \"cable_hooks.glb (mesh and node named like the anchor, node translation = position)\",\n"
        "  \"anchors\": [\n";
    char line[160];
    for (std::size_t i = 0; i < anchors.size(); ++i) {
        std::snprintf(line, sizeof line, "    {\"name\": \"%s\", \"position\": [%.6f, %.6f, %.6f]}%s\n",
                      anchors[i].name.c_str(), anchors[i].x, anchors[i].y, anchors[i].z,
                      i + 1 < anchors.size() ? "," : "");
        s += line;
    }
    s += "  ]\n}\n";
    return s;
}

}  // namespace tunnel
