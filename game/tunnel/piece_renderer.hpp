// Draws the tunnel's environment pieces bent along the curved space on the GPU: each refined piece mesh is
// laid along +z once and drawn instanced, instance k shifted to its piece's start z and bent in the vertex
// shader by curved_space's cs_bend() with the frame's segment records (camera-relative SSBO). Its GL goes
// through engine/gfx (resources, draw).
#pragma once

#include <curved_space/gpu.hpp>
#include <engine/gfx/shadow.hpp>
#include <engine/assets/mesh_data.hpp>
#include <engine/core/expected.hpp>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

namespace tunnel {

using engine::Error;
using engine::Expected;

/// How a surface is shaded (procedural detail in the fragment shader, from the unbent position).
enum class Surface : int {
    concrete = 0,  ///< wall: 1 m x 30 degree panels with seams and per-panel tone
    steel = 1,     ///< ribs, hooks: plain, a bit of specular
    grating = 2,   ///< walkway: slats across the tunnel
};

/// The frame's lights and view. Lamps hang on the tunnel ceiling every lamp_spacing_m (unbent z), lighting
/// the walls in warm pools; the camera carries a head lamp; fog fades toward fog_color.
struct PieceFrame {
    glm::mat4 clip_from_rel{1.0f};  ///< projection * camera rotation (positions are camera-relative)
    std::span<const curved_space::GpuSegment> segments{};
    glm::vec3 to_light{0.3f, 1.0f, 0.5f};
    glm::vec3 fog_color{0.02f, 0.025f, 0.035f};
    float fog_distance_m = 45.0f;
    float lamp_spacing_m = 4.0f;
    float lamp_y_m = 2.1f;
    bool wireframe = false;
    /// The head lamp: its position relative to the eye and unit direction; `head_shadow` its shadow map (its
    /// light the lamp's view; null: unshadowed), looked up eye-relative (eye_m: the camera position).
    glm::vec3 head_rel_m{0.0f};
    glm::vec3 head_dir{0.0f, 0.0f, -1.0f};
    float head_cos_cone = 0.0f;  ///< cosine of the lamp's cone half angle (the beam fades over its outer fifth)
    const engine::gfx::ShadowMap* head_shadow = nullptr;
    glm::dvec3 eye_m{0.0};
    /// Depth only (a shadow map's casters): the same bent positions, no shading (an empty fragment shader).
    bool depth_only = false;
};

class PieceRenderer {
public:
    using MeshHandle = uint32_t;

    /// Compiles the program (errors carry the driver's log). Needs a current GL 4.5 context.
    static Expected<PieceRenderer> create();

    PieceRenderer();
    PieceRenderer(PieceRenderer&&) noexcept;
    PieceRenderer& operator=(PieceRenderer&&) noexcept;
    ~PieceRenderer();

    /// Uploads a mesh (positions relative to mesh.origin are baked to piece space; uvs may be empty).
    Expected<MeshHandle> add_mesh(const engine::assets::MeshData& mesh, std::string_view label);
    [[nodiscard]] std::size_t triangle_count(MeshHandle mesh) const;

    /// Uploads the segment records and sets the per-frame state (depth test, back-face culling). Returns the
    /// bytes uploaded.
    std::size_t begin(const PieceFrame& frame);
    /// Draws `mesh` once per entry of piece_z_m (the unbent z where that instance starts).
    void draw(MeshHandle mesh, Surface surface, const glm::vec3& albedo, std::span<const float> piece_z_m);
    /// Restores the polygon mode.
    void end();

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace tunnel
