// The wire module's result type is the runtime's one: engine::Status (engine/core/status.hpp). A failure's
// `index` is the offending INPUT node (-1 when no single node is to blame), its message e.g. "node 7: position.y
// is NaN". Functions returning Status never throw on bad input and never write NaN into their outputs.
#pragma once

#include "engine/core/status.hpp"

namespace wire {
using engine::Status;
}  // namespace wire
