// Ring records: centres, frames, radius, stretch-aware texture u, fold detection. The per-segment tables
// and lane kernels are in rings_tables.cpp.
#include "wire/rings.hpp"
#include "rings_internal.hpp"

#include "wire/detail/segment_soa.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace wire {
namespace detail {

/// Fritsch-Carlson-limited slope (per unit t) at node k from its neighbours' radii.
double node_slope(const Curve& curve, std::size_t k) {
    const std::size_t n = curve.radius_m.size();
    const bool closed = curve.closed;
    const bool has_left = closed || k > 0;
    const bool has_right = closed || k + 1 < n;
    const double rk = curve.radius_m[k];
    const double dl = has_left ? rk - curve.radius_m[k == 0 ? n - 1 : k - 1] : 0.0;
    const double dr = has_right ? curve.radius_m[k + 1 == n ? 0 : k + 1] - rk : 0.0;
    if (!has_left) return dr;
    if (!has_right) return dl;
    if (dl * dr <= 0.0) return 0.0;  // local extremum: flat, so no overshoot
    const double m = 0.5 * (dl + dr);
    const double lim = 3.0 * std::min(std::abs(dl), std::abs(dr));
    return std::clamp(m, -lim, lim);
}

}  // namespace detail

using detail::kGlPoints;
using detail::kGlW;
using detail::kGlX;
using detail::ring_samples;
using detail::SegmentCoeffs;
using detail::SegmentTables;
using detail::whole_vectors;

namespace {

struct Interval {
    double length_m;
    double u;  // integral of |B'| / (2 pi R stretch) dt
};

/// Length and texture advance over one segment from ta to tb (Gauss-Legendre).
Interval integrate(const SegmentCoeffs& c, double ta, double tb) {
    Interval out{0.0, 0.0};
    const double h = tb - ta;
    if (!(h > 0.0)) {
        return out;
    }
    if (c.constant_radius) {
        for (int k = 0; k < kGlPoints; ++k) out.length_m += (h * kGlW[k]) * glm::length(c.derivative(ta + h * kGlX[k]));
        out.u = out.length_m * c.u_per_m;
        return out;
    }
    for (int k = 0; k < kGlPoints; ++k) {
        const double t = ta + h * kGlX[k];
        const double speed = glm::length(c.derivative(t));
        const double w = h * kGlW[k];
        out.length_m += w * speed;
        out.u += w * speed / std::max(c.radius(t), 1e-30);
    }
    out.u *= c.u_scale;
    return out;
}

}  // namespace

double radius_at(const Curve& curve, uint32_t segment, double t) {
    return SegmentCoeffs(curve, segment).radius(t);
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

    out.origin_m = position(curve.segments[params[0].segment], params[0].t);
    // Whole segments (crossed ones, and a ring at t = 0 whose next ring is on a later segment): from one table.
    thread_local SegmentTables tables;  // grows once per thread, then reused
    // Boundary tangents only where some interval crosses a segment boundary (LOD below node resolution; the closed
    // wire's wrap step computes its own).
    bool crossing = false;
    for (std::size_t i = 1; i < n && !crossing; ++i) {
        crossing = params[i].segment + (params[i].t > 0.0 ? 1u : 0u) > params[i - 1].segment + 1u;
    }
    tables.build(curve, crossing);
    // The segment a partial interval or a slow tangent of ring `ring` is evaluated on, loaded when first needed
    // (rarely): for the leading rings on ring 0's segment by load() itself, for the others with the table's radius
    // polynomial (no node slopes again): the coefficients each ring had when every ring loaded its segment.
    std::size_t lead = 1;
    while (lead < n && params[lead].segment == params[0].segment) ++lead;
    SegmentCoeffs seg;
    uint32_t seg_index = params[0].segment;
    int loaded = -1;  // 0: load() of ring 0's segment, 1: the table's for seg_index
    auto use_segment = [&](std::size_t ring) {
        const uint32_t i = params[ring].segment;
        if (ring < lead) {
            if (loaded != 0) seg.load(curve, i);
            loaded = 0;
        } else if (loaded != 1 || i != seg_index) {
            seg.load_geometry(curve.segments[i]);
            tables.load_radius(i, seg);
            loaded = 1;
        }
        seg_index = i;
    };
    const std::vector<double>& whole_length_m = tables.length_m;
    const std::vector<double>& whole_u = tables.u;
    // Centre, tangent, radius and fold test of every ring in lanes (ring_samples), from the rings' segments
    // gathered into structure-of-arrays scratch with their radius polynomials.
    std::vector<double>& ring_data = tables.ring_data;
    std::vector<uint32_t>& ring_segment = tables.ring_segment;
    const std::size_t rn = whole_vectors(n);  // whole vectors, the rest copies of the last ring (see SegmentTables)
    ring_segment.resize(rn);
    ring_data.resize(26 * rn);
    double* const ring_b = ring_data.data();  // 12 arrays: the rings' segments, gather_segments()
    double* const ring_t = ring_b + 12 * rn;  // t
    double* const ring_r = ring_t + rn;       // 4 arrays: radius polynomial r0 .. r3
    double* const sample = ring_r + 4 * rn;   // 9 arrays: ring_samples()'s output
    for (std::size_t i = 0; i < rn; ++i) {
        const RingParam& p = params[std::min(i, n - 1)];
        ring_segment[i] = p.segment;
        ring_t[i] = p.t;
    }
    tables.radius_of(ring_segment.data(), rn, ring_r);
    detail::gather_segments(curve.segments.data(), ring_segment.data(), rn, ring_b);
    // The rings on ring 0's segment use load()'s radius polynomial, as use_segment() gives it to them (the table's
    // is the same unless a radius is not finite).
    SegmentCoeffs first;
    first.load_polynomial(curve, params[0].segment);
    for (std::size_t i = 0; i < lead; ++i) {
        ring_r[i] = first.r0;
        ring_r[rn + i] = first.r1;
        ring_r[2 * rn + i] = first.r2;
        ring_r[3 * rn + i] = first.r3;
    }
    ring_samples(ring_b, rn, ring_t, ring_r, out.origin_m.x, out.origin_m.y, out.origin_m.z, sample, sample + rn,
                 sample + 2 * rn, sample + 3 * rn, sample + 4 * rn, sample + 5 * rn, sample + 6 * rn, sample + 7 * rn,
                 sample + 8 * rn);
    double s = 0.0;
    double u = settings.u_start;
    for (std::size_t i = 0; i < n; ++i) {
        const RingParam p = params[i];
        out.centre_m[i] = glm::dvec3(sample[i], sample[rn + i], sample[2 * rn + i]);
        if (sample[8 * rn + i] == 0.0) {
            out.tangent_scratch[i] = glm::dvec3(sample[3 * rn + i], sample[4 * rn + i], sample[5 * rn + i]);
        } else {  // not surely above the noise: SegmentCoeffs::tiny_speed() decides (rare)
            use_segment(i);
            const glm::dvec3 d1 = seg.derivative(p.t);
            const double speed = std::sqrt(glm::dot(d1, d1));
            // vanishing derivative: the one-sided limits of unit_tangent()
            out.tangent_scratch[i] =
                speed > seg.tiny_speed() ? d1 * (1.0 / speed) : unit_tangent(curve.segments[p.segment], p.t);
        }
        // Fold: the inner side of the tube crosses itself where the radius reaches the curvature radius
        // |B'|^3 / |B' x B''| (ring_samples compares them squared, without a root).
        if (sample[7 * rn + i] != 0.0) {
            if (out.fold_count++ == 0) {
                out.first_fold_ring = static_cast<uint32_t>(i);
            }
        }
        Ring& ring = out.rings[i];
        ring.radius_m = static_cast<float>(sample[6 * rn + i]);
        ring.segment = p.segment;

        // Arc length and u of the interval to the next ring: the rest of this segment, every segment the interval
        // crosses (LOD below the node resolution gives segments no ring of their own), and the next ring's part of
        // its segment; for a closed wire the last interval returns to ring 0.
        if (i == 0) {
            out.arc_length_m[0] = 0.0;
            out.u[0] = u;
        }
        if (i + 1 < n || extra) {
            const bool wrap = i + 1 == n;
            const RingParam b = wrap ? params[0] : params[i + 1];
            const double tb = (!wrap && b.segment == p.segment) ? b.t : 1.0;
            Interval iv{whole_length_m[p.segment], whole_u[p.segment]};
            if (p.t != 0.0 || tb != 1.0) {
                use_segment(i);
                iv = integrate(seg, p.t, tb);
            }
            if (wrap || b.segment != p.segment) {
                const std::size_t end = wrap ? curve.segment_count() : b.segment;
                for (std::size_t k = p.segment + 1; k < end; ++k) {  // crossed segments, whole
                    iv.length_m += whole_length_m[k];
                    iv.u += whole_u[k];
                }
            }
            if (!wrap && b.segment != p.segment && b.t > 0.0) {  // custom params: the next segment's part too
                // At t = 1 (an open wire's last ring, on a segment without a ring of its own): the whole segment,
                // from the table.
                const Interval ib = b.t == 1.0 && tables.exact()
                                        ? Interval{whole_length_m[b.segment], whole_u[b.segment]}
                                        : integrate(SegmentCoeffs(curve, b.segment), 0.0, b.t);
                iv.length_m += ib.length_m;
                iv.u += ib.u;
            }
            s += iv.length_m;
            u += iv.u;
            out.arc_length_m[i + 1] = s;
            out.u[i + 1] = u;
        }
    }
    out.length_m = s;

    const FrameInput in{&curve,           params,         out.origin_m, out.centre_m, out.tangent_scratch,
                        out.arc_length_m, tables.tangent, tables.soa};
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
