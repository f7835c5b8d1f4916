// A wire's nodes as the GPU curve pass reads them (the nodes path): its curve nodes (coincident ones merged by
// build_curve's rule) as offsets from an origin kept in double (the centre of their box, a point with float
// coordinates, so the GPU's header carries it in 12 bytes: a wire keeps its precision wherever it is), plus "extras"
// for the wires that have them: per-node tension, bias and continuity (Catmull-Rom wires that carry them, or the
// curvature-driven tension, computed here with build_curve's formula; a vec4 a node) and per-segment stretch (4
// segments a vec4). The wire systems pack these on their worker threads, so the renderer's thread only copies them.
//
// Two node formats (GpuCurveHeader's kHeaderQuantised, shaders/gpu_records.h). Quantised, 8 bytes a node: each
// offset a multiple of the wire's quantum 2^e metres, three 21-bit integers, after one 8-byte unit holding the
// wire's radius and e; chosen where the wire has one radius and the quantum keeps the held nodes within
// kQuantumOfRadius of its radius and kQuantumOfChord of its shortest chord (below). Float, 16 bytes a node: the
// offsets as floats, the radius in w (per-node radii, or a quantum too coarse for the wire: a wire much longer than
// it is thick, or with chords far shorter than its extent).
//
// Why those bounds: a node moved by d moves the tube's surface by at most d, so d <= r / 1024 is 1/2048 of the
// tube's width on screen at any distance (a pixel only where the tube is 2048 pixels wide); and a chord's direction
// turns by at most 2 d / chord <= 2^-14 rad, so a ring's frame turns by about that (its surface moves by 1e-4 of
// the radius; the rotation-minimizing frame's twist changes only in second order). Where they stop holding: nothing bounds the automatic spline's turn ramp (1e-8..1e-6 rad at collinear
// nodes) below the quantum, as nothing bounds it below float rounding; both paths then differ as they did with
// float offsets, measured in the picture tests.
#pragma once

#include "wire/lod.hpp"
#include "wire/nodes.hpp"
#include "wire/spline.hpp"
#include "wire/status.hpp"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <vector>

namespace wire {

/// The quantised format's numbers (the GPU's copy: shaders/gpu_records.h, checked equal where both are seen):
/// 21-bit integers biased by 2^20, the exponent stored plus 256.
inline constexpr uint32_t kQuantBits = 21, kQuantMask = (1u << kQuantBits) - 1, kQuantBias = 1u << 20,
                          kQuantExpBias = 256;
/// A quantised wire's nodes lie within this fraction of its radius of the input's (half its quantum 2^e).
inline constexpr double kQuantumOfRadius = 1.0 / 1024.0;
/// ... and within this fraction of its shortest chord.
inline constexpr double kQuantumOfChord = 1.0 / 32768.0;

/// See the file comment.
struct PackedNodes {
    glm::dvec3 origin_m{};  ///< what the nodes are offsets from (world metres; float coordinates: float_point)
    /// The nodes as the GPU reads them, 8-byte units: quantised, the radius and exponent unit then one a node;
    /// else two a node (x, y, z, radius as floats). node() decodes them.
    std::vector<glm::uvec2> records;
    std::vector<glm::vec4> extras;  ///< per-node kb (if per_node_kb), then stretch (if stretch), 4 segments a vec4
    std::size_t node_count = 0;     ///< curve nodes (merged)
    bool quantised = false;
    int quantum_exp = 0;  ///< quantised: the offsets are multiples of 2^quantum_exp metres
    bool closed = false;
    SplineKind kind = SplineKind::catmull_rom;
    float alpha = 0.5f, tension = 0.0f, bias = 0.0f, continuity = 0.0f;  ///< wire-wide Kochanek-Bartels values
    bool per_node_kb = false;
    bool stretch = false;
    // For the CPU's cull (packed_bounding_sphere): how far the curve nodes' box reaches from origin_m (its half
    // diagonal, or a hair more: the origin is rounded to floats), their longest chord, the
    // largest tube radius and the tangent factor K (see node_bounding_sphere in lod.hpp).
    double half_diagonal_m = 0.0, max_chord_m = 0.0, max_radius_m = 0.0, tangent_factor = 1.0;
    [[nodiscard]] std::size_t segment_count() const { return closed ? node_count : node_count - 1; }
    /// Curve node j as the GPU decodes it: xyz its offset from origin_m (exact in float), w its radius.
    [[nodiscard]] glm::vec4 node(std::size_t j) const;
    /// Where the GPU holds a point of this wire given in world metres: origin_m plus the point's offset as the
    /// format rounds it (for references that must see what the GPU sees).
    [[nodiscard]] glm::dvec3 held(const glm::dvec3& world_m) const;
};

/// The point nearest `p` whose coordinates are floats (each rounded to nearest): a wire's origin on the nodes path,
/// and what references that must see what the GPU holds round with. Rounded through memory: GCC 12 at -O3
/// vectorized the round trip dvec3(vec3(p)) for two lanes of a loop and dropped it (x and y kept every bit).
[[nodiscard]] glm::dvec3 float_point(const glm::dvec3& p);

/// Whether the GPU curve pass builds `kind`: every kind the CPU has (linear, Catmull-Rom / Kochanek-Bartels, c2,
/// automatic); a kind added to the CPU later is false until the GPU has it (the systems then send its CPU curve).
[[nodiscard]] bool gpu_builds(SplineKind kind);

/// The node format pack_nodes writes: `fitted` quantises where the file comment's bounds hold (the default: what
/// the systems send), `floats` always writes float records (what the node stream writes).
enum class NodeFormat : uint8_t { fitted, floats };

/// build_curve's checks (check_curve_input) and the packing above, in one pass over the merged nodes. On failure
/// `out` is left as it was and the Status is build_curve's (naming the node), or says the kind is not built on the
/// GPU. The automatic spline's weights are read from the turning pattern on the GPU; its per-node tension travels
/// in the extras as the Catmull-Rom's does.
[[nodiscard]] Status pack_nodes(const WireNodes& nodes, const SplineSettings& settings, PackedNodes& out,
                                NodeFormat format = NodeFormat::fitted);

/// node_bounding_sphere (lod.hpp) of the packed wire, from what pack_nodes measured (the merged nodes' box and
/// chords: the curve build_curve makes; one pass fewer): linear and Catmull-Rom; radius -1 otherwise.
[[nodiscard]] BoundingSphere packed_bounding_sphere(const PackedNodes& packed);

}  // namespace wire
