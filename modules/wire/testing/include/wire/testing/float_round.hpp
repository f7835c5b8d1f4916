// A double vector rounded to float and back, for references that must see what the GPU holds.
#pragma once

#include <glm/vec3.hpp>

namespace wire::testing {

/// Each component rounded to the nearest float. Not `glm::dvec3(glm::vec3(v))`: GCC 12 at -O3 vectorizes that
/// round trip for two lanes of a loop and drops it (seen in gpu_curves_test: x and y kept every bit, z rounded),
/// so the volatile stores keep each rounding.
inline glm::dvec3 float_rounded(const glm::dvec3& v) {
    volatile float x = static_cast<float>(v.x), y = static_cast<float>(v.y), z = static_cast<float>(v.z);
    return {x, y, z};
}

}  // namespace wire::testing
