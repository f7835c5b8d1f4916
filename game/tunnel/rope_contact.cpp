// Contact geometry of the hanging cables (see rope_contact.hpp).
#include "tunnel/rope_contact.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace tunnel {

namespace {

// Signed distance from q to the box [lo, hi] in 2D (negative inside) and the outward normal there.
double box_distance_2d(const glm::dvec2& q, const glm::dvec2& lo, const glm::dvec2& hi, glm::dvec2& normal) {
    const glm::dvec2 c = 0.5 * (lo + hi);
    const glm::dvec2 half = 0.5 * (hi - lo);
    const glm::dvec2 d = glm::abs(q - c) - half;
    const glm::dvec2 sign(q.x < c.x ? -1.0 : 1.0, q.y < c.y ? -1.0 : 1.0);
    if (d.x > 0.0 || d.y > 0.0) {
        const glm::dvec2 out(std::max(d.x, 0.0), std::max(d.y, 0.0));
        const double len = glm::length(out);
        normal = out * sign / len;
        return len;
    }
    if (d.x > d.y) {
        normal = {sign.x, 0.0};
        return d.x;
    }
    normal = {0.0, sign.y};
    return d.y;
}

// Which shapes a query looks at (element_contact narrows them down per element).
struct Near {
    bool wall = true;
    bool ribs = true;
    bool walkway = true;
    uint32_t cables = ~0u;  // bit per wall cable
};

// The deepest contact of a point with the level geometry: signed distance (negative inside) and outward
// normal, unbent. Returns false when nothing is within `reach` of the point.
bool near_contact(const LevelShapes& g, double total_z, const glm::dvec3& p, double reach, double& distance,
                  glm::dvec3& normal, const Near& near) {
    distance = 1e30;
    const double rho = std::sqrt(p.x * p.x + p.y * p.y);
    const glm::dvec3 radial = rho > 1e-12 ? glm::dvec3(p.x / rho, p.y / rho, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    // Wall: inside the cylinder.
    if (near.wall && g.wall_radius_m - rho < reach) {
        distance = g.wall_radius_m - rho;
        normal = -radial;
    }
    // Ribs: in (rho, z) the rectangle [rib_inner, wall] x [z0, z1] of every piece.
    if (near.ribs && rho > g.rib_inner_radius_m - reach) {
        const double zp = std::floor(p.z / g.piece_length_m) * g.piece_length_m;
        for (double base : {zp - g.piece_length_m, zp, zp + g.piece_length_m}) {
            if (base < -1e-9 || base > total_z - 1e-9) continue;
            for (const glm::dvec2& z : g.rib_z_m) {
                if (p.z < base + z.x - reach || p.z > base + z.y + reach) continue;
                glm::dvec2 n2;
                const double d = box_distance_2d({rho, p.z}, {g.rib_inner_radius_m, base + z.x},
                                                 {g.wall_radius_m + 1.0, base + z.y}, n2);
                if (d < distance) {
                    distance = d;
                    normal = n2.x * radial + glm::dvec3(0.0, 0.0, n2.y);
                }
            }
        }
    }
    // Walkway: a box in (x, y) along the whole tunnel.
    if (near.walkway) {
        glm::dvec2 n2;
        const double d = box_distance_2d({p.x, p.y}, g.walkway_min_m, g.walkway_max_m, n2);
        if (d < distance) {
            distance = d;
            normal = {n2.x, n2.y, 0.0};
        }
    }
    // Wall cables: cylinders along z.
    for (std::size_t i = 0; i < g.cables.size(); ++i) {
        if ((near.cables & (1u << i)) == 0) continue;
        const LevelShapes::Cable& c = g.cables[i];
        const glm::dvec2 v = glm::dvec2(p.x, p.y) - c.section_m;
        const double len = glm::length(v);
        const double d = len - c.radius_m;
        if (d < distance) {
            distance = d;
            normal = len > 1e-12 ? glm::dvec3(v.x / len, v.y / len, 0.0) : glm::dvec3(0.0, 1.0, 0.0);
        }
    }
    return distance < reach;
}

}  // namespace

void closest_segments(const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& q0, const glm::dvec3& q1,
                      double& s, double& t) {
    const glm::dvec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
    const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
    if (a <= 1e-18 && e <= 1e-18) {
        s = t = 0.0;
        return;
    }
    if (a <= 1e-18) {
        s = 0.0;
        t = std::clamp(f / e, 0.0, 1.0);
        return;
    }
    const double c = glm::dot(d1, r);
    if (e <= 1e-18) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
        return;
    }
    const double b = glm::dot(d1, d2);
    const double denom = a * e - b * b;
    s = denom > 1e-18 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
    t = (b * s + f) / e;
    if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
}

double bent_metric(const glm::dvec3& n, double z_scale) {
    return std::sqrt(n.x * n.x + n.y * n.y + z_scale * z_scale * n.z * n.z);
}

bool point_contact(const LevelShapes& g, double total_z, const glm::dvec3& p, double reach, double& distance,
                   glm::dvec3& normal) {
    return near_contact(g, total_z, p, reach, distance, normal, {});
}

// Candidate points along the element: its ends, quarter points, and the points closest to the shapes'
// corners (ribs in (rho, z), walkway in (x, y)) and to the wall cables' axes, where the deepest point of a
// straight element lies.
bool element_contact(const LevelShapes& g, double total_z, const glm::dvec3& a, const glm::dvec3& b, double r,
                     double z_scale, ElementContact& out) {
    constexpr double kReach = 0.04;
    const double m = r * 1.3 + kReach;  // r / bent_metric <= r / z_scale; z_scale >= 0.8 in this level
    const glm::dvec3 lo = glm::min(a, b) - m;
    const glm::dvec3 hi = glm::max(a, b) + m;
    // rho is convex along a segment: its largest value is at an end.
    const double rho_a = std::sqrt(a.x * a.x + a.y * a.y), rho_b = std::sqrt(b.x * b.x + b.y * b.y);
    Near near;
    near.wall = std::max(rho_a, rho_b) > g.wall_radius_m - m;
    near.ribs = std::max(rho_a, rho_b) > g.rib_inner_radius_m - m;
    near.walkway = lo.y < g.walkway_max_m.y && hi.y > g.walkway_min_m.y && lo.x < g.walkway_max_m.x &&
                   hi.x > g.walkway_min_m.x;
    near.cables = 0;
    for (std::size_t i = 0; i < g.cables.size(); ++i) {
        const LevelShapes::Cable& c = g.cables[i];
        if (lo.x < c.section_m.x + c.radius_m && hi.x > c.section_m.x - c.radius_m &&
            lo.y < c.section_m.y + c.radius_m && hi.y > c.section_m.y - c.radius_m)
            near.cables |= 1u << i;
    }
    if (!near.wall && !near.ribs && !near.walkway && near.cables == 0) return false;

    double ts[32];
    int nt = 0;
    for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) ts[nt++] = t;
    const glm::dvec3 d = b - a;
    auto closest_t_2d = [&](const glm::dvec2& p0, const glm::dvec2& p1, const glm::dvec2& q) {
        const glm::dvec2 e = p1 - p0;
        const double ee = glm::dot(e, e);
        return ee > 1e-18 ? std::clamp(glm::dot(q - p0, e) / ee, 0.0, 1.0) : 0.0;
    };
    // Walkway corners and cable axes in (x, y): the element projects to a straight segment there.
    const glm::dvec2 a2(a.x, a.y), b2(b.x, b.y);
    if (near.walkway)
        for (const glm::dvec2& c :
             {g.walkway_min_m, g.walkway_max_m, glm::dvec2(g.walkway_min_m.x, g.walkway_max_m.y),
              glm::dvec2(g.walkway_max_m.x, g.walkway_min_m.y)})
            ts[nt++] = closest_t_2d(a2, b2, c);
    for (std::size_t i = 0; i < g.cables.size(); ++i)
        if ((near.cables & (1u << i)) != 0 && nt < 32) ts[nt++] = closest_t_2d(a2, b2, g.cables[i].section_m);
    // Rib corners in (rho, z): rho is nearly linear along a short element.
    if (near.ribs) {
        const glm::dvec2 ra(rho_a, a.z), rb(rho_b, b.z);
        for (double base = std::floor((lo.z - 1.0) / g.piece_length_m) * g.piece_length_m; base <= hi.z + 1.0;
             base += g.piece_length_m)
            for (const glm::dvec2& z : g.rib_z_m)
                for (double zc : {base + z.x, base + z.y})
                    if (zc > lo.z && zc < hi.z && nt < 32)
                        ts[nt++] = closest_t_2d(ra, rb, {g.rib_inner_radius_m, zc});
    }
    bool found = false;
    for (int i = 0; i < nt; ++i) {
        const glm::dvec3 p = a + ts[i] * d;
        double dist = 0.0;
        glm::dvec3 n;
        if (!near_contact(g, total_z, p, m, dist, n, near)) continue;
        const double depth = r / bent_metric(n, z_scale) - dist;
        if (depth > 0.0 && (!found || depth > out.depth_m)) {
            out = {ts[i], n, depth};
            found = true;
        }
    }
    return found;
}

}  // namespace tunnel
