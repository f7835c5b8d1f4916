// The pop-free blend's remap: the running pieces (on the previous target) mapped onto the new target curve through
// the junctions of matched node stretches, each new event's offset and its length from the motion it needs.
#include "pop_free_internal.hpp"
#include "wire/pop_free.hpp"

#include "wire/bezier.hpp"
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <unordered_map>

namespace wire {
using detail::smoothstep;

namespace {

using glm::dvec3;

CubicBezier operator-(const CubicBezier& a, const CubicBezier& b) {
    return {a.b0 - b.b0, a.b1 - b.b1, a.b2 - b.b2, a.b3 - b.b3};
}

// max over t of |D(t)|: how far the point at parameter t travels over a whole blend (sampled densely, plus
// the control points' bound where it is attained at an end).
double max_displacement(const CubicBezier& d) {
    double worst = 0.0;
    int best = 0;
    for (int i = 0; i <= 32; ++i) {
        const double v = glm::length(position(d, i / 32.0));
        if (v > worst) worst = v, best = i;
    }
    // Refined to the local maximum between the best sample's neighbours (golden section).
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double lo = std::max(0, best - 1) / 32.0, hi = std::min(32, best + 1) / 32.0;
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    double f1 = glm::length(position(d, x1)), f2 = glm::length(position(d, x2));
    for (int it = 0; it < 30; ++it) {
        if (f1 >= f2)
            hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = glm::length(position(d, x1));
        else
            lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = glm::length(position(d, x2));
    }
    return std::max({worst, f1, f2});
}
// How far one frame of an event can move the drawn curve (not its points), for a piece drawn as T + k D while the
// weight k runs from 1 to 0 over N frames (|dk| <= 1.5 / N a frame: smoothstep's peak slope). The drawn piece at
// weight k is C = T + k D = (1 - k) T + k Q with Q = T + D, so its tangent C' = (1 - k) T' + k Q' lies between T'
// and Q': a point moved by dk D(u) leaves the curve by at most dk |D x c| with c the unit tangent of C at u, and
// |D x c| <= |D x t_T| + |D| |t_Q - t_T| (c on the arc between t_T and t_Q). That is the first-order part
// `across`; sliding along C by dk |D| costs the second-order part dk^2 |D|^2 kappa / 2, with kappa <= max(|T''|,
// |Q''|) / (min(|T'|, |Q'|) cos(theta / 2))^2 the curvature of C (theta: the angle between T' and Q').
// A slide along the curve (D along the tangent: both curves pass through the same points at different
// parameters, as across unequal elements of centripetal or uniform Catmull-Rom) is not a motion of the curve:
// the event is as long as its motion across needs, not as long as the slide. Sampled (65 points; the caller
// keeps a margin). Where a tangent vanishes (a tension-1 end) the point's own travel |D| is used.
struct FrameMotion {
    double across = 0.0;  // max over u of |D x t_T| + |D| |t_Q - t_T|
    double curl = 0.0;    // max over u of |D|^2 kappa
};
FrameMotion frame_motion(const CubicBezier& t, const CubicBezier& d) {
    FrameMotion m;
    const CubicBezier q{t.b0 + d.b0, t.b1 + d.b1, t.b2 + d.b2, t.b3 + d.b3};
    for (int i = 0; i <= 64; ++i) {
        const double u = i / 64.0;
        const dvec3 dv = position(d, u), tv = derivative(t, u), qv = derivative(q, u);
        const double dl = glm::length(dv), tl = glm::length(tv), ql = glm::length(qv);
        const double scale =
            std::max({glm::length(t.b3 - t.b0), glm::length(t.b1 - t.b0), glm::length(t.b2 - t.b3), 1e-300});
        if (!(tl > 1e-9 * scale) || !(ql > 1e-9 * scale)) {
            m.across = std::max(m.across, dl);
            continue;
        }
        const dvec3 tt = tv / tl, tq = qv / ql;
        const double cos_theta = glm::dot(tt, tq);
        if (!(cos_theta > 0.0)) {  // tangents 90 degrees or more apart: no useful cone
            m.across = std::max(m.across, dl);
            continue;
        }
        m.across = std::max(m.across, glm::length(glm::cross(dv, tt)) + dl * glm::length(tq - tt));
        const double cos_half = std::sqrt(0.5 * (1.0 + cos_theta));
        const double speed = std::min(tl, ql) * cos_half;
        const double kappa =
            std::max(glm::length(second_derivative(t, u)), glm::length(second_derivative(q, u))) / (speed * speed);
        m.curl = std::max(m.curl, dl * dl * kappa);
    }
    return m;
}

// A run of consecutive segments of a curve, addressed by a chain parameter in [0, count] (segment floor(p),
// u = p - floor(p)). `first` is the curve segment of the chain's segment 0; closed curves wrap.
struct Chain {
    const Curve* curve = nullptr;
    std::size_t first = 0, count = 0;

    [[nodiscard]] const CubicBezier& seg(std::size_t k) const {
        return curve->segments[(first + k) % curve->segment_count()];
    }
    [[nodiscard]] dvec3 node(std::size_t k) const { return k < count ? seg(k).b0 : seg(count - 1).b3; }
    // Chain parameter of the point nearest to p. Segments are visited by a lower bound on their distance (each
    // lies inside the bounding box of its control points) and skipped once that bound exceeds the best.
    [[nodiscard]] double project(const dvec3& p) const {
        std::vector<std::pair<double, std::size_t>> order(count);
        for (std::size_t k = 0; k < count; ++k) {
            const CubicBezier& c = seg(k);
            const dvec3 lo = glm::min(glm::min(c.b0, c.b1), glm::min(c.b2, c.b3)),
                        hi = glm::max(glm::max(c.b0, c.b1), glm::max(c.b2, c.b3));
            order[k] = {std::max(0.0, glm::length(p - 0.5 * (lo + hi)) - 0.5 * glm::length(hi - lo)), k};
        }
        std::sort(order.begin(), order.end());
        double best = std::numeric_limits<double>::infinity(), best_param = 0.0;
        for (const auto& [bound, k] : order) {
            if (bound >= best) break;
            const double u = closest_parameter(seg(k), p);
            const double d = glm::length(position(seg(k), u) - p);
            if (d < best) best = d, best_param = static_cast<double>(k) + u;
        }
        return best_param;
    }
    [[nodiscard]] std::vector<double> cumulative() const {
        std::vector<double> cum(count + 1, 0.0);
        for (std::size_t k = 0; k < count; ++k) cum[k + 1] = cum[k] + arc_length_m(seg(k));
        return cum;
    }
};

// Chain parameter at arc length `value` (linear in u inside a segment: any monotone map tiles exactly).
double param_at(const std::vector<double>& cum, double value) {
    std::size_t k = 0;
    while (k + 2 < cum.size() && cum[k + 1] < value) ++k;
    const double len = cum[k + 1] - cum[k];
    return static_cast<double>(k) + (len > 0.0 ? std::clamp((value - cum[k]) / len, 0.0, 1.0) : 0.0);
}

struct Junction {
    double p, t;  // chain parameters on the previous (P) and the current (T) curve
};

bool increasing(const std::vector<Junction>& js) {
    for (std::size_t k = 1; k < js.size(); ++k) {
        if (!(js[k].p > js[k - 1].p + 1e-9) || !(js[k].t > js[k - 1].t + 1e-9)) return false;
    }
    return true;
}

// Junctions of one stretch between two matched nodes: the chains' own nodes (exact on their side), each placed
// on the other chain at its closest point; if that breaks the order, at equal arc-length fractions instead
// (a node of each side within 1e-9 of the same fraction share one junction). Returns them with both stretch
// ends, strictly increasing on both sides.
std::vector<Junction> stretch_junctions(const Chain& pc, const Chain& tc) {
    std::vector<Junction> js{{0.0, 0.0}};
    for (std::size_t k = 1; k < pc.count; ++k) js.push_back({static_cast<double>(k), tc.project(pc.node(k))});
    for (std::size_t k = 1; k < tc.count; ++k) js.push_back({pc.project(tc.node(k)), static_cast<double>(k)});
    js.push_back({static_cast<double>(pc.count), static_cast<double>(tc.count)});
    std::sort(js.begin() + 1, js.end() - 1, [](const Junction& a, const Junction& b) { return a.p < b.p; });
    if (increasing(js)) return js;

    const std::vector<double> cp = pc.cumulative(), ct = tc.cumulative();
    js.assign(1, Junction{0.0, 0.0});
    std::size_t i = 1, j = 1;
    while (i < pc.count || j < tc.count) {
        const double fp = i < pc.count ? cp[i] / cp.back() : 2.0, ft = j < tc.count ? ct[j] / ct.back() : 2.0;
        if (std::abs(fp - ft) < 1e-9) {
            js.push_back({static_cast<double>(i++), static_cast<double>(j++)});
        } else if (fp < ft) {
            js.push_back({static_cast<double>(i++), param_at(ct, fp * ct.back())});
        } else {
            js.push_back({param_at(cp, ft * cp.back()), static_cast<double>(j++)});
        }
    }
    js.push_back({static_cast<double>(pc.count), static_cast<double>(tc.count)});
    return js;
}

// Segment index and local range of a chain-parameter interval [a, b] that lies inside one segment.
void locate(double a, double b, std::size_t count, std::size_t& seg, double& u0, double& u1) {
    double k = std::floor(a);
    if (b > k + 1.0) k = std::floor(b) - 1.0;  // a rounded just below a node
    k = std::clamp(k, 0.0, static_cast<double>(count - 1));
    seg = static_cast<std::size_t>(k);
    u0 = std::clamp(a - k, 0.0, 1.0), u1 = std::clamp(b - k, 0.0, 1.0);
}

}  // namespace

// Maps the pieces (on the previous target) onto T and adds the new event's offset P - T.
void PopFreeCurve::remap(const Curve& T, const std::vector<uint32_t>& tid) {
    const Curve& P = target_;
    const std::size_t pn = P.node_count(), tn = T.node_count();
    const std::size_t ps = P.segment_count(), ts = T.segment_count();
    const bool closed = T.closed;

    std::unordered_map<uint32_t, std::size_t> p_index;
    for (std::size_t i = 0; i < pn; ++i) p_index.emplace(target_ids_[i], i);

    // Matched nodes in order along the wire, as (P node, T node) in chain coordinates. A closed loop is cut at
    // its first common node (none: at node 0 of each); an open wire's ends always pair with each other.
    std::size_t p_shift = 0, t_shift = 0;
    if (closed) {
        for (std::size_t j = 0; j < tn; ++j) {
            const auto it = p_index.find(tid[j]);
            if (it != p_index.end()) {
                p_shift = it->second, t_shift = j;
                break;
            }
        }
    }
    std::vector<std::pair<std::size_t, std::size_t>> pairs{{0, 0}};
    for (std::size_t k = 1; k < tn; ++k) {
        const std::size_t j = (k + t_shift) % tn;
        const auto it = p_index.find(tid[j]);
        if (it == p_index.end()) continue;
        const std::size_t i = (it->second + pn - p_shift) % pn;
        if (i <= pairs.back().first) continue;                    // out of order: both sides treated as unmatched
        if (!closed && (i == pn - 1) != (k == tn - 1)) continue;  // only the ends pair with the ends
        if (!closed && i == pn - 1) continue;                     // the end pair is added below
        pairs.push_back({i, k});
    }
    pairs.push_back({ps, ts});

    // Per old segment: its pieces (an index range into pieces_).
    std::vector<std::size_t> first(ps + 1, 0);
    for (const Piece& p : pieces_) ++first[p.segment + 1];
    for (std::size_t s = 0; s < ps; ++s) first[s + 1] += first[s];

    const std::size_t layers = events_.size();
    std::vector<Piece> out;
    double max_d = 0.0;
    auto emit = [&](std::size_t sp, double a, double b, std::size_t st, double c, double d) {
        // P segment sp over [a, b] corresponds to T segment st over [c, d], affinely in the parameter.
        const CubicBezier& pseg = P.segments[sp];
        const CubicBezier& tseg = T.segments[st];
        auto map = [&](double x) { return x <= a ? c : x >= b ? d : c + (x - a) / (b - a) * (d - c); };
        auto add = [&](double x0, double x1, const Piece* old) {
            Piece np;
            np.segment = static_cast<uint32_t>(st);
            np.u0 = map(x0), np.u1 = map(x1);
            np.offset.reserve(layers + 1);
            for (std::size_t e = 0; e < layers; ++e) {
                if (old == nullptr) {
                    np.offset.push_back(CubicBezier{});
                } else {
                    const double w = old->u1 - old->u0;
                    np.offset.push_back(sub_segment(old->offset[e], x0 <= old->u0 ? 0.0 : (x0 - old->u0) / w,
                                                    x1 >= old->u1 ? 1.0 : (x1 - old->u0) / w));
                }
            }
            const CubicBezier dn = sub_segment(pseg, x0, x1) - sub_segment(tseg, np.u0, np.u1);
            max_d = std::max(max_d, max_displacement(dn));
            np.offset.push_back(dn);
            out.push_back(std::move(np));
        };
        if (first[sp] == first[sp + 1]) {
            add(a, b, nullptr);
            return;
        }
        for (std::size_t q = first[sp]; q < first[sp + 1]; ++q) {
            const Piece& old = pieces_[q];
            const double x0 = std::max(a, old.u0), x1 = std::min(b, old.u1);
            if (x1 > x0) add(x0, x1, &old);
        }
    };

    const Chain pchain{&P, closed ? p_shift : 0, ps}, tchain{&T, closed ? t_shift : 0, ts};
    for (std::size_t m = 0; m + 1 < pairs.size(); ++m) {
        const std::size_t pa = pairs[m].first, pb = pairs[m + 1].first, ta = pairs[m].second, tb = pairs[m + 1].second;
        std::vector<Junction> js;
        if (pb - pa == 1 && tb - ta == 1) {
            js = {{0.0, 0.0}, {1.0, 1.0}};
        } else {
            js = stretch_junctions(Chain{&P, (pchain.first + pa) % ps, pb - pa},
                                   Chain{&T, (tchain.first + ta) % ts, tb - ta});
        }
        for (std::size_t q = 0; q + 1 < js.size(); ++q) {
            std::size_t sp = 0, st = 0;
            double a = 0, b = 0, c = 0, d = 0;
            locate(js[q].p, js[q + 1].p, pb - pa, sp, a, b);
            locate(js[q].t, js[q + 1].t, tb - ta, st, c, d);
            emit((pchain.first + pa + sp) % ps, a, b, (tchain.first + ta + st) % ts, c, d);
        }
    }
    std::stable_sort(out.begin(), out.end(), [](const Piece& x, const Piece& y) {
        return x.segment != y.segment ? x.segment < y.segment : x.u0 < y.u0;
    });
    pieces_ = std::move(out);

    // The new event, unless nothing moved. The running events are folded into it: its offset is what the
    // curve drawn this frame holds off T (their offsets at this frame's weights, plus P - T), so the switch
    // shows what they would have shown, and from here one blend carries the whole remaining change. Events
    // that kept their own clocks would add their speeds (three of them at 1 mm a frame: 3 mm); one event keeps
    // the per-frame bound. Its length: see pop_free.hpp.
    if (max_d > 0.0) {
        std::vector<double> keep(layers);
        for (std::size_t e = 0; e < layers; ++e)
            keep[e] = 1.0 - smoothstep(static_cast<double>(events_[e].elapsed) / events_[e].frames);
        max_d = 0.0;
        FrameMotion motion;
        double gap = 0.0;
        const Chain whole_t{&T, 0, ts};
        for (Piece& p : pieces_) {
            CubicBezier c = p.offset.back();
            for (std::size_t e = 0; e < layers; ++e) {
                const CubicBezier& d = p.offset[e];
                c.b0 += keep[e] * d.b0, c.b1 += keep[e] * d.b1, c.b2 += keep[e] * d.b2, c.b3 += keep[e] * d.b3;
            }
            p.offset.assign(1, c);
            max_d = std::max(max_d, max_displacement(c));
            const FrameMotion pm = frame_motion(sub_segment(T.segments[p.segment], p.u0, p.u1), c);
            motion.across = std::max(motion.across, pm.across), motion.curl = std::max(motion.curl, pm.curl);
            // An open wire's end moving along its tangent lengthens or shortens the curve: that is motion.
            if (!closed && p.segment == 0 && p.u0 == 0.0) motion.across = std::max(motion.across, glm::length(c.b0));
            if (!closed && p.segment + 1 == ts && p.u1 == 1.0)
                motion.across = std::max(motion.across, glm::length(c.b3));
        }
        // How far the curve drawn now (Q, this frame: the event's weight is still 1) is from T, both ways, at the
        // pieces' samples: a lower bound of the switch's lag (the distance is exact at each sample). The length
        // below keeps each frame under 0.15 of it, as N >= 15 keeps each frame under 1/10 of max|D| when D runs
        // point to nearest point: a slide that hardly moves the curve is not blended faster than the curve's
        // own change allows (uniform Catmull-Rom across unequal elements: points travel far along a curve that
        // barely changes, and the drawn curve cuts its bends meanwhile).
        events_.assign(1, Event{0, 1, max_d, 0.0});
        Curve shown;
        assemble(T, shown);
        const Chain whole_q{&shown, 0, shown.segment_count()};
        const auto distance_to = [](const Chain& chain, const dvec3& x) {
            const double at = chain.project(x);
            std::size_t k = 0;
            double u0 = 0, u1 = 0;
            locate(at, at, chain.count, k, u0, u1);
            return glm::length(position(chain.seg(k), u0) - x);
        };
        for (const Piece& p : pieces_) {
            const CubicBezier tp = sub_segment(T.segments[p.segment], p.u0, p.u1);
            for (int i = 0; i <= 16; ++i) {
                const dvec3 t = position(tp, i / 16.0);
                gap = std::max(
                    {gap, distance_to(whole_t, t + position(p.offset.back(), i / 16.0)), distance_to(whole_q, t)});
            }
        }
        // The per-frame bound of N frames (see frame_motion): a point moves by at most 1.5 max|D| / N; the curve by
        // at most 1.5 across / N + 1.125 curl / N^2 (with a 10% margin for the sampling). The shortest N that
        // keeps either under max_step_m, within [min_frames_, max_frames_].
        const double step = settings_.max_step_m;
        const double across = 1.1 * std::min(motion.across, max_d), curl = 1.1 * motion.curl;
        const auto bound = [&](double n) {
            return std::min(1.5 * max_d / n, 1.5 * across / n + 1.125 * curl / (n * n));
        };
        // The shortest N whose bound is at most `limit`.
        const auto need_for = [&](double limit) {
            return std::min(1.5 * max_d / limit,
                            (1.5 * across + std::sqrt(2.25 * across * across + 4.5 * limit * curl)) / (2.0 * limit));
        };
        // Under max_step_m, and under 0.15 of how far the drawn curve is from T (above).
        const double need = gap > 0.0 ? std::max(need_for(step), need_for(0.15 * gap)) : need_for(step);
        const int frames = need >= static_cast<double>(max_frames_)
                               ? max_frames_
                               : std::max(min_frames_, static_cast<int>(std::ceil(need)));
        events_.assign(1, Event{0, frames, max_d, bound(frames)});
        last_frames_ = frames;
        ++started_;
    } else {
        for (Piece& p : pieces_) p.offset.pop_back();
    }
}

}  // namespace wire
