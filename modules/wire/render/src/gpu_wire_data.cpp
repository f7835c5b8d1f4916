// The CPU side of the GPU wire passes (gpu_wire_data.hpp): a wire's upload (header, curve nodes, extras) and
// the ring LOD program's uniforms.
#include "gpu_wire_data.hpp"

#include "wire/packed_nodes.hpp"
#include "wire/spline.hpp"

#include <epoxy/gl.h>
#include <glm/common.hpp>
#include <glm/mat3x3.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <numbers>

namespace wire::render::detail {

GpuCurveHeader packed_header(const PackedNodes& p, uint32_t segment_first, uint32_t slot, uint32_t material,
                             bool caps, const WireMotion& motion, uint32_t node_first, uint32_t extra_first) {
    GpuCurveHeader h;
    h.node_first = node_first;
    h.node_count = static_cast<uint32_t>(p.node_count);
    h.segment_first = segment_first;
    const uint32_t kind = p.kind == SplineKind::linear      ? kKindLinear
                          : p.kind == SplineKind::c2        ? kKindC2
                          : p.kind == SplineKind::automatic ? kKindAutomatic
                                                            : kKindCatmullRom;
    h.flags = (p.closed ? kHeaderClosed : 0u) | (kind << kHeaderKindShift) | (caps ? kHeaderCaps : 0u) |
              (p.per_node_kb ? kHeaderPerNode : 0u) | (p.stretch ? kHeaderStretch : 0u) |
              (motion.fit ? kHeaderFitMotion : 0u) | (p.quantised ? kHeaderQuantised : 0u) |
              (material << kHeaderMaterialShift);
    h.kb = {p.alpha, p.tension, p.bias, p.continuity};
    h.extra_first = extra_first;
    h.slot = slot;
    h.origin_m[0] = static_cast<float>(p.origin_m.x), h.origin_m[1] = static_cast<float>(p.origin_m.y),
    h.origin_m[2] = static_cast<float>(p.origin_m.z);  // exact: pack_nodes made it a float_point
    h.motion[0] = motion.rotation.x, h.motion[1] = motion.rotation.y, h.motion[2] = motion.rotation.z;
    return h;
}

void append_packed(const PackedNodes& p, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                   const WireMotion& motion, WireUpload& out) {
    out.headers.push_back(packed_header(p, segment_first, slot, material, caps, motion,
                                        static_cast<uint32_t>(out.nodes.size()),
                                        static_cast<uint32_t>(out.extras.size())));
    out.nodes.insert(out.nodes.end(), p.records.begin(), p.records.end());
    out.extras.insert(out.extras.end(), p.extras.begin(), p.extras.end());
}

Status append_wire(const WireNodes& wn, const SplineSettings& spline, uint32_t segment_first, uint32_t slot,
                   uint32_t material, bool caps, const WireMotion& motion, WireUpload& out,
                   uint32_t& segments) {
    thread_local PackedNodes packed;
    if (Status st = pack_nodes(wn, spline, packed); !st) return st;
    append_packed(packed, segment_first, slot, material, caps, motion, out);
    segments = static_cast<uint32_t>(packed.segment_count());
    return Status::success();
}

void append_segments(const Curve& curve, uint32_t segment_first, uint32_t slot, uint32_t material, bool caps,
                     const WireMotion& motion, WireUpload& out) {
    glm::dvec3 lo = curve.segments.front().b0, hi = lo;
    for (const CubicBezier& c : curve.segments) {
        for (const glm::dvec3* p : {&c.b0, &c.b1, &c.b2, &c.b3}) lo = glm::min(lo, *p), hi = glm::max(hi, *p);
    }
    const glm::dvec3 origin = float_point(0.5 * (lo + hi));
    GpuCurveHeader h;
    h.node_first = static_cast<uint32_t>(out.nodes.size());
    h.node_count = static_cast<uint32_t>(curve.closed ? curve.segment_count() : curve.segment_count() + 1);
    h.segment_first = segment_first;
    h.flags = (curve.closed ? kHeaderClosed : 0u) | (caps ? kHeaderCaps : 0u) | kHeaderGivenSegments |
              (material << kHeaderMaterialShift);
    h.slot = slot;
    h.origin_m[0] = static_cast<float>(origin.x), h.origin_m[1] = static_cast<float>(origin.y),
    h.origin_m[2] = static_cast<float>(origin.z);
    h.motion[0] = motion.rotation.x, h.motion[1] = motion.rotation.y, h.motion[2] = motion.rotation.z;
    out.headers.push_back(h);
    const std::size_t n = curve.radius_m.size();
    const auto radius = [&](std::size_t j) { return n == 0 ? kDefaultWireRadius_m : curve.radius_m[j % n]; };
    for (std::size_t k = 0; k < curve.segment_count(); ++k) {
        const CubicBezier& c = curve.segments[k];
        const float stretch = k < curve.stretch.size() ? curve.stretch[k] : 1.0f;
        push_vec4(out.nodes, glm::vec4(glm::vec3(c.b0 - origin), radius(k)));
        push_vec4(out.nodes, glm::vec4(glm::vec3(c.b1 - c.b0), radius(k + 1)));
        push_vec4(out.nodes, glm::vec4(glm::vec3(c.b2 - c.b1), stretch));
        push_vec4(out.nodes, glm::vec4(glm::vec3(c.b3 - c.b2), 0.0f));
    }
}

void push_vec4(std::vector<glm::uvec2>& nodes, const glm::vec4& v) {
    nodes.emplace_back(std::bit_cast<uint32_t>(v.x), std::bit_cast<uint32_t>(v.y));
    nodes.emplace_back(std::bit_cast<uint32_t>(v.z), std::bit_cast<uint32_t>(v.w));
}

void set_lod_uniforms(const engine::gfx::Program& program, const LodView& v, const LodSettings& st) {
    const auto at = [&](const char* name) { return program.uniform_location(name); };
    const glm::mat3 rotation(glm::dmat3(v.view_from_world));
    glUniformMatrix3fv(at("u_view_rot"), 1, GL_FALSE, &rotation[0][0]);
    glUniform3d(at("u_eye"), v.eye_m.x, v.eye_m.y, v.eye_m.z);
    glUniform1f(at("u_focal"), static_cast<float>(v.focal_px));
    glUniform1f(at("u_tan_x"), static_cast<float>(v.tan_half_x));
    glUniform1f(at("u_tan_y"), static_cast<float>(v.tan_half_y));
    glUniform1f(at("u_near"), static_cast<float>(v.near_m));
    glUniform1f(at("u_far"), static_cast<float>(v.far_m));
    // The settings as update_lod reads them (LodSettings::resolved), sides capped at what the GPU's table holds.
    const LodSettings r = st.resolved();
    glUniform1f(at("u_eps"), static_cast<float>(r.tolerance_px));
    glUniform1f(at("u_band"), static_cast<float>(r.hysteresis_band));
    glUniform1f(at("u_strip_px"), static_cast<float>(r.strip_radius_px));
    glUniform1f(at("u_line_px"), static_cast<float>(r.line_radius_px));
    glUniform1ui(at("u_max_rings"), r.max_rings_per_segment);
    glUniform1ui(at("u_max_sides"), std::min(r.max_sides, kMaxSides));
    glUniform1i(at("u_coarse"), r.coarse_offscreen_segments ? 1 : 0);
    glUniform1i(at("u_merge"), r.keep_node_resolution ? 0 : 1);
    static_assert(kMaxSides + 1 <= 4 * 65, "u_sagitta4 holds n = 0 .. kMaxSides");
    static const std::array<float, 4 * 65> sagitta = [] {
        std::array<float, 4 * 65> t{};
        for (uint32_t n = 3; n <= kMaxSides; ++n)
            t[n] = static_cast<float>(1.0 - std::cos(std::numbers::pi / n));
        return t;
    }();
    glUniform4fv(at("u_sagitta4"), 65, sagitta.data());
}

}  // namespace wire::render::detail
