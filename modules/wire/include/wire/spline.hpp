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
// automatic    Per node a sharpness s in [0,1] (smoothstep, so it moves continuously with the nodes) from the
//              turning angle phi, the neighbour length ratio q >= 1 and the stretch:
//                s = 1 - (1 - smoothstep(0.35, 1.2, phi (1 + ln q))) (1 - smoothstep(1.0, 1.02, stretch)).
//              s = 0: chordal Catmull-Rom (with a quadratic "Bessel" end tangent instead of the phantom node).
//              s > 0: the node tangent's direction blends toward (l_in^2 e_in + l_out^2 e_out) (the longer
//              neighbour dominates, so a long straight run stays on its line) and both sides' magnitudes blend
//              toward h = 0.5 min(l_in, l_out) (a bend rounds within the short segment, overshooting the node by
//              at most (4/27) h), and h shrinks to a tenth between 1% and 5% stretch (a taut wire runs straight
//              between its nodes). Both sides keep one direction: G1 everywhere (no tangent vanishes unless
//              tension reaches 1), C1 where s = 0. Tension (wire, node, curvature) applies as for catmull_rom;
//              bias and continuity do not.
//              The thresholds (0.35..1.2 rad, 1..2% and 1..5% stretch, 0.5) are tunable constants in spline.cpp.
// linear       b1, b2 at 1/3 and 2/3 of the chord.
#pragma once

#include "wire/curve.hpp"
#include "wire/nodes.hpp"
#include "wire/status.hpp"

namespace wire {

/// Builds the curve for `nodes`. On success `out` holds node_count() = merged nodes, segment_count() =
/// nodes - 1 (open) or nodes (closed), every value finite. On failure `out` is cleared and the Status names
/// the offending input node and field, e.g. "node 3: position.y is NaN". Never throws on bad input.
/// Cost O(n) time and memory for every kind (100,000 nodes: a few ms).
[[nodiscard]] Status build_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out);

/// The thesis' curvature-driven tension for one node: R = theta*Iz*L / (A*dL^2); 0 if R > 100 (or dL = 0),
/// else 1 - tanh(R/50). Non-finite or non-positive denominators give 0.
[[nodiscard]] double curvature_tension(double theta_rad, double iz_m4, double length_m, double delta_length_m,
                                       double area_m2);

}  // namespace wire
