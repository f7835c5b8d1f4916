// Test helper: the bytes of what a draw item carries (spans by content), to compare draw lists exactly.
#pragma once

#include "wire/draw.hpp"

#include <cstddef>
#include <vector>

namespace wire::systems::test {

/// Appends everything `it` carries to `out`; its entity (wire_id) only with `with_id`.
inline void append_item_bytes(const DrawItem& it, bool with_id, std::vector<unsigned char>& out) {
    auto put = [&](const void* p, std::size_t n) {
        const auto* b = static_cast<const unsigned char*>(p);
        out.insert(out.end(), b, b + n);
    };
    put(&it.origin_m, sizeof(it.origin_m));
    put(&it.material, sizeof(it.material));
    if (with_id) put(&it.wire_id, sizeof(it.wire_id));
    put(it.vertices.data(), it.vertices.size_bytes());
    put(it.indices.data(), it.indices.size_bytes());
    put(it.rings.data(), it.rings.size_bytes());
    put(&it.sides, sizeof(it.sides));
    put(&it.closed, sizeof(it.closed));
    put(&it.caps, sizeof(it.caps));
    put(&it.u_close, sizeof(it.u_close));
}

}  // namespace wire::systems::test
