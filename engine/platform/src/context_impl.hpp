// Internal helpers shared by the context implementations.
#pragma once

#include "engine/platform/context.hpp"

namespace engine::platform {

inline ContextDesc with_defaults(ContextDesc desc) {
    if (desc.width <= 0) desc.width = 1280;
    if (desc.height <= 0) desc.height = 720;
    if (desc.title.empty()) desc.title = "wires";
    return desc;
}

}  // namespace engine::platform
