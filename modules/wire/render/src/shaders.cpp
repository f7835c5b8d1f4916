// The wire programs' GLSL, assembled from the files in modules/wire/render/shaders (compiled in by
// cmake/EmbedGlsl.cmake). The ring expansion (rings_main.vert) reproduces wire::write_tube (tube.cpp) vertex
// for vertex: same vertex layout (rows of sides + 1, caps of centre + rim), same triangles and winding, same
// normal tilt by the radius slope, so both paths rasterize the same triangles. Only the order differs: the
// caps come first in the index pattern.
#include "shaders.hpp"

#include "gpu_wire_data.hpp"
#include "wire_glsl.hpp"

#include "engine/gfx/shadow.hpp"

#include <string>

namespace wire::render::detail {

std::string glsl_program(std::initializer_list<std::string_view> pieces) {
    std::string s = "#version 450 core\n";
    uint32_t k = 0;
    for (const std::string_view piece : pieces) {
        s += "#line 1 " + std::to_string(++k) + "\n";
        s += piece;
        if (!piece.empty() && piece.back() != '\n') s += '\n';
    }
    return s;
}

namespace {

/// The shared records (gpu_records.h) read as GLSL: its two macros, then the text.
constexpr std::string_view kRecordMacros = "#define WIRE_CONST const\n#define WIRE_ZERO\n";

}  // namespace

std::string vertex_source(bool cpu_mesh, bool draw_parameters) {
    // The record index piece first: the draw-parameters one holds an #extension, which must precede declarations.
    return glsl_program(
        {draw_parameters && !cpu_mesh ? glsl::record_draw_parameters_vert : glsl::record_attribute_vert,
         kRecordMacros, glsl::gpu_records_h, glsl::tube_common_vert,
         cpu_mesh ? glsl::mesh_main_vert : glsl::rings_main_vert});
}

std::string fragment_source(FragmentOutput output, std::string_view shading, std::string_view gbuffer) {
    switch (output) {
        case FragmentOutput::depth:
            return glsl_program({glsl::depth_frag});
        case FragmentOutput::gbuffer:
            return glsl_program({glsl::surface_inputs_frag, glsl::surface_frag,
                                 gbuffer.empty() ? glsl::default_gbuffer_frag : gbuffer,
                                 glsl::gbuffer_main_frag});
        case FragmentOutput::color:
            break;
    }
    return glsl_program({glsl::surface_inputs_frag, glsl::surface_frag, glsl::color_output_frag,
                         engine::gfx::shadow_glsl(), shading.empty() ? glsl::default_shading_frag : shading,
                         glsl::color_main_frag});
}

namespace {

/// The binding macros (kBindingMacros) as #defines.
std::string binding_defines() {
    std::string s;
    for (const BindingMacro& m : kBindingMacros)
        s += "#define " + std::string(m.name) + " " + std::to_string(m.binding) + "\n";
    return s;
}

}  // namespace

std::string curve_program_source() {
    const std::string defines = binding_defines();
    return glsl_program({defines, kRecordMacros, glsl::gpu_records_h, glsl::curves_comp, glsl::curves_motion_comp,
                         glsl::curves_main_comp});
}

std::string ring_lod_program_source() {
    const std::string defines = binding_defines();
    return glsl_program({defines, kRecordMacros, glsl::gpu_records_h, glsl::rings_buckets_comp, glsl::rings_comp,
                         glsl::rings_segment_comp, glsl::rings_lod_comp, glsl::rings_lod_main_comp});
}

std::string ring_commands_program_source() {
    const std::string defines = binding_defines();
    return glsl_program({defines, glsl::rings_scan_comp, glsl::rings_buckets_comp, glsl::rings_commands_main_comp});
}

std::string ring_place_program_source() {
    const std::string defines = binding_defines();
    return glsl_program({defines, kRecordMacros, glsl::gpu_records_h, glsl::rings_scan_comp, glsl::rings_buckets_comp,
                         glsl::rings_comp, glsl::rings_place_main_comp});
}

std::string ring_build_program_source() {
    const std::string defines = binding_defines();
    return glsl_program({defines, kRecordMacros, glsl::gpu_records_h, glsl::rings_buckets_comp, glsl::rings_comp,
                         glsl::rings_segment_comp, glsl::rings_frames_comp, glsl::rings_build_main_comp});
}

}  // namespace wire::render::detail
