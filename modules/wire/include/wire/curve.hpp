// The interface between the curve stage (spline.hpp: nodes -> Curve) and the ring stage (frames, rings, tube):
// a wire's centre line as a chain of cubic Bezier segments in double precision, metres.
#pragma once

#include <glm/vec3.hpp>
#include <glm/geometric.hpp>

#include <cstdint>
#include <vector>

namespace wire {

/// One cubic piece of a wire's centre line, Bezier control points b0..b3 (b0, b3 are nodes; metres).
/// Every spline the module offers (Catmull-Rom with any alpha, cardinal, Kochanek-Bartels, C2, automatic,
/// linear) is piecewise cubic, so this one form carries them all; its control hull bounds the segment.
struct CubicBezier {
    glm::dvec3 b0{}, b1{}, b2{}, b3{};
};

/// Position at t in [0,1] (de Casteljau-free Bernstein form; exact at t = 0 and t = 1).
inline glm::dvec3 position(const CubicBezier& c, double t) {
    const double s = 1.0 - t;
    return (s * s * s) * c.b0 + (3.0 * s * s * t) * c.b1 + (3.0 * s * t * t) * c.b2 + (t * t * t) * c.b3;
}
/// First derivative d/dt at t (analytic; metres per unit t).
inline glm::dvec3 derivative(const CubicBezier& c, double t) {
    const double s = 1.0 - t;
    return (3.0 * s * s) * (c.b1 - c.b0) + (6.0 * s * t) * (c.b2 - c.b1) + (3.0 * t * t) * (c.b3 - c.b2);
}
/// Second derivative d2/dt2 at t.
inline glm::dvec3 second_derivative(const CubicBezier& c, double t) {
    return (6.0 * (1.0 - t)) * (c.b2 - 2.0 * c.b1 + c.b0) + (6.0 * t) * (c.b3 - 2.0 * c.b2 + c.b1);
}

/// A wire's centre line after the curve stage.
/// Segment i runs from curve node i to curve node i+1; a closed curve's last segment returns to node 0.
/// Curve nodes are the input nodes after coincident ones were merged; `source_node` maps back so that
/// errors and outputs can name the input node.
struct Curve {
    std::vector<CubicBezier> segments;
    std::vector<uint32_t> source_node;  ///< per curve node: index of the input node it came from
    std::vector<float> radius_m;        ///< per curve node: tube radius (metres, > 0)
    std::vector<float> stretch;         ///< per segment: L_current / L_rest (1 = rest length; > 0)
    bool closed = false;

    [[nodiscard]] std::size_t node_count() const { return source_node.size(); }
    [[nodiscard]] std::size_t segment_count() const { return segments.size(); }
};

}  // namespace wire
