// Internal: the curve stage's input checks (settings, array sizes, node values) and their messages.
#pragma once

#include "wire/spline.hpp"

#include <cstddef>
#include <string>

namespace wire::curve_stage {

// Largest accepted |coordinate|: wire::kMaxCoordinate_m (nodes.hpp; DESIGN §5 asks for 1e6 m from the origin).

// A value as the messages write it: %.9g, NaN, +Inf, -Inf.
std::string describe(double v);
// "node i: ", the start of a message about input node i.
std::string node_prefix(std::size_t i);

// Every per-node array empty or one per node.
Status check_sizes(const WireNodes& w);
// Every setting finite and in range.
Status check_settings(const SplineSettings& s);
// Every node's values finite and in range (the physics arrays' too with use_physics).
Status check_nodes(const WireNodes& w, bool use_physics);

// Enough distinct nodes after merging coincident ones: `input` nodes merged to `merged` (2, a closed loop 3).
Status check_distinct(std::size_t input, std::size_t merged, bool closed);

// True when |v[i]| <= limit for every i < count (false for NaN and Inf), by the widest version the CPU has.
bool values_within(const double* v, std::size_t count, double limit);
// True when v[i] > limit for every i < count (false for NaN).
bool all_above(const double* v, std::size_t count, double limit);

}  // namespace wire::curve_stage
