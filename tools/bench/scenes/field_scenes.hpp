// The wire systems bench's scenes: which wires each holds and how `swaying` moves them. `standard`,
// `offscreen`, `swaying`: a field of hanging wires; `far`: 10,000 cables over a 2 km landscape. Plain
// functions of the wire index (deterministic); the camera paths are in camera_paths.hpp.
#pragma once

#include <wire/nodes.hpp>

#include <cstddef>

namespace wiretool::bench {

/// Nodes of every scene's wires.
constexpr int kFieldNodes = 64;

enum class SceneKind { standard, offscreen, swaying, far };

/// The scene's name in bench.csv and --scenes.
const char* scene_name(SceneKind k);
/// How many wires the scene holds: 10,000 for `far`, 1,000 for the others.
int scene_wire_count(SceneKind k);

/// Wire i of the field (20 rows high, count/20 deep): a catenary 10 m across, 3-8% longer than its chord,
/// through 64 nodes at equal arc lengths.
wire::WireNodes hanging_wire(int i);

/// Height of the `far` landscape's rolling ground at (x, z), metres.
double ground_m(double x, double z);

struct FarWire {
    wire::WireNodes nodes;
    float radius_m = 0.015f;
};

/// `far`: a 2 km x 2 km landscape (rolling ground) with 10,000 cables of 64 nodes: power lines (three
/// conductors per span, 120-260 m spans between 18-26 m towers, 2-4% slack) along 12 corridors of parallel
/// lines (wrapped at the landscape's edges), and rigging (mast stays, crane and ship rigging, 12-45 m,
/// sloped, 1-3% slack) in 60 clusters. Deterministic in i.
FarWire far_wire(int i);

/// `swaying`, frame > 0: the physics moved every node of wire `wire_index` a little (ends stay on their
/// posts).
void sway_nodes(wire::WireNodes& nodes, std::size_t wire_index, int frame);

}  // namespace wiretool::bench
