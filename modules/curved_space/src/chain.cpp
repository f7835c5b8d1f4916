// Chain of bend segments: validation, double-precision segment matrices, the CPU reference transform and
// conservative bounds.
#include "curved_space/chain.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace curved_space {
namespace {

std::string format_number(double v) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.17g", v);
    return buffer;
}

glm::dmat4 rotation_z(double c, double s) {
    glm::dmat4 m(1.0);  // column-major: m[col][row]
    m[0][0] = c;
    m[0][1] = s;
    m[1][0] = -s;
    m[1][1] = c;
    return m;
}

// Ry(a) takes +z to (sin a, 0, cos a) and +x to (cos a, 0, -sin a).
glm::dmat4 rotation_y(double a) {
    const double c = std::cos(a);
    const double s = std::sin(a);
    glm::dmat4 m(1.0);
    m[0][0] = c;
    m[0][2] = -s;
    m[2][0] = s;
    m[2][2] = c;
    return m;
}

glm::dvec3 apply_point(const glm::dmat4& m, const glm::dvec3& p) { return glm::dvec3(m * glm::dvec4(p, 1.0)); }
glm::dvec3 apply_vector(const glm::dmat4& m, const glm::dvec3& v) { return glm::dvec3(m * glm::dvec4(v, 0.0)); }

}  // namespace

Status validate(std::span<const Segment> segments) {
    double total_m = 0.0;
    for (std::size_t i = 0; i < segments.size(); ++i) {
        const Segment& s = segments[i];
        const std::string where = "segment " + std::to_string(i) + ": ";
        const int index = static_cast<int>(i);
        if (!std::isfinite(s.length_m))
            return Status::error(where + "length must be finite, got " + format_number(s.length_m), index);
        if (s.length_m <= 0.0)
            return Status::error(where + "length must be positive, got " + format_number(s.length_m), index);
        if (!std::isfinite(s.angle_rad))
            return Status::error(where + "angle must be finite, got " + format_number(s.angle_rad), index);
        if (!std::isfinite(s.direction_rad))
            return Status::error(where + "direction must be finite, got " + format_number(s.direction_rad), index);
        // Bounded (a bend radius of at least 1e-12 m) so curvature times any coordinate in range stays finite.
        if (!(std::abs(s.angle_rad / s.length_m) <= 1e12))
            return Status::error(where + "curvature angle/length must be at most 1e12 per metre, got angle " +
                                     format_number(s.angle_rad) + " over length " + format_number(s.length_m), index);
        total_m += s.length_m;
        // Bounded so the accumulated matrices stay finite (the wire module's coordinate range too).
        if (!(total_m <= 1e12))
            return Status::error(where + "the chain's total length exceeds 1e12 m (" + format_number(total_m) + ")",
                                 index);
    }
    return Status::success();
}

Status make_chain(std::span<const Segment> segments, Chain& out, const glm::dmat4& world_from_chain) {
    if (Status status = validate(segments); !status) return status;

    Chain chain;
    const std::size_t n = segments.size();
    chain.segments_.assign(segments.begin(), segments.end());
    chain.z_start_.assign(n + 1, 0.0);
    chain.kappa_.assign(n + 1, 0.0);
    chain.cos_gamma_.assign(n + 1, 1.0);
    chain.sin_gamma_.assign(n + 1, 0.0);
    chain.world_from_segment_.assign(n + 1, world_from_chain);
    chain.world_from_bend_.assign(n + 1, world_from_chain);

    for (std::size_t i = 0; i < n; ++i) {
        const Segment& s = segments[i];
        const double d = s.length_m;
        const double a = s.angle_rad;
        const double c = std::cos(s.direction_rad);
        const double sn = std::sin(s.direction_rad);
        chain.kappa_[i] = a / d;
        chain.cos_gamma_[i] = c;
        chain.sin_gamma_[i] = sn;
        chain.world_from_bend_[i] = chain.world_from_segment_[i] * rotation_z(c, sn);
        // End of the arc in the bend frame: (r (1 - cos a), 0, r sin a) written without r = d/a.
        const double half_sinc = sinc(0.5 * a);
        glm::dmat4 translate(1.0);
        translate[3] = glm::dvec4(d * (0.5 * a) * half_sinc * half_sinc, 0.0, d * sinc(a), 1.0);
        chain.world_from_segment_[i + 1] = chain.world_from_bend_[i] * translate * rotation_y(a) * rotation_z(c, -sn);
        chain.z_start_[i + 1] = chain.z_start_[i] + d;
    }
    chain.world_from_bend_[n] = chain.world_from_segment_[n];
    out = std::move(chain);
    return Status::success();
}

Chain::Location Chain::locate(double z_m) const {
    if (!(z_m >= 0.0)) return {0, true};  // also NaN: stays finite-indexed
    // Last start <= z; z_start_ is strictly increasing.
    const auto it = std::upper_bound(z_start_.begin(), z_start_.end(), z_m);
    const auto record = static_cast<std::size_t>(it - z_start_.begin()) - 1;
    return {record, record == segments_.size()};
}

BentVertex Chain::transform(const glm::dvec3& p, const glm::dvec3& n) const {
    const Location at = locate(p.z);
    const std::size_t i = at.record;
    const glm::dvec3 local{p.x, p.y, p.z - z_start_[i]};
    const double kappa = at.straight ? 0.0 : kappa_[i];
    BentVertex bent = bend_segment(kappa, cos_gamma_[i], sin_gamma_[i], local, n);
    const glm::dmat4& m = world_from_segment_[i];  // bend_segment already applied Rz(gamma)
    bent.position = apply_point(m, bent.position);
    bent.normal = apply_vector(m, bent.normal);  // rigid: stays unit
    return bent;
}

glm::dvec3 Chain::transform_point(const glm::dvec3& p) const { return transform(p, glm::dvec3(0.0)).position; }

Aabb Chain::bounds(const Aabb& box) const {
    Aabb result{glm::dvec3(std::numeric_limits<double>::infinity()),
                glm::dvec3(-std::numeric_limits<double>::infinity())};
    auto include = [&](const glm::dvec3& p, double inflate) {
        result.min = glm::min(result.min, p - inflate);
        result.max = glm::max(result.max, p + inflate);
    };
    const std::array<glm::dvec2, 4> corners{glm::dvec2{box.min.x, box.min.y}, glm::dvec2{box.max.x, box.min.y},
                                            glm::dvec2{box.min.x, box.max.y}, glm::dvec2{box.max.x, box.max.y}};
    constexpr double max_piece_angle = std::numbers::pi / 16.0;
    constexpr std::size_t max_pieces = 1024;

    // Covers [za, zb] (local to record i) with pieces of at most pi/16 rad. Over a piece, each edge of the box
    // parallel to z (a cross-section corner v_k, fixed) bends into a circular arc of radius |1/kappa - v_k.x|;
    // every bent point of the piece is a convex combination of the four corner arcs at the same z. An arc of
    // angle dth <= pi stays within its sagitta |1/kappa - x| (1 - cos(dth/2)) <= |1 - kappa x| dz dth / 8 of
    // its chord, so the piece lies in the hull of the 8 bent corners at its ends, inflated by that sagitta.
    auto cover = [&](std::size_t i, double kappa, double za, double zb) {
        const double c = cos_gamma_[i];
        const double s = sin_gamma_[i];
        std::array<glm::dvec3, 4> v{};  // cross-section corners in the bend frame
        double stretch = 0.0;           // largest |1 - kappa x| over the corners
        for (std::size_t k = 0; k < 4; ++k) {
            v[k] = {c * corners[k].x + s * corners[k].y, -s * corners[k].x + c * corners[k].y, 0.0};
            stretch = std::max(stretch, std::abs(1.0 - kappa * v[k].x));
        }
        // Enough pieces for the angle limit and for a total sagitta slack of 1e-3 of the local size:
        // n pieces inflate by stretch * (dz/n) * (dth/n) / 8.
        const double span = zb - za;
        const double total_angle = std::abs(kappa * span);
        const double tolerance = 1e-3 * (glm::length(box.max - box.min - glm::dvec3(0, 0, box.max.z - box.min.z)) + span);
        const double by_sagitta =
            tolerance > 0.0 ? std::sqrt(stretch * span * total_angle / (8.0 * tolerance)) : 1.0;
        const auto pieces = static_cast<std::size_t>(std::clamp(
            std::ceil(std::max(total_angle / max_piece_angle, by_sagitta)), 1.0, static_cast<double>(max_pieces)));
        const glm::dmat4& m = world_from_bend_[i];
        const glm::dvec3 zero(0.0);
        auto bent = [&](const glm::dvec3& w, double z) {
            return apply_point(m, bend_segment(kappa, 1.0, 0.0, {w.x, w.y, z}, zero).position);
        };
        for (std::size_t piece = 0; piece < pieces; ++piece) {
            const double z0 = za + (zb - za) * static_cast<double>(piece) / static_cast<double>(pieces);
            const double z1 = piece + 1 == pieces
                                  ? zb
                                  : za + (zb - za) * static_cast<double>(piece + 1) / static_cast<double>(pieces);
            const double dz = z1 - z0;
            const double dth = std::abs(kappa * dz);
            if (dth <= std::numbers::pi) {
                const double inflate = stretch * dz * dth / 8.0;
                for (const glm::dvec3& w : v) {
                    include(bent(w, z0), inflate);
                    include(bent(w, z1), inflate);
                }
            } else {
                // Capped piece count: an arc of length |1 - kappa x| dz stays within half of it from its middle.
                const double zm = 0.5 * (z0 + z1);
                for (const glm::dvec3& w : v) include(bent(w, zm), 0.5 * stretch * dz);
            }
        }
    };

    const double lo = box.min.z;
    const double hi = box.max.z;
    const std::size_t n = segments_.size();
    if (lo < 0.0) cover(0, 0.0, lo, std::min(hi, 0.0));
    for (std::size_t i = 0; i < n; ++i) {
        const double za = std::max(lo, z_start_[i]);
        const double zb = std::min(hi, z_start_[i + 1]);
        if (za <= zb) cover(i, kappa_[i], za - z_start_[i], zb - z_start_[i]);
    }
    // An empty chain has no segment to cover a flat box at z = 0: the end record does.
    if (hi > z_start_[n] || (n == 0 && lo >= 0.0))
        cover(n, 0.0, std::max(lo, z_start_[n]) - z_start_[n], hi - z_start_[n]);
    return result;
}

std::size_t bend_vertices(const Chain& chain, std::span<float> positions, std::span<float> normals,
                          const glm::dvec3& origin_m) {
    assert(positions.size() % 3 == 0 && "positions: xyz per vertex");
    assert((normals.empty() || normals.size() == positions.size()) && "normals: empty or one per position");
    std::size_t folded = 0;
    const std::size_t count = positions.size() / 3;
    for (std::size_t v = 0; v < count; ++v) {
        const glm::dvec3 p = origin_m + glm::dvec3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
        const glm::dvec3 n = normals.empty()
                                 ? glm::dvec3(0.0)
                                 : glm::dvec3(normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]);
        const BentVertex bent = chain.transform(p, n);
        folded += bent.folded ? 1 : 0;
        const glm::dvec3 q = bent.position - origin_m;
        for (int k = 0; k < 3; ++k) positions[3 * v + static_cast<std::size_t>(k)] = static_cast<float>(q[k]);
        if (!normals.empty())
            for (int k = 0; k < 3; ++k)
                normals[3 * v + static_cast<std::size_t>(k)] = static_cast<float>(bent.normal[k]);
    }
    return folded;
}

}  // namespace curved_space
