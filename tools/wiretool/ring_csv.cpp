// Ring CSV rows shared by `wiretool mesh` and `wiretool view`.
#include "ring_csv.hpp"

#include <cstdio>

namespace wiretool {

void append_ring_rows(std::string& csv, std::size_t frame, std::size_t wire_index, const wire::RingSet& r,
                      long sides) {
    char line[680];
    for (std::size_t i = 0; i < r.params.size(); ++i) {
        const glm::dvec3 c = r.origin_m + r.centre_m[i];
        const wire::Frame& f = r.frames[i];
        int n = std::snprintf(
            line, sizeof line,
            "%zu,%zu,%zu,%u,%.17g,%.17g,%.17g,%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.17g", frame,
            wire_index, i, r.params[i].segment, r.params[i].t, c.x, c.y, c.z, f.t.x, f.t.y, f.t.z, f.r.x, f.r.y,
            f.r.z, f.s.x, f.s.y, f.s.z, double(r.rings[i].radius_m), r.u[i]);
        if (sides >= 0) n += std::snprintf(line + n, sizeof line - static_cast<std::size_t>(n), ",%ld", sides);
        csv.append(line, static_cast<std::size_t>(n));
        csv.push_back('\n');
    }
}

}  // namespace wiretool
