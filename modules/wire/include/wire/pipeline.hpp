// One wire's stages driven without the ECS, for offline use (wiretool mesh, the tests' reference): fixed or
// tolerance tessellation instead of the screen-space LOD, and the state one wire keeps between successive states
// (the pop-free blend, the first frame carried by the wire's motion). Every step is a wire-core function that the
// ECS systems (modules/wire/systems) call too: PopFreeCurve::update, segment_ring_counts / the LOD, place_rings,
// carried_frames, build_rings, build_tube; the systems add the per-frame scheduling, change tracking and caching.
#pragma once

#include "wire/curve.hpp"
#include "wire/motion.hpp"
#include "wire/pop_free.hpp"
#include "wire/nodes.hpp"
#include "wire/rings.hpp"
#include "wire/status.hpp"
#include "wire/tessellate.hpp"
#include "wire/tube.hpp"

#include <vector>

namespace wire {

/// Settings of every stage; zero/default-initialized is sensible (see each struct).
struct PipelineSettings {
    SplineSettings spline{};
    TessellateSettings tessellate{};
    TubeSettings tube{};
    FrameMethod frame_method = FrameMethod::double_reflection;
    bool pop_free = true;  ///< blend (PopFreeCurve) when node ids appear or vanish between states
    PopFreeSettings blend{};  ///< blend length and per-frame step bound; its `spline` is taken from `spline`
};

/// Stateful per wire: call update() with each new state of the wire's nodes, in order.
class WirePipeline {
public:
    /// Builds curve, rings and mesh for this state. On bad input returns the curve stage's Status (naming
    /// the input node) and keeps the previous outputs and state untouched.
    [[nodiscard]] Status update(const WireNodes& nodes, const PipelineSettings& settings);

    [[nodiscard]] const Curve& curve() const { return rendered_; }
    [[nodiscard]] const PopFreeCurve& pop_free() const { return pop_free_curve_; }
    [[nodiscard]] const RingSet& rings() const { return rings_; }
    [[nodiscard]] const TubeMesh& mesh() const { return mesh_; }
    [[nodiscard]] std::size_t states() const { return states_; }

private:
    PopFreeCurve pop_free_curve_;
    SplineSettings pop_free_spline_{};  ///< the spline settings pop_free_curve_ was made with
    bool pop_free_ = false;
    Curve rendered_;  ///< what is drawn (the newest nodes' curve unless the pop-free blend is blending)
    std::vector<uint32_t> counts_;
    std::vector<RingParam> params_;
    RingSet rings_;
    MotionReference motion_{};  ///< the nodes rings_'s first frame was built from (its motion carries the frame)
    TubeMesh mesh_;
    std::size_t states_ = 0;
};

}  // namespace wire
