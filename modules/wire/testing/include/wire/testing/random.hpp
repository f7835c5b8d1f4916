// The random generator of the test families: splitmix64, so a family gives the same cases on every platform and
// standard library (std's distributions are implementation-defined). Test support only (target wire::testing).
#pragma once

#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace wire::testing {

/// splitmix64 with the draws the families need. Every draw is a pure function of the state.
struct Random {
    uint64_t state = 0;

    /// The next 64 random bits.
    uint64_t next() {
        uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    /// Uniform in [lo, hi) (53 random bits).
    double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53; }
    /// Log-uniform in [lo, hi); lo, hi > 0.
    double log_uniform(double lo, double hi) { return std::exp(uniform(std::log(lo), std::log(hi))); }
    /// An integer in [lo, hi] (modulo bias below 2^-32 for the small ranges used here).
    int integer(int lo, int hi) { return lo + static_cast<int>(next() % static_cast<uint64_t>(hi - lo + 1)); }
    /// A unit vector, uniform on the sphere.
    glm::dvec3 unit() {
        const double z = uniform(-1.0, 1.0), a = uniform(0.0, 2.0 * std::numbers::pi);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        return {r * std::cos(a), r * std::sin(a), z};
    }
};

}  // namespace wire::testing
