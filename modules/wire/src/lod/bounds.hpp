// Internal: building LodBounds (the span hierarchy), all of it or the levels an update can read.
#pragma once

#include "wire/lod.hpp"

#include <cstddef>

namespace wire::lod_stage {

// The levels an update of a wire inside the frustum reads (update_lod_once()). With deviations that never
// decrease from a level to the one above, a level l whose smallest deviation fails at the far depth of the wire's
// sphere, (dev_min(l) c) k > z_hi (c = focal / eps, k the sphere's off-axis bound: set_depth_range()'s test), makes
// every level above it fail too and none fit (their largest deviation is at least that, and the fit test's
// denominator new_scale z_lo is at most z_hi), so set_depth_range() reads nothing above l and the walk starts below
// it. The root (the one other node the update reads) has a ratio above 1: its deviation is >= dev_min(l), and
// its sphere's nearest depth is at most the depth of the wire's first control point, which lies in both spheres,
// so at most z_hi, up to roundings far below `slack`; the update takes it as not one interval, which it is not.
// Deviations never decrease when no value overflows and none is NaN (a parent's is the larger child's plus a
// square root, rounded up or equal): the coordinates are finite, below 1e149 in magnitude (then no square or sum
// of squares of the kernels overflows), which the sphere's box shows for all but NaN ones and level 0's probe
// (NaN then) for those.
struct TopLevels {
    double c, k, above;  // stop after level l when (dev_min(l) c) k > above (= z_hi + slack)
};

// Returns the number of levels built: all, or with `stop` (when level 0's probe shows every coordinate finite)
// up to the first that TopLevels lets stop after; that level below the root has its deviations (and their range)
// but no spheres, which the update does not read (the walk starts below it).
std::size_t compute_lod_bounds_impl(const Curve& curve, LodBounds& out, const BoundingSphere* known_sphere,
                                    const TopLevels* stop = nullptr);

}  // namespace wire::lod_stage
