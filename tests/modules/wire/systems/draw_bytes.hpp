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
    // The nodes path's: the packed nodes as the GPU gets them, a blend's curve, the motion, the generation.
    if (it.packed_nodes != nullptr) {
        const PackedNodes& p = *it.packed_nodes;
        put(&p.origin_m, sizeof(p.origin_m));
        put(p.records.data(), p.records.size() * sizeof(p.records[0]));
        put(p.extras.data(), p.extras.size() * sizeof(p.extras[0]));
        put(&p.node_count, sizeof(p.node_count));
        put(&p.quantised, sizeof(p.quantised));
        put(&p.quantum_exp, sizeof(p.quantum_exp));
    }
    if (it.curve != nullptr) put(it.curve->segments.data(), it.curve->segments.size() * sizeof(it.curve->segments[0]));
    put(&it.motion, sizeof(it.motion));
    put(&it.fit_motion, sizeof(it.fit_motion));
    put(&it.nodes_generation, sizeof(it.nodes_generation));
}

}  // namespace wire::systems::test
