// Coincident-node merging (a tolerance relative to the wire's size) and the chords of the merged nodes.
#include "spline/merge.hpp"

#include "simd/dispatch.hpp"  // WIRE_VECTOR_CLONES
#include "spline/scratch.hpp"
#include "spline/validate.hpp"  // all_above

#include <glm/geometric.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <string>

namespace wire::curve_stage {

using glm::dvec3;

namespace {

// Chords k = 0 .. count-1 from node coordinates a (3 per node, node k at 3k) to b (node k + 1's at 3k).
WIRE_VECTOR_CLONES
void chords_kernel(std::size_t count, const double* __restrict a, const double* __restrict b, double* __restrict dx,
                   double* __restrict dy, double* __restrict dz, double* __restrict len, double* __restrict ex,
                   double* __restrict ey, double* __restrict ez) {
    for (std::size_t k = 0; k < count; ++k) {
        // Differences of nearby doubles: exact, whatever the offset. Length as glm::length: (x*x + y*y) + z*z.
        const double x = b[3 * k] - a[3 * k], y = b[3 * k + 1] - a[3 * k + 1], z = b[3 * k + 2] - a[3 * k + 2];
        const double l = std::sqrt(x * x + y * y + z * z);
        const double inv = 1.0 / l;
        dx[k] = x, dy[k] = y, dz[k] = z, len[k] = l;
        ex[k] = x * inv, ey[k] = y * inv, ez[k] = z * inv;
    }
}

// Chords of the nodes P[0..n) (n >= 2; closed: the closing chord P[0] - P[n-1] too), lengths and unit directions.
void fill_chords(const dvec3* P, std::size_t n, bool closed, Chords& ch) {
    const std::size_t segs = closed ? n : n - 1;
    ch.segs = segs;
    for (std::vector<double>* v : {&ch.dx, &ch.dy, &ch.dz, &ch.len, &ch.ex, &ch.ey, &ch.ez}) v->resize(segs + 2);
    const auto chords = [&](std::size_t k0, std::size_t count, const dvec3* a, const dvec3* b) {
        chords_kernel(count, &a->x, &b->x, ch.dx.data() + 1 + k0, ch.dy.data() + 1 + k0, ch.dz.data() + 1 + k0,
                      ch.len.data() + 1 + k0, ch.ex.data() + 1 + k0, ch.ey.data() + 1 + k0, ch.ez.data() + 1 + k0);
    };
    in_whole_blocks(n - 1, [&](std::size_t k0, std::size_t count) { chords(k0, count, P + k0, P + k0 + 1); });
    if (closed) chords(n - 1, 1, P + (n - 1), P);
    for (std::vector<double>* v : {&ch.dx, &ch.dy, &ch.dz, &ch.len, &ch.ex, &ch.ey, &ch.ez}) {
        (*v)[0] = (*v)[segs];
        (*v)[segs + 1] = (*v)[1];
    }
}

// Bounding box of n nodes (3 finite coordinates each, node i's at 3i) into lo and hi (3 each, HUGE_VAL and
// -HUGE_VAL on entry). Minima and maxima are exact in any order (only the sign of a zero could depend on it, and
// the merge reads the box only through lengths), so two nodes at a time.
WIRE_VECTOR_CLONES
void bbox_kernel(const double* p, std::size_t n, double* lo, double* hi) {
    std::size_t i = 0;
#if defined(__GNUC__)
    using v2d = double __attribute__((vector_size(16)));  // native on the SSE2 baseline too
    if (n >= 2) {
        // 6 doubles (2 nodes) a step: x y | z x | y z.
        v2d l[3], h[3];
        for (int a = 0; a < 3; ++a) std::memcpy(&l[a], p + 2 * a, sizeof(v2d)), h[a] = l[a];
        for (i = 2; i + 2 <= n; i += 2) {
            for (int a = 0; a < 3; ++a) {
                v2d x;
                std::memcpy(&x, p + 3 * i + 2 * a, sizeof x);
                l[a] = x < l[a] ? x : l[a];
                h[a] = x > h[a] ? x : h[a];
            }
        }
        for (int a = 0; a < 3; ++a) {
            for (int lane = 0; lane < 2; ++lane) {
                const int axis = (2 * a + lane) % 3;
                lo[axis] = std::min(lo[axis], l[a][lane]);
                hi[axis] = std::max(hi[axis], h[a][lane]);
            }
        }
    }
#endif
    for (; i < n; ++i) {
        for (int axis = 0; axis < 3; ++axis) {
            lo[axis] = std::min(lo[axis], p[3 * i + axis]);
            hi[axis] = std::max(hi[axis], p[3 * i + axis]);
        }
    }
}

}  // namespace

const dvec3* merge_nodes(const WireNodes& w, const SplineSettings& s, Merged& m, Chords& ch, std::size_t& count) {
    const std::size_t n = w.positions.size();
    dvec3 lo(HUGE_VAL), hi(-HUGE_VAL);
    bbox_kernel(n ? &w.positions[0].x : nullptr, n, &lo.x, &hi.x);
    m.lo = lo, m.hi = hi;
    const double diag = n ? glm::length(hi - lo) : 0.0;
    const double max_abs = n ? std::max(glm::length(lo), glm::length(hi)) : 0.0;
    const double rel = s.merge_epsilon_rel > 0.0 ? s.merge_epsilon_rel : 1e-9;
    const double eps = std::max(rel * diag, 64.0 * DBL_EPSILON * max_abs);
    if (n >= 3) {
        // The chords of consecutive input nodes are the distances the merge tests (the closing one too: the
        // length of a negated difference is the same number); nothing merges when all exceed eps.
        fill_chords(w.positions.data(), n, s.closed, ch);
        if (all_above(ch.len.data() + 1, ch.segs, eps)) {
            // Already the identity of n nodes in the common case (the thread's build memory, reused by the
            // thread's wires, most of one size and merging nothing): not rewritten per wire then.
            if (!m.identity || m.first.size() != n) {
                m.first.resize(n), m.last.resize(n);
                for (std::size_t i = 0; i < n; ++i) m.first[i] = m.last[i] = static_cast<uint32_t>(i);
                m.identity = true;
            }
            count = n;
            return w.positions.data();
        }
    }
    m.p.clear(), m.first.clear(), m.last.clear();
    m.identity = false;
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
    count = m.p.size();
    if (count >= (s.closed ? 3u : 2u)) fill_chords(m.p.data(), count, s.closed, ch);
    return m.p.data();
}

}  // namespace wire::curve_stage

namespace wire {

Status check_curve_input(const WireNodes& nodes, const SplineSettings& settings) {
    if (Status st = curve_stage::check_settings(settings); !st) return st;
    if (Status st = curve_stage::check_sizes(nodes); !st) return st;
    const bool physics = settings.curvature_tension && !nodes.theta_rad.empty() && !nodes.iz_m4.empty() &&
                         !nodes.length_m.empty() && !nodes.delta_length_m.empty() && !nodes.area_m2.empty();
    if (Status st = curve_stage::check_nodes(nodes, physics); !st) return st;
    thread_local curve_stage::Merged m;
    thread_local curve_stage::Chords ch;
    std::size_t n = 0;
    (void)curve_stage::merge_nodes(nodes, settings, m, ch, n);
    if (Status st = curve_stage::check_distinct(nodes.size(), n, settings.closed); !st) return st;
    return Status::success();
}

std::size_t curve_nodes(const WireNodes& nodes, const SplineSettings& settings, std::vector<glm::dvec3>& out,
                        std::vector<uint32_t>* source, std::vector<uint32_t>* last) {
    thread_local curve_stage::Merged m;
    thread_local curve_stage::Chords ch;
    std::size_t count = 0;
    const glm::dvec3* p = curve_stage::merge_nodes(nodes, settings, m, ch, count);
    out.assign(p, p + count);
    if (source != nullptr) source->assign(m.first.begin(), m.first.begin() + static_cast<std::ptrdiff_t>(count));
    if (last != nullptr) last->assign(m.last.begin(), m.last.begin() + static_cast<std::ptrdiff_t>(count));
    return count;
}

}  // namespace wire
