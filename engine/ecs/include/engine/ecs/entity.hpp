// Entity handles: 32-bit generational ids, 20 bits of slot index and 12 bits of version.
// A destroyed entity's slot is reused with a higher version, so an old handle to it is detected as stale.
#pragma once

#include <cstdint>

/// Entity-component-system core: entities, sparse-set storages, views, change tracking, schedule.
namespace engine::ecs {

/// An entity handle. Value layout: (version << 20) | index. Compare with ==; null_entity is never alive.
enum class Entity : std::uint32_t {};

inline constexpr std::uint32_t entity_index_bits = 20;  ///< bits of the slot index in a handle
inline constexpr std::uint32_t entity_index_mask = (1u << entity_index_bits) - 1u;  ///< also the null index
inline constexpr std::uint32_t entity_version_mask = 0xFFFu;                        ///< 12 bits
/// Largest number of entity slots a registry can hand out (index 0xFFFFF is reserved for null).
inline constexpr std::uint32_t max_entities = entity_index_mask;

/// The "no entity" handle: index 0xFFFFF, version 0xFFF. valid(null_entity) is always false.
inline constexpr Entity null_entity{0xFFFFFFFFu};

/// The handle's 32-bit value.
[[nodiscard]] constexpr std::uint32_t to_integral(Entity e) noexcept {
    return static_cast<std::uint32_t>(e);
}
/// The slot index of a handle, in [0, max_entities] (max_entities only for null_entity).
[[nodiscard]] constexpr std::uint32_t to_index(Entity e) noexcept {
    return to_integral(e) & entity_index_mask;
}
/// The version (generation) of a handle, in [0, 4095].
[[nodiscard]] constexpr std::uint32_t to_version(Entity e) noexcept {
    return to_integral(e) >> entity_index_bits;
}
/// Builds a handle from an index (< 2^20) and a version (< 2^12); extra bits are masked off.
[[nodiscard]] constexpr Entity make_entity(std::uint32_t index, std::uint32_t version) noexcept {
    return Entity{((version & entity_version_mask) << entity_index_bits) | (index & entity_index_mask)};
}

}  // namespace engine::ecs
