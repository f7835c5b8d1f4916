// The curve stage: a wire's nodes -> its centre line as cubic Bezier segments (wire::Curve).
//
// Every kind computes analytic Hermite tangents and converts B1 = P1 + m1/3, B2 = P2 - m2/3; segments
// interpolate the (merged) nodes exactly: b0 and b3 are copies of the node positions.
//
// catmull_rom  Non-uniform knots d_k = |P[k+1]-P[k]|^alpha (DESIGN 4.1). At node j with incoming chord D_in
//              and outgoing chord D_out, rho = d_out/d_in, the per-segment (u in [0,1]) tangents are
//                start of the outgoing segment  (1-t) [ (1+b)(1+c) rho^2/(1+rho) D_in + (1-b)(1-c) 1/(1+rho) D_out ]
//                end of the incoming segment    (1-t) [ (1+b)(1-c) rho/(1+rho) D_in + (1-b)(1+c) 1/(rho(1+rho)) D_out ]
//              With t = b = c = 0 this is exactly the DESIGN formula times the segment's knot length; with
//              rho = 1 it is the textbook Kochanek-Bartels spline. That is the non-uniform generalization used:
//              the uniform weights 1/2 become the Catmull-Rom weights d_out/(d_in+d_out), d_in/(d_in+d_out)
//              (which is what KB's "(2 N_i)/(N_i + N_{i+1})" frame-count correction approximates).
//              Only ratios of knot lengths enter (computed as exp(alpha * log ratio)), so coincident-ish nodes
//              give the true centripetal limit (tangent -> 0), never 0/0. Open ends: phantom P[-1] = 2P[0]-P[1].
//              Tension t = 1 - (1 - t_wire_or_node) * (1 - t_curvature); the thesis' t_curvature = 0 for R > 100,
//              else 1 - tanh(R/50) (note: that formula steps from 0.036 to 0 at R = 100, as published).
//              C1 for c = 0, any bias, t < 1 (tension and bias scale both sides of a node alike, so the
//              knot-ratio C1 condition still holds); t = 1 gives a corner, c != 0 a deliberate kink.
// c2           Chordal knots; tangents from the global C2 system (rows normalized, diagonally dominant,
//              Thomas algorithm O(n)); open ends not-a-knot (O(h^4) on smooth sag, where natural ends force
//              zero curvature that a hanging cable does not have); 3 nodes: the interpolating parabola;
//              closed: cyclic system by Sherman-Morrison. Tension, bias, continuity are ignored (they break C2).
// automatic    The spline under tension a cable obeys (EI w'''' - T w'' = q), as Nielson's nu-spline: chordal
//              knots, C1, one cubic per segment, and at node i the jump of the second derivative equals
//              nu_i times the tangent; in the normalized C2 rows (see c2) that adds w_i to the diagonal 2.
//              w_i = 0 gives exactly c2 (not-a-knot ends); w_i -> inf a corner. w_i is read from the nodes'
//              turning pattern: the curvature vector k_i = (e_out - e_in) / mean element is compared with
//              the neighbours' (carried to node i's tangent, interpolated in arc length):
//                d = |k_i - k~_i| / (|k_i| + |k~_i|),  share = |k_i| / (|k_i| + |k~_i|),
//                g = smoothstep(0.55, 0.85, d) * smoothstep(0.3, 0.45, share),  w_i = (1 + 3e4)^g - 1,
//              plus (1 + 30)^g' - 1 with g' = smoothstep(0.55, 0.85, d) * (1 - smoothstep(0, 0.1, share)) at a
//              straight node next to a turn (the end of a load-free span: damps c2's ringing into it).
//              Spread-out turning (sag, drums, sheaves, helices: d small) -> g = 0: the accurate C2 spline,
//              whatever the stretch. A turn the neighbours do not share (a corner between straight runs, an
//              alternating zig-zag) -> g = 1: straight runs and a rounding of ~3e-5 of the element at the turn
//              (the tangent shrinks to ~3/(2 + 3e4) of c2's, never 0: G1 everywhere). Open ends blend from
//              not-a-knot to free as node 1 or 2 (n-2 or n-3) gets tensed. Continuous in the nodes (g and w
//              are smooth functions of them). Stretch is not used: the turning pattern, not the stretch,
//              shows where a distributed load acts. Why, and where it stops holding: modules/wire/DESIGN.md.
//              Tension (wire, node, curvature) scales both tangents at a node as for catmull_rom; bias and
//              continuity do not apply. Cost O(n) (one tridiagonal solve, as c2).
// linear       b1, b2 at 1/3 and 2/3 of the chord.
#pragma once

#include "wire/curve.hpp"
#include "wire/nodes.hpp"
#include "wire/status.hpp"

#include <cstddef>
#include <span>
#include <utility>
#include <vector>

namespace wire {

/// Builds the curve for `nodes`. On success `out` holds node_count() = merged nodes, segment_count() =
/// nodes - 1 (open) or nodes (closed), every value finite. On failure `out` is cleared and the Status names
/// the offending input node and field, e.g. "node 3: position.y is NaN". Never throws on bad input.
/// Cost O(n) time and memory for every kind (100,000 nodes: a few ms).
[[nodiscard]] Status build_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out);

/// build_curve for two wires: the same outputs and statuses, bit for bit, as two build_curve calls (also when
/// out0 and out1 are the same curve, which then holds the second). Faster where both are open c2 or automatic wires with the same number of curve nodes: the
/// tridiagonal solve, a serial chain of divisions per wire, runs for both side by side.
[[nodiscard]] std::pair<Status, Status> build_curve_pair(const WireNodes& nodes0, const SplineSettings& settings0,
                                                         Curve& out0, const WireNodes& nodes1,
                                                         const SplineSettings& settings1, Curve& out1);

/// One wire for build_curves(): its nodes and settings, the curve to write, and (after the call) its status.
struct CurveBuildJob {
    const WireNodes* nodes = nullptr;          ///< the wire's nodes
    const SplineSettings* settings = nullptr;  ///< its settings
    Curve* out = nullptr;                      ///< the curve to write (cleared on failure, as build_curve's)
    Status status;                             ///< build_curve's status, set by the call
};

/// build_curve for every job, in order: the same outputs and statuses, bit for bit, as a build_curve call for each
/// (also when two jobs write one curve, which then holds the later one). Faster where open c2 or automatic wires
/// have the same number of curve nodes: their tridiagonal solves, a serial chain of divisions per wire, run side by
/// side (four, else two, at once; any number of jobs is taken four at a time).
void build_curves(std::span<CurveBuildJob> jobs);

/// The curve nodes build_curve builds `nodes` through: coincident neighbours merged by its rule and epsilon
/// (the first of a group kept; a closed loop's last node dropped where it coincides with its first). Positions
/// only, no validation (build_curve's checks come first). Returns out.size(); fewer than 2 (3 closed) means
/// build_curve fails on the wire. `source` (optional): per curve node, the input node its per-node values come
/// from (the first of its group, as build_curve reads them). `last` (optional): per curve node, the last input node
/// of its group (a segment's stretch is that of the element starting there, as build_curve reads it).
std::size_t curve_nodes(const WireNodes& nodes, const SplineSettings& settings, std::vector<glm::dvec3>& out,
                        std::vector<uint32_t>* source = nullptr, std::vector<uint32_t>* last = nullptr);

/// build_curve's checks without the build (the GPU curve path validates on the CPU, builds on the GPU): the same
/// Status for bad settings, sizes, node values and too few distinct nodes (build_curve's messages, naming the
/// node). Not checked: the tangent overflow of an extreme alpha (build_curve finds it while building).
[[nodiscard]] Status check_curve_input(const WireNodes& nodes, const SplineSettings& settings);

/// The thesis' curvature-driven tension for one node: R = theta*Iz*L / (A*dL^2); 0 if R > 100 (or dL = 0),
/// else 1 - tanh(R/50). Non-finite or non-positive denominators give 0.
[[nodiscard]] double curvature_tension(double theta_rad, double iz_m4, double length_m, double delta_length_m,
                                       double area_m2);

}  // namespace wire
