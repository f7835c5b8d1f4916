// The curve stage: a wire's nodes -> its Bezier segments (spline.hpp): the checks, the merge, each spline kind's
// Hermite tangents, the tangent systems' solves (two or four wires side by side) and the records; the nu-spline
// system's setup and the segment tangents from node tangents are in spline/hermite.cpp.
#include "wire/spline.hpp"

#include "spline/hermite.hpp"
#include "spline/kernels.hpp"
#include "spline/merge.hpp"
#include "spline/scratch.hpp"
#include "spline/tension.hpp"
#include "spline/tridiagonal.hpp"
#include "spline/validate.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace wire {

using namespace curve_stage;

namespace {

// The log-domain knot ratio's clamp, exp(-+300), for the pow-free alphas.
const double kMinKnotRatio = std::exp(-300.0);
const double kMaxKnotRatio = std::exp(300.0);

}  // namespace

double curvature_tension(double theta_rad, double iz_m4, double length_m, double delta_length_m, double area_m2) {
    const double den = area_m2 * delta_length_m * delta_length_m;
    if (!(den > 0.0) || !std::isfinite(den)) return 0.0;
    const double R = std::abs(theta_rad * iz_m4 * length_m) / den;
    if (!(R <= 100.0)) return 0.0;
    return 1.0 - std::tanh(R / 50.0);
}

// Empties `c` keeping its capacity: a Curve reused across frames does not allocate.
void clear_curve(Curve& c) {
    c.segments.clear(), c.source_node.clear(), c.radius_m.clear(), c.stretch.clear();
    c.closed = false;
}

namespace {

// One wire's working memory in the curve stage (per thread, reused: no allocation per call once it is large
// enough), and what its build carries from begin_curve to end_curve.
struct CurveBuild {
    Merged m;
    Chords ch;
    Tangents tg;
    std::vector<double> g, gs, w;  // automatic: tension weights
    Pool pool;                     // c2, automatic: the tangent system
    TangentSolve ts;
    const dvec3* P = nullptr;  // the curve's nodes (merged)
    std::size_t n = 0, segs = 0;
    bool physics = false;  // the physics arrays drive a curvature tension
    bool solved = false;   // c2, automatic: node tangents in ts (once ts.pending is solved)
};

// Catmull-Rom / Kochanek-Bartels segment tangents into build.tg (see spline.hpp).
void catmull_rom_tangents(const WireNodes& nodes, const SplineSettings& settings, CurveBuild& build) {
    const Merged& m = build.m;
    const Chords& ch = build.ch;
    Tangents& tg = build.tg;
    const std::size_t n = build.n, segs = build.segs;
    const bool closed = settings.closed, physics = build.physics;
    const double alpha = settings.alpha;
    for (std::size_t j = 0; j < n; ++j) {
        const uint32_t src = m.first[j];
        const bool has_in = closed || j > 0, has_out = closed || j + 1 < n;
        const std::size_t kin = has_in ? (j == 0 ? segs - 1 : j - 1) : 0;
        const std::size_t kout = has_out ? (j == segs ? 0 : j) : segs - 1;
        // Open ends reflect the missing neighbour (P[-1] = 2P[0]-P[1]): the missing chord equals the other.
        const dvec3 din = has_in ? ch.d(kin) : ch.d(kout);
        const dvec3 dout = has_out ? ch.d(kout) : ch.d(kin);
        const double lin = has_in ? ch.l(kin) : ch.l(kout);
        const double lout = has_out ? ch.l(kout) : ch.l(kin);

        const double t_user = nodes.kb_tension.empty() ? settings.tension : nodes.kb_tension[src];
        const double b = nodes.kb_bias.empty() ? settings.bias : nodes.kb_bias[src];
        const double c = nodes.kb_continuity.empty() ? settings.continuity : nodes.kb_continuity[src];
        double t_curv = 0.0;
        if (physics) {
            t_curv = curvature_tension(nodes.theta_rad[src], nodes.iz_m4[src], nodes.length_m[src],
                                       nodes.delta_length_m[src], nodes.area_m2[src]);
        }
        const double t = 1.0 - (1.0 - t_user) * (1.0 - t_curv);
        const double keep = 1.0 - t;

        // Only the knot ratio matters; computed in the log domain so extreme alpha or spacing cannot give 0/0.
        // alpha 1 and 0.5 (chordal, centripetal): the ratio itself and its square root, no log/exp; the
        // same clamp as the log domain's (both lengths are > 0 and finite, so the ratio is never 0/0).
        double rho;
        if (alpha == 1.0 || alpha == 0.5) {
            rho = lout / lin;
            if (alpha == 0.5) rho = std::sqrt(rho);
            rho = std::clamp(rho, kMinKnotRatio, kMaxKnotRatio);
        } else {
            const double lr = alpha == 0.0 ? 0.0 : std::clamp(alpha * (std::log(lout) - std::log(lin)), -300.0, 300.0);
            rho = std::exp(lr);
        }
        const double w = rho / (1.0 + rho), iw = 1.0 / (1.0 + rho);  // w + iw = 1
        const dvec3 start = keep * (((1.0 + b) * (1.0 + c) * rho * w) * din + ((1.0 - b) * (1.0 - c) * iw) * dout);
        const dvec3 end = keep * (((1.0 + b) * (1.0 - c) * w) * din + ((1.0 - b) * (1.0 + c) * iw / rho) * dout);
        if (has_out) tg.set0(kout, start);
        if (has_in) tg.set1(kin, end);
    }
}

// build_curve without its clearing of `out` on entry, in two halves around the tridiagonal solve of c2 and
// automatic curves (b.ts.pending: solve() or thomas_pair() runs it in between). Every field of `out` is
// overwritten on success (the segments resized, not cleared first: a curve reused for the same wire is not
// zero-filled before it is written), and build_curve clears it on failure.
Status begin_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out, CurveBuild& b) {
    b.ts.pending = false, b.solved = false;
    if (Status st = check_settings(settings); !st) return st;
    if (Status st = check_sizes(nodes); !st) return st;
    const bool physics = settings.curvature_tension && !nodes.theta_rad.empty() && !nodes.iz_m4.empty() &&
                         !nodes.length_m.empty() && !nodes.delta_length_m.empty() && !nodes.area_m2.empty();
    if (Status st = check_nodes(nodes, physics); !st) return st;

    Merged& m = b.m;
    Chords& ch = b.ch;
    std::size_t n = 0;
    const dvec3* const P = merge_nodes(nodes, settings, m, ch, n);
    const bool closed = settings.closed;
    if (Status st = check_distinct(nodes.size(), n, closed); !st) return st;
    const std::size_t segs = closed ? n : n - 1;

    std::vector<float>& seg_stretch = out.stretch;  // built in place
    seg_stretch.assign(segs, 1.0f);
    if (!nodes.stretch.empty()) {
        for (std::size_t k = 0; k < segs; ++k) seg_stretch[k] = nodes.stretch[m.last[k]];
    }

    b.P = P, b.n = n, b.segs = segs, b.physics = physics;

    // Segment tangents (t0 at a segment's start, t1 at its end); c2 and automatic: node tangents, from the
    // tangent system set up here and solved before end_curve.
    Tangents& tg = b.tg;
    tg.resize(segs);
    const SplineKind kind = settings.kind;
    if (kind == SplineKind::linear) {
        for (std::size_t k = 0; k < segs; ++k) tg.set0(k, ch.d(k)), tg.set1(k, ch.d(k));
    } else if (kind == SplineKind::c2) {
        // C2 interpolating spline with chordal knots (not-a-knot ends; the parabola through 3 nodes): the
        // automatic spline's system with no node tensed (w = 0 everywhere, ends purely not-a-knot).
        const double* const untensed = zeros(n);
        start_tangents(ch, n, closed, untensed, untensed, untensed, b.pool, b.ts);
        b.solved = true;
    } else if (kind == SplineKind::automatic) {
        if (concentrated_turns(ch, n, closed, b.g, b.gs, b.w)) {
            start_tangents(ch, n, closed, b.g.data(), b.gs.data(), b.w.data(), b.pool, b.ts);
        } else {
            const double* const untensed = zeros(n);
            start_tangents(ch, n, closed, untensed, untensed, untensed, b.pool, b.ts);
        }
        b.solved = true;
    } else {
        catmull_rom_tangents(nodes, settings, b);
    }
    return Status::success();
}

Status end_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out, CurveBuild& b) {
    const Merged& m = b.m;
    const Chords& ch = b.ch;
    Tangents& tg = b.tg;
    const dvec3* const P = b.P;
    const std::size_t n = b.n, segs = b.segs;
    const bool closed = settings.closed, physics = b.physics;
    // The records are written from the node tangents (c2, and an automatic spline that no tension scales) or
    // from segment tangents.
    NodeTangents node_form{};
    if (b.solved) node_form = finish_tangents(b.ts);
    if (settings.kind == SplineKind::automatic) {
        // Tension (wire, node, curvature-driven) scales both tangents at a node, as for catmull_rom (G1 kept;
        // C2 only where it is 0). Nothing to scale with the wire's tension 0 and no per-node or physics input.
        if (!nodes.kb_tension.empty() || physics || settings.tension != 0.0) {
            segment_tangents(node_form, ch, tg);
            node_form = {};
            for (std::size_t j = 0; j < n; ++j) {
                const uint32_t src = m.first[j];
                const double t_user = nodes.kb_tension.empty() ? settings.tension : nodes.kb_tension[src];
                const double t_curv =
                    physics ? curvature_tension(nodes.theta_rad[src], nodes.iz_m4[src], nodes.length_m[src],
                                                nodes.delta_length_m[src], nodes.area_m2[src])
                            : 0.0;
                const double keep = (1.0 - t_user) * (1.0 - t_curv);
                if (keep == 1.0) continue;
                if (closed || j + 1 < n) tg.scale0(j == segs ? 0 : j, keep);
                if (closed || j > 0) tg.scale1(j == 0 ? segs - 1 : j - 1, keep);
            }
        }
    }

    // The Bezier records (inner control points B1 = P0 + t0/3, B2 = P1 - t1/3) and the range check of the inner
    // control points. Finite is not enough: a control point past the coordinate range (an extreme alpha)
    // overflows the tube's float vertices downstream.
    constexpr double kMaxControl_m = 10.0 * kMaxCoordinate_m;
    // The node-tangent records test the offsets t/3 instead (in their structure-of-arrays form, before they are
    // interleaved into records): the nodes are within +-kMaxCoordinate_m (check_nodes), so offsets within
    // +-kMaxOffset_m give control points within +-9e12 (rounding is monotonic and 9e12 is a double). Sufficient,
    // not necessary: when it fails, the exact test below decides (a control point just in range passes it).
    constexpr double kMaxOffset_m = kMaxControl_m - 2.0 * kMaxCoordinate_m;
    static_assert(sizeof(CubicBezier) == 12 * sizeof(double));
    out.segments.resize(segs);
    CubicBezier* const seg = out.segments.data();
    const auto segments = [&](std::size_t k0, std::size_t count, const dvec3* p0, const dvec3* p1) {
        if (node_form.x != nullptr) {
            return node_segments(count, &p0->x, &p1->x, node_form.x + k0, node_form.y + k0, node_form.z + k0,
                                 ch.len.data() + 1 + k0, &seg[k0].b0.x, kMaxOffset_m);
        }
        return segments_kernel(count, &p0->x, &p1->x, tg.t0x + k0, tg.t0y + k0, tg.t0z + k0, tg.t1x + k0, tg.t1y + k0,
                               tg.t1z + k0, &seg[k0].b0.x, kMaxControl_m);
    };
    bool in_range = segments(0, n - 1, P, P + 1);
    if (closed) in_range &= segments(n - 1, 1, P + (n - 1), P);
    if (!in_range) {
        for (std::size_t k = 0; k < segs; ++k) {
            if (values_within(&seg[k].b1.x, 6, kMaxControl_m)) continue;
            const uint32_t src = m.first[k];
            clear_curve(out);
            return Status::error(node_prefix(src) + "tangent overflowed (alpha " + describe(settings.alpha) +
                                     " is too extreme for this node spacing)",
                                 static_cast<int>(src));
        }
    }
    out.closed = closed;
    out.source_node = m.first;
    const float wire_radius = settings.radius_m > 0.0f ? settings.radius_m : kDefaultWireRadius_m;
    if (nodes.radius_m.empty()) {
        out.radius_m.assign(n, wire_radius);
    } else {
        out.radius_m.resize(n);
        for (std::size_t j = 0; j < n; ++j) {
            const float r = nodes.radius_m[m.first[j]];
            out.radius_m[j] = r > 0.0f ? r : wire_radius;
        }
    }
    return Status::success();
}

// A thread's build memory: build_curve uses the first, build_curves (and build_curve_pair) one per wire (nothing
// calls build_curve between a group's begin_curve and end_curve), so a thread keeps at most two builds' worth for
// its largest wires and two more for wires of up to 1,024 nodes (build_curves' kGroupNodes).
CurveBuild& thread_build(std::size_t k) {
    thread_local CurveBuild b[4];
    return b[k];
}

}  // namespace

Status build_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out) {
    CurveBuild& b = thread_build(0);
    Status st = begin_curve(nodes, settings, out, b);
    if (st && b.ts.pending) solve(b.ts);
    if (st) st = end_curve(nodes, settings, out, b);
    if (!st) clear_curve(out);
    return st;
}

void build_curves(std::span<CurveBuildJob> jobs) {
    if (jobs.size() > 4) {  // four at a time, in order
        for (std::size_t first = 0; first < jobs.size(); first += 4) {
            build_curves(jobs.subspan(first, std::min<std::size_t>(4, jobs.size() - first)));
        }
        return;
    }
    const std::size_t count = jobs.size();
    // Two jobs writing one curve cannot be built side by side: what build_curve calls in order leave (the later
    // job's curve).
    for (std::size_t k = 1; k < count; ++k) {
        for (std::size_t l = 0; l < k; ++l) {
            if (jobs[k].out != jobs[l].out) continue;
            for (CurveBuildJob& job : jobs) job.status = build_curve(*job.nodes, *job.settings, *job.out);
            return;
        }
    }
    // Four builds in flight keep four builds' working memory per thread: only wires of up to kGroupNodes nodes
    // take the third and fourth (a group with a larger wire is built as two pairs, in the first two builds).
    constexpr std::size_t kGroupNodes = 1024;
    const auto large = [](const CurveBuildJob& j) { return j.nodes->size() > kGroupNodes; };
    if (count > 2 && std::any_of(jobs.begin(), jobs.begin() + count, large)) {
        build_curves(jobs.first(2));
        build_curves(jobs.subspan(2, count - 2));
        return;
    }
    CurveBuild* b[4] = {};
    for (std::size_t k = 0; k < count; ++k) {  // each build keeps its own memory until its end
        b[k] = &thread_build(k);
        jobs[k].status = begin_curve(*jobs[k].nodes, *jobs[k].settings, *jobs[k].out, *b[k]);
    }
    // The pending solves: four of one size side by side, else pairs of one size, else alone (the same results).
    const auto pending = [&](std::size_t k) { return jobs[k].status.ok() && b[k]->ts.pending; };
    bool solved[4] = {};
#if defined(__GNUC__)
    if (count == 4 && pending(0) && pending(1) && pending(2) && pending(3) && b[0]->ts.m >= 4 &&
        b[1]->ts.m == b[0]->ts.m && b[2]->ts.m == b[0]->ts.m && b[3]->ts.m == b[0]->ts.m) {
        TangentSolve* const s[4] = {&b[0]->ts, &b[1]->ts, &b[2]->ts, &b[3]->ts};
        thomas_quad(s);
        solved[0] = solved[1] = solved[2] = solved[3] = true;
    }
#endif
    for (std::size_t k = 0; k < count; ++k) {
        if (!pending(k) || solved[k]) continue;
        solved[k] = true;
        std::size_t other = k + 1;
        while (other < count && !(pending(other) && !solved[other] && b[other]->ts.m == b[k]->ts.m)) ++other;
        if (other < count && b[k]->ts.m >= 4) {
            thomas_pair(b[k]->ts, b[other]->ts);
            solved[other] = true;
        } else {
            solve(b[k]->ts);
        }
    }
    for (std::size_t k = 0; k < count; ++k) {
        CurveBuildJob& job = jobs[k];
        if (job.status) job.status = end_curve(*job.nodes, *job.settings, *job.out, *b[k]);
        if (!job.status) clear_curve(*job.out);
    }
}

std::pair<Status, Status> build_curve_pair(const WireNodes& nodes0, const SplineSettings& settings0, Curve& out0,
                                           const WireNodes& nodes1, const SplineSettings& settings1, Curve& out1) {
    CurveBuildJob jobs[2] = {{&nodes0, &settings0, &out0, {}}, {&nodes1, &settings1, &out1, {}}};
    build_curves(jobs);
    return {std::move(jobs[0].status), std::move(jobs[1].status)};
}

}  // namespace wire
