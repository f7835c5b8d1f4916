// The bulk node stream (nodes path): a physics engine (or numpy) writes many wires' nodes for a frame straight into
// the memory the renderer uploads from, one pass over each node: read from the caller's array, checked (finite, in
// range, radius), offset from the wire's origin, written as the GPU reads it (16 bytes a node) into the fenced,
// persistently mapped region, with the box the merge rule needs measured on the way. No per-wire heap allocation,
// no second copy: the curve, LOD, frames and rings are computed on the GPU as for every nodes-path wire.
//
// Streamed wires are the renderer's, not ECS entities: they have a StreamStyle instead of a Style and live until
// removed. Per frame, on the render thread: begin(nodes) maps room for that many nodes; write()/write_many() from
// any threads (different wires; write_many uses worker threads itself); then WireRenderer::draw() (a DrawList on
// the nodes path, possibly empty) draws the streamed wires with the list's, in one set of dispatches and draws. A
// wire not written in a frame keeps drawing its last curve (its state stays on the GPU); a wire whose nodes are bad
// (NaN, out of range, too few distinct nodes) keeps its last curve too, and errors() says why with the messages the
// ECS path gives ("stream wire 3: node 5: position.y is NaN"). The check costs nothing extra: it runs in the
// copying pass, and only a wire that fails it (or has nodes closer than the merge tolerance) is read a second time,
// to find the message or merge as build_curve does (wire::pack_nodes).
//
// Motion: the first frame of a wire whose node count is unchanged and that merged nothing is carried by its motion,
// fitted on the GPU by index (as for ECS wires matched by index). Not carried by the stream: node ids (the pop-free
// blend of nodes inserted or removed), stretch and per-node spline values; a wire that needs them is an ECS wire
// (wire::systems set_nodes / edit_nodes), drawn by the same draw() beside the streamed ones.
#pragma once

#include "wire/nodes.hpp"
#include "wire/spline.hpp"

#include "engine/core/expected.hpp"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace wire::render {

using engine::Error;
using engine::Expected;
using engine::Status;

namespace detail {
class NodePath;
struct StreamState;
}  // namespace detail

/// How a streamed wire looks (wire::systems::Style's fields that the nodes path reads). Zero means default.
struct StreamStyle {
    float radius_m = kDefaultWireRadius_m;  ///< tube radius where a node's radius is 0 (or not given); 0 -> 1 cm
    uint32_t material = 0;                  ///< the renderer's material index
    uint32_t max_sides = 0;                 ///< the LOD's most radial sides for this wire; 0 -> 16
    SplineKind kind = SplineKind::automatic;  ///< linear, catmull_rom, c2 or automatic (the GPU builds these)
    double alpha = 0.5;                     ///< Catmull-Rom: knot exponent (0.5 centripetal)
    double tension = 0.0, bias = 0.0, continuity = 0.0;  ///< Kochanek-Bartels, wire-wide
    bool closed = false;                    ///< closed loop
    bool caps = true;                       ///< flat end caps on open wires
};

/// A streamed wire (an index, reused after remove()).
struct StreamWire {
    uint32_t index = UINT32_MAX;
    friend bool operator==(StreamWire, StreamWire) = default;
};

/// A write whose nodes were refused: the wire keeps drawing its last curve.
struct StreamError {
    StreamWire wire;
    int node = -1;        ///< the offending input node, -1 if no single node
    std::string message;  ///< "stream wire 3: node 5: position.y is NaN"
};

class NodeStream {
public:
    NodeStream();
    ~NodeStream();
    NodeStream(const NodeStream&) = delete;
    NodeStream& operator=(const NodeStream&) = delete;

    /// A new wire (no nodes yet: drawn from its first valid write). Errors name the bad style value.
    Expected<StreamWire> add(const StreamStyle& style = {});
    /// Takes effect at its next write. False for a wire that is not live or a bad style.
    Status set_style(StreamWire wire, const StreamStyle& style);
    /// Frees the wire's GPU state; its index may be reused by add().
    void remove(StreamWire wire);
    [[nodiscard]] bool live(StreamWire wire) const;
    [[nodiscard]] std::size_t size() const;  ///< live wires
    /// The DrawnRings::wire_id the renderer reports for a streamed wire (the top bit set: never an entity's).
    [[nodiscard]] static uint64_t wire_id(StreamWire wire) { return (uint64_t{1} << 63) | wire.index; }

    /// Starts a frame on the render thread (GL current): room for `nodes` nodes (the sum of this frame's writes'
    /// counts) in the renderer's mapped memory. Clears errors(). A frame begun and not drawn is dropped by the next
    /// begin() (its wires keep their last curves).
    Status begin(std::size_t nodes);
    /// Wire `wire`'s nodes this frame: world positions in double, `stride` bytes apart (24 for glm::dvec3; a
    /// physics engine's node records work in place); `radius` (optional, `radius_stride` bytes apart) each node's
    /// radius, 0 for the wire's. True when written; false when refused (errors() says why) or out of room.
    bool write(StreamWire wire, const double* xyz, std::size_t count, std::size_t stride = 24,
               const float* radius = nullptr, std::size_t radius_stride = 4);
    /// Wire `wire`'s nodes as float offsets from `origin_m` (world, double), `stride` bytes apart (12 for
    /// glm::vec3, 16 for vec4): what a float physics engine holds.
    bool write(StreamWire wire, const glm::dvec3& origin_m, const float* xyz, std::size_t count,
               std::size_t stride = 12, const float* radius = nullptr, std::size_t radius_stride = 4);
    /// Many wires of `count` nodes each in one call, on worker threads: wire k's node j at
    /// xyz[3 * (k * count + j)] (a numpy array of shape (wires, count, 3)). Returns the wires written.
    std::size_t write_many(std::span<const StreamWire> wires, const double* xyz, std::size_t count);
    /// As above with float offsets, wire k's from origins_m[k].
    std::size_t write_many(std::span<const StreamWire> wires, std::span<const glm::dvec3> origins_m, const float* xyz,
                           std::size_t count);

    /// This frame's refused writes, in no particular order.
    [[nodiscard]] std::vector<StreamError> errors() const;
    /// Nodes this frame's writes used of begin()'s room; bytes they wrote into mapped memory (16 a node).
    [[nodiscard]] std::size_t nodes_written() const;
    /// Memory the stream holds: its per-wire records on the CPU (capacity), and the mapped regions (one per frame
    /// in flight, sized by the largest begin()).
    [[nodiscard]] std::size_t state_bytes() const;
    [[nodiscard]] std::size_t mapped_bytes() const;
    /// Whether the renderer could make the nodes path (begin() fails with its reason otherwise).
    [[nodiscard]] Status usable() const;

    /// Internal (the renderer's): the stream's state, which its nodes path reads.
    detail::StreamState& state() { return *state_; }

private:
    std::unique_ptr<detail::StreamState> state_;
};

}  // namespace wire::render
