// Internal: merging coincident nodes, and the chords of the curve's nodes (structure of arrays).
#pragma once

#include "wire/spline.hpp"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace wire::curve_stage {

using glm::dvec3;

// Merged nodes: the first input node of each group is kept; `last` is the group's last input node, whose
// element is the one that leaves the group (its stretch belongs to the outgoing segment).
struct Merged {
    std::vector<dvec3> p;
    std::vector<uint32_t> first, last;
    bool identity = false;  // first and last hold 0 .. size-1 (nothing merged): kept for the next wire of that size
    dvec3 lo{0.0}, hi{0.0};  // the input nodes' box (merge_nodes' last call)
};

// Segment chords, structure of arrays. Segment k is at index k + 1; index 0 repeats the last segment and index
// segs + 1 the first (wrap-around ghosts, so per-node passes read a node's incoming chord at i and outgoing at
// i + 1 without index arithmetic; on open wires the ghosts only feed end values that are overwritten).
struct Chords {
    std::vector<double> dx, dy, dz;  // chords
    std::vector<double> len;         // their lengths (> merge epsilon)
    std::vector<double> ex, ey, ez;  // unit directions d / len (computed once; every kind that needs them reads these)
    std::size_t segs = 0;
    dvec3 d(std::size_t k) const { return {dx[k + 1], dy[k + 1], dz[k + 1]}; }
    dvec3 e(std::size_t k) const { return {ex[k + 1], ey[k + 1], ez[k + 1]}; }
    double l(std::size_t k) const { return len[k + 1]; }
};

// Coincident-node merging. Returns the curve's nodes: the input positions themselves when nothing merges (the
// common case: decided from the input's chords, which are then the curve's), else m.p. `ch` holds the chords of
// the returned nodes when there are at least 2 of them (3 closed).

const dvec3* merge_nodes(const WireNodes& w, const SplineSettings& s, Merged& m, Chords& ch, std::size_t& count);

}  // namespace wire::curve_stage
