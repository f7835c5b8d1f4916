// Per-frame GPU data for the curved-space bend: segment records for a UBO/SSBO and the GLSL function that
// bends a vertex exactly like Chain::transform (same record choice, same stable sinc). No GL calls here.
#pragma once

#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "curved_space/chain.hpp"

namespace curved_space {

/// One record per segment plus one for the end of the chain (segment_count() + 1 in all). The layout is the
/// same under std140 and std430 (a mat4 and two vec4, 96 bytes), in GLSL:
///   struct CsSegment { mat4 world_from_bend; vec4 params; vec4 direction; };
struct GpuSegment {
    /// Chain::world_from_bend(i) with the camera position subtracted from its translation in double before
    /// the conversion to float: vertices come out camera-relative (world minus camera), so a chain 1e6 m from
    /// the origin keeps its precision near the camera.
    glm::mat4 world_from_bend{1.0f};
    glm::vec4 params{0.0f};     ///< z_start_m, length_m, kappa_per_m, gamma_rad (end record: total, 0, 0, 0)
    glm::vec4 direction{0.0f};  ///< cos(gamma), sin(gamma), 0, 0 (computed in double)
};
static_assert(sizeof(GpuSegment) == 96, "GpuSegment must match the std140/std430 layout of CsSegment");

/// The records for this frame; camera_position_m is in the chain's world space.
[[nodiscard]] std::vector<GpuSegment> gpu_segments(const Chain& chain, const glm::dvec3& camera_position_m);

/// Default SSBO binding of the records in glsl_bend_source().
inline constexpr unsigned segment_buffer_binding = 3;

/// GLSL 4.50 source (no #version line) declaring
///   layout(std430, binding = CS_SEGMENT_BINDING) readonly buffer CurvedSpaceSegments { CsSegment cs_segments[]; };
///   float cs_sinc(float t);
///   void cs_bend(vec3 p, vec3 n, out vec3 p_bent, out vec3 n_bent, out bool folded);
/// cs_bend takes an unbent position and normal and returns the camera-relative bent position and the unit
/// bent normal. The record is found by binary search on params.x over all records (the array's length());
/// before the chain and after it the map is straight. CS_SEGMENT_BINDING defaults to segment_buffer_binding
/// unless the including shader #defines it first. Usable in vertex and compute shaders.
[[nodiscard]] std::string_view glsl_bend_source();

}  // namespace curved_space
