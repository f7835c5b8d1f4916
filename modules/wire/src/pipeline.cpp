// WirePipeline: the stages of one wire chained, with state carried between successive states.
#include "wire/pipeline.hpp"

#include "wire/spline.hpp"

namespace wire {

Status WirePipeline::update(const WireNodes& nodes, const PipelineSettings& settings) {
    Curve next;
    if (Status st = build_curve(nodes, settings.spline, next); !st.ok) return st;
    target_ = std::move(next);
    rendered_ = target_;

    segment_ring_counts(rendered_, settings.tessellate, counts_);
    place_rings(rendered_, counts_, params_);

    RingSettings ring_settings;
    ring_settings.frames.method = settings.frame_method;
    if (states_ > 0 && !rings_.frames.empty()) {
        // Temporal coherence: carry the first normal over instead of re-seeding from a world axis.
        ring_settings.frames.has_previous_normal = true;
        ring_settings.frames.previous_normal = rings_.frames.front().r;
    }
    build_rings(rendered_, params_, ring_settings, rings_);
    build_tube(rings_, settings.tube, mesh_);
    ++states_;
    return Status::success();
}

}  // namespace wire
