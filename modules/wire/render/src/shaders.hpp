// The wire programs' GLSL (internal; the text is in modules/wire/render/shaders): the curve program and the
// ring pass's four compute programs, one vertex shader per upload path, the fragment shaders.
#pragma once

#include "gpu_records.hpp"

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>

namespace wire::render::detail {

/// `cpu_mesh`: vertex attributes 0 position, 1 normal, 2 uv (TubeVertex) and 3 the vertex's draw index (uint,
/// streamed beside the vertices). Otherwise the ring expansion from gl_VertexID of an instanced indexed draw over
/// the static pattern, one instance per chunk (upload_plan.hpp), its record (draw index, first band) in the SSBO
/// at binding 3. `draw_parameters` (the rings only): the chunk index is gl_BaseInstanceARB + gl_InstanceID
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
/// The ring pass's programs, dispatched in this order: LOD, place (stage 0), commands, place (stage 1), rings (each
/// from the binding macros and the pieces its stage reads). The LOD program (one invocation per wire): the slot's
/// first normal turned by the wire's motion, the rings per segment (the LOD's or the caller's), the drawn sides.
/// The shared records, rings_buckets.comp, rings.comp, rings_segment.comp, rings_lod.comp, rings_lod_main.comp.
std::string ring_lod_program_source();
/// The place program (one workgroup, in wire order): stage 0 the ring ranges (a prefix sum), the reserve, the
/// chunk counts per bucket; stage 1 the chunk records in each bucket in wire order. The shared records,
/// rings_scan.comp, rings_buckets.comp, rings.comp, rings_place_main.comp.
std::string ring_place_program_source();
/// Most ring records the place program addresses: its sums saturate at 2^31 - 1 (rings_scan.comp's kSat), so a
/// capacity or reserve below that is compared exactly.
inline constexpr std::size_t kMaxRingRecords = 0x7ffffffe;
/// The commands program (one workgroup): the indirect commands and each bucket's first chunk (a prefix sum).
/// rings_scan.comp, rings_buckets.comp, rings_commands_main.comp.
std::string ring_commands_program_source();
/// The rings program (one invocation per wire): the rings with their frames and u, the draw record.
/// The shared records, rings_buckets.comp, rings.comp, rings_segment.comp, rings_frames.comp, rings_build_main.comp.
std::string ring_build_program_source();

}  // namespace wire::render::detail
