// WirePipeline: the stages of one wire chained, with state carried between successive states.
#include "wire/pipeline.hpp"

namespace wire {

Status WirePipeline::update(const WireNodes& nodes, const PipelineSettings& settings) {
    // A change of spline settings or of the pop-free blend starts a new history: the curves are not comparable.
    if (states_ == 0 || pop_free_ != settings.pop_free || pop_free_spline_ != settings.spline) {
        PopFreeSettings m = settings.blend;
        m.spline = settings.spline;
        m.enabled = settings.pop_free;
        pop_free_curve_ = PopFreeCurve(m);
        pop_free_spline_ = settings.spline;
        pop_free_ = settings.pop_free;
    }
    Curve next;
    if (Status st = pop_free_curve_.update(nodes, next); !st.ok()) return st;
    rendered_ = std::move(next);

    segment_ring_counts(rendered_, settings.tessellate, counts_);
    place_rings(rendered_, counts_, params_);

    RingSettings ring_settings;
    ring_settings.frames = carried_frames(settings.frame_method,
                                          states_ > 0 && !rings_.frames.empty() ? &rings_.frames.front() : nullptr,
                                          motion_, nodes);
    build_rings(rendered_, params_, ring_settings, rings_);
    motion_ = motion_reference(nodes);
    build_tube(rings_, settings.tube, mesh_);
    ++states_;
    return Status::success();
}

}  // namespace wire
