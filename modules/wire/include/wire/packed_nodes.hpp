// A wire's nodes as the GPU curve pass reads them (issue 30, the nodes path): its curve nodes (coincident ones
// merged by build_curve's rule) as float offsets from an origin kept in double (the centre of their box), 16 bytes a
// node with the tube radius in w (the origin is a point with float coordinates, so the GPU's header carries it in
// 12 bytes: the offsets are taken from it in double, so a wire keeps its precision wherever it is), plus "extras" for the wires that have them: per-node tension, bias and continuity
// (Catmull-Rom wires that carry them, or the curvature-driven tension, computed here with build_curve's formula; a
// vec4 a node) and per-segment stretch (4 segments a vec4). The wire systems pack these on their worker threads, so
// the renderer's thread only copies them (as the rings system packs ring records for the gpu-rings path).
#pragma once

#include "wire/lod.hpp"
#include "wire/nodes.hpp"
#include "wire/spline.hpp"
#include "wire/status.hpp"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <vector>

namespace wire {

/// See the file comment.
struct PackedNodes {
    glm::dvec3 origin_m{};          ///< what `nodes` are offsets from (world metres; float coordinates: float_point)
    std::vector<glm::vec4> nodes;   ///< per curve node: xyz offset from origin_m, w the tube radius
    std::vector<glm::vec4> extras;  ///< per-node kb (if per_node_kb), then stretch (if stretch), 4 segments a vec4
    bool closed = false;
    SplineKind kind = SplineKind::catmull_rom;
    float alpha = 0.5f, tension = 0.0f, bias = 0.0f, continuity = 0.0f;  ///< wire-wide Kochanek-Bartels values
    bool per_node_kb = false;
    bool stretch = false;
    // For the CPU's cull (packed_bounding_sphere): how far the curve nodes' box reaches from origin_m (its half
    // diagonal, or a hair more: the origin is rounded to floats), their longest chord, the
    // largest tube radius and the tangent factor K (see node_bounding_sphere in lod.hpp).
    double half_diagonal_m = 0.0, max_chord_m = 0.0, max_radius_m = 0.0, tangent_factor = 1.0;
    [[nodiscard]] std::size_t segment_count() const { return closed ? nodes.size() : nodes.size() - 1; }
};

/// The point nearest `p` whose coordinates are floats (each rounded to nearest): a wire's origin on the nodes path,
/// and what references that must see what the GPU holds round with. Rounded through memory: GCC 12 at -O3
/// vectorized the round trip dvec3(vec3(p)) for two lanes of a loop and dropped it (x and y kept every bit).
[[nodiscard]] glm::dvec3 float_point(const glm::dvec3& p);

/// Whether the GPU curve pass builds `kind`: every kind the CPU has (linear, Catmull-Rom / Kochanek-Bartels, c2,
/// automatic); a kind added to the CPU later is false until the GPU has it (the systems then send its CPU curve).
[[nodiscard]] bool gpu_builds(SplineKind kind);

/// build_curve's checks (check_curve_input) and the packing above, in one pass over the merged nodes. On failure
/// `out` is left as it was and the Status is build_curve's (naming the node), or says the kind is not built on the
/// GPU. The automatic spline's weights are read from the turning pattern on the GPU; its per-node tension travels
/// in the extras as the Catmull-Rom's does.
[[nodiscard]] Status pack_nodes(const WireNodes& nodes, const SplineSettings& settings, PackedNodes& out);

/// node_bounding_sphere (lod.hpp) of the packed wire, from what pack_nodes measured (the merged nodes' box and
/// chords: the curve build_curve makes; one pass fewer): linear and Catmull-Rom; radius -1 otherwise.
[[nodiscard]] BoundingSphere packed_bounding_sphere(const PackedNodes& packed);

}  // namespace wire
