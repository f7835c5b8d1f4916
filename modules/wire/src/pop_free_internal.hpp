// Internal: what the pop-free blend's update and assembly (pop_free.cpp) share with the remap of its pieces
// (pop_free_remap.cpp).
#pragma once

namespace wire::detail {

/// The blend weight's easing: 3 s^2 - 2 s^3 of s clamped to [0, 1].
double smoothstep(double s);

}  // namespace wire::detail
