// Rotation-minimizing frames by double reflection, hairpin subdivision, closed-loop holonomy removal; baselines.
#include "wire/frames.hpp"

#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

namespace wire {
namespace {

/// Steps whose tangent turns by more than 45 degrees are split (see Transporter::reflect).
constexpr double kSplitCos = 0.70710678118654752;

double max_abs(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

/// r made orthogonal to unit t and normalized; `fallback` (also made orthogonal) if r is (nearly) parallel to t.
glm::dvec3 orthonormalize(const glm::dvec3& r, const glm::dvec3& t) {
    glm::dvec3 p = r - glm::dot(r, t) * t;
    const double len2 = glm::dot(p, p);
    if (len2 > 1e-20) {
        return p * (1.0 / std::sqrt(len2));
    }
    return seed_normal(t);
}

/// Minimal rotation taking unit t0 to unit t1, applied to r0 (the rotation method). Antiparallel tangents: the
/// rotation by pi about r0's direction (keeps r, flips the binormal), the minimum the geometry allows.
glm::dvec3 rotate_minimal(const glm::dvec3& t0, const glm::dvec3& t1, const glm::dvec3& r0) {
    const double c = glm::dot(t0, t1);
    if (c < -1.0 + 1e-12) {
        return orthonormalize(r0, t1);
    }
    const glm::dvec3 v = glm::cross(t0, t1);  // axis * sin(angle)
    // Rodrigues with cos = c, axis*sin = v: R r = c r + v x r + v (v.r) / (1 + c).
    return c * r0 + glm::cross(v, r0) + v * (glm::dot(v, r0) / (1.0 + c));
}

struct Sample {
    glm::dvec3 x;  // position relative to the origin
    glm::dvec3 t;  // unit tangent
};

enum class Mirrors : uint8_t { ok, split, degenerate };

/// The two mirrors of the double-reflection step a -> b: each reflection is r - f (v.r) v with f = 2 / |v|^2 (no
/// normalization, so no square root). `split` (mirrors valid) when the hairpin guard wants the step subdivided;
/// `degenerate` (invalid) when the tangent reverses at a repeated point or the second mirror vanishes.
struct MirrorPair {
    glm::dvec3 v1{}, v2{};
    double f1 = 0.0, f2 = 0.0;
};

Mirrors mirrors(const Sample& a, const Sample& b, double noise, MirrorPair& m) {
    glm::dvec3 v1 = b.x - a.x;
    double c1 = glm::dot(v1, v1);
    // Below the rounding noise of the positions the chord has no direction: a repeated point. The reflection
    // about the plane normal to t0 + t1 takes t0 to -t1 and the second one (about t1) to t1, as needed.
    if (c1 <= noise * noise * 64.0) {
        v1 = a.t + b.t;
        c1 = glm::dot(v1, v1);
        if (c1 < 1e-20) {
            return Mirrors::degenerate;
        }
    }
    const double f1 = 2.0 / c1;
    const glm::dvec3 tl = a.t - (f1 * glm::dot(v1, a.t)) * v1;  // t0 reflected
    const glm::dvec3 v2 = b.t - tl;
    const double c2 = glm::dot(v2, v2);
    if (c2 < 1e-20) {
        return Mirrors::degenerate;
    }
    m = MirrorPair{v1, v2, f1, 2.0 / c2};
    // Hairpin guard. c2 ~ 0: the tangent turns "the wrong way" within the step (a loop), the second mirror is
    // ill-conditioned. A turn of more than 45 degrees in one step (a hairpin under coarse sampling): the
    // method's error grows with the turn per step. Either way the step is split at its parameter midpoint; at a
    // cusp only the half containing it keeps splitting, so the cost is O(depth), not O(2^depth).
    return (c2 < 0.1 || glm::dot(a.t, b.t) < kSplitCos) ? Mirrors::split : Mirrors::ok;
}

glm::dvec3 reflect_pair(const MirrorPair& m, glm::dvec3 r) {
    r -= (m.f1 * glm::dot(m.v1, r)) * m.v1;
    r -= (m.f2 * glm::dot(m.v2, r)) * m.v2;
    return r;
}

class Transporter {
public:
    Transporter(const FrameInput& in, const FrameSettings& s, FrameStats& stats)
        : in_(in), method_(s.method), max_depth_(s.max_subdivision_depth ? s.max_subdivision_depth : 10),
          stats_(stats), origin_noise_(1e-13 * max_abs(in.origin_m)) {}

    /// Rounding noise of positions near a and b (a chord below it is a repeated point).
    [[nodiscard]] double noise(const Sample& a, const Sample& b) const {
        return origin_noise_ + 1e-13 * (max_abs(a.x) + max_abs(b.x));
    }

    /// Carries normal r0 at a (on segment seg at parameter ta) to b (at parameter tb of the same segment, or the
    /// next ring whose position equals that point).
    glm::dvec3 step(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb, const Sample& b) {
        switch (method_) {
            case FrameMethod::rotation: return orthonormalize(rotate_minimal(a.t, b.t, r0), b.t);
            case FrameMethod::projection: return orthonormalize(r0, b.t);
            case FrameMethod::double_reflection: break;
        }
        return reflect(seg, ta, a, r0, tb, b, 0);
    }

private:
    glm::dvec3 reflect(uint32_t seg, double ta, const Sample& a, const glm::dvec3& r0, double tb, const Sample& b,
                       uint32_t depth) {
        MirrorPair mp;
        const Mirrors m = mirrors(a, b, noise(a, b), mp);
        if (m != Mirrors::ok && depth < max_depth_ && in_.curve != nullptr && tb > ta) {
            if (depth == 0) {
                ++stats_.subdivided_steps;
            }
            const CubicBezier& c = in_.curve->segments[seg];
            const double tm = 0.5 * (ta + tb);
            Sample mid{position(c, tm) - in_.origin_m, unit_tangent(c, tm)};
            if (mid.t == glm::dvec3(0.0)) {
                mid.t = a.t;
            }
            const glm::dvec3 rm = reflect(seg, ta, a, r0, tm, mid, depth + 1);
            return reflect(seg, tm, mid, rm, tb, b, depth + 1);
        }
        if (m == Mirrors::degenerate) {  // tangent reverses at a point: the minimal rotation
            ++stats_.fallback_steps;
            return orthonormalize(rotate_minimal(a.t, b.t, r0), b.t);
        }
        // Each reflection preserves length and the pair preserves handedness; re-project against rounding drift.
        return orthonormalize(reflect_pair(mp, r0), b.t);
    }

    const FrameInput& in_;
    FrameMethod method_;
    uint32_t max_depth_;
    FrameStats& stats_;
    double origin_noise_;
};

}  // namespace

glm::dvec3 seed_normal(const glm::dvec3& t) {
    const glm::dvec3 a = glm::abs(t);
    glm::dvec3 e{0.0};
    if (a.x <= a.y && a.x <= a.z) {
        e.x = 1.0;
    } else if (a.y <= a.z) {
        e.y = 1.0;
    } else {
        e.z = 1.0;
    }
    return glm::normalize(e - glm::dot(e, t) * t);
}

glm::dvec3 unit_tangent(const CubicBezier& c, double t, bool* degenerate) {
    const double extent = std::max({max_abs(c.b1 - c.b0), max_abs(c.b2 - c.b0), max_abs(c.b3 - c.b0)});
    // Derivatives below this are rounding noise of the control-point differences (or exactly zero).
    const double tiny = 1e-10 * extent + 1e-15 * max_abs(c.b0) + 1e-300;
    const glm::dvec3 d1 = derivative(c, t);
    const double l1 = glm::length(d1);
    if (l1 > tiny) {
        if (degenerate) *degenerate = false;
        return d1 / l1;
    }
    if (degenerate) *degenerate = true;
    // One-sided limits: B'(t + h) ~ h B''(t); at t = 1 only the left side exists, B'(1 - h) ~ -h B''(1).
    const double side = t >= 1.0 ? -1.0 : 1.0;
    const glm::dvec3 d2 = side * second_derivative(c, t);
    const double l2 = glm::length(d2);
    if (l2 > tiny) {
        return d2 / l2;
    }
    const glm::dvec3 d3 = 6.0 * (c.b3 - 3.0 * c.b2 + 3.0 * c.b1 - c.b0);  // B'(t+h) ~ h^2/2 B'''
    const double l3 = glm::length(d3);
    if (l3 > tiny) {
        return d3 / l3;
    }
    const glm::dvec3 chord = c.b3 - c.b0;
    const double lc = glm::length(chord);
    if (lc > tiny) {
        return chord / lc;
    }
    return glm::dvec3(0.0);
}

namespace {
/// Unit tangent at t = 0, computed as build_rings computes a ring's there (B'(0) = 3 (b1 - b0), times the
/// reciprocal of its length), so a crossed boundary and a ring at the same point carry the same tangent; where the
/// derivative vanishes, unit_tangent()'s one-sided limits.
glm::dvec3 boundary_tangent(const CubicBezier& c) {
    const glm::dvec3 d = 3.0 * (c.b1 - c.b0);
    const double speed = std::sqrt(glm::dot(d, d));
    const double extent = std::max({max_abs(c.b1 - c.b0), max_abs(c.b2 - c.b0), max_abs(c.b3 - c.b0)});
    if (speed > 1e-10 * extent + 1e-15 * max_abs(c.b0) + 1e-300) return d * (1.0 / speed);
    return unit_tangent(c, 0.0);
}
}  // namespace

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
    glm::dvec3 r0 = seed_normal(t0);
    if (settings.has_previous_normal) {
        const glm::dvec3 p = settings.previous_normal - glm::dot(settings.previous_normal, t0) * t0;
        const double len = glm::length(p);
        if (len > 1e-6 && std::isfinite(len)) {
            r0 = p / len;
            stats.seeded_from_previous = true;
        }
    }
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
        // mirrors are not normalized), H2 H1 = I - f1 v1 v1^T - f2 v2 v2^T + f1 f2 (v2.v1) v2 v1^T; a NaN marks a
        // step for the guarded path. Pass 2 then carries r by one matrix-vector product per step: the only serial
        // dependency, and a short one (no square root, no division), which is what bounds the speed. Reflections
        // keep |r| = 1 and r normal to t up to rounding, which is removed every 64 steps (drift stays ~1e-15); the
        // count runs over points, so a span's rings are re-projected exactly where the node-resolution rings are.
        // Pass 3: binormals.
        struct Point {
            Sample s;
            uint32_t seg;   // the segment a step from this point runs along
            double ta;      // ... from this parameter
            int64_t ring;   // ring index, or -1 for a crossed boundary
        };
        thread_local std::vector<Point> points;  // grows once per thread, then reused
        points.clear();
        points.push_back(Point{{in.centre_m[0], out[0].t}, in.params[0].segment, in.params[0].t, 0});
        for (std::size_t i = 1; i < n; ++i) {
            const RingParam& pa = in.params[i - 1];
            const RingParam& pb = in.params[i];
            if (crosses(pa, pb, false)) {
                glm::dvec3 cur_t = out[i - 1].t;
                for (std::size_t k = static_cast<std::size_t>(pa.segment) + 1; k < boundary_end(pb, false); ++k) {
                    const CubicBezier& c = in.curve->segments[k];
                    glm::dvec3 t = boundary_tangent(c);
                    if (t == glm::dvec3(0.0)) t = cur_t;
                    points.push_back(Point{{c.b0 - in.origin_m, t}, static_cast<uint32_t>(k), 0.0, -1});
                    cur_t = t;
                }
            }
            points.push_back(Point{{in.centre_m[i], out[i].t}, pb.segment, pb.t, static_cast<int64_t>(i)});
        }
        const std::size_t m = points.size();
        thread_local std::vector<glm::dmat3> step_matrix;
        step_matrix.resize(m);
        constexpr double kSpecial = std::numeric_limits<double>::quiet_NaN();
        for (std::size_t j = 1; j < m; ++j) {
            const Sample& a = points[j - 1].s;
            const Sample& b = points[j].s;
            MirrorPair mp;
            if (mirrors(a, b, transport.noise(a, b), mp) == Mirrors::ok) {
                const double k = mp.f1 * glm::dot(mp.v2, mp.v1);
                glm::dmat3 mat(1.0);
                for (int c = 0; c < 3; ++c) {  // column c: e_c - f1 v1 v1_c - f2 v2 (v2_c - f1 (v2.v1) v1_c)
                    mat[c] -= mp.v1 * (mp.f1 * mp.v1[c]) + mp.v2 * (mp.f2 * (mp.v2[c] - k * mp.v1[c]));
                }
                step_matrix[j] = mat;
            } else {
                step_matrix[j][0][0] = kSpecial;
            }
        }
        glm::dvec3 r = r0;
        for (std::size_t j = 1; j < m; ++j) {
            const Point& a = points[j - 1];
            const Point& b = points[j];
            if (std::isnan(step_matrix[j][0][0])) {
                const double tb = b.seg == a.seg ? b.ta : 1.0;
                r = transport.step(a.seg, a.ta, a.s, glm::normalize(r), tb, b.s);
            } else {
                r = step_matrix[j] * r;
                if ((j & 63) == 0) {  // reflections preserve length and plane; only rounding drifts, slowly
                    r = orthonormalize(r, b.s.t);
                }
            }
            if (b.ring >= 0) out[static_cast<std::size_t>(b.ring)].r = r;
        }
        for (std::size_t i = 1; i < n; ++i) {
            out[i].s = glm::cross(out[i].t, out[i].r);
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
