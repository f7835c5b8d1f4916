// The screen-error measure: the largest pixel distance from the curve to the polyline of its rings' centres.
#include "wire/lod.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace wire {
namespace {

// Point-to-segment distance in 2D.
double distance_to_piece(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    double t = len2 > 0.0 ? glm::dot(p - a, ab) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return glm::length(p - (a + t * ab));
}

// Pixel distance from p to the view-space piece a-b after clipping it to z >= near; infinity if nothing is left.
double distance_to_view_piece(const glm::dvec2& p_px, glm::dvec3 a, glm::dvec3 b, const LodView& view) {
    const double n = view.near_m;
    if (a.z < n && b.z < n) return std::numeric_limits<double>::infinity();
    if (a.z < n) a = a + (b - a) * ((n - a.z) / (b.z - a.z));
    if (b.z < n) b = b + (a - b) * ((n - b.z) / (a.z - b.z));
    a.z = std::max(a.z, n);
    b.z = std::max(b.z, n);
    return distance_to_piece(p_px, view.view_to_px(a), view.view_to_px(b));
}

}  // namespace

ScreenError measure_screen_error(const Curve& curve, std::span<const RingParam> params, const LodView& view,
                                 int samples_per_segment) {
    ScreenError out;
    const std::size_t n_seg = curve.segment_count();
    const std::size_t n_rings = params.size();
    if (n_seg == 0 || n_rings == 0 || samples_per_segment < 1) return out;

    std::vector<glm::dvec3> centre(n_rings);
    for (std::size_t k = 0; k < n_rings; ++k) {
        centre[k] = view.to_view(position(curve.segments[params[k].segment], params[k].t));
    }
    // First ring of every segment (rings are in segment order).
    std::vector<std::size_t> first(n_seg + 1, n_rings);
    for (std::size_t k = n_rings; k-- > 0;) first[params[k].segment] = k;
    for (std::size_t i = n_seg; i-- > 0;) first[i] = std::min(first[i], first[i + 1]);

    const std::size_t n_pieces = curve.closed ? n_rings : n_rings - 1;
    auto piece_distance = [&](const glm::dvec2& p, std::ptrdiff_t j) {
        if (curve.closed) {
            j = (j % static_cast<std::ptrdiff_t>(n_pieces) + static_cast<std::ptrdiff_t>(n_pieces)) %
                static_cast<std::ptrdiff_t>(n_pieces);
        } else if (j < 0 || j >= static_cast<std::ptrdiff_t>(n_pieces)) {
            return std::numeric_limits<double>::infinity();
        }
        const std::size_t a = static_cast<std::size_t>(j);
        const std::size_t b = (a + 1) % n_rings;
        return distance_to_view_piece(p, centre[a], centre[b], view);
    };

    for (std::size_t i = 0; i < n_seg; ++i) {
        const std::size_t lo = first[i];
        const std::size_t hi = first[i + 1];  // one past the segment's last ring
        for (int s = 0; s <= samples_per_segment; ++s) {
            const double t = static_cast<double>(s) / samples_per_segment;
            const glm::dvec3 q = view.to_view(position(curve.segments[i], t));
            if (!(q.z >= view.near_m && q.z <= view.far_m)) continue;
            const glm::dvec2 p = view.view_to_px(q);
            if (!(p.x >= 0.0 && p.x <= view.width_px && p.y >= 0.0 && p.y <= view.height_px)) continue;
            // The piece that holds t: the last ring of this segment with param t <= t.
            std::ptrdiff_t k = static_cast<std::ptrdiff_t>(lo);
            while (static_cast<std::size_t>(k + 1) < hi && params[static_cast<std::size_t>(k + 1)].t <= t) ++k;
            if (lo == hi) k = static_cast<std::ptrdiff_t>(lo) - 1;  // no ring on this segment (count 0): neighbours
            const double d = std::min({piece_distance(p, k - 1), piece_distance(p, k), piece_distance(p, k + 1)});
            ++out.samples;
            if (d > out.max_px) {
                out.max_px = d;
                out.worst_segment = static_cast<uint32_t>(i);
                out.worst_t = t;
            }
        }
    }
    return out;
}

}  // namespace wire
