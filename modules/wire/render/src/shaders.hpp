// The wire programs' GLSL (internal; the text is in modules/wire/render/shaders): the curve and ring compute
// programs, one vertex shader per upload path, the fragment shaders.
#pragma once

#include "gpu_records.hpp"

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

namespace wire::render::detail {

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
/// The curve program: the binding macros (kBindingMacros), the shared records (gpu_records.h), curves*.comp.
std::string curve_program_source();
/// The ring program: the binding macros, the shared records, rings*.comp.
std::string ring_program_source();

}  // namespace wire::render::detail
