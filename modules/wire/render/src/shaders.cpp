// GLSL sources. The ring expansion reproduces wire::write_tube (tube.cpp) vertex for vertex: same layout,
// same triangle order and winding, same normal tilt by the radius slope, so both paths rasterize the same
// triangles.
#include "shaders.hpp"

namespace wire::render::detail {
namespace {

constexpr std::string_view kHeader = R"(#version 450 core
)";

constexpr std::string_view kDrawParameters = R"(#extension GL_ARB_shader_draw_parameters : require
uint draw_index() { return uint(gl_BaseInstanceARB); }
)";

constexpr std::string_view kDrawAttribute = R"(layout(location = 3) in uint a_draw;
uint draw_index() { return a_draw; }
)";

constexpr std::string_view kCommon = R"(
struct DrawData {
  vec3 offset_m; uint ring_first;
  uint ring_count; uint sides; uint flags; float u_close;
};
layout(std430, binding = 0) readonly buffer Draws { DrawData draws[]; };
const uint kClosed = 1u, kCaps = 2u, kTilt = 4u;
uniform mat4 u_clip_from_rel;   // projection * camera rotation: positions are camera-relative
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_rel_m;               // fragment position minus camera position
)";

constexpr std::string_view kCpuMain = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
void main() {
  DrawData d = draws[draw_index()];
  vec3 rel = d.offset_m + a_position;
  v_rel_m = rel;
  v_normal = a_normal;
  v_uv = a_uv;
  gl_Position = u_clip_from_rel * vec4(rel, 1.0);
}
)";

constexpr std::string_view kRingsMain = R"(
struct Ring { vec3 centre_m; float radius_m; vec3 normal; float u; vec3 binormal; uint segment; };
layout(std430, binding = 1) readonly buffer Rings { Ring rings[]; };
const float kTwoPi = 6.28318530717958647692;

// wire::write_tube's slope_at: central difference of radius over chord length, one-sided at open ends.
float slope_at(DrawData d, uint i) {
  uint n = d.ring_count;
  if ((d.flags & kTilt) == 0u || n < 2u) return 0.0;
  bool closed = (d.flags & kClosed) != 0u;
  uint lo = i > 0u ? i - 1u : (closed ? n - 1u : i);
  uint hi = i + 1u < n ? i + 1u : (closed ? 0u : i);
  Ring rl = rings[d.ring_first + lo], rh = rings[d.ring_first + hi], ri = rings[d.ring_first + i];
  float dr = rh.radius_m - rl.radius_m;
  if (dr == 0.0) return 0.0;
  float ds = length(rh.centre_m - ri.centre_m) + length(ri.centre_m - rl.centre_m);
  return ds > 0.0 ? dr / ds : 0.0;
}

void main() {
  DrawData d = draws[draw_index()];
  uint n = d.sides;
  uint vid = uint(gl_VertexID);
  bool closed = (d.flags & kClosed) != 0u;
  uint bands = d.ring_count - 1u + (closed ? 1u : 0u);
  uint side_vertices = bands * 6u * n;
  vec3 pos;
  vec3 nrm;
  vec2 uv;
  if (vid < side_vertices) {
    // Band b joins ring rows b and b + 1; quad j: (a_j, a_j+1, b_j), (a_j+1, b_j+1, b_j), CCW from outside.
    uint band = vid / (6u * n);
    uint rem = vid - band * 6u * n;
    uint j = rem / 6u;
    uint c = rem - j * 6u;
    uint row = band + ((c == 2u || c == 4u || c == 5u) ? 1u : 0u);
    uint s = j + ((c == 1u || c == 3u || c == 4u) ? 1u : 0u);
    uint i = row == d.ring_count ? 0u : row;  // a closed wire's last row repeats ring 0 ...
    Ring r = rings[d.ring_first + i];
    float u = row == d.ring_count ? d.u_close : r.u;  // ... with u = u_close
    float phi = kTwoPi * float(s == n ? 0u : s) / float(n);
    float cp = cos(phi), sp = sin(phi);
    float slope = slope_at(d, i);
    float a = 1.0 / sqrt(1.0 + slope * slope);
    vec3 tb = (slope * a) * cross(r.normal, r.binormal);
    pos = r.centre_m + (cp * (r.radius_m * r.normal) + sp * (r.radius_m * r.binormal));
    nrm = -tb + (cp * (a * r.normal) + sp * (a * r.binormal));
    uv = vec2(u, float(s) / float(n));
  } else {
    // Caps: start cap faces -t (centre, rim_k, rim_j), end cap +t (centre, rim_j, rim_k), k = j + 1 mod n.
    uint k = vid - side_vertices;
    uint cap = k / (3u * n);
    uint rem = k - cap * 3u * n;
    uint j = rem / 3u;
    uint c = rem - j * 3u;
    Ring r = rings[d.ring_first + (cap == 0u ? 0u : d.ring_count - 1u)];
    nrm = (cap == 0u ? -1.0 : 1.0) * cross(r.normal, r.binormal);
    if (c == 0u) {
      pos = r.centre_m;
      uv = vec2(0.5);
    } else {
      uint jn = (j + 1u) % n;
      uint rim = cap == 0u ? (c == 1u ? jn : j) : (c == 1u ? j : jn);
      float phi = kTwoPi * float(rim) / float(n);
      float cp = cos(phi), sp = sin(phi);
      pos = r.centre_m + (cp * (r.radius_m * r.normal) + sp * (r.radius_m * r.binormal));
      uv = vec2(0.5) + 0.5 * vec2(cp, sp);
    }
  }
  vec3 rel = d.offset_m + pos;
  v_rel_m = rel;
  v_normal = nrm;
  v_uv = uv;
  gl_Position = u_clip_from_rel * vec4(rel, 1.0);
}
)";

constexpr std::string_view kFragmentHead = R"(#version 450 core
in vec3 v_normal;
in vec2 v_uv;
in vec3 v_rel_m;
layout(binding = 0) uniform sampler2D u_texture;
uniform vec3 u_tint;
uniform vec3 u_to_light;     // unit, toward the light
uniform vec3 u_light_color;
uniform float u_ambient;     // fraction of albedo on the unlit side
uniform float u_specular;    // Blinn-Phong specular strength
uniform float u_shininess;
out vec4 o_color;
)";

constexpr std::string_view kDefaultShading = R"(
vec3 shade(vec3 albedo, vec3 n, vec3 to_eye) {
  float diffuse = max(dot(n, u_to_light), 0.0);
  vec3 h = normalize(u_to_light + to_eye);
  float spec = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) : 0.0;
  return (albedo * (u_ambient + (1.0 - u_ambient) * diffuse) + u_specular * spec) * u_light_color;
}
)";

constexpr std::string_view kFragmentMain = R"(
void main() {
  vec3 n = normalize(v_normal);
  if (!gl_FrontFacing) n = -n;  // wireframe and cut-away views see back faces
  vec3 albedo = texture(u_texture, v_uv).rgb * u_tint;
  o_color = vec4(shade(albedo, n, normalize(-v_rel_m)), 1.0);
}
)";

}  // namespace

std::string vertex_source(bool cpu_mesh, bool draw_parameters) {
    std::string s(kHeader);
    s += draw_parameters ? kDrawParameters : kDrawAttribute;
    s += kCommon;
    s += cpu_mesh ? kCpuMain : kRingsMain;
    return s;
}

std::string fragment_source(std::string_view shading) {
    std::string s(kFragmentHead);
    if (shading.empty()) {
        s += kDefaultShading;
    } else {
        s += shading;
    }
    s += kFragmentMain;
    return s;
}

}  // namespace wire::render::detail
