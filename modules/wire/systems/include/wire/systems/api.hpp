// Game-side API of wire entities: spawn, update, inspect. Destroy with registry.destroy(entity): every wire
// component lives on the entity, so nothing else holds on to it.
//
// \code
//   engine::ecs::Entity w = wire::systems::spawn_wire(registry, nodes, {.radius_m = 0.02f});
//   wire::systems::set_nodes(registry, w, moved_nodes);    // or edit_nodes(registry, w).positions[3] = p;
//   wire::systems::insert_node(registry, w, 4, midpoint);  // a new node with a fresh stable id
//   registry.destroy(w);
// \endcode
#pragma once

#include "wire/systems/components.hpp"

#include <engine/ecs/registry.hpp>

#include <string>

/// The wire module's ECS side: wire entities (Nodes + Style and the derived components), the game-side API
/// that spawns and updates them, and the systems that turn them into a DrawList every frame (install()).
namespace wire::systems {

/// A new wire entity with `nodes` and `style`, plus the systems' derived components (empty until the systems
/// run). Invalid nodes are not an error here: the curve system reports them (WireError) and skips the wire.
engine::ecs::Entity spawn_wire(engine::ecs::Registry& registry, WireNodes nodes, const Style& style = {});

/// Replaces the wire's nodes and marks them changed. Asserts (ECS) that `wire` is a live wire entity.
void set_nodes(engine::ecs::Registry& registry, engine::ecs::Entity wire, WireNodes nodes);

/// The wire's nodes for writing in place, marked changed (the stamp is taken now: write before the systems run).
[[nodiscard]] WireNodes& edit_nodes(engine::ecs::Registry& registry, engine::ecs::Entity wire);

/// Replaces the style and marks it changed (the curve is rebuilt; a spline change restarts the blend state).
void set_style(engine::ecs::Registry& registry, engine::ecs::Entity wire, const Style& style);

/// Inserts a node before index `at` (at == size(): appends) with a new stable id (max id + 1; ids are made explicit
/// first if they were implicit), keeping every optional per-node array as long as positions (new entries copy the
/// neighbour's value). Returns the new id. The pop-free curve stage blends the change in.
uint32_t insert_node(engine::ecs::Registry& registry, engine::ecs::Entity wire, std::size_t at,
                     const glm::dvec3& position_m);

/// Removes node `at` (< size()) and its entries in every optional array; ids of the others are kept.
void remove_node(engine::ecs::Registry& registry, engine::ecs::Entity wire, std::size_t at);

/// The wire's error, or nullptr if its nodes are valid (or it is not a wire).
[[nodiscard]] const WireError* wire_error(const engine::ecs::Registry& registry, engine::ecs::Entity wire);

/// "wire entity 12 (index 12, version 0)": how messages name a wire.
[[nodiscard]] std::string describe_entity(engine::ecs::Entity wire);

}  // namespace wire::systems
