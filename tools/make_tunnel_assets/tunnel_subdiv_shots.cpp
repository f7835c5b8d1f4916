// Before/after screenshots of subdivision on a bent piece: the coarse tunnel pieces bent 90 degrees over
// their 4 m (curved_space CPU bend) at level 0 and at the level choose_subdivision_level picks for the view.
//   tunnel_subdiv_shots [--out DIR]   (default out/subdiv) -> DIR/before.png, DIR/after.png
#include "tunnel_pieces.hpp"

#include <curved_space/chain.hpp>
#include <engine/assets/subdivide.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/gfx/mesh.hpp>
#include <engine/platform/capture.hpp>
#include <engine/platform/context.hpp>
#include <engine/scene/camera.hpp>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Piece {
    engine::assets::MeshData coarse;
    glm::vec3 albedo;
};

engine::gfx::PrimitiveMesh to_gfx(const engine::assets::MeshData& m) {
    engine::gfx::PrimitiveMesh g;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        engine::gfx::Vertex vertex;
        vertex.position = glm::vec3(glm::dvec3(m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]) + m.origin);
        vertex.normal = glm::vec3(m.normals[3 * v], m.normals[3 * v + 1], m.normals[3 * v + 2]);
        g.vertices.push_back(vertex);
    }
    g.indices = m.indices;
    return g;
}

}  // namespace

int main(int argc, char** argv) {
    std::string out_dir = "out/subdiv";
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
            out_dir = argv[++i];
        } else {
            std::fprintf(stderr, "usage: tunnel_subdiv_shots [--out DIR]\n");
            return 2;
        }
    }
    const int width = 960, height = 720;
    auto context = engine::platform::create_headless_context({.width = width, .height = height, .quiet = true});
    if (!context) {
        std::fprintf(stderr, "tunnel_subdiv_shots: %s\n", context.error().message.c_str());
        return 1;
    }
    auto renderer = engine::gfx::LitRenderer::create();
    if (!renderer) {
        std::fprintf(stderr, "tunnel_subdiv_shots: %s\n", renderer.error().message.c_str());
        return 1;
    }

    const tunnel::TunnelSpec spec;
    std::vector<Piece> pieces;
    for (auto& m : tunnel::straight_section(spec)) pieces.push_back({std::move(m), {0.75f, 0.72f, 0.66f}});
    for (auto& m : tunnel::wall_details(spec)) {
        const glm::vec3 albedo = m.name == "walkway" ? glm::vec3(0.35f, 0.45f, 0.6f) : glm::vec3(0.8f, 0.45f, 0.2f);
        pieces.push_back({std::move(m), albedo});
    }
    for (auto& m : tunnel::cable_hooks(spec)) pieces.push_back({std::move(m), {0.9f, 0.85f, 0.2f}});

    // 90 degrees over the 4 m piece, toward +x: a strong bend (kappa r = 0.98 at the inner wall).
    const double angle_rad = kPi / 2;
    const curved_space::Segment segment{.length_m = spec.length_m, .angle_rad = angle_rad, .direction_rad = 0.0};
    curved_space::Chain chain;
    if (auto s = curved_space::make_chain(std::span(&segment, 1), chain); !s.ok()) {
        std::fprintf(stderr, "tunnel_subdiv_shots: %s\n", s.message.c_str());
        return 1;
    }
    engine::scene::Camera camera;
    camera.aspect = float(width) / float(height);
    camera.fov_y_rad = glm::radians(70.0f);
    camera.position = {-1.0f, 0.3f, 0.3f};
    camera.target = glm::vec3(chain.transform_point({-0.3, -0.4, 3.2}));
    const double focal_px = camera.focal_px(float(height));

    for (const bool after : {false, true}) {
        context.value()->begin_frame();
        engine::gfx::clear({0.05f, 0.05f, 0.07f, 1.0f});
        renderer->begin(camera.view_projection(), {.to_light = {-0.3f, 0.8f, -0.5f}, .ambient = 0.25f});
        std::vector<engine::gfx::GpuMesh> uploaded;
        std::size_t triangles = 0;
        for (const Piece& piece : pieces) {
            engine::assets::ControlMesh control;
            if (auto s = engine::assets::make_control_mesh(piece.coarse, control); !s.ok()) {
                std::fprintf(stderr, "tunnel_subdiv_shots: %s\n", s.message.c_str());
                return 1;
            }
            // The piece's nearest distance to the camera, conservatively the distance to the nearest coarse
            // vertex minus the piece's largest face (the camera stands inside the tunnel).
            double nearest_m = 1e30;
            for (std::size_t v = 0; v < control.positions.size() / 3; ++v) {
                const glm::dvec3 p = chain.transform_point(control.origin + glm::dvec3(control.positions[3 * v],
                                                                                       control.positions[3 * v + 1],
                                                                                       control.positions[3 * v + 2]));
                nearest_m = std::min(nearest_m, glm::length(p - glm::dvec3(camera.position)));
            }
            const auto model = engine::assets::refinement_error_model(control);
            const int level = after ? engine::assets::choose_subdivision_level(
                                          model, {.curvature_per_m = angle_rad / spec.length_m,
                                                  .distance_m = nearest_m - model.max_axial_extent_m,
                                                  .focal_px = focal_px,
                                                  .tolerance_px = 0.5})
                                    : 0;
            engine::assets::MeshData refined;
            if (auto s = engine::assets::subdivide(control, level, refined); !s.ok()) {
                std::fprintf(stderr, "tunnel_subdiv_shots: %s\n", s.message.c_str());
                return 1;
            }
            curved_space::bend_vertices(chain, refined.positions, refined.normals, refined.origin);
            triangles += refined.triangle_count();
            if (after)
                std::printf("%-12s level %d  (predicted %.4f m at %.2f m = %.2f px)\n", piece.coarse.name.c_str(), level,
                            engine::assets::predicted_error_m(model, angle_rad / spec.length_m, level), nearest_m,
                            engine::assets::predicted_error_m(model, angle_rad / spec.length_m, level) * focal_px /
                                std::max(0.01, nearest_m - model.max_axial_extent_m));
            auto gpu = engine::gfx::upload_mesh(to_gfx(refined), piece.coarse.name);
            if (!gpu) {
                std::fprintf(stderr, "tunnel_subdiv_shots: %s\n", gpu.error().message.c_str());
                return 1;
            }
            renderer->draw(gpu.value(), glm::mat4(1.0f), piece.albedo);
            uploaded.push_back(std::move(gpu.value()));
        }
        const std::string path = out_dir + (after ? "/after.png" : "/before.png");
        if (auto s = engine::platform::capture_png(*context.value(), path); !s) {
            std::fprintf(stderr, "tunnel_subdiv_shots: %s\n", s.message.c_str());
            return 1;
        }
        context.value()->end_frame();
        std::printf("%s: %zu triangles\n", path.c_str(), triangles);
    }
    return 0;
}
