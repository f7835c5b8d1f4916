// Catmull-Clark refinement of coarse pieces through OpenSubdiv Far, and the screen-error level choice.
#include <engine/assets/subdivide.hpp>

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <numeric>
#include <unordered_map>

namespace engine::assets {
namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

std::string who(const std::string& name) { return "mesh '" + name + "'"; }

glm::dvec3 vec3_at(const std::vector<float>& xyz, std::size_t i) {
    return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
}

// Newell's normal: twice the area vector of a planar polygon, robust for slightly non-planar quads.
glm::dvec3 area_normal(const std::vector<float>& positions, const int* verts, int n) {
    glm::dvec3 sum(0.0);
    for (int i = 0; i < n; ++i) {
        const glm::dvec3 a = vec3_at(positions, static_cast<std::size_t>(verts[i]));
        const glm::dvec3 b = vec3_at(positions, static_cast<std::size_t>(verts[(i + 1) % n]));
        sum += glm::cross(a, b);
    }
    return sum;
}

double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
    const double la = glm::length(a), lb = glm::length(b);
    if (la == 0.0 || lb == 0.0) return 0.0;
    return std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
}

std::uint64_t edge_key(int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

std::uint32_t float_bits(float f) {
    if (f == 0.0f) f = 0.0f;  // -0 and +0 weld
    std::uint32_t u = 0;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

// OpenSubdiv reports topology errors through a global callback; keep the last message of this thread.
thread_local std::string g_osd_error;
void capture_osd_error(Far::ErrorType, const char* message) {
    if (!g_osd_error.empty()) g_osd_error += "; ";
    g_osd_error += message ? message : "unknown error";
}

struct Corner {
    int vertex = 0;       // welded control vertex
    std::uint32_t source = 0;  // index of the glTF vertex (for its normal)
};

// Face-vertex offsets of a ControlMesh.
std::vector<int> face_offsets(const ControlMesh& m) {
    std::vector<int> offsets(m.face_sizes.size() + 1, 0);
    for (std::size_t f = 0; f < m.face_sizes.size(); ++f) offsets[f + 1] = offsets[f] + m.face_sizes[f];
    return offsets;
}

// Checks that every directed edge is used once: catches non-manifold edges (3+ faces) and flipped faces.
Status check_manifold(const ControlMesh& m) {
    std::unordered_map<std::uint64_t, int> directed;
    const std::vector<int> offsets = face_offsets(m);
    for (std::size_t f = 0; f < m.face_sizes.size(); ++f) {
        const int n = m.face_sizes[f];
        for (int i = 0; i < n; ++i) {
            const int a = m.face_vertices[static_cast<std::size_t>(offsets[f] + i)];
            const int b = m.face_vertices[static_cast<std::size_t>(offsets[f] + (i + 1) % n)];
            if (a == b)
                return Status::error(who(m.name) + ": degenerate face " + std::to_string(f) + " (vertex " +
                                       std::to_string(a) + " repeated)");
            if (++directed[edge_key(a, b)] > 1)
                return Status::error(who(m.name) + ": non-manifold edge between vertices " + std::to_string(a) +
                                       " and " + std::to_string(b) +
                                       " (used twice in the same direction: 3+ faces or a flipped face)");
        }
    }
    return {};
}

}  // namespace

std::size_t ControlMesh::quad_count() const {
    return static_cast<std::size_t>(std::count(face_sizes.begin(), face_sizes.end(), 4));
}

Status make_control_mesh(const MeshData& tri, ControlMesh& out) {
    ControlMesh m;
    m.name = tri.name;
    m.origin = tri.origin;
    const std::size_t n = tri.vertex_count();
    if (tri.triangle_count() == 0) return Status::error(who(tri.name) + ": no triangles to subdivide");
    if (tri.positions.size() != 3 * n || (!tri.uvs.empty() && tri.uvs.size() != 2 * n) ||
        (!tri.normals.empty() && tri.normals.size() != 3 * n) || tri.indices.size() % 3 != 0)
        return Status::error(who(tri.name) + ": attribute arrays do not match the vertex count");
    for (std::uint32_t i : tri.indices)
        if (i >= n) return Status::error(who(tri.name) + ": index " + std::to_string(i) + " out of range");

    // Weld equal positions into control vertices.
    std::map<std::array<std::uint32_t, 3>, int> weld;
    std::vector<int> welded(n);
    for (std::size_t v = 0; v < n; ++v) {
        const float* p = &tri.positions[3 * v];
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            return Status::error(who(tri.name) + ": vertex " + std::to_string(v) + " has a non-finite position");
        const std::array<std::uint32_t, 3> key{float_bits(p[0]), float_bits(p[1]), float_bits(p[2])};
        auto [it, inserted] = weld.try_emplace(key, static_cast<int>(m.positions.size() / 3));
        if (inserted) m.positions.insert(m.positions.end(), p, p + 3);
        welded[v] = it->second;
    }

    // Pair consecutive coplanar triangles sharing an edge into quads.
    std::vector<Corner> corners;
    const std::size_t tris = tri.triangle_count();
    auto corner_of = [&](std::size_t t, int k) {
        const std::uint32_t src = tri.indices[3 * t + static_cast<std::size_t>((k % 3 + 3) % 3)];
        return Corner{welded[src], src};
    };
    const double coplanar_cos = std::cos(0.5 * 3.14159265358979323846 / 180.0);
    for (std::size_t t = 0; t < tris; ++t) {
        bool merged = false;
        if (t + 1 < tris) {
            for (int i = 0; i < 3 && !merged; ++i) {
                const Corner p0 = corner_of(t, i), p1 = corner_of(t, i + 1), p2 = corner_of(t, i + 2);
                for (int j = 0; j < 3 && !merged; ++j) {
                    const Corner q0 = corner_of(t + 1, j), q1 = corner_of(t + 1, j + 1), q2 = corner_of(t + 1, j + 2);
                    if (q0.vertex != p1.vertex || q1.vertex != p0.vertex || q2.vertex == p2.vertex) continue;
                    const std::array<Corner, 4> quad{p1, p2, p0, q2};
                    std::array<glm::dvec3, 4> x;
                    for (int k = 0; k < 4; ++k) x[k] = vec3_at(m.positions, static_cast<std::size_t>(quad[k].vertex));
                    const glm::dvec3 n1 = glm::cross(x[1] - x[0], x[2] - x[0]);
                    const glm::dvec3 n2 = glm::cross(x[2] - x[0], x[3] - x[0]);
                    if (glm::length(n1) == 0.0 || glm::length(n2) == 0.0) continue;
                    if (glm::dot(glm::normalize(n1), glm::normalize(n2)) < coplanar_cos) continue;
                    const glm::dvec3 nq = n1 + n2;
                    bool convex = true;
                    for (int k = 0; k < 4; ++k)
                        convex = convex && glm::dot(glm::cross(x[(k + 1) % 4] - x[k], x[(k + 2) % 4] - x[(k + 1) % 4]), nq) > 0.0;
                    if (!convex) continue;
                    corners.insert(corners.end(), quad.begin(), quad.end());
                    m.face_sizes.push_back(4);
                    merged = true;
                }
            }
        }
        if (merged) {
            ++t;
            continue;
        }
        for (int k = 0; k < 3; ++k) corners.push_back(corner_of(t, k));
        m.face_sizes.push_back(3);
    }
    for (const Corner& c : corners) m.face_vertices.push_back(c.vertex);
    if (Status s = check_manifold(m); !s.ok()) return s;

    // Face-varying uvs: one value per distinct (control vertex, uv).
    if (!tri.uvs.empty()) {
        std::map<std::array<std::uint32_t, 3>, int> values;
        for (const Corner& c : corners) {
            const float u = tri.uvs[2 * c.source], v = tri.uvs[2 * c.source + 1];
            const std::array<std::uint32_t, 3> key{static_cast<std::uint32_t>(c.vertex), float_bits(u), float_bits(v)};
            auto [it, inserted] = values.try_emplace(key, static_cast<int>(m.uv_values.size() / 2));
            if (inserted) {
                m.uv_values.push_back(u);
                m.uv_values.push_back(v);
            }
            m.face_uvs.push_back(it->second);
        }
    }

    // Hard edges: the two faces of an edge disagree on the normal at one of its end points.
    if (!tri.normals.empty()) {
        const double hard_rad = 1.0 * 3.14159265358979323846 / 180.0;
        const std::vector<int> offsets = face_offsets(m);
        std::vector<std::size_t> next_corner(corners.size());
        for (std::size_t f = 0; f < m.face_sizes.size(); ++f)
            for (int i = 0; i < m.face_sizes[f]; ++i)
                next_corner[static_cast<std::size_t>(offsets[f] + i)] =
                    static_cast<std::size_t>(offsets[f] + (i + 1) % m.face_sizes[f]);
        const auto normal = [&](std::size_t c) { return vec3_at(tri.normals, corners[c].source); };
        std::unordered_map<std::uint64_t, std::size_t> directed;  // a -> b edge -> corner at a
        for (std::size_t c = 0; c < corners.size(); ++c)
            directed[edge_key(corners[c].vertex, corners[next_corner[c]].vertex)] = c;
        for (std::size_t c = 0; c < corners.size(); ++c) {
            const int a = corners[c].vertex, b = corners[next_corner[c]].vertex;
            if (a > b) continue;  // each shared edge once
            const auto twin = directed.find(edge_key(b, a));
            if (twin == directed.end()) continue;  // boundary
            const std::size_t other_b = twin->second, other_a = next_corner[other_b];
            if (angle_between(normal(c), normal(other_a)) > hard_rad ||
                angle_between(normal(next_corner[c]), normal(other_b)) > hard_rad) {
                m.crease_vertices.push_back(a);
                m.crease_vertices.push_back(b);
            }
        }
    }
    out = std::move(m);
    return {};
}

Status subdivide(const ControlMesh& coarse, int level, MeshData& out) {
    if (level < 0 || level > kMaxSubdivisionLevel)
        return Status::error(who(coarse.name) + ": subdivision level " + std::to_string(level) +
                               " out of range [0, " + std::to_string(kMaxSubdivisionLevel) + "]");
    if (coarse.face_sizes.empty()) return Status::error(who(coarse.name) + ": no faces to subdivide");
    const int num_vertices = static_cast<int>(coarse.positions.size() / 3);
    const int corner_total = std::accumulate(coarse.face_sizes.begin(), coarse.face_sizes.end(), 0);
    if (static_cast<int>(coarse.face_vertices.size()) != corner_total ||
        (!coarse.face_uvs.empty() && static_cast<int>(coarse.face_uvs.size()) != corner_total))
        return Status::error(who(coarse.name) + ": face arrays do not match the face sizes");
    for (int v : coarse.face_vertices)
        if (v < 0 || v >= num_vertices)
            return Status::error(who(coarse.name) + ": face vertex " + std::to_string(v) + " out of range");
    for (int s : coarse.face_sizes)
        if (s < 3) return Status::error(who(coarse.name) + ": face with " + std::to_string(s) + " vertices");
    if (Status s = check_manifold(coarse); !s.ok()) return s;

    Far::TopologyDescriptor desc;
    desc.numVertices = num_vertices;
    desc.numFaces = static_cast<int>(coarse.face_sizes.size());
    desc.numVertsPerFace = coarse.face_sizes.data();
    desc.vertIndicesPerFace = coarse.face_vertices.data();
    const std::vector<float> crease_weights(coarse.crease_vertices.size() / 2, Sdc::Crease::SHARPNESS_INFINITE);
    desc.numCreases = static_cast<int>(crease_weights.size());
    desc.creaseVertexIndexPairs = coarse.crease_vertices.data();
    desc.creaseWeights = crease_weights.data();
    const bool has_uv = !coarse.face_uvs.empty();
    Far::TopologyDescriptor::FVarChannel uv_channel;
    uv_channel.numValues = static_cast<int>(coarse.uv_values.size() / 2);
    uv_channel.valueIndices = coarse.face_uvs.data();
    if (has_uv) {
        desc.numFVarChannels = 1;
        desc.fvarChannels = &uv_channel;
    }

    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_CORNERS_ONLY);
    g_osd_error.clear();
    Far::SetErrorCallback(capture_osd_error);
    std::unique_ptr<Far::TopologyRefiner> refiner(Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Create(
        desc, Far::TopologyRefinerFactory<Far::TopologyDescriptor>::Options(Sdc::SCHEME_CATMARK, sdc)));
    if (!refiner)
        return Status::error(who(coarse.name) + ": OpenSubdiv could not build the topology" +
                               (g_osd_error.empty() ? std::string() : ": " + g_osd_error));
    Far::TopologyRefiner::UniformOptions uniform(level);
    uniform.fullTopologyInLastLevel = true;
    refiner->RefineUniform(uniform);

    struct Point {
        float x = 0, y = 0, z = 0;
        void Clear() { x = y = z = 0; }
        void AddWithWeight(const Point& p, float w) {
            x += w * p.x;
            y += w * p.y;
            z += w * p.z;
        }
    };
    struct Uv {
        float u = 0, v = 0;
        void Clear() { u = v = 0; }
        void AddWithWeight(const Uv& p, float w) {
            u += w * p.u;
            v += w * p.v;
        }
    };
    std::vector<Point> points(static_cast<std::size_t>(num_vertices));
    for (std::size_t i = 0; i < points.size(); ++i)
        points[i] = {coarse.positions[3 * i], coarse.positions[3 * i + 1], coarse.positions[3 * i + 2]};
    std::vector<Uv> uvs(coarse.uv_values.size() / 2);
    for (std::size_t i = 0; i < uvs.size(); ++i) uvs[i] = {coarse.uv_values[2 * i], coarse.uv_values[2 * i + 1]};
    Far::PrimvarRefiner primvar(*refiner);
    for (int l = 1; l <= level; ++l) {
        const Far::TopologyLevel& child = refiner->GetLevel(l);
        std::vector<Point> next_points(static_cast<std::size_t>(child.GetNumVertices()));
        Point* dst_points = next_points.data();
        primvar.Interpolate(l, points.data(), dst_points);
        points = std::move(next_points);
        if (has_uv) {
            std::vector<Uv> next_uvs(static_cast<std::size_t>(child.GetNumFVarValues(0)));
            Uv* dst_uvs = next_uvs.data();
            primvar.InterpolateFaceVarying(l, uvs.data(), dst_uvs, 0);
            uvs = std::move(next_uvs);
        }
    }

    const Far::TopologyLevel& top = refiner->GetLevel(level);
    const int faces = top.GetNumFaces();
    std::vector<int> offsets(static_cast<std::size_t>(faces) + 1, 0);
    for (int f = 0; f < faces; ++f) offsets[static_cast<std::size_t>(f) + 1] = offsets[static_cast<std::size_t>(f)] + top.GetFaceVertices(f).size();
    std::vector<glm::dvec3> face_normal(static_cast<std::size_t>(faces));
    for (int f = 0; f < faces; ++f) {
        const Far::ConstIndexArray fv = top.GetFaceVertices(f);
        glm::dvec3 sum(0.0);
        for (int i = 0; i < fv.size(); ++i) {
            const Point& a = points[static_cast<std::size_t>(fv[i])];
            const Point& b = points[static_cast<std::size_t>(fv[(i + 1) % fv.size()])];
            sum += glm::cross(glm::dvec3(a.x, a.y, a.z), glm::dvec3(b.x, b.y, b.z));
        }
        face_normal[static_cast<std::size_t>(f)] = sum;
    }

    // Smoothing groups: corners around a vertex joined across smooth manifold edges (union-find).
    std::vector<int> parent(static_cast<std::size_t>(offsets.back()));
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&](int c) {
        while (parent[static_cast<std::size_t>(c)] != c) {
            parent[static_cast<std::size_t>(c)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(c)])];
            c = parent[static_cast<std::size_t>(c)];
        }
        return c;
    };
    const auto corner = [&](int f, int v) {
        const Far::ConstIndexArray fv = top.GetFaceVertices(f);
        for (int i = 0; i < fv.size(); ++i)
            if (fv[i] == v) return offsets[static_cast<std::size_t>(f)] + i;
        return -1;
    };
    for (int e = 0; e < top.GetNumEdges(); ++e) {
        const Far::ConstIndexArray ef = top.GetEdgeFaces(e);
        if (ef.size() != 2 || top.IsEdgeInfSharp(e)) continue;
        const Far::ConstIndexArray ev = top.GetEdgeVertices(e);
        for (int k = 0; k < 2; ++k) {
            const int a = find(corner(ef[0], ev[k])), b = find(corner(ef[1], ev[k]));
            if (a >= 0 && b >= 0 && a != b) parent[static_cast<std::size_t>(a)] = b;
        }
    }
    std::vector<glm::dvec3> group_normal(parent.size(), glm::dvec3(0.0));
    for (int f = 0; f < faces; ++f)
        for (int c = offsets[static_cast<std::size_t>(f)]; c < offsets[static_cast<std::size_t>(f) + 1]; ++c)
            group_normal[static_cast<std::size_t>(find(c))] += face_normal[static_cast<std::size_t>(f)];

    MeshData result;
    result.name = coarse.name;
    result.origin = coarse.origin;
    struct Key {
        int uv, group, index;
    };
    std::vector<std::vector<Key>> emitted(points.size());
    std::vector<std::uint32_t> face_out;
    for (int f = 0; f < faces; ++f) {
        const Far::ConstIndexArray fv = top.GetFaceVertices(f);
        face_out.clear();
        for (int i = 0; i < fv.size(); ++i) {
            const int c = offsets[static_cast<std::size_t>(f)] + i;
            const int group = find(c);
            const int uv = has_uv ? top.GetFaceFVarValues(f, 0)[i] : -1;
            auto& list = emitted[static_cast<std::size_t>(fv[i])];
            auto it = std::find_if(list.begin(), list.end(), [&](const Key& k) { return k.uv == uv && k.group == group; });
            if (it == list.end()) {
                const Point& p = points[static_cast<std::size_t>(fv[i])];
                glm::dvec3 nrm = group_normal[static_cast<std::size_t>(group)];
                if (glm::length(nrm) == 0.0) nrm = face_normal[static_cast<std::size_t>(f)];
                if (glm::length(nrm) == 0.0) nrm = glm::dvec3(0.0, 0.0, 1.0);
                nrm = glm::normalize(nrm);
                const int index = static_cast<int>(result.positions.size() / 3);
                result.positions.insert(result.positions.end(), {p.x, p.y, p.z});
                result.normals.insert(result.normals.end(),
                                      {static_cast<float>(nrm.x), static_cast<float>(nrm.y), static_cast<float>(nrm.z)});
                if (has_uv) result.uvs.insert(result.uvs.end(), {uvs[static_cast<std::size_t>(uv)].u, uvs[static_cast<std::size_t>(uv)].v});
                list.push_back({uv, group, index});
                face_out.push_back(static_cast<std::uint32_t>(index));
            } else {
                face_out.push_back(static_cast<std::uint32_t>(it->index));
            }
        }
        for (std::size_t i = 1; i + 1 < face_out.size(); ++i)
            result.indices.insert(result.indices.end(), {face_out[0], face_out[i], face_out[i + 1]});
    }
    for (float x : result.positions)
        if (!std::isfinite(x)) return Status::error(who(coarse.name) + ": refinement produced a non-finite position");
    out = std::move(result);
    return {};
}

Status subdivide(const MeshData& coarse_triangles, int level, MeshData& out) {
    ControlMesh control;
    if (Status s = make_control_mesh(coarse_triangles, control); !s.ok()) return s;
    return subdivide(control, level, out);
}

RefinementErrorModel refinement_error_model(const ControlMesh& m) {
    RefinementErrorModel model;
    const std::size_t nv = m.positions.size() / 3;
    for (std::size_t v = 0; v < nv; ++v) {
        const glm::dvec3 p = m.origin + vec3_at(m.positions, v);
        model.max_radius_m = std::max(model.max_radius_m, std::hypot(p.x, p.y));
    }
    const std::vector<int> offsets = face_offsets(m);
    const std::size_t faces = m.face_sizes.size();
    std::vector<glm::dvec3> normal(faces);
    for (std::size_t f = 0; f < faces; ++f) {
        const int* fv = &m.face_vertices[static_cast<std::size_t>(offsets[f])];
        normal[f] = area_normal(m.positions, fv, m.face_sizes[f]);
        double zmin = 1e300, zmax = -1e300;
        for (int i = 0; i < m.face_sizes[f]; ++i) {
            const double z = m.positions[3 * static_cast<std::size_t>(fv[i]) + 2];
            zmin = std::min(zmin, z);
            zmax = std::max(zmax, z);
        }
        model.max_axial_extent_m = std::max(model.max_axial_extent_m, zmax - zmin);
    }
    std::unordered_map<std::uint64_t, int> crease;
    for (std::size_t i = 0; i + 1 < m.crease_vertices.size(); i += 2) {
        const int a = m.crease_vertices[i], b = m.crease_vertices[i + 1];
        crease[edge_key(std::min(a, b), std::max(a, b))] = 1;
    }
    std::unordered_map<std::uint64_t, std::vector<std::size_t>> edge_faces;
    for (std::size_t f = 0; f < faces; ++f)
        for (int i = 0; i < m.face_sizes[f]; ++i) {
            const int a = m.face_vertices[static_cast<std::size_t>(offsets[f] + i)];
            const int b = m.face_vertices[static_cast<std::size_t>(offsets[f] + (i + 1) % m.face_sizes[f])];
            edge_faces[edge_key(std::min(a, b), std::max(a, b))].push_back(f);
        }
    for (const auto& [key, fs] : edge_faces) {
        if (fs.size() != 2 || crease.count(key)) continue;
        const double theta = angle_between(normal[fs[0]], normal[fs[1]]);
        const glm::dvec3 a = vec3_at(m.positions, key >> 32), b = vec3_at(m.positions, key & 0xffffffffu);
        const glm::dvec3 dir = glm::length(b - a) > 0.0 ? glm::normalize(b - a) : glm::dvec3(0.0);
        double width = 0.0;  // how far the faces reach from the edge: the span that bends by theta
        for (std::size_t f : fs)
            for (int i = 0; i < m.face_sizes[f]; ++i) {
                const glm::dvec3 d = vec3_at(m.positions, static_cast<std::size_t>(m.face_vertices[static_cast<std::size_t>(offsets[f] + i)])) - a;
                width = std::max(width, glm::length(d - glm::dot(d, dir) * dir));
            }
        model.shape_error_m = std::max(model.shape_error_m, width * theta / 6.0);
    }
    return model;
}

double predicted_error_m(const RefinementErrorModel& model, double curvature_per_m, int level) {
    const double kappa = std::abs(curvature_per_m);
    const double h = model.max_axial_extent_m;
    const double bend = kappa * (1.0 + kappa * model.max_radius_m) * h * h / 8.0;
    return (model.shape_error_m + bend) / std::pow(4.0, std::max(level, 0));
}

int choose_subdivision_level(const RefinementErrorModel& model, const LevelQuery& q) {
    const int max_level = std::clamp(q.max_level, 0, kMaxSubdivisionLevel);
    const double distance = std::isfinite(q.distance_m) ? std::max(q.distance_m, 0.01) : 0.01;
    for (int level = 0; level < max_level; ++level)
        if (predicted_error_m(model, q.curvature_per_m, level) * q.focal_px / distance <= q.tolerance_px)
            return level;
    return max_level;
}

int choose_subdivision_level(const MeshData& coarse, const LevelQuery& query) {
    ControlMesh control;
    if (!make_control_mesh(coarse, control).ok()) return std::clamp(query.max_level, 0, kMaxSubdivisionLevel);
    return choose_subdivision_level(refinement_error_model(control), query);
}

}  // namespace engine::assets
