// The wire programs' GLSL (internal; the text is in modules/wire/render/shaders): the curve and ring compute
// programs, one vertex shader per upload path, the fragment shaders.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

namespace wire::render::detail {

/// Per-draw record in the SSBO at binding 0 (std430, 32 bytes); must match DrawData in the GLSL.
struct GpuDraw {
    float offset_m[3];    ///< wire origin minus camera position (computed in double)
    uint32_t ring_first;  ///< gpu-rings: first 32-bit word of the wire's PackedRings in the ring SSBO (binding 1)
    uint32_t ring_count;
    uint32_t sides;
    uint32_t flags;  ///< kClosed | kCaps | kTilt | kStrip | kLine | kStreamedRings
    float u_close;
};
static_assert(sizeof(GpuDraw) == 32);
inline constexpr uint32_t kClosed = 1u, kCaps = 2u, kTilt = 4u, kStrip = 8u, kLine = 16u;  // kStrip: sides 2, kLine: sides 1
/// Retained path: this wire's rings are in the frame's region (SSBO binding 4), not in the retained storage.
inline constexpr uint32_t kStreamedRings = 32u;

/// `cpu_mesh`: vertex attributes 0 position, 1 normal, 2 uv (TubeVertex) and 3 the vertex's draw index (uint,
/// streamed beside the vertices). Otherwise the ring expansion from gl_VertexID of an instanced indexed draw over
/// the static pattern, one instance per chunk (upload_plan.hpp), its record (draw index, first band) in the SSBO
/// at binding 3. `draw_parameters` (gpu-rings only): the chunk index is gl_BaseInstanceARB + gl_InstanceID
/// (ARB_shader_draw_parameters), else the instanced attribute at location 3 (divisor 1; its buffer holds 0, 1,
/// 2, ... so it reads baseInstance + instance).
std::string vertex_source(bool cpu_mesh, bool draw_parameters);
/// What a fragment shader writes (WireRenderer's Output).
enum class FragmentOutput { color, depth, gbuffer };
/// `shading` (color): optional GLSL defining vec3 shade(vec3 albedo, vec3 n, vec3 to_eye); empty: the default
/// lighting. `gbuffer` (gbuffer): optional GLSL declaring its outputs and defining void write_gbuffer(vec3 albedo,
/// vec3 n, vec3 rel_m, float roughness); empty: the default layout. depth: a shader that writes nothing.
std::string fragment_source(FragmentOutput output, std::string_view shading, std::string_view gbuffer);

/// One program's GLSL: `#version 450 core`, then each piece after `#line 1 k` (k = 1, 2, ...), so a driver's
/// message names piece k and its line ("k:line" on Mesa, "k(line)" on NVIDIA).
std::string glsl_program(std::initializer_list<std::string_view> pieces);
/// The curve program: the binding macros (kBindingMacros), wire_header.comp, curves*.comp.
std::string curve_program_source();
/// The ring program: the binding macros, wire_header.comp, rings*.comp.
std::string ring_program_source();

}  // namespace wire::render::detail
