// The accuracy bench's pops: the largest jump between consecutive rendered curves when nodes are inserted and
// removed, without and with the pop-free blend (the blend of wire::PopFreeCurve).
#pragma once

#include <wire/nodes.hpp>

#include <vector>

namespace wiretool::bench {

/// Samples per segment of the pop metric (--quick: 96). Its polyline error is ~h^2 k / 8: at 32 a strongly
/// overshooting 2 m segment (chordal on the stretched run) reads a 1.1 mm pop that 256 samples show to be
/// 0.02 mm.
constexpr int kPopSamplesPerSegment = 256;
constexpr int kQuickPopSamplesPerSegment = 96;

struct Pops {
    double unblended_m = 0.0;
    double blended_m = 0.0;
};

/// One event on a static scene: a node inserted exactly on the curve in the middle of the middle segment,
/// then an original interior node removed.
Pops event_pops(const wire::WireNodes& nodes, const wire::SplineSettings& spline, int samples);

/// Churn: the catenary's nodes while the simulation refines and coarsens: every 5 frames an event, two of
/// every three insert a node exactly on the rendered target curve (middle of a random segment), the third
/// removes a random one of the inserted nodes (coarsening undoes refinement; the original nodes stay, as the
/// posts and the physics' coarsest level would). The states of every frame, in order.
std::vector<wire::WireNodes> churn_states(const wire::WireNodes& start, const wire::SplineSettings& spline,
                                          int frames);

/// The largest jumps over the churn states, each shown for one frame.
Pops churn_pops(const std::vector<wire::WireNodes>& states, const wire::SplineSettings& spline, int samples);

}  // namespace wiretool::bench
