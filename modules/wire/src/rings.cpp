// Ring records: centres, frames, radius, stretch-aware texture u, fold detection.
#include "wire/rings.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

namespace wire {
namespace {

// 5-point Gauss-Legendre on [0,1]: nodes (1 + x_k)/2, weights w_k/2.
constexpr double kGlX[5] = {0.0469100770306680, 0.2307653449471585, 0.5, 0.7692346550528415, 0.9530899229693320};
constexpr double kGlW[5] = {0.1184634425280945, 0.2393143352496832, 0.2844444444444444, 0.2393143352496832,
                            0.1184634425280945};

/// Fritsch-Carlson-limited slope (per unit t) at node k from its neighbours' radii.
double node_slope(const Curve& curve, std::size_t k) {
    const std::size_t n = curve.radius_m.size();
    const bool closed = curve.closed;
    const bool has_left = closed || k > 0;
    const bool has_right = closed || k + 1 < n;
    const double rk = curve.radius_m[k];
    const double dl = has_left ? rk - curve.radius_m[(k + n - 1) % n] : 0.0;
    const double dr = has_right ? curve.radius_m[(k + 1) % n] - rk : 0.0;
    if (!has_left) return dr;
    if (!has_right) return dl;
    if (dl * dr <= 0.0) return 0.0;  // local extremum: flat, so no overshoot
    const double m = 0.5 * (dl + dr);
    const double lim = 3.0 * std::min(std::abs(dl), std::abs(dr));
    return std::clamp(m, -lim, lim);
}

struct Interval {
    double length_m;
    double u;  // integral of |B'| / (2 pi R stretch) dt
};

/// Length and texture advance over segment `seg` from ta to tb.
Interval integrate(const Curve& curve, uint32_t seg, double ta, double tb, double stretch) {
    Interval out{0.0, 0.0};
    const double h = tb - ta;
    if (!(h > 0.0)) {
        return out;
    }
    const CubicBezier& c = curve.segments[seg];
    for (int k = 0; k < 5; ++k) {
        const double t = ta + h * kGlX[k];
        const double speed = glm::length(derivative(c, t));
        const double w = h * kGlW[k];
        out.length_m += w * speed;
        out.u += w * speed / std::max(radius_at(curve, seg, t), 1e-30);
    }
    out.u /= 2.0 * std::numbers::pi * stretch;
    return out;
}

}  // namespace

double radius_at(const Curve& curve, uint32_t segment, double t) {
    const std::size_t n = curve.radius_m.size();
    if (n == 0) {
        return 1.0;
    }
    const std::size_t a = std::min<std::size_t>(segment, n - 1);
    const std::size_t b = curve.closed ? (a + 1) % n : std::min(a + 1, n - 1);
    const double r0 = curve.radius_m[a];
    const double r1 = curve.radius_m[b];
    const double m0 = node_slope(curve, a);
    const double m1 = node_slope(curve, b);
    const double t2 = t * t;
    const double t3 = t2 * t;
    return (2 * t3 - 3 * t2 + 1) * r0 + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * r1 + (t3 - t2) * m1;
}

void build_rings(const Curve& curve, std::span<const RingParam> params, const RingSettings& settings, RingSet& out) {
    const std::size_t n = params.size();
    out.closed = curve.closed;
    out.params.assign(params.begin(), params.end());
    out.rings.resize(n);
    out.frames.resize(n);
    out.centre_m.resize(n);
    out.tangent_scratch.resize(n);
    const std::size_t extra = curve.closed && n > 0 ? 1 : 0;
    out.arc_length_m.resize(n + extra);
    out.u.resize(n + extra);
    out.fold_count = 0;
    out.first_fold_ring = 0;
    out.length_m = 0.0;
    if (n == 0) {
        out.frame_stats = FrameStats{};
        return;
    }
    assert(curve.stretch.size() == curve.segment_count() && "build_rings: one stretch per segment");

    out.origin_m = position(curve.segments[params[0].segment], params[0].t);
    for (std::size_t i = 0; i < n; ++i) {
        const RingParam p = params[i];
        const CubicBezier& c = curve.segments[p.segment];
        out.centre_m[i] = position(c, p.t) - out.origin_m;
        out.tangent_scratch[i] = unit_tangent(c, p.t);

        // Fold: the inner side of the tube crosses itself where the radius reaches the curvature radius.
        const glm::dvec3 d1 = derivative(c, p.t);
        const glm::dvec3 d2 = second_derivative(c, p.t);
        const double speed = glm::length(d1);
        const double radius = radius_at(curve, p.segment, p.t);
        const double bend = glm::length(glm::cross(d1, d2));  // = curvature * speed^3
        if (radius * bend >= speed * speed * speed && bend > 0.0) {
            if (out.fold_count++ == 0) {
                out.first_fold_ring = static_cast<uint32_t>(i);
            }
        }
        out.rings[i].radius_m = static_cast<float>(radius);
        out.rings[i].segment = p.segment;
    }

    // Arc length and u, interval by interval (always within one segment: a step into the next segment ends at t=1).
    double s = 0.0;
    double u = settings.u_start;
    out.arc_length_m[0] = 0.0;
    out.u[0] = u;
    const std::size_t intervals = n - 1 + extra;
    for (std::size_t i = 0; i < intervals; ++i) {
        const RingParam a = params[i];
        const bool wrap = i + 1 == n;
        const RingParam b = wrap ? params[0] : params[i + 1];
        const double tb = (!wrap && b.segment == a.segment) ? b.t : 1.0;
        double stretch = curve.stretch[a.segment];
        if (!(stretch > 0.0) || !std::isfinite(stretch)) {
            stretch = 1.0;
        }
        Interval iv{};
        if (!wrap && b.segment != a.segment && b.segment != a.segment + 1) {
            iv = Interval{0.0, 0.0};  // params skipped segments: callers pass place_rings() output
        } else {
            iv = integrate(curve, a.segment, a.t, tb, stretch);
            // A step into the next segment that does not start at t = 0 (custom params) adds that segment's part.
            if (!wrap && b.segment != a.segment && b.t > 0.0) {
                double stretch_b = curve.stretch[b.segment];
                stretch_b = (stretch_b > 0.0 && std::isfinite(stretch_b)) ? stretch_b : 1.0;
                const Interval ib = integrate(curve, b.segment, 0.0, b.t, stretch_b);
                iv.length_m += ib.length_m;
                iv.u += ib.u;
            }
        }
        s += iv.length_m;
        u += iv.u;
        out.arc_length_m[i + 1] = s;
        out.u[i + 1] = u;
    }
    out.length_m = s;

    const FrameInput in{&curve, params, out.origin_m, out.centre_m, out.tangent_scratch, out.arc_length_m};
    out.frame_stats = compute_frames(in, settings.frames, out.frames);

    for (std::size_t i = 0; i < n; ++i) {
        Ring& r = out.rings[i];
        r.centre_m = glm::vec3(out.centre_m[i]);
        r.normal = glm::vec3(out.frames[i].r);
        r.binormal = glm::vec3(out.frames[i].s);
        r.u = static_cast<float>(out.u[i]);
    }
}

}  // namespace wire
