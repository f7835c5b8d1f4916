// Rotation-minimizing frames of a wire's rings (compute_frames: first frame, the double-reflection passes,
// closed-loop holonomy removal; the transport step is in frames_transport.cpp); the segment tables.
#include "wire/frames.hpp"
#include "frames_internal.hpp"
#include "wire/detail/segment_soa.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES
#include "simd/transpose.hpp"

#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

namespace wire {

using detail::carry_normal;
using detail::CarryChain;
using detail::max_abs;
using detail::Sample;
using detail::segment_start_points;
using detail::step_matrices;
using detail::Transporter;

namespace detail {

WIRE_VECTOR_CLONES void boundary_tangents(const double* __restrict b, std::size_t n, double* __restrict tx,
                                          double* __restrict ty, double* __restrict tz, double* __restrict ok) {
    for (std::size_t k = 0; k < n; ++k) boundary_tangent(b, n, k, tx, ty, tz, ok);
}

namespace {

/// transpose_segments() of the segments segment(0) .. segment(n - 1): four at a time by three 4x4 transposes.
template <class Segment>
[[gnu::always_inline]] inline void transpose_of(Segment segment, std::size_t n, std::size_t stride, double* out) {
    static_assert(sizeof(CubicBezier) == 12 * sizeof(double), "CubicBezier: 12 doubles, b0 to b3");
    using V = simd::v4d;  // 4 doubles (two SSE registers on the baseline)
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        const double* in[4] = {&segment(k).b0.x, &segment(k + 1).b0.x, &segment(k + 2).b0.x, &segment(k + 3).b0.x};
        for (std::size_t g = 0; g < 3; ++g) {  // doubles 4g .. 4g + 3 of each of the four segments
            V r[4];
            for (std::size_t s = 0; s < 4; ++s) std::memcpy(&r[s], in[s] + 4 * g, sizeof(V));
            V c[4];
            simd::transpose4x4(r, c);
            for (std::size_t j = 0; j < 4; ++j) std::memcpy(out + (4 * g + j) * stride + k, &c[j], sizeof(V));
        }
    }
    for (; k < n; ++k) {
        const double* in = &segment(k).b0.x;
        for (std::size_t j = 0; j < 12; ++j) out[j * stride + k] = in[j];
    }
}

}  // namespace

WIRE_VECTOR_CLONES void transpose_segments(const CubicBezier* segments, std::size_t n, double* out,
                                           std::size_t stride) {
    transpose_of([segments](std::size_t k) -> const CubicBezier& { return segments[k]; }, n, stride ? stride : n, out);
}

WIRE_VECTOR_CLONES void gather_segments(const CubicBezier* segments, const uint32_t* index, std::size_t n,
                                        double* out) {
    transpose_of([segments, index](std::size_t k) -> const CubicBezier& { return segments[index[k]]; }, n, n, out);
}

}  // namespace detail

FrameStats compute_frames(const FrameInput& in, const FrameSettings& settings, std::span<Frame> out) {
    FrameStats stats;
    const std::size_t n = in.params.size();
    assert(out.size() == n && in.centre_m.size() == n && in.tangent.size() == n && "compute_frames: sizes");
    if (n == 0) {
        return stats;
    }
    const bool closed = in.curve != nullptr && in.curve->closed;

    // Tangents: zero ones (a segment that is one point) take the previous ring's, the leading ones the first valid.
    std::size_t first_valid = n;
    for (std::size_t i = 0; i < n; ++i) {
        if (in.tangent[i] != glm::dvec3(0.0)) {
            first_valid = i;
            break;
        }
    }
    glm::dvec3 prev_t = first_valid < n ? in.tangent[first_valid] : glm::dvec3(0.0, 0.0, 1.0);
    for (std::size_t i = 0; i < n; ++i) {
        if (in.tangent[i] == glm::dvec3(0.0)) {
            ++stats.degenerate_tangents;
            out[i].t = prev_t;
        } else {
            out[i].t = in.tangent[i];
            prev_t = in.tangent[i];
        }
    }

    // First frame: carried over from the previous state when possible, else seeded from the least-aligned axis.
    const glm::dvec3 t0 = out[0].t;
    glm::dvec3 r0{};
    if (settings.has_previous_normal) {
        const glm::dvec3 p = settings.previous_normal - glm::dot(settings.previous_normal, t0) * t0;
        const double len = glm::length(p);
        if (len > 1e-6 && std::isfinite(len)) {
            r0 = p / len;
            stats.seeded_from_previous = true;
        }
    }
    if (!stats.seeded_from_previous) r0 = seed_normal(t0);
    out[0].r = r0;
    out[0].s = glm::cross(t0, r0);

    Transporter transport(in, settings, stats);
    // A step that crosses whole segments (LOD below the node resolution: an interval spanning several segments)
    // is carried through every segment boundary it crosses, so the frames equal those of one ring per segment at
    // the rings both have (no twist pop when spans merge or split). Boundaries pa.segment+1 .. end-1 lie between.
    const std::size_t n_seg = in.curve != nullptr ? in.curve->segment_count() : 0;
    auto boundary_end = [&](const RingParam& pb, bool wrap) -> std::size_t {
        return wrap ? n_seg : static_cast<std::size_t>(pb.segment) + (pb.t > 0.0 ? 1 : 0);
    };
    auto crosses = [&](const RingParam& pa, const RingParam& pb, bool wrap) {
        return n_seg != 0 && boundary_end(pb, wrap) > static_cast<std::size_t>(pa.segment) + 1;
    };
    auto carry = [&](const RingParam& pa, const Sample& a, glm::dvec3 r, const RingParam& pb, const Sample& b,
                     bool wrap) {
        const std::size_t end = boundary_end(pb, wrap);
        uint32_t seg = pa.segment;
        double ta = pa.t;
        Sample cur = a;
        for (std::size_t k = static_cast<std::size_t>(pa.segment) + 1; k < end; ++k) {
            const CubicBezier& c = in.curve->segments[k];
            Sample next{c.b0 - in.origin_m, unit_tangent(c, 0.0)};
            if (next.t == glm::dvec3(0.0)) next.t = cur.t;
            r = transport.step(seg, ta, cur, r, 1.0, next);
            seg = static_cast<uint32_t>(k);
            ta = 0.0;
            cur = next;
        }
        const double tb = !wrap && pb.segment == seg ? pb.t : 1.0;
        return transport.step(seg, ta, cur, r, tb, b);
    };
    auto general_step = [&](std::size_t i, const glm::dvec3& r_prev) {
        const RingParam& pa = in.params[i - 1];
        const RingParam& pb = in.params[i];
        const Sample a{in.centre_m[i - 1], out[i - 1].t};
        const Sample b{in.centre_m[i], out[i].t};
        if (crosses(pa, pb, false)) return carry(pa, a, r_prev, pb, b, false);
        const double tb = pb.segment == pa.segment ? pb.t : 1.0;
        return transport.step(pa.segment, pa.t, a, r_prev, tb, b);
    };
    if (settings.method == FrameMethod::double_reflection) {
        // The points the normal is carried through, in order: every ring and, between two rings, every segment
        // boundary the interval crosses (LOD below the node resolution), so a span's rings get the frames that one
        // ring per segment would give them (no twist pop when spans merge or split), and the boundaries take the
        // same independent-per-step path as rings. A boundary's tangent is computed as a ring's at t = 0 is.
        // Pass 1, independent per step: the product of the two reflections as one matrix (no square root: the
        // mirrors are not normalized), H2 H1 = I - f1 v1 v1^T - f2 v2 v2^T + f1 f2 (v2.v1) v2 v1^T; a flag marks a
        // step for the guarded path. Pass 2 then carries r by one matrix-vector product per step: the only serial
        // dependency, and a short one (no square root, no division), which is what bounds the speed. Reflections
        // keep |r| = 1 and r normal to t up to rounding, which is removed every 64 steps (drift stays ~1e-15); the
        // count runs over points, so a span's rings are re-projected exactly where the node-resolution rings are.
        // Pass 3 writes the rings' normals and binormals.
        const CubicBezier* const segs = in.curve != nullptr ? in.curve->segments.data() : nullptr;
        // The points, in structure-of-arrays scratch (grows once per thread, then reused): position, tangent, the
        // segment and parameter a step from the point runs along (segment starts: computed, see CarryChain), and
        // the point of every ring (the other points are crossed boundaries).
        // Rings only at segment starts (t = 0, at most one per segment; the last may be at t = 1: LOD at or below the
        // node resolution, the common moving wire) with build_rings' tables: the points are the segment starts
        // from ring 0's on, in order, so they are copied from the tables in lanes and the rings written over their
        // starts. Else (and without the tables) point by point.
        const std::size_t ss = in.segment_soa.size() / 12;  // the tables' stride
        bool starts = n_seg != 0 && in.segment_soa.size() == 12 * ss && ss >= n_seg &&
                      in.boundary_tangent.size() == 4 * ss && in.params[0].t == 0.0;
        for (std::size_t i = 1; i < n && starts; ++i) {
            const RingParam& pa = in.params[i - 1];
            const RingParam& pb = in.params[i];
            starts = pa.t == 0.0 &&
                     (pb.t == 0.0 ? pb.segment > pa.segment : (i + 1 == n && pb.t == 1.0 && pb.segment >= pa.segment));
        }
        const std::size_t s0 = in.params[0].segment;
        const std::size_t count = in.params[n - 1].segment + 1 - s0;  // with `starts`: segment starts from ring 0's on
        std::size_t m = starts ? count + (in.params[n - 1].t == 1.0 ? 1 : 0) : n;
        std::size_t first_crossed = n_seg, last_crossed = 0;  // boundary range whose tangents are needed
        for (std::size_t i = 1; i < n && !starts; ++i) {
            const RingParam& pa = in.params[i - 1];
            const RingParam& pb = in.params[i];
            if (crosses(pa, pb, false)) {
                const std::size_t end = boundary_end(pb, false);
                m += end - (pa.segment + 1);
                first_crossed = std::min<std::size_t>(first_crossed, pa.segment + 1);
                last_crossed = std::max(last_crossed, end);
            }
        }
        thread_local std::vector<double> soa;
        thread_local std::vector<uint32_t> point_seg;
        thread_local std::vector<double> point_ta;
        thread_local std::vector<uint32_t> ring_point;  // the point of every ring
        const std::size_t nb = last_crossed > first_crossed ? last_crossed - first_crossed : 0;
        // The arrays have room for whole vectors of steps (8 lanes): step_matrices then runs no remainder loop
        // (the steps past the last point, between copies of it, are computed and never read).
        const std::size_t mp = 1 + (m - 1 + 7) / 8 * 8;
        soa.resize(19 * mp + 4 * nb);
        if (!starts) {  // segment starts: CarryChain knows their segments and parameters
            point_seg.resize(m);
            point_ta.resize(m);
        }
        ring_point.resize(n);
        double* const px = soa.data();
        double* const py = px + mp;
        double* const pz = py + mp;
        double* const ptx = pz + mp;
        double* const pty = ptx + mp;
        double* const ptz = pty + mp;
        double* const blocks = ptz + mp;      // step_matrices()' blocks: the step into j, and whether it is guarded
        double* const nx = blocks + 10 * mp;  // 3 arrays: the normal carried to point j
        double* const ny = nx + mp;
        double* const nz = ny + mp;
        // Boundary tangents of the crossed range (detail::boundary_tangents): build_rings's, for every segment, or
        // computed here; a vanishing derivative (flag 0) takes unit_tangent()'s one-sided limits below.
        double* const btan = nz + mp;  // 4 arrays: x, y, z, ok
        const double* bt = btan;
        std::size_t bt_stride = nb;
        if (nb != 0 && in.boundary_tangent.size() % 4 == 0 && in.boundary_tangent.size() >= 4 * n_seg) {
            bt = in.boundary_tangent.data() + first_crossed;
            bt_stride = in.boundary_tangent.size() / 4;
        } else if (nb != 0) {
            thread_local std::vector<double> transposed;
            transposed.resize(12 * nb);
            detail::transpose_segments(segs + first_crossed, nb, transposed.data());
            detail::boundary_tangents(transposed.data(), nb, btan, btan + nb, btan + 2 * nb, btan + 3 * nb);
        }
        std::size_t j = 0;
        auto put = [&](const glm::dvec3& x, const glm::dvec3& t, uint32_t seg, double ta, int64_t ring) {
            px[j] = x.x;
            py[j] = x.y;
            pz[j] = x.z;
            ptx[j] = t.x;
            pty[j] = t.y;
            ptz[j] = t.z;
            point_seg[j] = seg;
            point_ta[j] = ta;
            if (ring >= 0) ring_point[static_cast<std::size_t>(ring)] = static_cast<uint32_t>(j);
            ++j;
        };
        if (starts) {
            const double* const b = in.segment_soa.data() + s0;
            const double* const t = in.boundary_tangent.data() + s0;
            const double* const tok = t + 3 * ss;
            const bool unfit = segment_start_points(b, b + ss, b + 2 * ss, t, t + ss, t + 2 * ss, tok, in.origin_m.x,
                                                    in.origin_m.y, in.origin_m.z, count, px, py, pz, ptx, pty, ptz);
            // The rings over their starts (a ring's segment and t are its start's; the last ring may be at t = 1,
            // one point more).
            for (std::size_t i = 0; i < n; ++i) {
                const std::size_t q = i + 1 == n && in.params[i].t == 1.0 ? count : in.params[i].segment - s0;
                px[q] = in.centre_m[i].x;
                py[q] = in.centre_m[i].y;
                pz[q] = in.centre_m[i].z;
                ptx[q] = out[i].t.x;
                pty[q] = out[i].t.y;
                ptz[q] = out[i].t.z;
                ring_point[i] = static_cast<uint32_t>(q);
            }
            j = m;  // their segments and parameters: CarryChain::segment_of(), t_of()
            // A boundary tangent whose flag is 0 takes unit_tangent()'s limits, a zero one the previous point's (the
            // test reads the tables, not the point arrays just written in lanes). Rare: segment_start_points tells.
            std::size_t next_ring = 0;  // the first ring whose point is not before q (ring_point increases)
            for (std::size_t q = 1; q < count && unfit; ++q) {
                while (ring_point[next_ring] < q) ++next_ring;  // the last ring's point is at least count - 1
                const glm::dvec3 table_t(t[q], t[ss + q], t[2 * ss + q]);
                if ((tok[q] != 0.0 && table_t != glm::dvec3(0.0)) || ring_point[next_ring] == q) continue;
                glm::dvec3 tq = tok[q] != 0.0 ? table_t : unit_tangent(segs[s0 + q], 0.0);
                if (tq == glm::dvec3(0.0)) tq = glm::dvec3(ptx[q - 1], pty[q - 1], ptz[q - 1]);
                ptx[q] = tq.x;
                pty[q] = tq.y;
                ptz[q] = tq.z;
            }
        } else {
            put(in.centre_m[0], out[0].t, in.params[0].segment, in.params[0].t, 0);
            for (std::size_t i = 1; i < n; ++i) {
                const RingParam& pa = in.params[i - 1];
                const RingParam& pb = in.params[i];
                if (crosses(pa, pb, false)) {
                    glm::dvec3 cur_t = out[i - 1].t;
                    for (std::size_t k = static_cast<std::size_t>(pa.segment) + 1; k < boundary_end(pb, false); ++k) {
                        const CubicBezier& c = segs[k];
                        const std::size_t b = k - first_crossed;
                        glm::dvec3 t = bt[3 * bt_stride + b] != 0.0
                                           ? glm::dvec3(bt[b], bt[bt_stride + b], bt[2 * bt_stride + b])
                                           : unit_tangent(c, 0.0);
                        if (t == glm::dvec3(0.0)) t = cur_t;
                        put(c.b0 - in.origin_m, t, static_cast<uint32_t>(k), 0.0, -1);
                        cur_t = t;
                    }
                }
                put(in.centre_m[i], out[i].t, pb.segment, pb.t, static_cast<int64_t>(i));
            }
        }
        assert(j == m);
        // Pass 1: mirrors() and the step matrix of every step, branch-free (selects), vectorized; a step mirrors()
        // would not call ok is flagged for the guarded path.
        for (std::size_t q = m; q < mp; ++q) {
            px[q] = px[m - 1];
            py[q] = py[m - 1];
            pz[q] = pz[m - 1];
            ptx[q] = ptx[m - 1];
            pty[q] = pty[m - 1];
            ptz[q] = ptz[m - 1];
        }
        step_matrices(px, py, pz, ptx, pty, ptz, mp, 1e-13 * max_abs(in.origin_m), blocks);
        // Pass 2: carry r, one matrix-vector product per step (the serial part); guarded steps through Transporter.
        CarryChain chain{m, r0, blocks, px, py, pz, ptx, pty, ptz, nullptr, nullptr, nx, ny, nz, &transport, s0, count};
        if (!starts) {
            chain.point_seg = point_seg.data();
            chain.point_ta = point_ta.data();
        }
        carry_normal(chain);
        // Pass 3: the rings' normals and binormals (after the carry: a branch on whether a point is a ring, in the
        // carry loop, is mispredicted wherever LOD leaves segments without rings).
        for (std::size_t i = 1; i < n; ++i) {
            const std::size_t q = ring_point[i];
            Frame& f = out[i];
            f.r = glm::dvec3(nx[q], ny[q], nz[q]);
            f.s = glm::cross(f.t, f.r);
        }
    } else {
        for (std::size_t i = 1; i < n; ++i) {
            out[i].r = general_step(i, out[i - 1].r);
            out[i].s = glm::cross(out[i].t, out[i].r);
        }
    }

    if (closed && n >= 1) {
        // Transport once more, from the last ring back to ring 0 (t = 1 of the last segment), and measure the twist.
        const RingParam& pa = in.params[n - 1];
        const Sample a{in.centre_m[n - 1], out[n - 1].t};
        const Sample b{in.centre_m[0], out[0].t};
        const glm::dvec3 r_end = crosses(pa, in.params[0], true)
                                     ? carry(pa, a, out[n - 1].r, in.params[0], b, true)
                                     : transport.step(pa.segment, pa.t, a, out[n - 1].r, 1.0, b);
        const double delta = std::atan2(glm::dot(glm::cross(out[0].r, r_end), out[0].t), glm::dot(out[0].r, r_end));
        stats.holonomy_rad = delta;
        if (!settings.keep_holonomy && delta != 0.0) {
            // Arc length per ring; chord lengths if none were given.
            double total = 0.0;
            const bool have_s = in.arc_length_m.size() == n + 1;
            if (have_s) {
                total = in.arc_length_m[n];
            } else {
                for (std::size_t i = 0; i < n; ++i) {
                    total += glm::length(in.centre_m[(i + 1) % n] - in.centre_m[i]);
                }
            }
            double s = 0.0;
            for (std::size_t i = 1; i < n; ++i) {
                s = have_s ? in.arc_length_m[i] : s + glm::length(in.centre_m[i] - in.centre_m[i - 1]);
                const double angle = total > 0.0 ? -delta * s / total : 0.0;
                const double ca = std::cos(angle);
                const double sa = std::sin(angle);
                const glm::dvec3 r = ca * out[i].r + sa * out[i].s;  // rotation about t by angle
                out[i].s = ca * out[i].s - sa * out[i].r;
                out[i].r = r;
            }
        }
    }
    return stats;
}

}  // namespace wire
