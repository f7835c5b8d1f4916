// The Bullet rope scene of examples/bullet_ropes: a floor, a box, and soft-body ropes and cables
// (BulletSoftBody) whose nodes are handed to wire entities every frame; plus the few GL objects that draw it.
//
//   RopeScene scene(registry);                    // Bullet world + one wire entity per rope
//   scene.step(1.0 / 60.0);                       // Bullet steps, then set_nodes() on every rope's wire
//   schedule.run(registry, 1.0 / 60.0);           // the wire systems build the DrawList
//   view.draw(scene, context.draw_list, camera);  // floor and box (lit), then the wires
#pragma once

#include <engine/ecs/entity.hpp>
#include <engine/ecs/registry.hpp>
#include <engine/gfx/lit_renderer.hpp>
#include <engine/gfx/mesh.hpp>
#include <engine/core/expected.hpp>
#include <engine/scene/camera.hpp>
#include <wire/draw.hpp>
#include <wire/nodes.hpp>
#include <wire/render/node_stream.hpp>
#include <wire/render/wire_renderer.hpp>

#include <glm/vec3.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

class btSoftBody;

namespace bullet_ropes {

/// Axis-aligned box in metres.
struct Box {
    glm::vec3 centre_m{0.0f};
    glm::vec3 half_m{0.5f};
};

/// One rope or cable: Bullet soft body -> wire entity.
struct Rope {
    std::string name;
    btSoftBody* body = nullptr;  ///< owned by the scene's Bullet world
    engine::ecs::Entity wire = engine::ecs::null_entity;  ///< its wire entity (null when streamed)
    wire::render::StreamWire stream{};                    ///< its streamed wire (RopeScene::stream_to)
    float radius_m = 0.03f;
    uint32_t material = 0;   ///< renderer material (RopeView adds one per rope colour)
    glm::vec3 colour{1.0f};  ///< tint of that material (linear RGB)
};

/// The wire nodes of a Bullet soft body: node positions in order, ids = node index (Bullet never inserts or
/// removes rope nodes, so the index is a stable id).
[[nodiscard]] wire::WireNodes wire_nodes(const btSoftBody& body);

/// Bullet world (soft + rigid), a static floor (top at y = 0) and box, four ropes: two hanging from one end
/// that start horizontal and swing down (one into the box), a slack cable fixed at both ends sagging over the
/// box, and a free rope dropped onto the box's edge. Deterministic: the same steps give the same nodes.
class RopeScene {
public:
    explicit RopeScene(engine::ecs::Registry& registry);
    ~RopeScene();
    RopeScene(const RopeScene&) = delete;
    RopeScene& operator=(const RopeScene&) = delete;

    /// Advances Bullet by dt_s (fixed internal steps of 1/240 s), then hands every rope's nodes to its wire
    /// (wire::systems::set_nodes).
    void step(double dt_s);
    /// Hands every rope's current nodes to its wire (step() calls this): to its wire entity (set_nodes), or, after
    /// stream_to(), straight from Bullet's node records into the renderer's mapped memory (one frame of the
    /// stream: begin() and a write per rope, reading each node's position in place).
    void sync_wires();
    /// From now on the ropes are the stream's wires (the nodes path): their wire entities are destroyed and the
    /// next sync_wires() writes the stream. The stream must outlive the scene's use of it.
    engine::Status stream_to(wire::render::NodeStream& stream);

    [[nodiscard]] const std::vector<Rope>& ropes() const { return ropes_; }
    [[nodiscard]] const Box& box() const { return box_; }
    [[nodiscard]] double time_s() const { return time_s_; }

private:
    struct World;
    engine::ecs::Registry& registry_;
    std::unique_ptr<World> world_;
    std::vector<Rope> ropes_;
    wire::render::NodeStream* stream_ = nullptr;
    Box box_{};
    double time_s_ = 0.0;
};

/// GL side: a lit floor and box (engine::gfx::LitRenderer) and the wires (wire::render::WireRenderer), one
/// material per rope colour. Needs a current GL 4.5 context.
class RopeView {
public:
    static engine::Expected<RopeView> create(const RopeScene& scene);

    /// Clears, draws the floor and the box, then the wires of `list`.
    /// The list carries the wire systems' LOD (the nodes path evaluates it on the GPU).
    void draw(const RopeScene& scene, const wire::DrawList& list, const engine::scene::Camera& camera);

    /// The wire renderer's preferred upload path (nodes where the context has compute; logged once).
    [[nodiscard]] wire::UploadPath preferred_path() { return wires_->preferred_path(); }
    /// The renderer's node stream (draw() draws its wires beside the list's).
    [[nodiscard]] wire::render::NodeStream& node_stream() { return wires_->node_stream(); }

    /// Background colour the frame is cleared to.
    static constexpr glm::vec3 kBackground{0.62f, 0.70f, 0.80f};
    /// Albedo of the floor and the box (neutral greys, so rope colours stand out).
    static constexpr glm::vec3 kFloorAlbedo{0.42f, 0.42f, 0.40f};
    static constexpr glm::vec3 kBoxAlbedo{0.70f, 0.68f, 0.64f};

private:
    RopeView() = default;
    engine::gfx::LitRenderer lit_;
    engine::gfx::GpuMesh floor_;
    engine::gfx::GpuMesh box_;
    std::unique_ptr<wire::render::WireRenderer> wires_;
    glm::mat4 box_model_{1.0f};

public:
    RopeView(RopeView&&) noexcept = default;
    RopeView& operator=(RopeView&&) noexcept = default;
};

/// The camera both the program and the test use: looking at the box from the front and a little above.
[[nodiscard]] engine::scene::Camera default_camera(int width_px, int height_px);

}  // namespace bullet_ropes
