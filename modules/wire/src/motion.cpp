// The best-fit rotation of a wire's nodes between two states (motion.hpp): Horn's quaternion method, weighted.
#include "wire/motion.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace wire {
namespace {

using glm::dvec3;

// det of the 3x3 minor of m without row r and column c.
double minor3(const double m[4][4], int r, int c) {
    int rows[3], cols[3];
    for (int i = 0, k = 0; i < 4; ++i)
        if (i != r) rows[k++] = i;
    for (int j = 0, k = 0; j < 4; ++j)
        if (j != c) cols[k++] = j;
    const auto e = [&](int i, int j) { return m[rows[i]][cols[j]]; };
    return e(0, 0) * (e(1, 1) * e(2, 2) - e(1, 2) * e(2, 1)) - e(0, 1) * (e(1, 0) * e(2, 2) - e(1, 2) * e(2, 0)) +
           e(0, 2) * (e(1, 0) * e(2, 1) - e(1, 1) * e(2, 0));
}

// The top eigenpair of Horn's symmetric, traceless 4x4 matrix N (the quaternion characteristic polynomial method,
// Theobald 2005): the largest root of det(N - x I) = x^4 + c2 x^2 + c1 x + c0 by Newton from an upper bound (it
// descends monotonically onto it), then the eigenvector as the largest column of the adjugate of N - x I (rank 3).
// A few hundred operations where Jacobi sweeps take thousands. Returns false when no column stands out.
bool top_eigenvector(const double N[4][4], double upper, double q[4]) {
    double N2[4][4] = {};
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            for (int k = 0; k < 4; ++k) N2[i][j] += N[i][k] * N[k][j];
    double tr2 = 0.0, tr3 = 0.0;
    for (int i = 0; i < 4; ++i) {
        tr2 += N2[i][i];
        for (int k = 0; k < 4; ++k) tr3 += N2[i][k] * N[k][i];
    }
    double det = 0.0;
    for (int c = 0; c < 4; ++c) det += ((c & 1) ? -1.0 : 1.0) * N[0][c] * minor3(N, 0, c);
    const double c2 = -0.5 * tr2, c1 = -tr3 / 3.0, c0 = det;
    double x = upper;
    for (int it = 0; it < 60; ++it) {
        const double x2 = x * x;
        const double p = (x2 + c2) * x2 + c1 * x + c0, dp = 4.0 * x2 * x + 2.0 * c2 * x + c1;
        if (!(dp != 0.0)) break;
        const double step = p / dp;
        x -= step;
        if (!(std::abs(step) > 1e-15 * std::abs(x))) break;
    }
    double A[4][4];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) A[i][j] = N[i][j] - (i == j ? x : 0.0);
    // Column j of adj(A): (-1)^(i+j) det(minor(A, j, i)), i = 0..3; adj(A) = k q q^T, so the column through the
    // largest diagonal entry is the largest and most accurate one.
    int j = 0;
    double diag = -1.0;
    for (int k = 0; k < 4; ++k) {
        const double d = std::abs(minor3(A, k, k));
        if (d > diag) diag = d, j = k;
    }
    double best = 0.0;
    for (int i = 0; i < 4; ++i) {
        q[i] = (((i + j) & 1) ? -1.0 : 1.0) * minor3(A, j, i);
        best += q[i] * q[i];
    }
    return best > 0.0 && std::isfinite(best);
}

// The nodes a reference takes from a state of n nodes: 0, 1, 2, 3, then each step 1.5x the last (5, 8, 12, 18,
// 27, ...), the last entry always the last node. Returns how many (at most kCapacity).
uint32_t reference_indices(std::size_t n, std::size_t (&at)[MotionReference::kCapacity]) {
    if (n == 0) return 0;
    std::size_t i = 0, step = 1;
    uint32_t count = 0;
    for (;;) {
        at[count++] = i;
        if (i + 1 >= n || count == MotionReference::kCapacity) return count;
        if (i >= 3) step = std::max<std::size_t>(step + 1, (step * 3) / 2);
        i = count + 1 == MotionReference::kCapacity ? n - 1 : std::min(n - 1, i + step);
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

namespace {

// 2 e2 / e1^2 of the weighted covariance of `p` (e1 = s1 + s2 + s3, e2 = s1 s2 + s1 s3 + s2 s3, its eigenvalues): 0
// for collinear points, and 2 (s2 + s3) / (s1 + s2 + s3) to first order in (s2 + s3) / s1, which is Horn's
// eigenvalue gap over its top eigenvalue for a rigid motion of these points. No root, no trigonometry.
double determinacy(const dvec3* p, const double* w, uint32_t m) {
    double wsum = 0.0;
    dvec3 c(0.0);
    for (uint32_t k = 0; k < m; ++k) wsum += w[k], c += w[k] * p[k];
    if (!(wsum > 0.0)) return 0.0;
    c /= wsum;
    double xx = 0.0, yy = 0.0, zz = 0.0, xy = 0.0, xz = 0.0, yz = 0.0;
    for (uint32_t k = 0; k < m; ++k) {
        const dvec3 d = p[k] - c;
        xx += w[k] * d.x * d.x, yy += w[k] * d.y * d.y, zz += w[k] * d.z * d.z;
        xy += w[k] * d.x * d.y, xz += w[k] * d.x * d.z, yz += w[k] * d.y * d.z;
    }
    const double e1 = xx + yy + zz;
    const double e2 = xx * yy - xy * xy + xx * zz - xz * xz + yy * zz - yz * yz;
    if (!(e1 > 0.0) || !std::isfinite(e1)) return 0.0;
    return std::max(0.0, 2.0 * e2 / (e1 * e1));
}

}  // namespace

MotionReference motion_samples(const WireNodes& nodes) {
    MotionReference ref;
    const std::size_t n = nodes.size();
    ref.node_count = static_cast<uint32_t>(n);
    ref.by_index = nodes.ids.size() != n;
    // Nodes 0, 1, 2, 3, then each step 1.5x the last, and always the last node (reference_indices): the start
    // dense, the whole wire spanned (a far node pins the rotation about a straight start).
    std::size_t at[MotionReference::kCapacity];
    ref.count = reference_indices(n, at);
    for (uint32_t k = 0; k < ref.count; ++k) {
        ref.position[k] = nodes.positions[at[k]];
        ref.id[k] = ref.by_index ? static_cast<uint32_t>(at[k]) : nodes.ids[at[k]];
    }
    return ref;
}

bool samples_match(const MotionReference& from, const WireNodes& to) {
    const std::size_t n = to.size();
    if (from.count == 0 || from.node_count != n || from.by_index != (to.ids.size() != n)) return false;
    if (from.by_index) return true;
    std::size_t at[MotionReference::kCapacity];
    (void)reference_indices(n, at);
    for (uint32_t k = 0; k < from.count; ++k)
        if (to.ids[at[k]] != from.id[k]) return false;
    return true;
}

MotionReference motion_reference(const WireNodes& nodes) {
    MotionReference ref = motion_samples(nodes);
    weigh_reference(ref);
    return ref;
}

void weigh_reference(MotionReference& ref) {
    if (ref.count == 0) return;
    // `s`: the length of the polyline through the reference's nodes (the polyline through all nodes where they
    // are dense, at the start; beyond, chords of the sparse ones, a little short of it: it only shapes the weights).
    double arc[MotionReference::kCapacity];
    double s = 0.0;
    for (uint32_t k = 0; k < ref.count; ++k) {
        if (k != 0) s += glm::length(ref.position[k] - ref.position[k - 1]);
        arc[k] = s;
    }
    // The reach: from two elements, quadrupled until the nodes within it fix a rotation (or it spans the wire).
    const uint32_t m = ref.count;
    const double whole = arc[m - 1];
    double reach = std::max(arc[std::min<uint32_t>(2, m - 1)], 1e-300);
    double w[MotionReference::kCapacity];
    double fixed = 0.0;
    for (;;) {
        for (uint32_t k = 0; k < m; ++k) {  // (1 + s / 4l)^-4: falls like exp(-s / l) near the start, no exp
            const double r = 1.0 / (1.0 + arc[k] / (4.0 * reach));
            w[k] = (r * r) * (r * r);
        }
        fixed = determinacy(ref.position.data(), w, m);
        if (fixed >= 1e-3 || !(reach < whole)) break;
        reach *= 4.0;
    }
    for (uint32_t k = 0; k < m; ++k) ref.weight[k] = static_cast<float>(w[k]);
    ref.determinacy = static_cast<float>(fixed);
}

namespace {

// One weighted fit of matched pairs (a old, b new) with weights w; confidence 0 where it cannot be had.
MotionFit fit_pairs(const dvec3* a, const dvec3* b, const double* w, uint32_t m, double fixed) {
    MotionFit fit;
    fit.matched = m;
    // For a rigid motion the top eigenvalue is the spread and the gap to the next one, over it, is the reference's
    // determinacy: what fixes the rotation about the line through the nodes (see the header for the thresholds).
    // Nodes that do not fix it get the projection: nothing to solve.
    const double confidence = smoothstep(1e-4, 1e-3, fixed);
    if (!(confidence > 0.0)) return fit;
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
    double v[4] = {};
    if (!top_eigenvector(N, spread, v)) return fit;
    glm::dquat q(v[0], v[1], v[2], v[3]);
    const double len = std::sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
    if (!(len > 0.0) || !std::isfinite(len)) return fit;
    q = q * (1.0 / len);
    if (q.w < 0.0) q = -q;  // the shorter way round
    fit.rotation = q;
    fit.confidence = confidence;
    return fit;
}

}  // namespace

MotionFit fit_motion(const MotionReference& from, const WireNodes& to) {
    MotionFit fit;
    if (from.count == 0) return fit;
    const bool by_index = to.ids.size() != to.size();
    if (by_index != from.by_index || (by_index && to.size() != from.node_count)) return fit;
    dvec3 a[MotionReference::kCapacity], b[MotionReference::kCapacity];
    double w[MotionReference::kCapacity];
    uint32_t m = 0;
    bool moved = false;
    std::size_t at[MotionReference::kCapacity];  // where the reference's nodes were: ids are looked up from there
    (void)reference_indices(from.node_count, at);
    for (uint32_t k = 0; k < from.count; ++k) {
        const long j = by_index ? static_cast<long>(from.id[k]) : find_id(to, from.id[k], at[k]);
        if (j < 0) continue;
        a[m] = from.position[k];
        b[m] = to.positions[static_cast<std::size_t>(j)];
        w[m] = from.weight[k];
        moved = moved || b[m] != a[m];
        ++m;
    }
    fit.matched = m;
    if (m < 3) return fit;
    if (!moved) {  // the nodes did not move (a static wire seen anew): no rotation, none to solve for
        fit.confidence = 1.0;
        return fit;
    }
    return fit_pairs(a, b, w, m, from.determinacy);
}

glm::dquat carried_rotation(const MotionFit& fit) {
    if (!(fit.confidence > 0.0)) return {1.0, 0.0, 0.0, 0.0};
    if (fit.confidence >= 1.0) return fit.rotation;
    // A fraction of the rotation: the same axis, `confidence` of its angle (q^c, q.w >= 0).
    const glm::dvec3 v(fit.rotation.x, fit.rotation.y, fit.rotation.z);
    const double sin_half = glm::length(v);
    if (!(sin_half > 0.0)) return {1.0, 0.0, 0.0, 0.0};
    const double half = std::atan2(sin_half, fit.rotation.w) * fit.confidence;
    const glm::dvec3 axis = v / sin_half;
    return glm::dquat(std::cos(half), std::sin(half) * axis);
}

glm::dvec3 carry_normal(const MotionFit& fit, const glm::dvec3& previous_normal) {
    if (!(fit.confidence > 0.0)) return previous_normal;
    return carried_rotation(fit) * previous_normal;
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
