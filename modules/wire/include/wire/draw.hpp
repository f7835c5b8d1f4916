// The interface between the wire systems (CPU: which wires, what geometry) and the wire renderer (GL: upload
// and draw): one DrawItem per visible wire per frame. Plain data; the arrays are owned by the systems and
// stay valid until the next frame's systems run.
#pragma once

#include "wire/lod.hpp"
#include "wire/nodes.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/rings.hpp"
#include "wire/spline.hpp"
#include "wire/tube.hpp"

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace wire {

/// How wire geometry reaches the GPU.
enum class UploadPath : uint8_t {
    cpu_mesh,  ///< vertices + indices built on the CPU (TubeVertex, 32 bytes a vertex): the portable reference
    /// nodes only: the nodes of wires whose nodes changed (8 bytes a node plus 8 where the wire's nodes are
    /// quantised, else 16; packed_nodes.hpp) plus a 64-byte header, and 4 bytes a visible wire; curve, LOD (below
    /// the node resolution too), frames, rings and the draw's arguments are
    /// computed on the GPU (wire/render's nodes path), the ring vertex shader draws them
    gpu_nodes,
};

/// The name of an upload path on command lines, in Python and in reports: "cpu" (cpu_mesh), "nodes" (gpu_nodes).
[[nodiscard]] constexpr std::string_view upload_path_name(UploadPath path) {
    switch (path) {
        case UploadPath::cpu_mesh: return "cpu";
        case UploadPath::gpu_nodes: return "nodes";
    }
    return "?";
}
/// The one-line notice a front end prints when `name` is a retired path's name ("gpu": the ring records the CPU
/// built, retired in 0.4, drawn on the nodes path until the name goes in 0.5); empty for any other name.
[[nodiscard]] constexpr std::string_view retired_path_note(std::string_view name) {
    return name == "gpu" ? "upload path 'gpu' (ring records built on the CPU) was retired in 0.4: drawing on 'nodes' "
                           "(the name goes in 0.5)"
                         : "";
}
/// The path named `name` (upload_path_name's names; "gpu", retired, names gpu_nodes: see retired_path_note);
/// nullopt for any other name.
[[nodiscard]] constexpr std::optional<UploadPath> parse_upload_path(std::string_view name) {
    if (name == "gpu") return UploadPath::gpu_nodes;
    for (UploadPath p : {UploadPath::cpu_mesh, UploadPath::gpu_nodes}) {
        if (upload_path_name(p) == name) return p;
    }
    return std::nullopt;
}

/// One visible wire this frame. Positions inside are relative to origin_m (double, world), so the renderer can
/// draw camera-relative: offset = origin_m - camera position, computed in double, sent as float.
struct DrawItem {
    glm::dvec3 origin_m{};   ///< world position the item's geometry is relative to
    uint32_t material = 0;   ///< index into the renderer's material table (texture, colour)
    uint64_t wire_id = 0;    ///< the wire's entity (unique while it lives; the nodes path's slot key)

    // cpu_mesh path
    std::span<const TubeVertex> vertices;  ///< tube vertices (cpu_mesh path)
    std::span<const uint32_t> indices;  ///< relative to this item's first vertex

    /// cpu_mesh: the rings the mesh was built from (not read by the renderer; checks and tools read them)
    std::span<const Ring> rings;
    // gpu_nodes path
    const WireNodes* nodes = nullptr;  ///< validated nodes (the systems' checks); alive until the draw returns
    /// `nodes` packed for the GPU (wire::pack_nodes, done by the systems on their worker threads); when set, the
    /// renderer copies it and does not read `nodes`.
    const PackedNodes* packed_nodes = nullptr;
    /// Instead of `nodes`: the curve itself (a wire in a pop-free blend draws the blended curve), sent as its
    /// segments (64 bytes each) while it blends.
    const Curve* curve = nullptr;
    SplineSettings spline{};           ///< the curve's settings (kind, closed, radius, ...)
    /// Changes whenever `nodes` or `spline` change; the renderer keeps the wire's curve on the GPU while
    /// (wire_id, nodes_generation) stays the same. 0: unknown (the nodes are sent every frame).
    uint64_t nodes_generation = 0;
    /// How the wire moved since the nodes the renderer last got for it: the vector part of wire::carried_rotation
    /// (motion.hpp), which turns the first frame kept on the GPU as the CPU path's carried_frames turns its own.
    /// Zero: none known (the first frame is the last one projected onto the new first tangent).
    glm::vec3 motion{};
    /// Instead of `motion`: the GPU fits it against the nodes it got last for this wire, by index (wire::
    /// samples_match says when that equals fit_motion's match by id; the nodes must be packed without merging).
    bool fit_motion = false;

    uint32_t sides = 8;      ///< radial sides of a tube (>= 3); 2 = camera-facing strip, 1 = one-pixel AA line
    bool closed = false;     ///< closed loop (the last ring connects back to the first)
    bool caps = true;        ///< flat end caps on open wires
    float u_close = 0.0f;    ///< closed wires: u where the loop returns to ring 0 (RingSet::u.back())
};

/// Everything the renderer needs for one frame.
struct DrawList {
    UploadPath path = UploadPath::cpu_mesh;  ///< which of the item's arrays are filled
    std::vector<DrawItem> items;             ///< the visible wires, in entity order
    /// The LOD the systems evaluated this frame (wire::systems::WireContext::lod, set by the draw-list stage): the
    /// nodes path evaluates the same settings on the GPU, so no setting is copied by hand.
    LodSettings lod{};
};

}  // namespace wire
