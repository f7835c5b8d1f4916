#include "rope_scene.hpp"

#include <wire/systems/api.hpp>

#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <cstdio>
#include <utility>

namespace bullet_ropes {
namespace {

btVector3 bt(const glm::vec3& v) {
    return {v.x, v.y, v.z};
}

// A soft-body rope through `points` (one node per point, links between neighbours). mass_kg is the whole
// rope's.
btSoftBody* make_rope(btSoftBodyWorldInfo& info, const std::vector<btVector3>& points, float mass_kg,
                      bool fix_first, bool fix_last) {
    const int n = static_cast<int>(points.size());
    std::vector<btScalar> masses(points.size(), mass_kg / static_cast<float>(n));
    auto* body = new btSoftBody(&info, n, points.data(), masses.data());
    for (int i = 0; i + 1 < n; ++i) body->appendLink(i, i + 1);
    if (fix_first) body->setMass(0, 0.0f);
    if (fix_last) body->setMass(n - 1, 0.0f);
    return body;
}

// n points on the straight line a -> b.
std::vector<btVector3> line(const btVector3& a, const btVector3& b, int n) {
    std::vector<btVector3> p;
    for (int i = 0; i < n; ++i)
        p.push_back(a.lerp(b, static_cast<btScalar>(i) / static_cast<btScalar>(n - 1)));
    return p;
}

// n points on a parabola from a to b sagging by `sag` in the middle (a slack cable's rest shape).
std::vector<btVector3> sagging(const btVector3& a, const btVector3& b, float sag, int n) {
    std::vector<btVector3> p = line(a, b, n);
    for (int i = 0; i < n; ++i) {
        const float s = static_cast<float>(i) / static_cast<float>(n - 1);
        p[i].setY(p[i].y() - 4.0f * sag * s * (1.0f - s));
    }
    return p;
}

}  // namespace

struct RopeScene::World {
    btSoftBodyRigidBodyCollisionConfiguration collision{};
    btCollisionDispatcher dispatcher{&collision};
    btDbvtBroadphase broadphase{};
    btSequentialImpulseConstraintSolver solver{};
    btDefaultSoftBodySolver soft_solver{};
    btSoftRigidDynamicsWorld world{&dispatcher, &broadphase, &solver, &collision, &soft_solver};
    btSoftBodyWorldInfo& info = world.getWorldInfo();
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btRigidBody>> rigid;
    std::vector<std::unique_ptr<btSoftBody>> soft;

    void add_static_box(const glm::vec3& centre, const glm::vec3& half) {
        shapes.push_back(std::make_unique<btBoxShape>(bt(half)));
        shapes.back()->setMargin(0.002f);  // Bullet rounds a box's edges by its margin (default 4 cm)
        btTransform transform;
        transform.setIdentity();
        transform.setOrigin(bt(centre));
        btRigidBody::btRigidBodyConstructionInfo ci(0.0f, nullptr, shapes.back().get());
        ci.m_startWorldTransform = transform;
        ci.m_friction = 0.8f;
        rigid.push_back(std::make_unique<btRigidBody>(ci));
        world.addRigidBody(rigid.back().get());
    }

    ~World() {
        for (auto& s : soft) world.removeSoftBody(s.get());
        for (auto& r : rigid) world.removeRigidBody(r.get());
    }
};

wire::WireNodes wire_nodes(const btSoftBody& body) {
    wire::WireNodes nodes;
    const int n = body.m_nodes.size();
    nodes.positions.reserve(static_cast<std::size_t>(n));
    nodes.ids.reserve(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const btVector3& x = body.m_nodes[i].m_x;
        nodes.positions.emplace_back(x.x(), x.y(), x.z());
        nodes.ids.push_back(static_cast<uint32_t>(i));  // Bullet keeps its rope nodes: index = stable id
    }
    return nodes;
}

RopeScene::RopeScene(engine::ecs::Registry& registry)
    : registry_(registry), world_(std::make_unique<World>()) {
    World& w = *world_;
    w.world.setGravity(btVector3(0.0f, -9.81f, 0.0f));
    w.info.m_gravity = btVector3(0.0f, -9.81f, 0.0f);
    w.info.air_density = 1.2f;
    w.info.m_sparsesdf.Initialize();
    w.info.m_sparsesdf.setDefaultVoxelsz(
        0.025f);                 // rigid shapes' distance field: 2.5 cm cells (default 25 cm
    w.info.m_sparsesdf.Reset();  // rounds the box's edges by centimetres)

    w.add_static_box({0.0f, -0.5f, 0.0f}, {8.0f, 0.5f, 8.0f});  // floor, top at y = 0
    box_ = {{0.35f, 0.35f, -0.2f}, {0.35f, 0.35f, 0.35f}};
    w.add_static_box(box_.centre_m, box_.half_m);

    struct Spec {
        const char* name;
        std::vector<btVector3> points;
        float mass_kg;
        bool fix_first;
        bool fix_last;
        float radius_m;
        glm::vec3 colour;
    };
    const std::vector<Spec> specs = {
        // Hangs from (-1.6, 2.2) and starts horizontal: 2.6 m long, swings down and drags over the floor.
        {"red rope",
         line({-1.6f, 2.2f, 0.3f}, {1.0f, 2.2f, 0.3f}, 48),
         0.5f,
         true,
         false,
         0.03f,
         {0.95f, 0.12f, 0.08f}},
        // Hangs from (1.8, 2.1) and starts horizontal toward -x: 2.2 m long, swings into the box.
        {"green rope",
         line({1.8f, 2.1f, -0.2f}, {-0.4f, 2.1f, -0.2f}, 40),
         0.4f,
         true,
         false,
         0.03f,
         {0.10f, 0.85f, 0.15f}},
        // A slack cable fixed at both ends, sagging just above the box (released from a shallower sag: it
        // swings).
        {"blue cable",
         sagging({-1.8f, 1.5f, -0.45f}, {1.8f, 1.5f, -0.45f}, 0.65f, 48),
         0.8f,
         true,
         true,
         0.035f,
         {0.10f, 0.30f, 1.00f}},
        // A free rope dropped across the box: drapes over its edge onto the floor.
        {"yellow rope",
         line({-0.6f, 1.1f, 0.05f}, {0.9f, 1.3f, 0.1f}, 30),
         0.3f,
         false,
         false,
         0.025f,
         {1.00f, 0.80f, 0.05f}},
    };
    for (std::size_t i = 0; i < specs.size(); ++i) {
        const Spec& s = specs[i];
        btSoftBody* body = make_rope(w.info, s.points, s.mass_kg, s.fix_first, s.fix_last);
        btSoftBody::Material* m = body->m_materials[0];
        m->m_kLST = 1.0f;                        // inextensible links
        body->generateBendingConstraints(2, m);  // a little bending stiffness
        body->m_cfg.piterations = 16;
        body->m_cfg.kDF = 0.6f;    // friction with rigid bodies
        body->m_cfg.kDP = 0.002f;  // damping
        body->m_cfg.kCHR = 1.0f;   // rigid contact hardness
        body->getCollisionShape()->setMargin(s.radius_m);
        w.world.addSoftBody(body);
        w.soft.emplace_back(body);

        Rope rope;
        rope.name = s.name;
        rope.body = body;
        rope.radius_m = s.radius_m;
        rope.material = static_cast<uint32_t>(i + 1);  // RopeView: material 0 is the renderer's default
        rope.colour = s.colour;
        // One wire entity per soft body; its nodes are replaced every frame (sync_wires).
        rope.wire = wire::systems::spawn_wire(registry_, wire_nodes(*body),
                                              {.radius_m = s.radius_m, .material = rope.material});
        ropes_.push_back(std::move(rope));
    }
}

RopeScene::~RopeScene() = default;

void RopeScene::step(double dt_s) {
    constexpr btScalar kFixedStep = 1.0f / 240.0f;
    const int max_steps = static_cast<int>(std::ceil(dt_s / kFixedStep)) + 1;
    world_->world.stepSimulation(static_cast<btScalar>(dt_s), max_steps, kFixedStep);
    world_->info.m_sparsesdf.GarbageCollect();
    time_s_ += dt_s;
    sync_wires();
}

void RopeScene::sync_wires() {
    if (stream_ == nullptr) {
        for (const Rope& rope : ropes_) wire::systems::set_nodes(registry_, rope.wire, wire_nodes(*rope.body));
        return;
    }
    std::size_t nodes = 0;
    for (const Rope& rope : ropes_) nodes += static_cast<std::size_t>(rope.body->m_nodes.size());
    if (engine::Status st = stream_->begin(nodes); !st) {
        std::fprintf(stderr, "bullet_ropes: %s\n", st.message.c_str());
        return;
    }
    for (const Rope& rope : ropes_) {
        // Bullet's node records in place: each node's m_x, sizeof(Node) bytes apart; ids are the indices.
        const btAlignedObjectArray<btSoftBody::Node>& n = rope.body->m_nodes;
        const btScalar* first = &n[0].m_x.x();
        const auto count = static_cast<std::size_t>(n.size());
        bool ok = false;
        if constexpr (sizeof(btScalar) == sizeof(float)) {
            ok = stream_->write(rope.stream, glm::dvec3(0.0), reinterpret_cast<const float*>(first), count,
                                sizeof(btSoftBody::Node));
        } else {
            ok = stream_->write(rope.stream, reinterpret_cast<const double*>(first), count, sizeof(btSoftBody::Node));
        }
        if (!ok) {
            for (const wire::render::StreamError& e : stream_->errors()) {
                if (e.wire == rope.stream) std::fprintf(stderr, "bullet_ropes: %s: %s\n", rope.name.c_str(), e.message.c_str());
            }
        }
    }
}

engine::Status RopeScene::stream_to(wire::render::NodeStream& stream) {
    if (engine::Status st = stream.usable(); !st) return st;
    for (Rope& rope : ropes_) {
        auto made = stream.add({.radius_m = rope.radius_m, .material = rope.material});
        if (!made) return engine::Status::error(rope.name + ": " + made.error().message);
        rope.stream = *made;
        if (registry_.valid(rope.wire)) registry_.destroy(rope.wire);
        rope.wire = engine::ecs::null_entity;
    }
    stream_ = &stream;
    sync_wires();
    return engine::Status::success();
}

engine::Expected<RopeView> RopeView::create(const RopeScene& scene) {
    RopeView view;
    auto lit = engine::gfx::LitRenderer::create();
    if (!lit) return lit.error();
    view.lit_ = std::move(*lit);
    auto floor = engine::gfx::upload_mesh(engine::gfx::make_plane_mesh(8.0f), "floor");
    if (!floor) return floor.error();
    view.floor_ = std::move(*floor);
    auto box = engine::gfx::upload_mesh(engine::gfx::make_box_mesh(scene.box().half_m), "box");
    if (!box) return box.error();
    view.box_ = std::move(*box);
    view.box_model_ = glm::translate(glm::mat4(1.0f), scene.box().centre_m);
    auto wires = wire::render::WireRenderer::create();
    if (!wires) return wires.error();
    view.wires_ = std::make_unique<wire::render::WireRenderer>(std::move(*wires));
    for (const Rope& rope : scene.ropes()) {
        while (view.wires_->materials().size() <= rope.material) view.wires_->add_material({});
        view.wires_->set_material(rope.material, {.tint = rope.colour});
    }
    return view;
}

void RopeView::draw(const RopeScene& scene, const wire::DrawList& list, const engine::scene::Camera& camera) {
    (void)scene;
    engine::gfx::clear(glm::vec4(kBackground, 1.0f));
    const engine::gfx::DirectionalLight light{.to_light = {0.4f, 1.0f, 0.6f}, .ambient = 0.35f};
    lit_.begin(camera.view_projection(), light);  // floor and box sit near the origin
    lit_.draw(floor_, glm::mat4(1.0f), kFloorAlbedo);
    lit_.draw(box_, box_model_, kBoxAlbedo);
    wires_->draw(list, camera, {.light = {.to_light = {0.4f, 1.0f, 0.6f}, .ambient = 0.35f}});
}

engine::scene::Camera default_camera(int width_px, int height_px) {
    return {
        .position = {0.3f, 2.3f, 4.2f},
        .target = {0.0f, 0.7f, -0.2f},
        .fov_y_rad = glm::radians(50.0f),
        .aspect = static_cast<float>(width_px) / static_cast<float>(height_px),
        .near_m = 0.1f,
        .far_m = 50.0f,
    };
}

}  // namespace bullet_ropes
