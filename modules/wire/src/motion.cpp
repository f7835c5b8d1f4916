// The best-fit rotation of a wire's nodes between two states (motion.hpp): Horn's quaternion method, weighted.
#include "wire/motion.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace wire {
namespace {

using glm::dvec3;

// Eigen-decomposition of a symmetric 4x4 matrix by cyclic Jacobi rotations (converges quadratically; a handful of
// sweeps reach double precision). On return a's diagonal holds the eigenvalues and v's columns the eigenvectors.
void jacobi4(double a[4][4], double v[4][4]) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) v[i][j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < 32; ++sweep) {
        double off = 0.0, diag = 0.0;
        for (int i = 0; i < 4; ++i) {
            diag += a[i][i] * a[i][i];
            for (int j = i + 1; j < 4; ++j) off += a[i][j] * a[i][j];
        }
        if (!(off > 1e-34 * diag)) break;  // also stops on NaN
        for (int p = 0; p < 4; ++p) {
            for (int q = p + 1; q < 4; ++q) {
                if (a[p][q] == 0.0) continue;
                const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 4; ++k) {  // a = J^T a J
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 4; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                for (int k = 0; k < 4; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
        }
    }
}

// Where `id` sits in `to` (or -1): the same index first (ids rarely move far), then outward from it.
long find_id(const WireNodes& to, uint32_t id, std::size_t hint) {
    const std::size_t n = to.ids.size();
    if (n == 0) return -1;
    hint = std::min(hint, n - 1);
    for (std::size_t d = 0; d < n; ++d) {
        if (hint + d < n && to.ids[hint + d] == id) return static_cast<long>(hint + d);
        if (d != 0 && d <= hint && to.ids[hint - d] == id) return static_cast<long>(hint - d);
        if (hint + d >= n && d > hint) break;
    }
    return -1;
}

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

}  // namespace

MotionReference motion_reference(const WireNodes& nodes) {
    MotionReference ref;
    const std::size_t n = nodes.size();
    ref.node_count = static_cast<uint32_t>(n);
    ref.by_index = nodes.ids.size() != n;
    if (n == 0) return ref;
    // Nodes 0, 1, 2, 3, then each step 1.5x the last, and always the last node: the start dense, the whole wire
    // spanned (a far node pins the rotation about a straight start).
    std::size_t i = 0, step = 1, at = 0;  // `at`: the node whose polyline length `s` is
    double s = 0.0;
    while (ref.count < MotionReference::kCapacity) {
        for (; at < i; ++at) s += glm::length(nodes.positions[at + 1] - nodes.positions[at]);
        const uint32_t k = ref.count++;
        ref.position[k] = nodes.positions[i];
        ref.id[k] = ref.by_index ? static_cast<uint32_t>(i) : nodes.ids[i];
        ref.arc[k] = static_cast<float>(s);
        if (i + 1 >= n) break;
        if (i >= 3) step = std::max<std::size_t>(step + 1, (step * 3) / 2);
        i = ref.count + 1 == MotionReference::kCapacity ? n - 1 : std::min(n - 1, i + step);
    }
    return ref;
}

namespace {

// One weighted fit of matched pairs (a old, b new) with weights w; confidence from the eigenvalue gap.
MotionFit fit_pairs(const dvec3* a, const dvec3* b, const double* w, uint32_t m) {
    MotionFit fit;
    fit.matched = m;
    double wsum = 0.0;
    dvec3 ca(0.0), cb(0.0);
    for (uint32_t k = 0; k < m; ++k) wsum += w[k], ca += w[k] * a[k], cb += w[k] * b[k];
    if (m < 3 || !(wsum > 0.0)) return fit;
    ca /= wsum;
    cb /= wsum;
    // S = sum w (a - ca)(b - cb)^T and the spread E = sum w (|a - ca|^2 + |b - cb|^2) / 2.
    double S[3][3] = {};
    double spread = 0.0;
    for (uint32_t k = 0; k < m; ++k) {
        const dvec3 x = a[k] - ca, y = b[k] - cb;
        spread += 0.5 * w[k] * (glm::dot(x, x) + glm::dot(y, y));
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) S[r][c] += w[k] * x[r] * y[c];
    }
    if (!(spread > 0.0) || !std::isfinite(spread)) return fit;
    // Horn's matrix: its top eigenvector is the unit quaternion (w, x, y, z) of the rotation taking a to b.
    const double sxx = S[0][0], sxy = S[0][1], sxz = S[0][2], syx = S[1][0], syy = S[1][1], syz = S[1][2],
                 szx = S[2][0], szy = S[2][1], szz = S[2][2];
    double N[4][4] = {{sxx + syy + szz, syz - szy, szx - sxz, sxy - syx},
                      {syz - szy, sxx - syy - szz, sxy + syx, szx + sxz},
                      {szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy},
                      {sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz}};
    double V[4][4];
    jacobi4(N, V);
    int top = 0;
    for (int i = 1; i < 4; ++i)
        if (N[i][i] > N[top][top]) top = i;
    double second = -HUGE_VAL;
    for (int i = 0; i < 4; ++i)
        if (i != top) second = std::max(second, N[i][i]);
    glm::dquat q(V[0][top], V[1][top], V[2][top], V[3][top]);
    const double len = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (!(len > 0.0) || !std::isfinite(len)) return fit;
    q = q * (1.0 / len);
    if (q.w < 0.0) q = -q;  // the shorter way round
    fit.rotation = q;
    // For a rigid motion the top eigenvalue is the spread; the gap to the next one is what fixes the rotation
    // about the line through the nodes (see the header for the two thresholds).
    fit.confidence = smoothstep(1e-4, 1e-3, (N[top][top] - second) / spread);
    return fit;
}

}  // namespace

MotionFit fit_motion(const MotionReference& from, const WireNodes& to) {
    MotionFit fit;
    if (from.count == 0) return fit;
    const bool by_index = to.ids.size() != to.size();
    if (by_index != from.by_index || (by_index && to.size() != from.node_count)) return fit;
    dvec3 a[MotionReference::kCapacity], b[MotionReference::kCapacity];
    double arc[MotionReference::kCapacity], w[MotionReference::kCapacity];
    uint32_t m = 0;
    for (uint32_t k = 0; k < from.count; ++k) {
        const long j = by_index ? static_cast<long>(from.id[k]) : find_id(to, from.id[k], k);
        if (j < 0) continue;
        a[m] = from.position[k];
        b[m] = to.positions[static_cast<std::size_t>(j)];
        arc[m] = from.arc[k];
        ++m;
    }
    fit.matched = m;
    if (m < 3) return fit;
    // The reach: from two elements, doubled until the nodes within it fix the rotation (or it spans the wire).
    const double whole = arc[m - 1];
    double reach = std::max(arc[std::min<uint32_t>(2, m - 1)], 1e-300);
    for (;;) {
        for (uint32_t k = 0; k < m; ++k) w[k] = std::exp(-arc[k] / reach);
        fit = fit_pairs(a, b, w, m);
        if (fit.confidence >= 1.0 || !(reach < whole)) return fit;
        reach *= 2.0;
    }
}

glm::dvec3 carry_normal(const MotionFit& fit, const glm::dvec3& previous_normal) {
    if (!(fit.confidence > 0.0)) return previous_normal;
    if (fit.confidence >= 1.0) return fit.rotation * previous_normal;
    // A fraction of the rotation: the same axis, `confidence` of its angle (q^c, q.w >= 0).
    const glm::dvec3 v(fit.rotation.x, fit.rotation.y, fit.rotation.z);
    const double sin_half = glm::length(v);
    if (!(sin_half > 0.0)) return previous_normal;
    const double half = std::atan2(sin_half, fit.rotation.w) * fit.confidence;
    const glm::dvec3 axis = v / sin_half;
    const glm::dquat part(std::cos(half), std::sin(half) * axis);
    return part * previous_normal;
}

FrameSettings carried_frames(FrameMethod method, const Frame* last_first, const MotionReference& built_from,
                             const WireNodes& nodes) {
    FrameSettings settings;
    settings.method = method;
    if (last_first != nullptr) {
        // Temporal coherence: the first normal moves with the wire instead of being re-seeded from a world axis.
        settings.has_previous_normal = true;
        settings.previous_normal = carry_normal(fit_motion(built_from, nodes), last_first->r);
    }
    return settings;
}

}  // namespace wire
