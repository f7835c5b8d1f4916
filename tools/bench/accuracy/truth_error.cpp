// The accuracy bench's error measures (truth_error.hpp).
#include "bench/accuracy/truth_error.hpp"

#include <wire/frames.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace wiretool::bench {
namespace {

constexpr double kPi = std::numbers::pi;

double point_segment_distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

/// Distance from p (a point drawn for curve segment `segment`) to the scene's exact curve.
double truth_distance(const ReferenceScene& s, const glm::dvec3& p, const wire::Curve& curve,
                      uint32_t segment) {
    if (s.catenary_truth) return s.catenary.distance(p);
    // Search the dense truth between the nodes one before and two after the segment's start node.
    const std::size_t n = s.node_param.size();
    const std::size_t first = curve.source_node[segment];
    const std::size_t last = segment + 1 < curve.node_count() ? curve.source_node[segment + 1] : n - 1;
    const double p0 = s.node_param[first > 0 ? first - 1 : 0];
    const double p1 = s.node_param[std::min(last + 1, n - 1)];
    auto lo = std::lower_bound(s.dense_param.begin(), s.dense_param.end(), p0);
    auto hi = std::upper_bound(s.dense_param.begin(), s.dense_param.end(), p1);
    std::size_t i0 = static_cast<std::size_t>(lo - s.dense_param.begin());
    std::size_t i1 = std::min(static_cast<std::size_t>(hi - s.dense_param.begin()), s.dense.size() - 1);
    if (i0 > 0) --i0;
    double best = 1e300;
    for (std::size_t i = i0; i < i1; ++i)
        best = std::min(best, point_segment_distance(p, s.dense[i], s.dense[i + 1]));
    return best;
}

/// Ring parameters with `sub` steps per ring interval (ring i of `params` is entry i*sub), for a reference
/// RMF.
std::vector<wire::RingParam> refine(const std::vector<wire::RingParam>& params, int sub) {
    std::vector<wire::RingParam> out;
    for (std::size_t i = 0; i + 1 < params.size(); ++i) {
        const wire::RingParam a = params[i], b = params[i + 1];
        const double tb = b.segment == a.segment ? b.t : 1.0;
        for (int k = 0; k < sub; ++k) out.push_back({a.segment, a.t + (tb - a.t) * k / sub});
    }
    out.push_back(params.back());
    return out;
}

}  // namespace

double world_error_m(const ReferenceScene& s, const wire::Curve& curve,
                     const std::vector<wire::RingParam>& params) {
    double worst = 0.0;
    for (std::size_t i = 0; i < params.size(); ++i) {
        const glm::dvec3 a = wire::position(curve.segments[params[i].segment], params[i].t);
        const bool last = i + 1 == params.size();
        const glm::dvec3 b =
            last ? a : wire::position(curve.segments[params[i + 1].segment], params[i + 1].t);
        for (int q = 0; q < (last ? 1 : 4); ++q) {
            const glm::dvec3 p = a + (b - a) * (q / 4.0);
            if (s.straight_segments > 0) {
                if (params[i].segment < s.straight_segments &&
                    (last || params[i + 1].segment < s.straight_segments))
                    worst = std::max(worst, std::hypot(p.y, p.z));
            } else {
                worst = std::max(worst, truth_distance(s, p, curve, params[i].segment));
            }
        }
    }
    return worst;
}

double twist_error_deg(const wire::Curve& curve, const std::vector<wire::RingParam>& params,
                       const wire::RingSet& rings) {
    constexpr int kSub = 64;
    const std::vector<wire::RingParam> fine = refine(params, kSub);
    wire::RingSet ref;
    wire::build_rings(curve, fine, {}, ref);
    double worst = 0.0;
    for (std::size_t i = 0; i < rings.frames.size(); ++i) {
        const wire::Frame& g = ref.frames[i * kSub];
        const wire::Frame& f = rings.frames[i];
        worst =
            std::max(worst, std::abs(std::atan2(glm::dot(glm::cross(g.r, f.r), g.t), glm::dot(g.r, f.r))));
    }
    return worst * 180.0 / kPi;
}

}  // namespace wiretool::bench
