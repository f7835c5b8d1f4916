// Components of a wire entity. The game writes Nodes and Style (through the api.hpp calls, which stamp them
// as changed); the wire systems own everything else and keep it between frames.
#pragma once

#include "wire/curve.hpp"
#include "wire/lod.hpp"
#include "wire/motion.hpp"
#include "wire/pop_free.hpp"
#include "wire/nodes.hpp"
#include "wire/packed_nodes.hpp"
#include "wire/rings.hpp"
#include "wire/tube.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace wire::systems {

/// The wire's lumped-element nodes (wire::WireNodes: positions, stable ids, stretch, optional radius and physics
/// arrays). Written by the game or the physics; every write must stamp it (set_nodes / edit_nodes / patch).
struct Nodes : WireNodes {};

/// How the wire looks. Zero means default.
struct Style {
    float radius_m = kDefaultWireRadius_m;  ///< tube radius where a node's radius is 0; 0 -> 1 cm
    uint32_t max_sides = 0;       ///< upper clamp of the LOD's radial sides; 0 -> 16
    SplineSettings spline{.kind = SplineKind::automatic};  ///< curve settings (default: automatic, the best measured;
                                                           ///< spline.closed and spline.radius_m come from this Style)
    uint32_t material = 0;        ///< renderer material index
    bool caps = true;             ///< flat end caps on open wires
    bool closed = false;          ///< closed loop
    float blend_s = 0.0f;         ///< pop-free blend length for small changes, seconds (pop_free.hpp); 0 -> 0.25 s
};

// ---- derived state, owned by the systems (read them, do not write them) ----

/// Curve stage: the rendered curve (pop-free: blended while nodes appear or vanish) and its change counter.
///
/// Released while culled and moving: a wire the LOD stage culls in a frame its curve changed (it moves), that is
/// on the fast path (pop_free_stale) and not blending, releases `curve` (`released` set; `bounds` and
/// `previous_nodes` stay): its next change rebuilds the curve anyway. The LOD stage rebuilds a released curve
/// from `previous_nodes` (bit for bit the released one) as soon as `bounds` is not outside the view, before it
/// decides the wire, so the wire comes back as if it had never been released (generation advances, so rings and
/// mesh are rebuilt); the curve stage rebuilds it likewise when the current nodes are invalid (the wire keeps its
/// last valid curve). Readers of `curve` (tools, tests) see an empty curve only for a culled wire.
struct WireCurve {
    // Field order: what the curve stage reads and writes for every moving wire every frame (curve, settings,
    // counters, flags, bounds, previous_nodes) is contiguous, and what the LOD stage reads of a moving wire
    // (lod_bounds.data, its last member, to curve, flags and bounds) lies within it: ~9 contiguous cache lines a
    // wire for both stages instead of ~11 scattered over 1.2 KB. The pop-free state, which the fast path leaves
    // alone, comes last.
    /// The LOD's per-wire bound and spans of `curve` (lod.hpp), kept only by a visible wire whose curve did not
    /// change since its last LOD update (a static wire that sees the camera move: WireLod::Coherence reuses them
    /// while their version stands). A wire whose curve changed this frame gets them in per-thread scratch of the
    /// LOD stage and keeps none; a wire whose sphere is outside the view needs none; a culled wire releases them.
    LodBounds lod_bounds{};
    Curve curve;                       ///< what is drawn; empty until the nodes were valid once, or released
    SplineSettings spline{};           ///< settings the pop-free state was made with (a change resets it)
    uint64_t generation = 0;           ///< +1 each time `curve` changes (or is rebuilt after a release)
    uint64_t builds = 0;               ///< times the curve was built for this wire (test/statistics counter)
    bool released = false;             ///< `curve` is released (culled and moving, see above)
    bool blending = false;             ///< a blend is in progress: the curve changes next frame too
    bool pop_free_on = true;           ///< WireContext::pop_free the pop-free state was made with
    bool pop_free_stale = false;       ///< `pop-free blend` lags behind `curve` (the fast path ran); released while it does
    float blend_s = 0.0f;              ///< Style::blend_s the pop-free state was made with
    BoundingSphere bounds{};           ///< of `curve`, recomputed with it (the LOD's O(1) off-screen test); kept
                                       ///< while released
    uint64_t bounds_generation = 0;    ///< `generation` whose curve `bounds` was computed from (0: none known; a
                                       ///< failed update may rewrite `curve`): then the LOD stage takes `bounds`
                                       ///< as the LodBounds' sphere instead of computing it again
    uint64_t lod_bounds_generation = 0;  ///< `generation` lod_bounds were computed for (0: none kept)
    // Fast path: while no node id appears or vanishes and nothing blends, the pop-free state would only show the
    // exact curve, so build_curve runs alone (5x cheaper) and the pop-free state is re-primed from
    // `previous_nodes` (the last valid state) when the ids change. While stale the pop-free state is released
    // (re-priming rebuilds it from previous_nodes anyway); build_curve's output buffer is per thread, not per wire.
    WireNodes previous_nodes;          ///< the last valid nodes (re-primes `pop-free blend` when ids change)
    /// UploadPath::gpu_nodes: the last valid nodes packed for the GPU (wire::pack_nodes, on the curve stage's
    /// worker threads; the renderer only copies them). Empty on the other paths.
    PackedNodes packed;
    PopFreeCurve pop_free{PopFreeSettings{}};  ///< pop-free state: blends nodes in and out over frames
};

/// LOD stage: visibility, per-segment ring counts and sides for the context's camera.
struct WireLodState {
    WireLod lod;                       ///< visibility, per-segment ring counts and sides
    uint64_t generation = 0;           ///< +1 each time counts or visibility change
    uint64_t seen_curve = 0;           ///< WireCurve::generation the LOD was computed for
    uint64_t seen_view = 0;            ///< WireContext view generation the LOD was computed for
    uint64_t updates = 0;              ///< times update_lod ran for this wire
};

/// Ring stage: ring records along the wire (cpu_mesh: the mesh stage builds the tube from them).
/// Kept per wire: `params` and the float records `rings.rings`, plus rings.origin_m, rings.closed, rings.length_m,
/// fold counts and frame stats, and ring 0's frame (`rings.frames` has one entry: carried over to the next state).
/// The double per-ring arrays build_rings produces (frames, centres, arc length, u, tangents, its params copy)
/// are per-thread scratch, not kept: every rebuild recomputes them. `u_close` is the closed loop's u at the join.
/// A culled wire whose curve changed since its rings were built releases rings and params (the next visible
/// frame rebuilds them anyway); a culled wire that did not change keeps them (turning back to it rebuilds nothing).
struct WireRings {
    std::vector<RingParam> params;     ///< where the rings sit on the curve (segment, t)
    RingSet rings;                     ///< float ring records, ring 0's frame and the scalars (see above)
    float u_close = 0.0f;              ///< closed wires: texture u where the loop closes (0 for open wires)
    FrameSettings frame_settings{};    ///< what the last build seeded its first normal with (wire_ring_set redoes it)
    /// The nodes ring 0's frame was built from: their motion carries it on. UploadPath::gpu_nodes: the nodes the
    /// renderer was last given for this wire (motion_samples: the rotation from them to the next ones turns the
    /// first frame the GPU kept, DrawItem::motion / fit_motion), WireCurve::generation `sent_curve`, and whether
    /// they went as packed nodes none of which were merged (the GPU then fits the next motion itself).
    MotionReference motion{};
    uint64_t sent_curve = 0;
    bool sent_unmerged = false;
    uint64_t generation = 0;           ///< +1 each time the rings are rebuilt
    uint64_t seen_curve = 0;           ///< WireCurve::generation the rings were built from
    uint64_t seen_lod = 0;             ///< WireLodState::generation the rings were built from
};

/// Mesh stage (cpu_mesh path only): the tube's vertices and indices.
struct WireMesh {
    TubeMesh mesh;                     ///< vertices (TubeVertex) and triangle indices
    uint64_t generation = 0;           ///< +1 each time the mesh is rebuilt
    uint64_t seen_rings = 0;           ///< WireRings::generation the mesh was built from
    uint32_t sides = 0;                ///< radial sides the mesh was built with
    bool caps = true;                  ///< the mesh has end caps
};

/// A wire whose nodes are invalid (NaN, fewer than 2 distinct nodes, ...): the message names the entity and the
/// input node, e.g. "wire entity 12 (index 12, version 0): node 3: position.y is NaN". Reported once (in
/// WireContext::new_errors and through WireContext::on_error) when it appears or its message changes; removed
/// when the nodes become valid again. While it is present the wire keeps drawing its last valid curve, if any.
struct WireError {
    std::string message;               ///< names the entity, the node and the problem
    int node = -1;                     ///< offending input node, -1 if no single node
};

}  // namespace wire::systems
