// Pop-free multiresolution: union-topology geomorphs keyed by node id (see multires.hpp).
#include "wire/multires.hpp"

#include "wire/bezier.hpp"
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <unordered_set>

namespace wire {
namespace {

using glm::dvec3;

CubicBezier operator-(const CubicBezier& a, const CubicBezier& b) { return {a.b0 - b.b0, a.b1 - b.b1, a.b2 - b.b2, a.b3 - b.b3}; }
CubicBezier add_scaled(const CubicBezier& a, const CubicBezier& d, double s) {
    return {a.b0 + s * d.b0, a.b1 + s * d.b1, a.b2 + s * d.b2, a.b3 + s * d.b3};
}
// max over t of |D(t)|, D(t) the Bezier combination of the offsets: how far the point at parameter t travels
// over the whole geomorph (sampled densely; at most the largest control-point offset).
double max_displacement(const CubicBezier& d) {
    double worst = 0.0;
    for (int i = 0; i <= 32; ++i) worst = std::max(worst, glm::length(position(d, i / 32.0)));
    return worst;
}

// A run of consecutive segments of a curve, addressed by a chain parameter in [0, count]: segment floor(p), u = p - floor(p).
struct Chain {
    const CubicBezier* seg = nullptr;
    std::size_t count = 0;

    [[nodiscard]] CubicBezier piece(double p0, double p1) const {
        std::size_t k = static_cast<std::size_t>(std::floor(p0));
        if (k >= count) k = count - 1;
        return sub_segment(seg[k], p0 - static_cast<double>(k), std::min(1.0, p1 - static_cast<double>(k)));
    }
    // Chain parameter of the point nearest to p. Segments are visited by a lower bound on their distance (each
    // lies inside the bounding sphere of its control points) and skipped once that bound exceeds the best.
    [[nodiscard]] double project(const dvec3& p) const {
        std::vector<std::pair<double, std::size_t>> order(count);
        for (std::size_t k = 0; k < count; ++k) {
            const CubicBezier& c = seg[k];
            const dvec3 lo = glm::min(glm::min(c.b0, c.b1), glm::min(c.b2, c.b3)), hi = glm::max(glm::max(c.b0, c.b1), glm::max(c.b2, c.b3));
            order[k] = {std::max(0.0, glm::length(p - 0.5 * (lo + hi)) - 0.5 * glm::length(hi - lo)), k};
        }
        std::sort(order.begin(), order.end());
        double best = std::numeric_limits<double>::infinity(), best_param = -1.0;
        for (const auto& [bound, k] : order) {
            if (bound >= best) break;
            const double u = closest_parameter(seg[k], p);
            const double d = glm::length(position(seg[k], u) - p);
            if (d < best) best = d, best_param = static_cast<double>(k) + u;
        }
        return best_param;
    }
    // Chain parameter at arc-length fraction f (linear in u inside a segment: any monotone map tiles exactly).
    [[nodiscard]] double at_fraction(double f, const std::vector<double>& cum) const {
        const double target = f * cum.back();
        std::size_t k = 0;
        while (k + 1 < count && cum[k + 1] < target) ++k;
        const double len = cum[k + 1] - cum[k];
        return static_cast<double>(k) + (len > 0.0 ? std::clamp((target - cum[k]) / len, 0.0, 1.0) : 0.0);
    }
    [[nodiscard]] std::vector<double> cumulative() const {
        std::vector<double> cum(count + 1, 0.0);
        for (std::size_t k = 0; k < count; ++k) cum[k + 1] = cum[k] + arc_length_m(seg[k]);
        return cum;
    }
};

struct UnionPoint {
    double old_param, new_param;
    uint32_t id;
    bool ghost;
    bool old_node, new_node;  // the point is a node of that chain (its parameter is exact), else projected
};


bool increasing(const std::vector<UnionPoint>& pts, double end_old, double end_new) {
    double po = 0.0, pn = 0.0;
    for (const UnionPoint& p : pts) {
        if (!(p.old_param > po + 1e-9) || !(p.new_param > pn + 1e-9)) return false;
        po = p.old_param, pn = p.new_param;
    }
    return po < end_old - 1e-9 && pn < end_new - 1e-9;
}

// Union points of an old and a new chain with the same two anchors. Nodes present in both are matched exactly;
// an old-only node is placed on the new chain at its closest point and vice versa (so a node inserted exactly
// on the old curve does not move at all). If those projections disagree on the order, each stretch between
// matched nodes is cut at arc-length fractions instead (nodes closer than 1e-6 of the stretch pair up).
bool union_points(const Chain& oc, const std::vector<uint32_t>& old_ids, const Chain& nc,
                  const std::vector<uint32_t>& new_ids, std::vector<UnionPoint>& pts) {
    std::unordered_map<uint32_t, std::size_t> new_interior;
    for (std::size_t k = 1; k < nc.count; ++k) new_interior.emplace(new_ids[k], k);
    std::unordered_set<uint32_t> matched;
    pts.clear();
    for (std::size_t k = 1; k < oc.count; ++k) {
        const auto it = new_interior.find(old_ids[k]);
        if (it != new_interior.end()) {
            matched.insert(old_ids[k]);
            pts.push_back({static_cast<double>(k), static_cast<double>(it->second), old_ids[k], false, true, true});
        } else {
            pts.push_back({static_cast<double>(k), nc.project(oc.seg[k].b0), old_ids[k], true, true, false});
        }
    }
    for (std::size_t k = 1; k < nc.count; ++k) {
        if (!matched.count(new_ids[k])) pts.push_back({oc.project(nc.seg[k].b0), static_cast<double>(k), new_ids[k], false, false, true});
    }
    auto by_old = [](const UnionPoint& a, const UnionPoint& b) { return a.old_param < b.old_param; };
    std::sort(pts.begin(), pts.end(), by_old);
    const double end_old = static_cast<double>(oc.count), end_new = static_cast<double>(nc.count);
    if (increasing(pts, end_old, end_new)) return true;

    // Fallback: between consecutive matched nodes (and the anchors), merge both node lists by local arc fraction.
    const std::vector<double> co = oc.cumulative(), cn = nc.cumulative();
    std::vector<UnionPoint> pairs{{0.0, 0.0, 0, false, true, true}};
    for (const UnionPoint& p : pts) if (p.old_node && p.new_node) pairs.push_back(p);
    pairs.push_back({end_old, end_new, 0, false, true, true});
    std::vector<UnionPoint> out;
    auto param_at = [](const std::vector<double>& cum, double value) {
        std::size_t k = 0;
        while (k + 2 < cum.size() && cum[k + 1] < value) ++k;
        const double len = cum[k + 1] - cum[k];
        return static_cast<double>(k) + (len > 0.0 ? std::clamp((value - cum[k]) / len, 0.0, 1.0) : 0.0);
    };
    for (std::size_t m = 0; m + 1 < pairs.size(); ++m) {
        const std::size_t oa = static_cast<std::size_t>(pairs[m].old_param), ob = static_cast<std::size_t>(pairs[m + 1].old_param);
        const std::size_t na = static_cast<std::size_t>(pairs[m].new_param), nb = static_cast<std::size_t>(pairs[m + 1].new_param);
        if (ob <= oa || nb <= na) return false;  // matched nodes out of order
        const double lo_o = co[oa], len_o = co[ob] - co[oa], lo_n = cn[na], len_n = cn[nb] - cn[na];
        if (!(len_o > 0.0) || !(len_n > 0.0)) return false;
        std::size_t i = oa + 1, j = na + 1;
        while (i < ob || j < nb) {
            const double fo = i < ob ? (co[i] - lo_o) / len_o : 2.0, fn = j < nb ? (cn[j] - lo_n) / len_n : 2.0;
            if (std::abs(fo - fn) < 1e-6) {  // an old and a new node at the same place: one junction
                out.push_back({static_cast<double>(i), static_cast<double>(j), new_ids[j], false, true, true});
                ++i, ++j;
            } else if (fo < fn) {
                out.push_back({static_cast<double>(i), param_at(cn, lo_n + fo * len_n), old_ids[i], true, true, false});
                ++i;
            } else {
                out.push_back({param_at(co, lo_o + fn * len_o), static_cast<double>(j), new_ids[j], false, false, true});
                ++j;
            }
        }
        if (m + 2 < pairs.size()) out.push_back(pairs[m + 1]);
    }
    pts = std::move(out);
    return increasing(pts, end_old, end_new);
}

// Drops ghost junctions (ids not in the current state) whose two pieces are, within tol_m, one cubic:
// the inverse of de Casteljau at the split ratio read off the tangent lengths at the junction.
void prune_ghosts(std::vector<CubicBezier>& segs, std::vector<uint32_t>& ids,
                  const std::unordered_map<uint32_t, std::size_t>& current, double tol_m) {
    std::vector<double> err(segs.size(), 0.0);
    for (std::size_t k = 1; k < segs.size();) {
        if (current.count(ids[k])) { ++k; continue; }
        const CubicBezier& L = segs[k - 1];
        const CubicBezier& R = segs[k];
        const double a = glm::length(L.b3 - L.b2), b = glm::length(R.b1 - R.b0);
        bool merged = false;
        if (a > 0.0 && b > 0.0) {
            const double u = a / (a + b);
            const CubicBezier C{L.b0, L.b0 + (L.b1 - L.b0) / u, R.b3 + (R.b2 - R.b3) / (1.0 - u), R.b3};
            double e = 0.0;
            for (int i = 0; i <= 16; ++i) {
                const double t = i / 16.0;
                e = std::max(e, glm::length(position(C, u * t) - position(L, t)));
                e = std::max(e, glm::length(position(C, u + (1.0 - u) * t) - position(R, t)));
            }
            const double total = std::max(err[k - 1], err[k]) + e;
            if (total <= tol_m) {
                segs[k - 1] = C, err[k - 1] = total;
                segs.erase(segs.begin() + static_cast<std::ptrdiff_t>(k));
                err.erase(err.begin() + static_cast<std::ptrdiff_t>(k));
                ids.erase(ids.begin() + static_cast<std::ptrdiff_t>(k));
                merged = true;
            }
        }
        if (!merged) ++k;
    }
}

}  // namespace

double rendered_jump_m(const Curve& before, const Curve& after, int per_segment) { return curve_jump_m(before, after, per_segment); }

MultiresCurve::MultiresCurve(const MultiresSettings& settings) : settings_(settings) {
    if (settings_.blend_frames <= 0) settings_.blend_frames = 8;
    if (!(settings_.max_step_m > 0.0)) settings_.max_step_m = 0.5e-3;
    if (settings_.max_blend_frames <= 0) settings_.max_blend_frames = 240;
}

void MultiresCurve::reset() {
    has_state_ = false;
    target_ = Curve{}, rendered_ = Curve{};
    target_ids_.clear(), rendered_ids_.clear(), blends_.clear();
}

Status MultiresCurve::update(const WireNodes& nodes, Curve& rendered) {
    Curve T;
    if (Status st = build_curve(nodes, settings_.spline, T); !st) {
        rendered = rendered_;
        return st;
    }
    const std::size_t tn = T.node_count();
    std::vector<uint32_t> tid(tn);
    for (std::size_t j = 0; j < tn; ++j) tid[j] = nodes.ids.empty() ? T.source_node[j] : nodes.ids[T.source_node[j]];

    auto show_target = [&](int reason) {
        if (has_state_ && settings_.geomorph) ++unremedied_, last_reason_ = reason;
        blends_.clear();
        rendered_ = T, rendered_ids_ = tid;
        target_ = std::move(T), target_ids_ = std::move(tid);
        has_state_ = true;
        rendered = rendered_;
        return Status::success();
    };
    std::unordered_map<uint32_t, std::size_t> t_index;
    for (std::size_t j = 0; j < tn; ++j) t_index.emplace(tid[j], j);
    // Without ids, nodes are named by index: a count change renames nodes, so only then is there nothing to key on.
    const bool renamed = nodes.ids.empty() && tn != target_ids_.size();
    if (!settings_.geomorph || !has_state_ || T.closed || target_.closed || t_index.size() != tn || renamed) return show_target(1);

    std::unordered_map<uint32_t, std::size_t> prev_index, rend_index;
    for (std::size_t i = 0; i < target_ids_.size(); ++i) prev_index.emplace(target_ids_[i], i);
    for (std::size_t r = 0; r < rendered_ids_.size(); ++r) rend_index.emplace(rendered_ids_[r], r);

    // Common nodes of the previous and the current state, in order along the wire.
    struct Common { std::size_t i, j; };
    std::vector<Common> commons;
    for (std::size_t j = 0; j < tn; ++j) {
        const auto it = prev_index.find(tid[j]);
        if (it == prev_index.end()) continue;
        if (!commons.empty() && it->second <= commons.back().i) return show_target(2);  // order changed: no remedy
        commons.push_back({it->second, j});
    }
    if (commons.size() < 2) return show_target(3);

    const std::size_t spans = commons.size() - 1;
    std::vector<char> event(spans, 0), affected(spans, 0);
    for (std::size_t s = 0; s < spans; ++s) {
        event[s] = (commons[s + 1].i - commons[s].i != 1) || (commons[s + 1].j - commons[s].j != 1);
    }
    const bool event_before = commons.front().i != 0 || commons.front().j != 0;
    const bool event_after = commons.back().i + 1 != target_ids_.size() || commons.back().j + 1 != tn;
    const SplineKind kind = settings_.spline.kind;
    const std::size_t support = kind == SplineKind::linear ? 0 : kind == SplineKind::c2 ? 3 : 1;
    for (std::size_t s = 0; s < spans; ++s) {
        if (!event[s]) continue;
        const std::size_t lo = s >= support ? s - support : 0, hi = std::min(spans - 1, s + support);
        for (std::size_t t = lo; t <= hi; ++t) affected[t] = 1;
    }
    if (event_before) for (std::size_t t = 0; t < std::min(spans, support); ++t) affected[t] = 1;
    if (event_after) for (std::size_t t = spans - std::min(spans, support); t < spans; ++t) affected[t] = 1;

    // Running blends: those touching an affected span restart (from what is on screen); the others advance.
    std::vector<Blend> kept;
    for (Blend& b : blends_) {
        const auto ia = prev_index.find(b.anchor_a), ib = prev_index.find(b.anchor_b);
        bool drop = ia == prev_index.end() || ib == prev_index.end();
        std::vector<std::size_t> overlapping;
        for (std::size_t s = 0; !drop && s < spans; ++s) {
            if (std::max(commons[s].i, ia->second) < std::min(commons[s + 1].i, ib->second)) overlapping.push_back(s);
        }
        for (std::size_t s : overlapping) drop = drop || affected[s];
        if (drop) {
            for (std::size_t s : overlapping) affected[s] = 1;
            continue;
        }
        b.keep -= b.rate;
        if (b.keep <= 1e-12) continue;  // finished: the span now equals the target exactly
        kept.push_back(std::move(b));
    }
    blends_ = std::move(kept);

    // New geomorphs, one per maximal run of affected spans, starting from the rendered curve. A run's inner
    // common nodes become union points like any other (they may sit mid-morph on screen), so only the run's
    // two anchors are pinned to the target, and those are never mid-morph: an anchor is a wire end or borders
    // a span that is shown as the target or by a running blend, whose own anchors are pinned.
    for (std::size_t s = 0; s < spans; ++s) {
        if (!affected[s]) continue;
        std::size_t e = s;
        while (e + 1 < spans && affected[e + 1]) ++e;
        const std::size_t run_first = s, run_last = e;
        s = e;
        const uint32_t id_a = tid[commons[run_first].j], id_b = tid[commons[run_last + 1].j];
        const auto ra = rend_index.find(id_a), rb = rend_index.find(id_b);
        if (ra == rend_index.end() || rb == rend_index.end() || ra->second >= rb->second) return show_target(4);
        // The old chain is what was on screen; ghosts whose two pieces merge back into one cubic within
        // prune_m are dropped first, so ghosts do not pile up while events keep restarting the morph.
        std::vector<CubicBezier> old_segs(rendered_.segments.begin() + static_cast<std::ptrdiff_t>(ra->second),
                                          rendered_.segments.begin() + static_cast<std::ptrdiff_t>(rb->second));
        std::vector<uint32_t> old_ids(rendered_ids_.begin() + static_cast<std::ptrdiff_t>(ra->second),
                                      rendered_ids_.begin() + static_cast<std::ptrdiff_t>(rb->second) + 1);
        prune_ghosts(old_segs, old_ids, t_index, 0.1 * settings_.max_step_m);
        const Chain old_chain{old_segs.data(), old_segs.size()};
        const std::size_t j0 = commons[run_first].j;
        const Chain new_chain{T.segments.data() + j0, commons[run_last + 1].j - j0};
        std::vector<uint32_t> new_ids(tid.begin() + static_cast<std::ptrdiff_t>(j0),
                                      tid.begin() + static_cast<std::ptrdiff_t>(j0 + new_chain.count) + 1);
        std::vector<UnionPoint> pts;
        if (!union_points(old_chain, old_ids, new_chain, new_ids, pts)) return show_target(5);

        Blend b;
        b.anchor_a = id_a, b.anchor_b = id_b;
        const double old_end = static_cast<double>(old_chain.count), new_end = static_cast<double>(new_chain.count);
        double prev_old = 0.0, prev_new = 0.0, max_d = 0.0;
        for (std::size_t q = 0; q <= pts.size(); ++q) {
            const double o = q < pts.size() ? pts[q].old_param : old_end, n = q < pts.size() ? pts[q].new_param : new_end;
            CubicBezier d = old_chain.piece(prev_old, o) - new_chain.piece(prev_new, n);
            if (q == 0) d.b0 = dvec3(0.0);
            if (q == pts.size()) d.b3 = dvec3(0.0);
            max_d = std::max(max_d, max_displacement(d));
            b.offset.push_back(d);
            prev_old = o, prev_new = n;
        }
        for (const UnionPoint& p : pts) {
            const double k = std::min(std::floor(p.new_param), new_end - 1.0);
            b.points.push_back({static_cast<uint32_t>(k), p.new_param - k, p.id, p.ghost});
        }
        if (!(max_d > 0.0)) continue;  // nothing moves: show the target directly
        // Constant speed: at most max_step_m per frame for every curve point, done in [blend_frames, max_blend_frames].
        const double min_frames = settings_.blend_frames, max_frames = std::max(settings_.max_blend_frames, settings_.blend_frames);
        b.rate = std::clamp(settings_.max_step_m / max_d, 1.0 / max_frames, 1.0 / min_frames);
        b.keep = 1.0;
        blends_.push_back(std::move(b));
    }

    // Assemble: target segments, except where a blend renders its span in the union topology.
    struct Placed { std::size_t ja, jb; const Blend* blend; };
    std::vector<Placed> placed;
    for (const Blend& b : blends_) {
        const auto ja = t_index.find(b.anchor_a), jb = t_index.find(b.anchor_b);
        if (ja == t_index.end() || jb == t_index.end() || ja->second >= jb->second) return show_target(6);
        placed.push_back({ja->second, jb->second, &b});
    }
    std::sort(placed.begin(), placed.end(), [](const Placed& a, const Placed& b) { return a.ja < b.ja; });
    for (std::size_t p = 1; p < placed.size(); ++p) {
        if (placed[p].ja < placed[p - 1].jb) return show_target(7);  // overlapping spans: cannot happen; be safe
    }

    Curve out;
    std::vector<uint32_t> ids;
    auto push_node = [&](uint32_t id, uint32_t source, float radius) {
        ids.push_back(id), out.source_node.push_back(source), out.radius_m.push_back(radius);
    };
    std::size_t next = 0;
    std::size_t j = 0;
    const std::size_t segs = T.segment_count();
    while (j < segs) {
        if (next < placed.size() && placed[next].ja == j) {
            const Placed& pl = placed[next++];
            const Blend& b = *pl.blend;
            const Chain chain{T.segments.data() + pl.ja, pl.jb - pl.ja};
            const double keep = b.keep;
            double prev = 0.0;
            push_node(tid[pl.ja], T.source_node[pl.ja], T.radius_m[pl.ja]);
            for (std::size_t q = 0; q <= b.points.size(); ++q) {
                const double p = q < b.points.size() ? b.points[q].segment + b.points[q].u : static_cast<double>(chain.count);
                out.segments.push_back(add_scaled(chain.piece(prev, p), b.offset[q], keep));
                const std::size_t seg = std::min(static_cast<std::size_t>(std::floor(prev)), chain.count - 1);
                out.stretch.push_back(T.stretch[pl.ja + seg]);
                if (q < b.points.size()) {
                    const Point& pt = b.points[q];
                    const std::size_t node = pl.ja + pt.segment;
                    const float r = static_cast<float>((1.0 - pt.u) * T.radius_m[node] + pt.u * T.radius_m[node + 1]);
                    push_node(pt.id, T.source_node[node], r);
                }
                prev = p;
            }
            j = pl.jb;
        } else {
            push_node(tid[j], T.source_node[j], T.radius_m[j]);
            out.segments.push_back(T.segments[j]);
            out.stretch.push_back(T.stretch[j]);
            ++j;
        }
    }
    push_node(tid[tn - 1], T.source_node[tn - 1], T.radius_m[tn - 1]);
    out.closed = false;
    if (std::unordered_set<uint32_t>(ids.begin(), ids.end()).size() != ids.size()) return show_target(8);  // a ghost id came back

    rendered_ = out, rendered_ids_ = std::move(ids);
    target_ = std::move(T), target_ids_ = std::move(tid);
    has_state_ = true;
    rendered = std::move(out);
    return Status::success();
}

}  // namespace wire
