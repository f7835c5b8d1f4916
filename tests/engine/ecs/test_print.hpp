// Test helper: lets GoogleTest print entity handles as index:version instead of raw bytes.
#pragma once

#include <engine/ecs/entity.hpp>

#include <ostream>

namespace engine::ecs {
inline void PrintTo(Entity e, std::ostream* os) {
    *os << to_index(e) << ':' << to_version(e);
}
}  // namespace engine::ecs
