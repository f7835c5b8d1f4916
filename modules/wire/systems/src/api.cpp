// Game-side API of wire entities: spawn, set/edit nodes, insert/remove a node, style, errors.
#include "wire/systems/api.hpp"

#include <algorithm>
#include <cassert>
#include <string_view>
#include <utility>

namespace wire::systems {
namespace {

using engine::ecs::Entity;
using engine::ecs::Registry;

// Inserts a copy of the neighbouring entry at `at` into an optional per-node array (empty arrays stay empty).
// An array of the wrong length (a caller error the curve system reports) stays wrong by as much, never written
// past its end.
template <class T>
void insert_like_neighbour(std::vector<T>& v, std::size_t at) {
    if (v.empty()) return;
    at = std::min(at, v.size());
    const std::size_t from = at < v.size() ? at : v.size() - 1;
    const T value = v[from];
    v.insert(v.begin() + static_cast<std::ptrdiff_t>(at), value);
}

template <class T>
void erase_at(std::vector<T>& v, std::size_t at) {
    if (at < v.size()) v.erase(v.begin() + static_cast<std::ptrdiff_t>(at));
}

}  // namespace

Entity spawn_wire(Registry& registry, WireNodes nodes, const Style& style) {
    const Entity e = registry.create();
    registry.emplace<Nodes>(e, std::move(nodes));
    registry.emplace<Style>(e, style);
    registry.emplace<WireCurve>(e);
    registry.emplace<WireLodState>(e);
    registry.emplace<WireRings>(e);
    registry.emplace<WireMesh>(e);
    return e;
}

void set_nodes(Registry& registry, Entity wire, WireNodes nodes) {
    static_cast<WireNodes&>(registry.patch<Nodes>(wire)) = std::move(nodes);
}

WireNodes& edit_nodes(Registry& registry, Entity wire) { return registry.patch<Nodes>(wire); }

void set_style(Registry& registry, Entity wire, const Style& style) { registry.replace<Style>(wire, style); }

uint32_t insert_node(Registry& registry, Entity wire, std::size_t at, const glm::dvec3& position_m) {
    WireNodes& n = registry.patch<Nodes>(wire);
    const std::size_t size = n.positions.size();
    assert(at <= size && "insert_node: index past the end");
    at = std::min(at, size);
    if (n.ids.size() != size) {
        n.ids.resize(size);
        for (std::size_t i = 0; i < size; ++i) n.ids[i] = static_cast<uint32_t>(i);
    }
    uint32_t id = 0;
    for (const uint32_t existing : n.ids) id = std::max(id, existing + 1);
    n.positions.insert(n.positions.begin() + static_cast<std::ptrdiff_t>(at), position_m);
    for_each_node_array([&](std::string_view name, auto member) {
        if (name != "ids") insert_like_neighbour(n.*member, at);  // the others take their neighbour's value
    });
    n.ids.insert(n.ids.begin() + static_cast<std::ptrdiff_t>(at), id);
    return id;
}

void remove_node(Registry& registry, Entity wire, std::size_t at) {
    WireNodes& n = registry.patch<Nodes>(wire);
    assert(at < n.positions.size() && "remove_node: index past the end");
    if (at >= n.positions.size()) return;
    if (n.ids.size() != n.positions.size()) {
        // Implicit ids (= index) would renumber every later node: make them explicit first.
        n.ids.resize(n.positions.size());
        for (std::size_t i = 0; i < n.ids.size(); ++i) n.ids[i] = static_cast<uint32_t>(i);
    }
    erase_at(n.positions, at);
    for_each_node_array([&](std::string_view, auto member) { erase_at(n.*member, at); });
}

const WireError* wire_error(const Registry& registry, Entity wire) { return registry.try_get<WireError>(wire); }

std::string describe_entity(Entity wire) {
    return "wire entity " + std::to_string(engine::ecs::to_integral(wire)) + " (index " +
           std::to_string(engine::ecs::to_index(wire)) + ", version " + std::to_string(engine::ecs::to_version(wire)) +
           ")";
}

}  // namespace wire::systems
