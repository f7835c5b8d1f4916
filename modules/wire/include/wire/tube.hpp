// Tube mesh from ring records: n sides with a duplicated seam, flat end caps, closed loops joined without a seam in u.
#pragma once

#include "wire/rings.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace wire {

/// Interleaved float32 vertex, 32 bytes. Positions are relative to the wire's origin (RingSet::origin_m), so they
/// resolve about 6e-8 of the wire's extent wherever the wire is; a radius below a few of those (1e-6 m on a 100 m
/// wire) collapses rings to points: the output stays finite, its triangles degenerate.
struct TubeVertex {
    glm::vec3 position{};
    glm::vec3 normal{};
    glm::vec2 uv{};
};
static_assert(sizeof(TubeVertex) == 32, "TubeVertex is 32 bytes");

/// Zero means default.
struct TubeSettings {
    uint32_t sides = 0;                ///< radial sides; 0 -> 8; values below 3 become 3
    bool caps = true;                  ///< flat end caps on open wires (closed wires never get caps)
    bool tilt_normals = true;          ///< tilt side normals by the radius slope dR/ds (cones shade as cones)
    /// Write vertices with non-temporal (cache-bypassing) stores: for large per-frame arenas that the CPU does not
    /// read back (a mapped GPU buffer). Needs a 16-byte aligned vertex span, else ignored. Off: plain stores.
    bool streaming_stores = false;
};

struct TubeCounts {
    std::size_t vertices = 0;
    std::size_t indices = 0;
};

/// Sizes write_tube() needs for `ring_count` rings.
/// Sides: (rings [+1 closed]) * (sides + 1) vertices, (rings - 1 [+1 closed]) * 6 * sides indices.
/// Caps (open, caps on, >= 1 ring): 2 * (sides + 1) vertices (centre + rim) and 2 * 3 * sides indices.
[[nodiscard]] TubeCounts tube_counts(std::size_t ring_count, bool closed, const TubeSettings& settings);

/// Writes the tube of `rings` into caller memory (e.g. a mapped arena) and returns the counts written.
/// Layout: ring i's vertices at i*(sides+1) + j, j = 0..sides (j = sides duplicates j = 0 with v = 1);
/// vertex = c + R (cos(phi) r + sin(phi) s), phi = 2 pi j / sides, uv = (ring u, j / sides); normal = the same
/// direction, tilted by the radius slope if settings.tilt_normals. A closed wire repeats ring 0 at the end with
/// u = u_close (continuous texture over the join) and no caps. Caps: centre vertex then `sides` rim vertices at
/// the ring positions, normal -t (start) / +t (end), uv = 0.5 + 0.5 (cos phi, sin phi).
/// Triangles are counter-clockwise seen from outside (outward normals). Indices are offset by base_vertex.
/// With caps the welded mesh is closed: every edge is shared by exactly two triangles.
/// No allocation (the cos/sin table per side count is built once per thread).
TubeCounts write_tube(std::span<const Ring> rings, bool closed, float u_close, const TubeSettings& settings,
                      std::span<TubeVertex> vertices, std::span<uint32_t> indices, uint32_t base_vertex = 0);

/// A tube mesh in its own buffers (reused across calls: no allocation once their capacity suffices).
struct TubeMesh {
    glm::dvec3 origin_m{};  ///< world position the vertex positions are relative to
    std::vector<TubeVertex> vertices;
    std::vector<uint32_t> indices;
};

/// The tube of a ring set into `out` (resized).
void build_tube(const RingSet& rings, const TubeSettings& settings, TubeMesh& out);

// ---- camera-facing strips (thin wires, DESIGN 4.5) ------------------------------------------------------------
// A strip wire is drawn with 2 vertices per ring, spread across the view by the vertex shader (the camera is not
// known here, so the mesh does not change when the camera moves). Strip vertex, in TubeVertex's 32 bytes:
//   position = ring centre, normal = xyz of the ring frame's unit quaternion (columns r, s, t; w >= 0 rebuilt as
//   sqrt(1 - |xyz|^2)), uv = (ring u, -R) for the vertex on the -side edge, (ring u, +R) for the +side one.
// Ring i's vertices are 2i (-) and 2i + 1 (+); a closed wire repeats ring 0 at the end with u = u_close.
// Triangles per band i: (2i+1, 2i+3, 2i+2), (2i+1, 2i+2, 2i): counter-clockwise on screen when the +side edge
// lies along t x (to eye). No caps.

/// Frame quaternion (x, y, z) with w >= 0 of a ring (columns normal, binormal, normal x binormal).
[[nodiscard]] glm::vec3 ring_frame_quaternion_xyz(const Ring& ring);
/// Vertices and indices write_strip() needs: (rings [+1 closed]) * 2 and (rings - 1 [+1 closed]) * 6.
[[nodiscard]] TubeCounts strip_counts(std::size_t ring_count, bool closed);
TubeCounts write_strip(std::span<const Ring> rings, bool closed, float u_close, std::span<TubeVertex> vertices,
                       std::span<uint32_t> indices, uint32_t base_vertex = 0);
/// The strip of a ring set into `out` (resized).
void build_strip(const RingSet& rings, TubeMesh& out);

}  // namespace wire
