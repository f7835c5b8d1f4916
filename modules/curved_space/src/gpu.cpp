// Segment records for the GPU and the GLSL bend function (kept beside the CPU reference it mirrors).
#include "curved_space/gpu.hpp"

#include <cmath>

namespace curved_space {

std::vector<GpuSegment> gpu_segments(const Chain& chain, const glm::dvec3& camera_position_m) {
    const std::size_t n = chain.segment_count();
    std::vector<GpuSegment> records(n + 1);
    for (std::size_t i = 0; i <= n; ++i) {
        glm::dmat4 m = chain.world_from_bend(i);
        m[3] -= glm::dvec4(camera_position_m, 0.0);
        GpuSegment& r = records[i];
        r.world_from_bend = glm::mat4(m);
        const double gamma = i < n ? chain.segment(i).direction_rad : 0.0;
        const double length = i < n ? chain.segment(i).length_m : 0.0;
        r.params = glm::vec4(static_cast<float>(chain.z_start_m(i)), static_cast<float>(length),
                             static_cast<float>(chain.kappa_per_m(i)), static_cast<float>(gamma));
        r.direction = glm::vec4(static_cast<float>(std::cos(gamma)), static_cast<float>(std::sin(gamma)), 0.0f, 0.0f);
    }
    return records;
}

std::string_view glsl_bend_source() {
    return R"glsl(
#ifndef CS_SEGMENT_BINDING
#define CS_SEGMENT_BINDING 3
#endif
struct CsSegment {
    mat4 world_from_bend;  // camera-relative
    vec4 params;           // z_start, length, kappa, gamma
    vec4 direction;        // cos(gamma), sin(gamma), 0, 0
};
layout(std430, binding = CS_SEGMENT_BINDING) readonly buffer CurvedSpaceSegments {
    CsSegment cs_segments[];
};

// sin(t)/t without dividing by a small t (float: the series is exact to rounding below 1e-2).
float cs_sinc(float t) {
    float t2 = t * t;
    if (abs(t) < 1e-2) return 1.0 - t2 / 6.0 * (1.0 - t2 / 20.0);
    return sin(t) / t;
}

// Bends an unbent position/normal along the chain: see curved_space::Chain::transform.
void cs_bend(vec3 p, vec3 n, out vec3 p_bent, out vec3 n_bent, out bool folded) {
    // Last record with z_start <= p.z (record 0 for p.z < 0).
    int lo = 0;
    int hi = cs_segments.length() - 1;
    while (lo < hi) {
        int mid = (lo + hi + 1) / 2;
        if (cs_segments[mid].params.x <= p.z) lo = mid; else hi = mid - 1;
    }
    vec4 params = cs_segments[lo].params;
    vec2 cs = cs_segments[lo].direction.xy;
    // Before the chain and after it (end record, kappa 0) the map is straight.
    float kappa = p.z < params.x ? 0.0 : params.z;
    float z = p.z - params.x;

    vec3 q = vec3(cs.x * p.x + cs.y * p.y, -cs.y * p.x + cs.x * p.y, z);
    vec3 m = vec3(cs.x * n.x + cs.y * n.y, -cs.y * n.x + cs.x * n.y, n.z);
    float th = kappa * z;
    float c = cos(th);
    float s = sin(th);
    float half_th = 0.5 * th;
    float sh = cs_sinc(half_th);
    vec3 b = vec3(q.x * c + z * half_th * sh * sh, q.y, z * cs_sinc(th) - q.x * s);

    float stretch = 1.0 - kappa * q.x;
    float sgn = stretch < 0.0 ? -1.0 : 1.0;
    vec3 a = vec3(abs(stretch) * m.x, abs(stretch) * m.y, sgn * m.z);
    if (dot(a, a) == 0.0) a = m;
    vec3 nb = vec3(c * a.x + s * a.z, a.y, -s * a.x + c * a.z);

    mat4 w = cs_segments[lo].world_from_bend;
    p_bent = (w * vec4(b, 1.0)).xyz;
    vec3 nw = mat3(w) * nb;
    float len = length(nw);
    n_bent = len > 0.0 ? nw / len : nw;
    folded = stretch <= 0.0;
}
)glsl";
}

}  // namespace curved_space
