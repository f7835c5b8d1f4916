// The pop-free blend: per-event blends of the offset between the previous and the current exact
// curve, keyed by node id (see pop_free.hpp). The remap of the pieces onto a new target is in
// pop_free_remap.cpp.
#include "wire/pop_free.hpp"
#include "pop_free_internal.hpp"

#include "wire/bezier.hpp"
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

namespace wire {
namespace detail {

double smoothstep(double s) {
    s = std::clamp(s, 0.0, 1.0);
    return s * s * (3.0 - 2.0 * s);
}

}  // namespace detail

using detail::smoothstep;

namespace {

using glm::dvec3;

bool is_zero(const CubicBezier& d) {
    const dvec3 z(0.0);
    return d.b0 == z && d.b1 == z && d.b2 == z && d.b3 == z;
}

}  // namespace

double rendered_jump_m(const Curve& before, const Curve& after, int per_segment) {
    return curve_jump_m(before, after, per_segment);
}

Status check_unique_ids(const WireNodes& nodes) {
    std::unordered_map<uint32_t, std::size_t> seen;
    seen.reserve(nodes.ids.size());
    for (std::size_t j = 0; j < nodes.ids.size(); ++j) {
        const auto [it, fresh] = seen.emplace(nodes.ids[j], j);
        if (!fresh) {
            return Status::error("node " + std::to_string(j) + ": id " + std::to_string(nodes.ids[j]) +
                                     " is used twice (also node " + std::to_string(it->second) + ")",
                                 static_cast<int>(j));
        }
    }
    return Status::success();
}

PopFreeCurve::PopFreeCurve(const PopFreeSettings& settings) : settings_(settings) {
    auto fix = [](double& v, double fallback) {
        if (!(v > 0.0) || !std::isfinite(v)) v = fallback;
    };
    fix(settings_.blend_s, 0.25);
    fix(settings_.frame_s, 1.0 / 60.0);
    fix(settings_.max_step_m, 1e-3);
    fix(settings_.max_blend_s, 4.0);
    settings_.max_blend_s = std::max(settings_.max_blend_s, settings_.blend_s);
    // Frames, at least 1 and at most a million (a blend of hours is a settings mistake, not a request).
    auto frames = [](double s) { return static_cast<int>(std::clamp(std::ceil(s - 1e-9), 1.0, 1e6)); };
    min_frames_ = frames(settings_.blend_s / settings_.frame_s);
    max_frames_ = std::max(min_frames_, frames(settings_.max_blend_s / settings_.frame_s));
}

void PopFreeCurve::reset() {
    has_state_ = false;
    target_ = Curve{}, rendered_ = Curve{};
    target_ids_.clear(), events_.clear(), pieces_.clear();
}

Status PopFreeCurve::update(const WireNodes& nodes, Curve& rendered) {
    Curve T;
    Status st = build_curve(nodes, settings_.spline, T);
    if (st.ok()) st = check_unique_ids(nodes);
    if (!st.ok()) {
        rendered = rendered_;
        return st;
    }
    const std::size_t tn = T.node_count();
    std::vector<uint32_t> tid(tn);
    for (std::size_t j = 0; j < tn; ++j) tid[j] = nodes.ids.empty() ? T.source_node[j] : nodes.ids[T.source_node[j]];

    // Every running event moves one frame on; those that reached their end contribute exactly 0 and go.
    std::vector<std::size_t> done;
    for (std::size_t e = 0; e < events_.size(); ++e) {
        if (++events_[e].elapsed >= events_[e].frames) done.push_back(e);
    }
    for (auto it = done.rbegin(); it != done.rend(); ++it) {
        events_.erase(events_.begin() + static_cast<std::ptrdiff_t>(*it));
        for (Piece& p : pieces_) p.offset.erase(p.offset.begin() + static_cast<std::ptrdiff_t>(*it));
    }

    const bool changed = tid != target_ids_ || T.segment_count() != target_.segment_count();
    // Without ids, nodes are named by index: a count change renames nodes, so then there is nothing to key on.
    const bool renamed = nodes.ids.empty() && tn != target_ids_.size();
    if (!settings_.enabled || !has_state_ || T.closed != target_.closed || renamed) {
        if (has_state_ && settings_.enabled && changed) ++unremedied_, last_reason_ = renamed ? 2 : 1;
        events_.clear(), pieces_.clear();
    } else if (changed) {
        remap(T, tid);
    }

    // Segments whose pieces carry no offset any more are drawn as T itself (the junctions rejoin exactly).
    std::vector<Piece> kept;
    kept.reserve(pieces_.size());
    for (std::size_t a = 0; a < pieces_.size();) {
        std::size_t b = a;
        bool any = false;
        while (b < pieces_.size() && pieces_[b].segment == pieces_[a].segment) {
            for (const CubicBezier& d : pieces_[b].offset) any = any || !is_zero(d);
            ++b;
        }
        if (any)
            for (std::size_t k = a; k < b; ++k) kept.push_back(std::move(pieces_[k]));
        a = b;
    }
    pieces_ = std::move(kept);
    if (pieces_.empty()) events_.clear();

    Curve out;
    assemble(T, out);
    rendered_ = out;
    target_ = std::move(T), target_ids_ = std::move(tid);
    has_state_ = true;
    rendered = std::move(out);
    return Status::success();
}

void PopFreeCurve::assemble(const Curve& T, Curve& out) const {
    std::vector<double> keep(events_.size());
    for (std::size_t e = 0; e < events_.size(); ++e) {
        keep[e] = 1.0 - smoothstep(static_cast<double>(events_[e].elapsed) / events_[e].frames);
    }
    const std::size_t segs = T.segment_count();
    out = Curve{};
    out.closed = T.closed;
    out.segments.reserve(segs + pieces_.size());
    std::size_t q = 0;
    for (std::size_t j = 0; j < segs; ++j) {
        const std::size_t next_node = (j + 1) % T.node_count();
        out.source_node.push_back(T.source_node[j]), out.radius_m.push_back(T.radius_m[j]);
        if (q >= pieces_.size() || pieces_[q].segment != j) {
            out.segments.push_back(T.segments[j]), out.stretch.push_back(T.stretch[j]);
            continue;
        }
        bool first_piece = true;
        for (; q < pieces_.size() && pieces_[q].segment == j; ++q) {
            const Piece& p = pieces_[q];
            if (!first_piece) {  // a junction inside the segment
                out.source_node.push_back(T.source_node[j]);
                out.radius_m.push_back(static_cast<float>((1.0 - p.u0) * T.radius_m[j] + p.u0 * T.radius_m[next_node]));
            }
            first_piece = false;
            CubicBezier c = sub_segment(T.segments[j], p.u0, p.u1);
            for (std::size_t e = 0; e < keep.size(); ++e) {
                const CubicBezier& d = p.offset[e];
                c.b0 += keep[e] * d.b0, c.b1 += keep[e] * d.b1, c.b2 += keep[e] * d.b2, c.b3 += keep[e] * d.b3;
            }
            out.segments.push_back(c), out.stretch.push_back(T.stretch[j]);
        }
    }
    if (!T.closed) out.source_node.push_back(T.source_node.back()), out.radius_m.push_back(T.radius_m.back());
}

}  // namespace wire
