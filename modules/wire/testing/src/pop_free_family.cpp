// Random node-event families for the pop-free blend and the exact curve distance they are measured with.
#include "wire/testing/pop_free_family.hpp"
#include "wire/testing/random.hpp"

#include "wire/bezier.hpp"
#include "wire/testing/reference.hpp"
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <cstring>
#include <unordered_set>

namespace wire {
namespace {

using glm::dvec3;

using Rng = testing::Random;

// Foot points on one curve: per-segment bounding spheres of the control points for pruning, and a warm start
// (the previous query's foot) for the usual case of queries that walk along the curve.
class FootFinder {
public:
    explicit FootFinder(const Curve& c) : c_(c) {
        for (const CubicBezier& s : c.segments) {
            const dvec3 lo = glm::min(glm::min(s.b0, s.b1), glm::min(s.b2, s.b3)), hi = glm::max(glm::max(s.b0, s.b1), glm::max(s.b2, s.b3));
            centre_.push_back(0.5 * (lo + hi)), radius_.push_back(0.5 * glm::length(hi - lo));
        }
    }
    // An upper bound: Newton from the last foot, moving to a neighbouring segment when it leaves this one.
    double local(const dvec3& p) {
        const std::size_t n = c_.segment_count();
        for (int moves = 0; moves < 4; ++moves) {
            const CubicBezier& s = c_.segments[seg_];
            for (int it = 0; it < 8; ++it) {
                const dvec3 d = position(s, t_) - p, d1 = derivative(s, t_), d2 = second_derivative(s, t_);
                const double f = glm::dot(d, d1), fp = glm::dot(d1, d1) + glm::dot(d, d2);
                if (!(fp > 0.0)) break;
                const double next = std::clamp(t_ - f / fp, 0.0, 1.0);
                const bool still = std::abs(next - t_) < 1e-13;
                t_ = next;
                if (still) break;
            }
            if (t_ <= 0.0 && (seg_ > 0 || c_.closed) && glm::dot(position(s, 0.0) - p, derivative(s, 0.0)) > 0.0) {
                seg_ = seg_ > 0 ? seg_ - 1 : n - 1, t_ = 1.0;
            } else if (t_ >= 1.0 && (seg_ + 1 < n || c_.closed) && glm::dot(position(s, 1.0) - p, derivative(s, 1.0)) < 0.0) {
                seg_ = seg_ + 1 < n ? seg_ + 1 : 0, t_ = 0.0;
            } else {
                break;
            }
        }
        return glm::length(position(c_.segments[seg_], t_) - p);
    }
    // The exact distance, given an upper bound.
    double global(const dvec3& p, double best) {
        for (std::size_t k = 0; k < c_.segment_count(); ++k) {
            if (glm::length(p - centre_[k]) - radius_[k] >= best) continue;
            const double t = closest_parameter(c_.segments[k], p);
            const double d = glm::length(position(c_.segments[k], t) - p);
            if (d < best) best = d, seg_ = k, t_ = t;
        }
        return best;
    }

private:
    const Curve& c_;
    std::vector<dvec3> centre_;
    std::vector<double> radius_;
    std::size_t seg_ = 0;
    double t_ = 0.0;
};

double directed_m(const Curve& from, const Curve& to, int per_segment) {
    if (from.segments.empty() || to.segments.empty()) return from.segments.empty() && to.segments.empty() ? 0.0 : std::numeric_limits<double>::infinity();
    FootFinder foot(to);
    double worst = 0.0;
    // A segment that `to` has too, bit for bit, is at distance 0 (most of a wire, away from its events).
    auto key = [](const CubicBezier& s) {
        uint64_t h = 1469598103934665603ull;
        for (const dvec3* v : {&s.b0, &s.b1, &s.b2, &s.b3}) {
            for (int k = 0; k < 3; ++k) {
                uint64_t bits = 0;
                std::memcpy(&bits, &(*v)[k], sizeof bits);
                h = (h ^ bits) * 1099511628211ull;
            }
        }
        return h;
    };
    std::unordered_set<uint64_t> shared;
    for (const CubicBezier& s : to.segments) shared.insert(key(s));
    // Exact distances at the samples (an upper bound, Newton from the previous foot, where that cannot raise
    // the maximum); each segment's largest is refined to the local maximum between its neighbours (golden
    // section on the warm-started foot, then one exact evaluation there).
    auto exact = [&](const dvec3& p) {
        const double up = foot.local(p);
        return up > 0.0 ? foot.global(p, up) : 0.0;
    };
    std::vector<double> d(static_cast<std::size_t>(per_segment) + 1);
    for (const CubicBezier& s : from.segments) {
        if (shared.count(key(s))) continue;
        std::size_t best = 0;
        for (int i = 0; i <= per_segment; ++i) {
            const dvec3 p = position(s, static_cast<double>(i) / per_segment);
            const double up = foot.local(p);
            d[static_cast<std::size_t>(i)] = up > worst ? foot.global(p, up) : up;
            if (d[static_cast<std::size_t>(i)] > d[best]) best = static_cast<std::size_t>(i);
        }
        worst = std::max(worst, d[best]);
        if (!(d[best] > 0.9 * worst) || d[best] <= 0.0) continue;
        const double at = static_cast<double>(best) / per_segment;
        double lo = std::max(0.0, at - 1.0 / per_segment), hi = std::min(1.0, at + 1.0 / per_segment);
        const double g = 0.5 * (std::sqrt(5.0) - 1.0);
        double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
        double f1 = foot.local(position(s, x1)), f2 = foot.local(position(s, x2));
        for (int it = 0; it < 40; ++it) {
            if (f1 >= f2) hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = foot.local(position(s, x1));
            else lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = foot.local(position(s, x2));
        }
        worst = std::max(worst, exact(position(s, f1 >= f2 ? x1 : x2)));
    }
    return worst;
}

WireNodes open_cable(Rng& rng, double& length_m, int forced_spacing) {
    length_m = rng.uniform(20.0, 40.0);
    const double slack = rng.uniform(0.01, 0.25);
    const double chord = length_m / (1.0 + slack), dy = chord * rng.uniform(-0.3, 0.3), dx = std::sqrt(chord * chord - dy * dy);
    const double heading = rng.uniform(0.0, 2.0 * std::numbers::pi);
    const dvec3 p1(rng.uniform(-50.0, 50.0), rng.uniform(0.0, 20.0), rng.uniform(-50.0, 50.0));
    const dvec3 p2 = p1 + dvec3(dx * std::cos(heading), dy, dx * std::sin(heading));
    Catenary cat;
    (void)cat.solve(p1, p2, length_m);
    const int n = rng.integer(16, 40), drawn = rng.integer(0, 2), spacing = forced_spacing >= 0 ? forced_spacing : drawn;
    std::vector<double> s(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const double f = static_cast<double>(i) / (n - 1);
        double g = f;
        if (spacing == 1) g = 0.5 * (1.0 - std::cos(f * std::numbers::pi));  // dense near the ends
        if (spacing == 2 && i > 0 && i + 1 < n) g = (i + rng.uniform(-0.35, 0.35)) / (n - 1);  // jittered
        s[static_cast<std::size_t>(i)] = length_m * g;
    }
    WireNodes w;
    w.positions = cat.points_at_arc_lengths(s);
    return w;
}

WireNodes closed_loop(Rng& rng, double& length_m) {
    length_m = rng.uniform(20.0, 40.0);
    const double r = length_m / (2.0 * std::numbers::pi);
    const double a = r * rng.uniform(1.0, 1.3), b = r * rng.uniform(0.7, 1.0), h = rng.uniform(0.0, 1.0);
    const int lobes = rng.integer(2, 3), n = rng.integer(24, 48);
    const dvec3 axis = rng.unit();
    const dvec3 u = glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0)));
    const dvec3 v = glm::cross(axis, u);
    const dvec3 centre(rng.uniform(-50.0, 50.0), rng.uniform(0.0, 20.0), rng.uniform(-50.0, 50.0));
    WireNodes w;
    for (int i = 0; i < n; ++i) {
        const double th = 2.0 * std::numbers::pi * (i + rng.uniform(-0.3, 0.3)) / n;
        w.positions.push_back(centre + a * std::cos(th) * u + b * std::sin(th) * v + h * std::sin(lobes * th) * axis);
    }
    return w;
}

}  // namespace

double curve_distance_m(const Curve& a, const Curve& b, int samples_per_segment) {
    const int s = std::max(1, samples_per_segment);
    return std::max(directed_m(a, b, s), directed_m(b, a, s));
}

PopFreeFamilyResult run_pop_free_family(const PopFreeFamilySettings& settings) {
    PopFreeFamilyResult out;
    Rng rng{settings.seed * 0x2545F4914F6CDD1Dull + 12345u};
    const int per_seg = std::max(1, settings.samples_per_segment);
    for (int cable = 0; cable < settings.cables && out.error.empty(); ++cable) {
        const bool closed = settings.shapes == 1 ? false : settings.shapes == 2 ? true : cable % 2 == 1;
        double length = 0.0;
        WireNodes nodes = closed ? closed_loop(rng, length) : open_cable(rng, length, settings.open_spacing);
        const std::size_t n0 = nodes.size();
        const double spacing = length / static_cast<double>(closed ? n0 : n0 - 1);
        uint32_t next_id = static_cast<uint32_t>(rng.integer(1, 1000)) * 1000u;
        for (std::size_t i = 0; i < nodes.size(); ++i) nodes.ids.push_back(next_id), next_id += 3;
        PopFreeSettings ms = settings.blend;
        ms.spline = settings.spline;
        ms.spline.closed = closed;
        PopFreeCurve m(ms);
        out.large_offset_m = settings.jump_bound_m * m.max_blend_frames() / 1.5;
        Curve prev, cur;
        if (Status st = m.update(nodes, prev); !st) {
            out.error = "cable " + std::to_string(cable) + ": " + st.message;
            break;
        }
        struct Running {
            std::size_t event;
            std::size_t end_frame;
            double pop, speed;  // speed: the design's per-frame bound (PopFreeCurve::last_frame_bound_m)
            std::size_t folded_after = std::numeric_limits<std::size_t>::max();  // folded into a later event
        };
        std::vector<Running> running;
        std::size_t frame = 0;
        auto step = [&](int type) {
            Curve before;
            if (type >= 0) before = m.target();
            const std::size_t started = m.events_started(), unremedied = m.unremedied();
            if (Status st = m.update(nodes, cur); !st) {
                out.error = "cable " + std::to_string(cable) + ", frame " + std::to_string(frame) + ": " + st.message;
                return;
            }
            ++frame, ++out.frames;
            // An event switched at frame f with N frames moves the drawn curve in frames f+1 .. f+N and keeps it
            // off the exact curve in frames f .. f+N-1.
            std::erase_if(running, [&](const Running& r) { return r.end_frame < frame; });
            if (type >= 0) {
                PopFreeEvent e;
                e.type = type, e.closed = closed, e.cable = cable, e.length_m = length;
                e.pop_m = curve_distance_m(before, m.target(), per_seg);
                e.frames = m.events_started() > started ? m.last_blend_frames() : 0;
                out.max_frames = std::max(out.max_frames, e.frames);
                out.unremedied += m.unremedied() - unremedied;
                e.offset_m = e.frames > 0 ? m.last_max_offset_m() : 0.0;
                e.frame_bound_m = e.frames > 0 ? m.last_frame_bound_m() : 0.0;
                out.large_events += e.frame_bound_m > settings.jump_bound_m;
                out.events.push_back(e);
                if (e.frames > 0) {
                    // The pop-free blend folds the running events into the new one (pop_free.hpp): what is left of them
                    // ends with it, and from the next frame on the new event's speed is the design's bound.
                    for (Running& r : running) r.end_frame = frame + static_cast<std::size_t>(e.frames), r.folded_after = std::min(r.folded_after, frame);
                    running.push_back({out.events.size() - 1, frame + static_cast<std::size_t>(e.frames), e.pop_m, e.frame_bound_m});
                }
                if (running.size() > 1) for (const Running& r : running) out.events[r.event].overlapped = true;
            }
            const double jump = curve_distance_m(prev, cur, per_seg), lag = curve_distance_m(cur, m.target(), per_seg);
            double pops = 0.0, lag_pops = 0.0;
            double speed = 0.0;
            bool any_off = false, large = false;
            for (const Running& r : running) {
                pops += r.pop, speed += frame <= r.folded_after ? r.speed : 0.0, large = large || out.events[r.event].frame_bound_m > settings.jump_bound_m;
                if (r.end_frame > frame) lag_pops += r.pop, any_off = true;
            }
            if (m.blending() != any_off) ++out.state_mismatch;
            if (!any_off) out.max_settled_gap_m = std::max(out.max_settled_gap_m, lag);
            if (!large) out.max_jump_m = std::max(out.max_jump_m, jump);
            if (jump > 1e-9) out.max_jump_over_design = std::max(out.max_jump_over_design, jump / std::max(speed, 1e-300));
            const std::string where = "cable " + std::to_string(cable) + (closed ? " (closed, " : " (open, ") +
                                      std::to_string(nodes.size()) + " nodes, " + std::to_string(length) + " m), frame " +
                                      std::to_string(frame) + ", " + std::to_string(running.size()) + " event(s) running";
            const double jr = jump > 1e-9 ? jump / std::max(pops, 1e-300) : 0.0, lr = lag > 1e-9 ? lag / std::max(lag_pops, 1e-300) : 0.0;
            if (jr > out.max_jump_ratio) out.max_jump_ratio = jr, out.worst_jump = where + ", jump " + std::to_string(jump) + " m, pops " + std::to_string(pops) + " m";
            if (lr > out.max_lag_ratio) out.max_lag_ratio = lr, out.worst_lag = where + ", lag " + std::to_string(lag) + " m, pops " + std::to_string(pops) + " m";
            for (const Running& r : running) {
                PopFreeEvent& e = out.events[r.event];
                e.jump_m = std::max(e.jump_m, jump), e.lag_m = std::max(e.lag_m, lag);
                e.jump_ratio = std::max(e.jump_ratio, jr), e.lag_ratio = std::max(e.lag_ratio, lr);
            }
            prev = cur;
        };
        for (int ev = 0; ev < settings.events_per_cable && out.error.empty(); ++ev) {
            const int gap = rng.integer(0, std::max(0, settings.max_gap_frames));
            for (int g = 0; g < gap && out.error.empty(); ++g) step(-1);
            // The physics keeps its resolution within a band around the cable's own: a few nodes fewer, some more.
            const std::size_t n = nodes.size();
            const bool may_insert = n < n0 + 8, may_remove = n + 4 > n0;
            const double r = rng.uniform(0.0, 1.0);
            int type = PopFreeEvent::insert;
            if (r < 0.45) type = may_insert ? PopFreeEvent::insert : PopFreeEvent::remove;
            else if (r < 0.9) type = may_remove ? PopFreeEvent::remove : PopFreeEvent::insert;
            else type = closed ? (may_remove ? PopFreeEvent::seam : PopFreeEvent::insert) : PopFreeEvent::replace_end;
            // Removal: anywhere along the wire (a loop's seam node 0 included), where a coarsening physics would
            // remove a node: the merged element stays within 2.5x the cable's own spacing (it would not leave a
            // 4 m element among 1 m ones). Where no such node is found in 20 draws, the event is an insertion.
            std::size_t victim = n;
            if (type == PopFreeEvent::remove || type == PopFreeEvent::seam) {
                for (int tries = 0; tries < 20 && victim == n; ++tries) {
                    const std::size_t at = type == PopFreeEvent::seam && tries == 0 ? 0
                                           : closed ? static_cast<std::size_t>(rng.integer(0, static_cast<int>(n) - 1))
                                                    : static_cast<std::size_t>(rng.integer(1, static_cast<int>(n) - 2));
                    const std::size_t a = at == 0 ? n - 1 : at - 1, b = at + 1 == n ? 0 : at + 1;
                    if (glm::length(nodes.positions[a] - nodes.positions[b]) <= 2.5 * spacing) victim = at;
                }
                type = victim == n ? PopFreeEvent::insert : closed && victim == 0 ? PopFreeEvent::seam : PopFreeEvent::remove;
            }
            if (type == PopFreeEvent::insert) {  // exactly on the current curve, inside a random segment
                const Curve& t = m.target();
                const std::size_t k = static_cast<std::size_t>(rng.integer(0, static_cast<int>(t.segment_count()) - 1));
                const dvec3 p = position(t.segments[k], rng.uniform(0.15, 0.85));
                const std::size_t at = t.source_node[k] + 1;
                nodes.positions.insert(nodes.positions.begin() + static_cast<std::ptrdiff_t>(at), p);
                nodes.ids.insert(nodes.ids.begin() + static_cast<std::ptrdiff_t>(at), next_id++);
            } else if (type == PopFreeEvent::remove || type == PopFreeEvent::seam) {
                nodes.positions.erase(nodes.positions.begin() + static_cast<std::ptrdiff_t>(victim));
                nodes.ids.erase(nodes.ids.begin() + static_cast<std::ptrdiff_t>(victim));
            } else {  // an end node re-created by the physics under a new id, up to 2 mm from where it was
                const std::size_t at = rng.integer(0, 1) == 0 ? 0 : n - 1;
                nodes.positions[at] += rng.uniform(0.0, 2e-3) * rng.unit();
                nodes.ids[at] = next_id++;
            }
            step(type);
        }
        // Hold the last state until every blend has ended, then one more frame to see it settled.
        for (int f = 0; f <= m.max_blend_frames() + 1 && out.error.empty() && (m.blending() || !running.empty()); ++f) step(-1);
        // (the frame after the last blend ended: nothing running, the exact curve drawn)
        if (out.error.empty()) step(-1);
    }
    return out;
}

}  // namespace wire
