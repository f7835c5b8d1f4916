// The accuracy bench's reference scenes: one wire each, whose nodes are taken from an exact curve at known
// parameters (catenary, helix, stretched run + tight bend, hairpin, smooth random curve, churn), with that
// curve kept as the truth to measure against and a camera that sees the whole wire.
#pragma once

#include "bench/common.hpp"

#include <wire/lod.hpp>
#include <wire/nodes.hpp>
#include <wire/testing/reference.hpp>

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace wiretool::bench {

/// A scene: one wire's nodes, taken from an exact curve at known parameters, and how to measure against it.
struct ReferenceScene {
    std::string name;
    std::string description;
    wire::WireNodes nodes;  ///< with ids (the pop events and churn need them)
    float stretch = 1.0f;   ///< for the physics arrays of the curvature-tension method
    // Truth: an exact catenary, or a dense polyline of the exact curve with the curve parameter of every
    // sample and of every node (so a query only searches near its own segment).
    bool catenary_truth = false;
    wire::Catenary catenary;
    std::vector<glm::dvec3> dense;
    std::vector<double> dense_param;
    std::vector<double> node_param;
    /// Only the first `straight_segments` segments are measured, against the line y = z = 0 (stretched run).
    uint32_t straight_segments = 0;
    bool churn = false;
    wire::LodView view;
};

/// The 20 m cable of DESIGN 4.8 between (0,0,0) and (16,2,0), 16 nodes dense near the ends
/// (s = L (1 - cos(pi i/15))/2: neighbour ratio ~10).
ReferenceScene catenary_scene(const std::string& name);

/// Helix of radius 1 m, pitch 0.3 m/rad, 3 turns, 12 nodes per turn (its exact RMF: DESIGN 4.3).
ReferenceScene helix_scene();

/// Stretched 6% along +x (nodes every 2 m to x = 10), a 0.1 m element turning 90 degrees down, then long
/// elements: the straight run must stay on its line.
ReferenceScene stretched_bend_scene();

/// Two 5 m legs 0.5 m apart joined by a half circle of radius 0.25 m; nodes every metre on the legs and at
/// every 45 degrees on the turn.
ReferenceScene hairpin_scene();

/// A smooth random curve (random Fourier series, fixed seed) through 40 nodes at random spacing (ratio up to
/// ~4).
ReferenceScene random_walk_scene();

/// The catenary refined and coarsened over the run (pops.hpp's churn_states); `churn` set.
ReferenceScene churn_scene();

/// The scenes `o` selects (--scenes; all by default), in the bench's order, each with its view set.
std::vector<ReferenceScene> reference_scenes(const Options& o);

}  // namespace wiretool::bench
