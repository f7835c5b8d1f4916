// Test harness (wire::render_testing, never installed): the nodes path's curve program driven alone. A compute pass
// that turns many wires' nodes into their Bezier segments in one dispatch, one invocation per wire, the way wire::build_curve does on the
// CPU, which stays the reference (tests/modules/wire/render/gpu_curves_test.cpp compares the two).
//
//   auto pass = wire::render::GpuCurvePass::create();   // needs a current GL 4.5 context
//   std::vector<wire::render::GpuCurveWire> wires = ...; // nodes + settings per wire
//   pass->build(wires);                                   // uploads, dispatches
//   pass->read_segments(out);                             // (tests, tools) the segments back, per wire
//
// Every kind the CPU has: linear; Catmull-Rom / Kochanek-Bartels with any alpha, wire-wide or per-node tension,
// bias and continuity, and the curvature-driven tension of nodes that carry the physics arrays (computed on the CPU
// with build_curve's formula and sent as 16 bytes a node, only for such wires); c2 (its tangent system solved by
// one invocation in double, GLSL 4.00's fp64: the not-a-knot end cancels by the ratio of the first two chords,
// which in float moved a 4-node wire with 100:1 chords by 1e-4 of its extent; closed loops cyclic); automatic (the
// c2 system with the concentrated-turn weights read from the turning pattern in the same invocation, as
// concentrated_turns does on the CPU, in double). The automatic spline's weights react to 1e-7 rad of noise at
// collinear nodes (its 1e-8 .. 1e-6 rad turn ramp): the float rounding of the nodes is such noise, so on taut runs
// the curve of the rounded nodes may differ visibly from the exact nodes' (by 0.1 of a zig-zag's extent at worst
// over the test's families); the GPU equals build_curve of the rounded nodes.
// Precision: nodes go to the GPU in float relative to the wire's own origin (the centre of its nodes' box,
// kept in double), so a wire far from the world origin keeps its float precision; the segments come back
// relative to that origin. Coincident nodes are merged on the CPU by build_curve's own rule
// (wire::curve_nodes), so both sides build the same curve nodes.
// Longest wire: bounded by buffer sizes only (one invocation walks its wire; no shared-memory tile).
#pragma once

#include "wire/curve.hpp"
#include "wire/nodes.hpp"
#include "wire/status.hpp"

#include "gpu_wire_data.hpp"

#include "engine/core/expected.hpp"
#include "engine/gfx/resources.hpp"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace wire::render {

/// One wire's input: its nodes and the settings build_curve would take.
struct GpuCurveWire {
    const WireNodes* nodes = nullptr;  ///< validated nodes (build_curve's checks), kept alive through build()
    SplineSettings spline{};           ///< its kind and settings, closed included
    /// The rotation carrying the wire's last first normal (kept on the GPU) to these nodes: the vector part of
    /// wire::carried_rotation (w >= 0). Read by GpuRingPass jobs that carry the frame from the last build.
    glm::vec3 motion{};
    /// Instead of `motion`: fit it on the GPU against this wire's nodes of the last build (by index: the same
    /// number of wires and of curve nodes; else no rotation), as wire::fit_motion would.
    bool fit_motion = false;
};


/// One wire's segments read back: control points relative to `origin_m`.
struct GpuCurveResult {
    glm::dvec3 origin_m{};
    std::vector<CubicBezier> segments;  ///< relative to origin_m (float values, widened)
    bool closed = false;                ///< a closed loop (one segment per node)
};

/// The compute pass (owns its GL program and buffers: create, use and destroy it with the same context current).
class GpuCurvePass {
public:
    /// Compiles the compute program. Fails (with the driver's log) without GL 4.3 compute.
    static engine::Expected<GpuCurvePass> create();

    /// Whether this pass builds `spline` (wire::gpu_builds: every kind the CPU has).
    [[nodiscard]] static bool supported(const SplineSettings& spline, const WireNodes& nodes);

    /// Builds every wire's segments on the GPU (one dispatch). A wire this pass cannot build (build_curve's checks:
    /// fewer than 2 distinct nodes, 3 closed, bad values) fails the call with a message naming the wire and why;
    /// nothing is dispatched then. Validate nodes first (build_curve's checks): NaN is not looked for here.
    /// Leaves shader storage bindings 0-4 pointing at its buffers and no program in use.
    [[nodiscard]] Status build(std::span<const GpuCurveWire> wires);

    /// The last build's segments, one result per wire (waits for the GPU).
    void read_segments(std::vector<GpuCurveResult>& out) const;

    [[nodiscard]] std::size_t node_bytes() const { return node_bytes_; }      ///< uploaded by the last build
    [[nodiscard]] std::size_t header_bytes() const { return header_bytes_; }  ///< uploaded by the last build
    /// Per-node kb and stretch uploaded by the last build (16 bytes a node, 4 a segment, for wires that have them).
    [[nodiscard]] std::size_t extra_bytes() const { return extra_bytes_; }

private:
    friend class GpuRingPass;  // reads the headers, nodes, segments and stretch this pass keeps on the GPU
    engine::gfx::Program program_;
    engine::gfx::Buffer headers_, nodes_, segments_, scratch_, extras_, motion_refs_;
    std::size_t motion_ref_wires_ = 0;  // wires motion_refs_ holds (kept between builds of as many wires)
    std::vector<detail::GpuCurveHeader> header_data_;
    std::vector<glm::dvec3> origins_;
    std::size_t segment_total_ = 0, node_bytes_ = 0, header_bytes_ = 0, extra_bytes_ = 0;
};

}  // namespace wire::render
