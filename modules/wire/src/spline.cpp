// The curve stage: validation, coincident-node merging, analytic Hermite tangents per spline kind, Bezier form.
#include "wire/spline.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace wire {
namespace {

using glm::dvec3;

std::string describe(double v) {
    if (std::isnan(v)) return "NaN";
    if (std::isinf(v)) return v > 0 ? "+Inf" : "-Inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    return buf;
}

std::string node_prefix(std::size_t i) { return "node " + std::to_string(i) + ": "; }

// Automatic mode at a sharp node: both tangents' magnitude -> kHug * the shorter neighbour chord. The bend
// then rounds off inside the short element with an overshoot of ~(4/27) kHug l_min past the node (Hermite
// basis maximum); 0.5 halves the overshoot of a uniform-like 1.0 while keeping the corner visibly round.
constexpr double kHug = 0.5;

// Largest accepted |coordinate| (metres): the tube's float vertices (relative to ring 0) and squared chord
// lengths must stay finite; 1e12 m is far beyond any scene (DESIGN §5 asks for 1e6 m from the origin).
constexpr double kMaxCoordinate_m = 1e12;

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

template <class T>
bool size_ok(const std::vector<T>& v, std::size_t n) { return v.empty() || v.size() == n; }

Status check_sizes(const WireNodes& w) {
    const std::size_t n = w.positions.size();
    struct Named { const char* name; std::size_t size; bool ok; };
    const Named arrays[] = {
        {"ids", w.ids.size(), size_ok(w.ids, n)},
        {"stretch", w.stretch.size(), size_ok(w.stretch, n)},
        {"radius_m", w.radius_m.size(), size_ok(w.radius_m, n)},
        {"theta_rad", w.theta_rad.size(), size_ok(w.theta_rad, n)},
        {"iz_m4", w.iz_m4.size(), size_ok(w.iz_m4, n)},
        {"length_m", w.length_m.size(), size_ok(w.length_m, n)},
        {"delta_length_m", w.delta_length_m.size(), size_ok(w.delta_length_m, n)},
        {"area_m2", w.area_m2.size(), size_ok(w.area_m2, n)},
        {"kb_tension", w.kb_tension.size(), size_ok(w.kb_tension, n)},
        {"kb_bias", w.kb_bias.size(), size_ok(w.kb_bias, n)},
        {"kb_continuity", w.kb_continuity.size(), size_ok(w.kb_continuity, n)},
    };
    for (const Named& a : arrays) {
        if (!a.ok) {
            return Status::error(std::string(a.name) + " has " + std::to_string(a.size) + " entries for " +
                                 std::to_string(n) + " nodes (must be empty or one per node)");
        }
    }
    return Status::success();
}

Status check_settings(const SplineSettings& s) {
    const struct { const char* name; double v; } finite[] = {
        {"alpha", s.alpha}, {"tension", s.tension}, {"bias", s.bias}, {"continuity", s.continuity},
        {"radius_m", s.radius_m}, {"merge_epsilon_rel", s.merge_epsilon_rel}};
    for (const auto& f : finite) {
        if (!std::isfinite(f.v)) return Status::error(std::string("settings.") + f.name + " is " + describe(f.v));
    }
    if (s.radius_m < 0.0f) return Status::error("settings.radius_m is " + describe(s.radius_m) + " (must be > 0; 0 means 1 cm)");
    if (s.merge_epsilon_rel < 0.0) return Status::error("settings.merge_epsilon_rel is " + describe(s.merge_epsilon_rel) + " (must be >= 0)");
    return Status::success();
}

Status check_nodes(const WireNodes& w, bool use_physics) {
    static const char* const kAxis[3] = {"x", "y", "z"};
    for (std::size_t i = 0; i < w.positions.size(); ++i) {
        for (int a = 0; a < 3; ++a) {
            const double v = w.positions[i][a];
            if (!std::isfinite(v)) return Status::error(node_prefix(i) + "position." + kAxis[a] + " is " + describe(v), static_cast<int>(i));
            if (std::abs(v) > kMaxCoordinate_m)
                return Status::error(node_prefix(i) + "position." + kAxis[a] + " is " + describe(v) +
                                         " (beyond the supported range of +-1e12 m)", static_cast<int>(i));
        }
        if (!w.stretch.empty() && !(w.stretch[i] > 0.0f && std::isfinite(w.stretch[i]))) {
            return Status::error(node_prefix(i) + "stretch is " + describe(w.stretch[i]) + " (must be finite and > 0)", static_cast<int>(i));
        }
        if (!w.radius_m.empty() && !(w.radius_m[i] >= 0.0f && std::isfinite(w.radius_m[i]))) {
            return Status::error(node_prefix(i) + "radius_m is " + describe(w.radius_m[i]) +
                                     " (must be finite and >= 0; 0 uses the wire's radius)", static_cast<int>(i));
        }
        const struct { const char* name; const std::vector<float>& v; } kb[] = {
            {"kb_tension", w.kb_tension}, {"kb_bias", w.kb_bias}, {"kb_continuity", w.kb_continuity}};
        for (const auto& k : kb) {
            if (!k.v.empty() && !std::isfinite(k.v[i])) return Status::error(node_prefix(i) + k.name + " is " + describe(k.v[i]), static_cast<int>(i));
        }
        if (use_physics) {
            const struct { const char* name; double v; } ph[] = {
                {"theta_rad", w.theta_rad[i]}, {"iz_m4", w.iz_m4[i]}, {"length_m", w.length_m[i]},
                {"delta_length_m", w.delta_length_m[i]}, {"area_m2", w.area_m2[i]}};
            for (const auto& p : ph) {
                if (!std::isfinite(p.v)) return Status::error(node_prefix(i) + p.name + " is " + describe(p.v), static_cast<int>(i));
            }
            if (!(w.area_m2[i] > 0.0)) return Status::error(node_prefix(i) + "area_m2 is " + describe(w.area_m2[i]) + " (must be > 0)", static_cast<int>(i));
        }
    }
    return Status::success();
}

// Merged nodes: the first input node of each group is kept; `last` is the group's last input node, whose
// element is the one that leaves the group (its stretch belongs to the outgoing segment).
struct Merged {
    std::vector<dvec3> p;
    std::vector<uint32_t> first, last;
};

void merge_nodes(const WireNodes& w, const SplineSettings& s, Merged& m) {
    const std::size_t n = w.positions.size();
    dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
    for (const dvec3& p : w.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const double diag = n ? glm::length(hi - lo) : 0.0;
    const double max_abs = n ? std::max(glm::length(lo), glm::length(hi)) : 0.0;
    const double rel = s.merge_epsilon_rel > 0.0 ? s.merge_epsilon_rel : 1e-9;
    const double eps = std::max(rel * diag, 64.0 * DBL_EPSILON * max_abs);
    m.p.clear(), m.first.clear(), m.last.clear();
    for (std::size_t i = 0; i < n; ++i) {
        if (!m.p.empty() && glm::length(w.positions[i] - m.p.back()) <= eps) {
            m.last.back() = static_cast<uint32_t>(i);
            continue;
        }
        m.p.push_back(w.positions[i]);
        m.first.push_back(static_cast<uint32_t>(i));
        m.last.push_back(static_cast<uint32_t>(i));
    }
    if (s.closed && m.p.size() >= 2 && glm::length(m.p.back() - m.p.front()) <= eps) {
        m.p.pop_back(), m.first.pop_back(), m.last.pop_back();  // the loop's end coincides with its start
    }
}

// Thomas algorithm for a tridiagonal system (sub a, diagonal b, super c); callers pass diagonally dominant rows.
template <class V>
void thomas(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c,
            std::vector<V>& r) {
    const std::size_t n = b.size();
    std::vector<double> cp(n);
    double den = b[0];
    cp[0] = c[0] / den;
    r[0] = r[0] / den;
    for (std::size_t i = 1; i < n; ++i) {
        den = b[i] - a[i] * cp[i - 1];
        cp[i] = c[i] / den;
        r[i] = (r[i] - a[i] * r[i - 1]) / den;
    }
    for (std::size_t i = n - 1; i-- > 0;) r[i] = r[i] - cp[i] * r[i + 1];
}

// Cyclic tridiagonal (corners a[0] at column n-1 and c[n-1] at column 0) by Sherman-Morrison, n >= 3.
void thomas_cyclic(const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c,
                   std::vector<dvec3>& r) {
    const std::size_t n = b.size();
    const double alpha = c[n - 1], beta = a[0], gamma = -b[0];
    std::vector<double> bb = b;
    bb[0] = b[0] - gamma;
    bb[n - 1] = b[n - 1] - alpha * beta / gamma;
    thomas(a, bb, c, r);
    std::vector<double> z(n, 0.0);
    z[0] = gamma, z[n - 1] = alpha;
    thomas(a, bb, c, z);
    const dvec3 fact = (r[0] + beta * r[n - 1] / gamma) / (1.0 + z[0] + beta * z[n - 1] / gamma);
    for (std::size_t i = 0; i < n; ++i) r[i] -= fact * z[i];
}

struct Chords {
    std::vector<dvec3> d;     // segment chords
    std::vector<double> len;  // their lengths (> merge epsilon)
};

// Per-segment Hermite tangents (per unit of the segment parameter u): t0 at the start, t1 at the end.
struct Tangents {
    std::vector<dvec3> t0, t1;
};

// C2 interpolating spline with chordal knots; tangents D per unit knot solved globally, then scaled by h.
void c2_tangents(const Chords& ch, bool closed, Tangents& tg) {
    const std::size_t segs = ch.d.size();
    const std::size_t n = closed ? segs : segs + 1;  // nodes
    std::vector<dvec3> s(segs);
    for (std::size_t k = 0; k < segs; ++k) s[k] = ch.d[k] / ch.len[k];
    std::vector<dvec3> D(n);
    if (closed) {
        std::vector<double> a(n), b(n, 2.0), c(n);
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t kin = (i + segs - 1) % segs, kout = i;
            const double hin = ch.len[kin], hout = ch.len[kout], sum = hin + hout;
            a[i] = hout / sum, c[i] = hin / sum;
            D[i] = 3.0 * (a[i] * s[kin] + c[i] * s[kout]);
        }
        thomas_cyclic(a, b, c, D);
    } else if (n == 2) {
        D[0] = D[1] = s[0];
    } else if (n == 3) {  // not-a-knot on 3 nodes is the interpolating parabola
        const double h0 = ch.len[0], h1 = ch.len[1], sum = h0 + h1;
        D[0] = s[0] - h0 * (s[1] - s[0]) / sum;
        D[1] = (h1 * s[0] + h0 * s[1]) / sum;
        D[2] = s[1] + h1 * (s[1] - s[0]) / sum;
    } else {
        // Rows i = 0..n-1 normalized: lambda_i D[i-1] + 2 D[i] + mu_i D[i+1] = r_i; ends not-a-knot:
        // row 0: b0 D0 + D1 = r0 with b0 = lambda_1, so row1 - row0 eliminates D0 exactly (pivot 1), and
        // likewise at the far end. The reduced system on D[1..n-2] has unit diagonal.
        const double h0 = ch.len[0], h1 = ch.len[1];
        const double b0 = h1 / (h0 + h1);
        const dvec3 r0 = (s[0] * (h1 * (3.0 * h0 + 2.0 * h1)) + (h0 * h0) * s[1]) / ((h0 + h1) * (h0 + h1));
        const double hL = ch.len[segs - 1], hP = ch.len[segs - 2];
        const double bl = hP / (hP + hL);
        const dvec3 rl = (s[segs - 1] * (hP * (3.0 * hL + 2.0 * hP)) + (hL * hL) * s[segs - 2]) / ((hP + hL) * (hP + hL));
        const std::size_t m = n - 2;
        std::vector<double> a(m), b(m, 2.0), c(m);
        std::vector<dvec3> r(m);
        for (std::size_t j = 0; j < m; ++j) {
            const std::size_t i = j + 1;
            const double hin = ch.len[i - 1], hout = ch.len[i], sum = hin + hout;
            a[j] = hout / sum, c[j] = hin / sum;
            r[j] = 3.0 * (a[j] * s[i - 1] + c[j] * s[i]);
        }
        r[0] -= r0, b[0] -= 1.0, a[0] = 0.0;
        r[m - 1] -= rl, b[m - 1] -= 1.0, c[m - 1] = 0.0;
        thomas(a, b, c, r);
        for (std::size_t j = 0; j < m; ++j) D[j + 1] = r[j];
        D[0] = (r0 - D[1]) / b0;
        D[n - 1] = (rl - D[n - 2]) / bl;
    }
    for (std::size_t k = 0; k < segs; ++k) {
        tg.t0[k] = D[k] * ch.len[k];
        tg.t1[k] = D[(k + 1) % n] * ch.len[k];
    }
}

}  // namespace

double curvature_tension(double theta_rad, double iz_m4, double length_m, double delta_length_m, double area_m2) {
    const double den = area_m2 * delta_length_m * delta_length_m;
    if (!(den > 0.0) || !std::isfinite(den)) return 0.0;
    const double R = std::abs(theta_rad * iz_m4 * length_m) / den;
    if (!(R <= 100.0)) return 0.0;
    return 1.0 - std::tanh(R / 50.0);
}

Status build_curve(const WireNodes& nodes, const SplineSettings& settings, Curve& out) {
    out = Curve{};
    if (Status st = check_settings(settings); !st) return st;
    if (Status st = check_sizes(nodes); !st) return st;
    const bool physics = settings.curvature_tension && !nodes.theta_rad.empty() && !nodes.iz_m4.empty() &&
                         !nodes.length_m.empty() && !nodes.delta_length_m.empty() && !nodes.area_m2.empty();
    if (Status st = check_nodes(nodes, physics); !st) return st;

    Merged m;
    merge_nodes(nodes, settings, m);
    const std::size_t n = m.p.size();
    const bool closed = settings.closed;
    if (n < 2) {
        return Status::error("a wire needs at least 2 distinct nodes, got " + std::to_string(nodes.size()) +
                             " node(s) and " + std::to_string(n) + " after merging coincident ones");
    }
    if (closed && n < 3) {
        return Status::error("a closed loop needs at least 3 distinct nodes, got " + std::to_string(n) +
                             " after merging coincident ones");
    }
    const std::size_t segs = closed ? n : n - 1;

    Chords ch;
    ch.d.resize(segs), ch.len.resize(segs);
    for (std::size_t k = 0; k < segs; ++k) {
        ch.d[k] = m.p[(k + 1) % n] - m.p[k];  // differences of nearby doubles: exact, whatever the offset
        ch.len[k] = glm::length(ch.d[k]);
    }
    std::vector<float> seg_stretch(segs, 1.0f);
    if (!nodes.stretch.empty()) {
        for (std::size_t k = 0; k < segs; ++k) seg_stretch[k] = nodes.stretch[m.last[k]];
    }

    Tangents tg;
    tg.t0.resize(segs), tg.t1.resize(segs);
    const SplineKind kind = settings.kind;
    if (kind == SplineKind::linear) {
        for (std::size_t k = 0; k < segs; ++k) tg.t0[k] = tg.t1[k] = ch.d[k];
    } else if (kind == SplineKind::c2) {
        c2_tangents(ch, closed, tg);
    } else {
        const bool automatic = kind == SplineKind::automatic;
        const double alpha = automatic ? 1.0 : settings.alpha;
        std::vector<double> sharp(n, 0.0);
        for (std::size_t j = 0; j < n; ++j) {
            const uint32_t src = m.first[j];
            const bool has_in = closed || j > 0, has_out = closed || j + 1 < n;
            const std::size_t kin = has_in ? (j + segs - 1) % segs : 0;
            const std::size_t kout = has_out ? j % segs : segs - 1;
            // Open ends reflect the missing neighbour (P[-1] = 2P[0]-P[1]): the missing chord equals the other.
            const dvec3 din = has_in ? ch.d[kin] : ch.d[kout];
            const dvec3 dout = has_out ? ch.d[kout] : ch.d[kin];
            const double lin = has_in ? ch.len[kin] : ch.len[kout];
            const double lout = has_out ? ch.len[kout] : ch.len[kin];

            double t_user = nodes.kb_tension.empty() ? settings.tension : nodes.kb_tension[src];
            const double b = automatic ? 0.0 : (nodes.kb_bias.empty() ? settings.bias : nodes.kb_bias[src]);
            const double c = automatic ? 0.0 : (nodes.kb_continuity.empty() ? settings.continuity : nodes.kb_continuity[src]);
            double t_curv = 0.0;
            if (physics) {
                t_curv = curvature_tension(nodes.theta_rad[src], nodes.iz_m4[src], nodes.length_m[src],
                                           nodes.delta_length_m[src], nodes.area_m2[src]);
            }
            const double t = 1.0 - (1.0 - t_user) * (1.0 - t_curv);
            const double keep = 1.0 - t;

            // Only the knot ratio matters; computed in the log domain so extreme alpha or spacing cannot give 0/0.
            const double lr = alpha == 0.0 ? 0.0 : std::clamp(alpha * (std::log(lout) - std::log(lin)), -300.0, 300.0);
            const double rho = std::exp(lr);
            const double w = rho / (1.0 + rho), iw = 1.0 / (1.0 + rho);  // w + iw = 1
            dvec3 start = keep * (((1.0 + b) * (1.0 + c) * rho * w) * din + ((1.0 - b) * (1.0 - c) * iw) * dout);
            dvec3 end = keep * (((1.0 + b) * (1.0 - c) * w) * din + ((1.0 - b) * (1.0 + c) * iw / rho) * dout);

            if (automatic && has_in && has_out) {
                const double phi = std::atan2(glm::length(glm::cross(din, dout)), glm::dot(din, dout));
                const double q = std::max(lin, lout) / std::min(lin, lout);
                const double st = std::max(seg_stretch[kin], seg_stretch[kout]);
                const double s_angle = smoothstep(0.35, 1.2, phi * (1.0 + std::log(q)));
                const double s_stretch = smoothstep(1.0, 1.02, st);
                const double s = 1.0 - (1.0 - s_angle) * (1.0 - s_stretch);
                sharp[j] = s;
                if (s > 0.0) {
                    const double ls = glm::length(start);
                    const dvec3 dir_c = ls > 0.0 ? start / ls : dvec3(0.0);
                    const dvec3 hug = lin * din + lout * dout;  // l_in^2 e_in + l_out^2 e_out
                    const double lh = glm::length(hug);
                    const dvec3 dir_s = lh > 0.0 ? hug / lh : dir_c;
                    const dvec3 mix = (1.0 - s) * dir_c + s * dir_s;
                    const double lm = glm::length(mix);
                    const dvec3 dir = lm > 0.0 ? mix / lm : dir_c;
                    // A taut wire runs straight between its nodes: from 1% to 5% stretch the rounding shrinks
                    // to a tenth (still G1: the tangent never vanishes, unlike tension 1).
                    const double h = kHug * (1.0 - 0.9 * smoothstep(1.01, 1.05, st)) * std::min(lin, lout);
                    start = ((1.0 - s) * ls + s * keep * h) * dir;
                    end = ((1.0 - s) * glm::length(end) + s * keep * h) * dir;
                }
            }
            if (has_out) tg.t0[kout] = start;
            if (has_in) tg.t1[kin] = end;
        }
        if (automatic && !closed && n >= 3) {
            // Quadratic (Bessel) end tangents instead of the phantom node's chord: O(h^2) on smooth sag; they
            // blend back to the chord as the neighbouring node gets sharp.
            auto end_tangent = [&](std::size_t k_end, std::size_t k_next, std::size_t node_next, bool at_start) {
                const double h0 = ch.len[k_end], h1 = ch.len[k_next];
                const dvec3 s0 = ch.d[k_end] / h0, s1 = ch.d[k_next] / h1;
                const dvec3 bessel = at_start ? s0 - (h0 / (h0 + h1)) * (s1 - s0) : s0 + (h0 / (h0 + h1)) * (s0 - s1);
                const double s = sharp[node_next];
                const dvec3 tan = ((1.0 - s) * h0) * bessel + s * ch.d[k_end];
                const double len_now = glm::length(at_start ? tg.t0[k_end] : tg.t1[k_end]);
                const double len_chord = h0;
                // keep the node's tension scaling (len_now / chord for the reflected tangent)
                return tan * (len_now / len_chord);
            };
            tg.t0[0] = end_tangent(0, 1, 1, true);
            tg.t1[segs - 1] = end_tangent(segs - 1, segs - 2, n - 2, false);
        }
    }

    out.closed = closed;
    out.segments.resize(segs);
    for (std::size_t k = 0; k < segs; ++k) {
        const dvec3& p0 = m.p[k];
        const dvec3& p1 = m.p[(k + 1) % n];
        CubicBezier& bz = out.segments[k];
        bz.b0 = p0;
        bz.b1 = p0 + tg.t0[k] / 3.0;
        bz.b2 = p1 - tg.t1[k] / 3.0;
        bz.b3 = p1;
        // Finite is not enough: a control point past the coordinate range (an extreme alpha) overflows the
        // tube's float vertices downstream.
        constexpr double kMaxControl_m = 10.0 * kMaxCoordinate_m;
        const auto in_range = [](const dvec3& b) {
            return std::abs(b.x) <= kMaxControl_m && std::abs(b.y) <= kMaxControl_m && std::abs(b.z) <= kMaxControl_m;
        };
        const bool finite = in_range(bz.b1) && in_range(bz.b2);  // false for NaN too
        if (!finite) {
            const uint32_t src = m.first[k];
            out = Curve{};
            return Status::error(node_prefix(src) + "tangent overflowed (alpha " + describe(settings.alpha) +
                                     " is too extreme for this node spacing)", static_cast<int>(src));
        }
    }
    out.source_node = m.first;
    out.radius_m.resize(n);
    const float wire_radius = settings.radius_m > 0.0f ? settings.radius_m : 0.01f;
    for (std::size_t j = 0; j < n; ++j) {
        const float r = nodes.radius_m.empty() ? 0.0f : nodes.radius_m[m.first[j]];
        out.radius_m[j] = r > 0.0f ? r : wire_radius;
    }
    out.stretch = std::move(seg_stretch);
    return Status::success();
}

}  // namespace wire
