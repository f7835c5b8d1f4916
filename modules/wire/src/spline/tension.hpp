// Internal: the automatic spline's tension, read from the nodes' turning pattern: which nodes turn without their
// neighbours' support (a concentrated turn) or end a load-free span, and the weights that tense them.
#pragma once

#include "spline/merge.hpp"  // Chords

#include <cstddef>
#include <vector>

namespace wire::curve_stage {

/// Per-node tension weights from the turning pattern (see the constants above): g in [0, 1] (concentrated
/// turn), straight in [0, 1] (end of a load-free span), and the diagonal addition w they give (0 where both are 0).
/// n curve nodes. Returns false when every weight is 0 (no node to decide, or none that gets a weight: most
/// wires), leaving the outputs untouched (not zero-filled); else every output is resized to n.
bool concentrated_turns(const Chords& ch, std::size_t n, bool closed, std::vector<double>& g,
                        std::vector<double>& straight, std::vector<double>& w);

// Per node (arrays offset so that node i's incoming chord length, previous node's curvature and previous edge are
// at index i, its own at i + 1, the next node's curvature at i + 2): the turn its neighbours predict, the spread's
// ingredients |k|^2, |k~|^2 and |k - k~|^2, and flag 1 where the spread may have to be decided (0: the neighbours
// predict this turn, d <= kSpreadLo, shown on squares without a root by kSpreadBound; the flagged nodes, about one
// a wire on a swaying cable, take the exact test in concentrated_turns; clones chosen at load time). Returns the number of flagged nodes.
std::size_t spread_kernel(std::size_t count, const double* len, const double* kx, const double* ky, const double* kz,
                          const double* ax, const double* ay, const double* az, const double* ec, const double* eq,
                          double* lk2, double* lp2, double* miss2, double* flag);

// The spread's exact test for a node: sum = |k| + |k~| > 0 and finite (lengths are >= 0 or NaN), and the miss
// beyond kSpreadLo of it. lk = |k| and sum are returned for the weights.
bool spread_decides(double lk2, double lp2, double miss2, double& lk, double& sum);

// The exact test for the nodes spread_kernel flagged (its outputs, count nodes), as concentrated_turns' weight loop
// applies it, for the tests (detail::spread_test): a flag stays 1 where the spread must be decided (lk2v, lp2v then
// hold |k| and |k| + |k~|), else becomes 0. Returns whether any stays 1.
bool decide_flagged(std::size_t count, double* lk2v, double* lp2v, const double* miss2v, double* flag);

}  // namespace wire::curve_stage
