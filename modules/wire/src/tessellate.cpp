// Ring placement: fixed, adaptive (Wang's formula) or externally given ring counts per segment.
#include "wire/tessellate.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace wire {

uint32_t wang_ring_count(const CubicBezier& c, double tolerance_m, uint32_t max_rings) {
    max_rings = std::max<uint32_t>(max_rings, 1);
    const double m = std::max(glm::length(c.b0 - 2.0 * c.b1 + c.b2), glm::length(c.b1 - 2.0 * c.b2 + c.b3));
    if (!(tolerance_m > 0.0) || !std::isfinite(m)) {
        return max_rings;
    }
    const double n = std::ceil(std::sqrt(3.0 * m / (4.0 * tolerance_m)));
    if (!(n < static_cast<double>(max_rings))) {
        return max_rings;
    }
    return std::max<uint32_t>(1, static_cast<uint32_t>(n));
}

void segment_ring_counts(const Curve& curve, const TessellateSettings& settings, std::vector<uint32_t>& counts) {
    counts.resize(curve.segment_count());
    if (settings.tolerance_m > 0.0) {
        const uint32_t max_rings = settings.max_rings_per_segment ? settings.max_rings_per_segment : 256;
        for (std::size_t i = 0; i < counts.size(); ++i) {
            counts[i] = wang_ring_count(curve.segments[i], settings.tolerance_m, max_rings);
        }
    } else {
        std::fill(counts.begin(), counts.end(), settings.rings_per_segment ? settings.rings_per_segment : 8u);
    }
}

std::size_t ring_count(std::span<const uint32_t> counts, bool closed) {
    std::size_t n = 0;
    for (const uint32_t c : counts) {
        n += c;
    }
    if (!counts.empty() && counts[0] == 0) ++n;  // segment 0 always starts a ring
    return n + ((!closed && !counts.empty()) ? 1 : 0);
}

void place_rings(const Curve& curve, std::span<const uint32_t> counts, std::vector<RingParam>& out) {
    assert(counts.size() == curve.segment_count() && "place_rings: one count per segment");
    place_rings(counts, curve.closed, out);
}

void place_rings(std::span<const uint32_t> counts, bool closed, std::vector<RingParam>& out) {
    out.resize(ring_count(counts, closed));
    std::size_t k = 0;
    const std::size_t size = out.size();
    for (std::size_t i = 0; i < counts.size(); ++i) {
        const uint32_t n = i == 0 ? std::max<uint32_t>(counts[i], 1) : counts[i];
        if (n <= 1 && k < size) {
            // The common counts below the node resolution (0: crossed, 1: one ring at t = 0): written without a
            // branch on which (they alternate irregularly); a count of 0 leaves the slot to the next ring.
            out[k] = RingParam{static_cast<uint32_t>(i), 0.0};
            k += n;
            continue;
        }
        for (uint32_t j = 0; j < n; ++j) {
            // j / n (not j * (1/n)): exactly the rounded k/N the promise names.
            out[k++] = RingParam{static_cast<uint32_t>(i), j == 0 ? 0.0 : static_cast<double>(j) / n};
        }
    }
    if (!closed && !counts.empty()) {
        out[k++] = RingParam{static_cast<uint32_t>(counts.size() - 1), 1.0};
    }
}

}  // namespace wire
