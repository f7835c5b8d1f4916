// Internal: the node stream's state (NodeStream's; the nodes path reads it at draw(): node_stream_emit.cpp).
#pragma once

#include "wire/render/node_stream.hpp"

#include "engine/gfx/stream_buffer.hpp"

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace wire::render::detail {

class NodePath;

/// The stream's wires and this frame's region (NodeStream's state; the nodes path reads it at draw()).
struct StreamState {
    /// Per wire, what a frame reads and writes (dense by StreamWire::index).
    struct Wire {
        uint32_t node_first = 0, count = 0;  ///< this frame's write: first node in the region, curve nodes (merged)
        uint32_t written = 0;                ///< frame of the last accepted write (0: none)
        uint32_t slot = UINT32_MAX, segment_first = 0, segments = 0;
        uint32_t sent_count = 0;             ///< curve nodes of the last upload the GPU got
        float origin[3] = {0, 0, 0};         ///< this write's origin (a float point)
        float centre[3] = {0, 0, 0};         ///< the last write's box centre as a float point (the next origin)
        uint32_t material = 0;               ///< StreamStyle::material (read by every frame's pass over the wires)
        bool has_centre = false, live = false, built = false, unmerged = false, sent_unmerged = false;
    };
    static_assert(sizeof(Wire) <= 64, "a wire's per-frame record in one cache line");
    std::vector<Wire> wires;
    std::vector<StreamStyle> styles;
    std::vector<uint32_t> free;
    std::size_t live = 0;

    engine::gfx::StreamBuffer buffer;
    bool buffer_made = false;
    engine::gfx::StreamRegion region{};
    bool active = false;      ///< begin() was called and the frame not drawn yet
    uint32_t frame = 0;       ///< begin() count (Wire::written compares to it)
    std::size_t header_capacity = 0, node_capacity = 0, header_at = 0, node_at = 0;
    std::atomic<std::size_t> cursor{0};  ///< nodes used of the region's room
    std::size_t headers = 0;             ///< headers emitted this frame
    /// Wires written this frame that need a slot or another segment count (the draw allocates them serially).
    std::vector<uint32_t> pending;
    std::mutex pending_mutex;
    void accepted(Wire& w, uint32_t index) {
        w.written = frame;
        const uint32_t segments = styles[index].closed ? w.count : w.count - 1;
        if (w.slot != UINT32_MAX && segments == w.segments) return;
        std::lock_guard lock(pending_mutex);
        pending.push_back(index);
    }

    mutable std::mutex error_mutex;
    std::vector<StreamError> errors;

    NodePath* path = nullptr;  ///< the renderer's nodes path (null: not made)
    Status unusable = Status::error("the node stream is not attached to a renderer (WireRenderer::node_stream())");

    void refuse(uint32_t wire, int node, std::string message) {
        std::lock_guard lock(error_mutex);
        errors.push_back({StreamWire{wire}, node, "stream wire " + std::to_string(wire) + ": " + std::move(message)});
    }
};

}  // namespace wire::render::detail
