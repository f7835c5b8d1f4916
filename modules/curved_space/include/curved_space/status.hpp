// The curved-space module's result type is the runtime's one: engine::Status (engine/core/status.hpp). A
// failure's `index` is the offending input segment (-1 when no single segment is to blame), its message e.g.
// "segment 3: length must be positive, got -1".
#pragma once

#include "engine/core/status.hpp"

namespace curved_space {
using engine::Status;
}  // namespace curved_space
