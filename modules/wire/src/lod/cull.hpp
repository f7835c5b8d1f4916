// Internal: the LOD state of a culled wire.
#pragma once

#include "wire/lod.hpp"

namespace wire::lod_stage {

// Empties `lod` as a culled wire's; changed: whether it held a visible wire's state.
void mark_culled(WireLod& lod, bool& changed);

}  // namespace wire::lod_stage
