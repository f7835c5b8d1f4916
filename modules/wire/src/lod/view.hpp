// Internal: the LOD's view geometry: the settings' defaults, world -> view, a control hull's nearest depth and
// off-axis factor, the screen edges' factors and the inflated frustum-plane test.
#pragma once

#include "wire/lod.hpp"

#include <glm/mat3x3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace wire::lod_stage {

constexpr double default_tolerance_px = 0.5;
constexpr uint32_t default_max_rings = 256;
constexpr uint32_t default_max_sides = 32;
constexpr double default_band = 0.25;
constexpr double default_strip_radius_px = 2.0;
constexpr double default_line_radius_px = 0.5;

inline double tolerance_or_default(double tolerance_px) {
    // Below 1e-6 px a finer tolerance changes nothing on screen, and a denormal one underflows the world-space
    // bound (tolerance * z / focal) to 0 on some paths but not others (fuzz_lod: 2.2e-317 px).
    constexpr double min_tolerance_px = 1e-6;
    if (!(tolerance_px > 0.0)) return default_tolerance_px;
    return tolerance_px < min_tolerance_px ? min_tolerance_px : tolerance_px;
}

// Nearest depth (clamped to near) and off-axis factor k of one segment's control hull.
struct HullDepth {
    double z_min = 0.0;
    double k = 1.0;
};

// A segment's four control points in view space (x right, y up, z depth).
using ViewHull = std::array<glm::dvec3, 4>;

// World -> view as a rotation and a translation (lookAt is rigid), taken once per wire.
struct ViewTransform {
    glm::dmat3 rotation;
    glm::dvec3 translation;
    explicit ViewTransform(const LodView& view)
        : rotation(view.view_from_world), translation(view.view_from_world[3]) {}
    [[nodiscard]] glm::dvec3 operator()(const glm::dvec3& p) const {
        const glm::dvec3 q = rotation * p + translation;
        return {q.x, q.y, -q.z};
    }
    [[nodiscard]] ViewHull hull(const CubicBezier& c) const {
        return {(*this)(c.b0), (*this)(c.b1), (*this)(c.b2), (*this)(c.b3)};
    }
};

inline HullDepth hull_depth(const ViewHull& p, const LodView& view) {
    double z_min = std::numeric_limits<double>::infinity();
    double a = 0.0;
    double b = 0.0;
    bool in_front = true;
    for (const glm::dvec3& q : p) {
        z_min = std::min(z_min, q.z);
        if (q.z >= view.near_m) {
            a = std::max(a, std::abs(q.x) / q.z);
            b = std::max(b, std::abs(q.y) / q.z);
        } else {
            in_front = false;
        }
    }
    if (!in_front) {
        // Part of the hull is behind the near plane: x/z is unbounded there, but only on-screen points count.
        a = view.tan_half_x;
        b = view.tan_half_y;
    }
    a = std::min(a, view.tan_half_x);
    b = std::min(b, view.tan_half_y);
    HullDepth h;
    h.z_min = std::max(z_min, view.near_m);
    h.k = std::sqrt(1.0 + a * a + b * b);
    return h;
}

// The screen edges' factors of a view: sqrt(1 + t^2) of each half angle's tangent (a distance to a side plane
// per unit of inflation) and the off-axis factor at the corner, sqrt(1 + tx^2 + ty^2). Every wire of a frame
// asks for the same view's: the last view's are kept (the same operations on the same tangents: the same bits).
struct EdgeFactors {
    double tx = std::numeric_limits<double>::quiet_NaN(), ty = std::numeric_limits<double>::quiet_NaN();
    double sx = 1.0, sy = 1.0, corner = 1.0;
};
inline const EdgeFactors& edge_factors(const LodView& view) {
    thread_local EdgeFactors e;
    if (!(e.tx == view.tan_half_x && e.ty == view.tan_half_y)) {
        const double tx = view.tan_half_x, ty = view.tan_half_y;
        e = {tx, ty, std::sqrt(1.0 + tx * tx), std::sqrt(1.0 + ty * ty), std::sqrt(1.0 + tx * tx + ty * ty)};
    }
    return e;
}

// The frustum planes in view space, tested against points inflated by a radius: bit i is set when the point is
// farther than radius_m outside plane i (left, right, bottom, top, near, far: the planes of LodView::planes).
struct PlaneTest {
    double tx, ty, rx, ry, r, near, far;
    PlaneTest(const LodView& view, double radius_m) : PlaneTest(view, radius_m, edge_factors(view)) {}
    PlaneTest(const LodView& view, double radius_m, const EdgeFactors& f)
        : tx(view.tan_half_x), ty(view.tan_half_y), rx(radius_m * f.sx), ry(radius_m * f.sy), r(radius_m),
          near(view.near_m), far(view.far_m) {}
    [[nodiscard]] unsigned outside(const glm::dvec3& q) const {
        unsigned m = 0;
        m |= (q.x + q.z * tx < -rx) ? 1u : 0u;
        m |= (q.z * tx - q.x < -rx) ? 2u : 0u;
        m |= (q.y + q.z * ty < -ry) ? 4u : 0u;
        m |= (q.z * ty - q.y < -ry) ? 8u : 0u;
        m |= (q.z - near < -r) ? 16u : 0u;
        m |= (far - q.z < -r) ? 32u : 0u;
        return m;
    }
    // Planes that all four points are outside of (0: the inflated hull may meet the frustum).
    [[nodiscard]] unsigned outside(const ViewHull& h) const {
        return outside(h[0]) & outside(h[1]) & outside(h[2]) & outside(h[3]);
    }
};

}  // namespace wire::lod_stage
