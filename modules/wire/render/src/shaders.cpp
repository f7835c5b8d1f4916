// GLSL sources. The ring expansion reproduces wire::write_tube (tube.cpp) vertex for vertex: same vertex
// layout (rows of sides + 1, caps of centre + rim), same triangles and winding, same normal tilt by the radius
// slope, so both paths rasterize the same triangles. Only the order differs: the caps come first in the index
// pattern.
#include "shaders.hpp"

#include "engine/gfx/shadow.hpp"

namespace wire::render::detail {
namespace {

constexpr std::string_view kHeader = R"(#version 450 core
)";

// record_index(): cpu-mesh, the vertex's draw index (a per-vertex attribute); gpu-rings, the chunk's index
// (the command's base instance plus the instance), from ARB_shader_draw_parameters or from the instanced
// attribute whose buffer holds 0, 1, 2, ...
constexpr std::string_view kDrawParameters = R"(#extension GL_ARB_shader_draw_parameters : require
uint record_index() { return uint(gl_BaseInstanceARB + gl_InstanceID); }
)";

constexpr std::string_view kDrawAttribute = R"(layout(location = 3) in uint a_record;
uint record_index() { return a_record; }
)";

// invariant: the cpu-mesh and ring programs compute gl_Position from the same values the same way; without it GL
// does not promise the same positions from two programs (their shared edges and depth ties could differ).
constexpr std::string_view kCommon = R"(
invariant gl_Position;
struct DrawData {
  vec3 offset_m; uint ring_first;
  uint ring_count; uint sides; uint flags; float u_close;
};
layout(std430, binding = 0) readonly buffer Draws { DrawData draws[]; };
const uint kClosed = 1u, kCaps = 2u, kTilt = 4u, kStrip = 8u, kLine = 16u;
// 2: camera-facing strip, 1: phone-wire line, 0: tube.
uint strip_mode(DrawData d) { return (d.flags & kStrip) != 0u ? 2u : (d.flags & kLine) != 0u ? 1u : 0u; }
uniform mat4 u_clip_from_rel;   // projection * camera rotation: positions are camera-relative
uniform vec2 u_viewport_px;     // viewport size (phone-wire lines are sized in pixels)
uniform bool u_push_back;       // shadow casters: strips and lines at the tube's far side from the eye (the light)
uniform float u_focal_px;       // (viewport height / 2) * projection[1][1]: pixels per metre at depth 1
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_rel_m;               // fragment position minus camera position
// Strips and phone-wire lines (DrawData.sides 2 and 1; 0 for tubes): the ring frame and the strip coordinate,
// from which the fragment shader rebuilds the tube's normal.
flat out uint v_mode;
out vec3 v_tangent;
out vec3 v_frame_r;
out vec3 v_frame_s;
out float v_strip;              // -1 .. 1 across the strip
out float v_alpha;              // phone-wire opacity: true width / drawn width

vec3 rotate_by(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }

void tube_outputs() {
  v_mode = 0u; v_tangent = vec3(0.0); v_frame_r = vec3(0.0); v_frame_s = vec3(0.0); v_strip = 0.0; v_alpha = 1.0;
}

// A camera-facing strip vertex (sides 2): the ring centre moved by +-R along t x (to eye), i.e. the edge of the
// tube's silhouette seen from the eye. A phone-wire vertex (sides 1): the centre moved in screen space so the
// line is one pixel across along the screen axis that crosses it most (each pixel column, or row, of the wire
// gets one pixel), its opacity the true width over that drawn width.
void strip_vertex(DrawData d, uint mode, vec3 centre, vec3 r, vec3 s, vec3 t, float radius, float u, float side) {
  vec3 rel = d.offset_m + centre;
  vec3 across = cross(t, -rel);
  float len = length(across);
  across = len > 1e-30 ? across / len : r;  // looking along the wire: any direction across it
  v_mode = mode; v_tangent = t; v_frame_r = r; v_frame_s = s; v_strip = side;
  v_normal = normalize(-rel);
  v_uv = vec2(u, 0.0);
  if (u_push_back) {  // the tube's far side, as its back faces are for a tube; wound back-facing (front faces culled)
    rel += radius * normalize(rel);
    side = -side;
  }
  if (mode == 2u) {
    rel += (side * radius) * across;
    v_alpha = 1.0;
    v_rel_m = rel;
    gl_Position = u_clip_from_rel * vec4(rel, 1.0);
    return;
  }
  vec4 clip = u_clip_from_rel * vec4(rel, 1.0);
  vec4 ahead = u_clip_from_rel * vec4(rel + t * max(radius, 1e-3 * max(clip.w, 1e-6)), 1.0);
  vec2 dir = ahead.xy / ahead.w - clip.xy / clip.w;
  dir *= u_viewport_px;  // to pixels (times 2, irrelevant for the direction)
  float dl = length(dir);
  dir = dl > 0.0 ? dir / dl : vec2(1.0, 0.0);
  float drawn_half_px = 0.5 * max(abs(dir.x), abs(dir.y));  // half of 1 px along the crossing axis
  float true_half_px = radius * u_focal_px / max(clip.w, 1e-6);
  float half_px = max(drawn_half_px, true_half_px);
  v_alpha = clamp(true_half_px / half_px, 0.0, 1.0);
  vec2 perp = vec2(dir.y, -dir.x);  // t x (to eye) on screen: the strip side, same winding
  clip.xy += (side * half_px * 2.0 * clip.w) * (perp / u_viewport_px);
  v_rel_m = rel;
  gl_Position = clip;
}
)";

constexpr std::string_view kCpuMain = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
void main() {
  DrawData d = draws[record_index()];
  if (strip_mode(d) != 0u) {  // strip vertex (wire::write_strip): centre, frame quaternion xyz, (u, +-R)
    vec4 q = vec4(a_normal, sqrt(max(0.0, 1.0 - dot(a_normal, a_normal))));
    strip_vertex(d, strip_mode(d), a_position, rotate_by(q, vec3(1.0, 0.0, 0.0)), rotate_by(q, vec3(0.0, 1.0, 0.0)),
                 rotate_by(q, vec3(0.0, 0.0, 1.0)), abs(a_uv.y), a_uv.x, a_uv.y < 0.0 ? -1.0 : 1.0);
    return;
  }
  tube_outputs();
  vec3 rel = d.offset_m + a_position;
  v_rel_m = rel;
  v_normal = a_normal;
  v_uv = a_uv;
  gl_Position = u_clip_from_rel * vec4(rel, 1.0);
}
)";

constexpr std::string_view kRingsMain = R"(
// Packed ring records (wire::render::PackedRing, 7 words): centre xyz, radius, u (floats), frame quaternion in
// smallest-three form (2-bit index of the largest component, three 20-bit components).
layout(std430, binding = 1) readonly buffer Rings { uint ring_words[]; };
// The retained path's wires that move (DrawData.flags & 32): their rings in the frame's stream region.
layout(std430, binding = 4) readonly buffer StreamRings { uint stream_words[]; };
// cos and sin of 2 pi j / n for n = 3, 4, ... (n + 1 entries each, the last repeating j = 0), computed as
// wire::write_tube's side table (double, then float): the two paths place rim vertices identically.
layout(std430, binding = 2) readonly buffer Circle { vec2 circle[]; };
// One record per instance (a chunk of a wire, upload_plan.hpp): the wire's draw index and its first band.
layout(std430, binding = 3) readonly buffer Chunks { uvec2 chunks[]; };
vec2 circle_at(uint n, uint j) { return circle[n * (n + 1u) / 2u - 6u + j]; }
const uint kCapVertexBase = 1073741824u;  // 1 << 30: vertex ids of the two caps (kCapVertexBase in upload_plan.hpp)

struct Ring { vec3 centre_m; float radius_m; float u; vec3 normal; vec3 binormal; vec3 tangent; };

uint ring_base(DrawData d, uint i) { return d.ring_first + i * 7u; }
uint ring_word(DrawData d, uint w) { return (d.flags & 32u) != 0u ? stream_words[w] : ring_words[w]; }
vec3 ring_centre(DrawData d, uint i) {
  uint b = ring_base(d, i);
  return vec3(uintBitsToFloat(ring_word(d, b)), uintBitsToFloat(ring_word(d, b + 1u)), uintBitsToFloat(ring_word(d, b + 2u)));
}
float ring_radius(DrawData d, uint i) { return uintBitsToFloat(ring_word(d, ring_base(d, i) + 3u)); }

float fixed20(uint k) { return (float(k) / 1048575.0 * 2.0 - 1.0) * 0.70710678; }

Ring load_ring(DrawData d, uint i) {
  uint b = ring_base(d, i);
  Ring r;
  r.centre_m = ring_centre(d, i);
  r.radius_m = uintBitsToFloat(ring_word(d, b + 3u));
  r.u = uintBitsToFloat(ring_word(d, b + 4u));
  uint w0 = ring_word(d, b + 5u), w1 = ring_word(d, b + 6u);
  uint largest = w0 & 3u;
  vec3 abc = vec3(fixed20((w0 >> 2u) & 1048575u), fixed20(((w0 >> 22u) | (w1 << 10u)) & 1048575u),
                  fixed20((w1 >> 10u) & 1048575u));
  float big = sqrt(max(0.0, 1.0 - dot(abc, abc)));
  vec4 q = largest == 0u ? vec4(big, abc) : largest == 1u ? vec4(abc.x, big, abc.yz)
         : largest == 2u ? vec4(abc.xy, big, abc.z) : vec4(abc, big);
  float x = q.x, y = q.y, z = q.z, w = q.w;
  r.normal = vec3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + w * z), 2.0 * (x * z - w * y));
  r.binormal = vec3(2.0 * (x * y - w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + w * x));
  r.tangent = vec3(2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y));
  return r;
}

// wire::write_tube's slope_at: central difference of radius over chord length, one-sided at open ends.
float slope_at(DrawData d, uint i, Ring ri) {
  uint n = d.ring_count;
  if ((d.flags & kTilt) == 0u || n < 2u) return 0.0;
  bool closed = (d.flags & kClosed) != 0u;
  uint lo = i > 0u ? i - 1u : (closed ? n - 1u : i);
  uint hi = i + 1u < n ? i + 1u : (closed ? 0u : i);
  float dr = ring_radius(d, hi) - ring_radius(d, lo);
  if (dr == 0.0) return 0.0;
  float ds = length(ring_centre(d, hi) - ri.centre_m) + length(ri.centre_m - ring_centre(d, lo));
  return ds > 0.0 ? clamp(dr / ds, -1e18, 1e18) : 0.0;  // as write_tube: 1 + slope^2 stays finite
}

// vid / m for m >= 4 without an integer division (software rasterizers run vector integer division one lane
// at a time): the float quotient is within 1 of the true one for vid < 2^24, then corrected exactly.
uint div_row(uint vid, uint m) {
  int q = int(float(vid) / float(m));
  int r = int(vid) - q * int(m);
  if (r < 0) q -= 1;
  else if (r >= int(m)) q += 1;
  return uint(q);
}

// Indexed: gl_VertexID is local_row * (n + 1) + s for the tube (row = the chunk's first band + local_row = ring,
// or ring_count for a closed wire's repeat of ring 0), kCapVertexBase + cap * (n + 1) + k for the caps (k = 0
// centre, 1 + j rim vertex j).
void main() {
  uvec2 chunk = chunks[record_index()];
  DrawData d = draws[chunk.x];
  uint n = d.sides;
  uint vid = uint(gl_VertexID);
  if (strip_mode(d) != 0u) {  // strip: vertex 2 row + (0: -side, 1: +side); a closed wire's last row repeats ring 0
    uint row = chunk.y + (vid >> 1u);
    uint i = row == d.ring_count ? 0u : row;
    Ring r = load_ring(d, i);
    float u = row == d.ring_count ? d.u_close : r.u;
    strip_vertex(d, strip_mode(d), r.centre_m, r.normal, r.binormal, r.tangent, r.radius_m, u, (vid & 1u) == 0u ? -1.0 : 1.0);
    return;
  }
  tube_outputs();
  vec3 pos;
  vec3 nrm;
  vec2 uv;
  if (vid < kCapVertexBase) {
    uint local_row = div_row(vid, n + 1u);
    uint s = vid - local_row * (n + 1u);
    uint row = chunk.y + local_row;
    uint i = row == d.ring_count ? 0u : row;  // a closed wire's last row repeats ring 0 ...
    Ring r = load_ring(d, i);
    float u = row == d.ring_count ? d.u_close : r.u;  // ... with u = u_close
    vec2 cs = circle_at(n, s);
    float cp = cs.x, sp = cs.y;
    float slope = slope_at(d, i, r);
    float a = 1.0 / sqrt(1.0 + slope * slope);
    vec3 tb = (slope * a) * r.tangent;
    pos = r.centre_m + (cp * (r.radius_m * r.normal) + sp * (r.radius_m * r.binormal));
    nrm = -tb + (cp * (a * r.normal) + sp * (a * r.binormal));
    uv = vec2(u, float(s) / float(n));
  } else {
    // Caps: start cap faces -t, end cap +t; the index pattern orders the triangles (centre, rim, rim).
    uint k = vid - kCapVertexBase;
    uint cap = k >= n + 1u ? 1u : 0u;
    uint c = k - cap * (n + 1u);
    Ring r = load_ring(d, cap == 0u ? 0u : d.ring_count - 1u);
    nrm = (cap == 0u ? -1.0 : 1.0) * r.tangent;
    if (c == 0u) {
      pos = r.centre_m;
      uv = vec2(0.5);
    } else {
      vec2 cs = circle_at(n, c - 1u);
      float cp = cs.x, sp = cs.y;
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
flat in uint v_mode;
in vec3 v_tangent;
in vec3 v_frame_r;
in vec3 v_frame_s;
in float v_strip;
in float v_alpha;
layout(binding = 0) uniform sampler2D u_texture;
uniform vec3 u_tint;
uniform vec3 u_to_light;     // unit, toward the light
uniform vec3 u_light_color;
uniform float u_ambient;     // fraction of albedo on the unlit side
uniform float u_specular;    // Blinn-Phong specular strength
uniform float u_shininess;
uniform float u_roughness;   // the material's (G-buffer output)
// The shadow map's visibility at this fragment (1 lit, 0 in shadow; 1 without a map): the default shading scales
// the light's diffuse and specular by it; a shading hook may read it.
float wire_shadow = 1.0;
)";

constexpr std::string_view kColorOutput = R"(
out vec4 o_color;
)";

// The default G-buffer layout: 0 normal (world, * 0.5 + 0.5), 1 albedo, 2 (roughness, 0, 0, 1).
constexpr std::string_view kDefaultGbuffer = R"(
layout(location = 0) out vec4 o_normal;
layout(location = 1) out vec4 o_albedo;
layout(location = 2) out vec4 o_material;
void write_gbuffer(vec3 albedo, vec3 n, vec3 rel_m, float roughness) {
  o_normal = vec4(n * 0.5 + 0.5, 1.0);
  o_albedo = vec4(albedo, 1.0);
  o_material = vec4(roughness, 0.0, 0.0, 1.0);
}
)";

constexpr std::string_view kDefaultShading = R"(
vec3 shade(vec3 albedo, vec3 n, vec3 to_eye) {
  float diffuse = max(dot(n, u_to_light), 0.0) * wire_shadow;
  vec3 h = normalize(u_to_light + to_eye);
  float spec = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) * wire_shadow : 0.0;
  return (albedo * (u_ambient + (1.0 - u_ambient) * diffuse) + u_specular * spec) * u_light_color;
}
)";

// The surface at this fragment: albedo, unit normal (facing the eye), unit direction to the eye, opacity.
constexpr std::string_view kSurface = R"(
struct Surface { vec3 albedo; vec3 n; vec3 to_eye; float alpha; };
Surface surface() {
  Surface o;
  if (v_mode != 0u) {
    // The tube a strip stands for: across = t x (to eye), facing = the to-eye direction without its t part;
    // the tube point seen at strip coordinate s has normal s across + sqrt(1 - s^2) facing (a phone-wire line
    // shades its centre, s = 0). Texture v is the angle of that normal in the ring frame, as the tube's j / n.
    vec3 to_eye = normalize(-v_rel_m);
    vec3 t = normalize(v_tangent);
    vec3 across = cross(t, to_eye);
    float len = length(across);
    across = len > 1e-6 ? across / len : normalize(v_frame_r);
    vec3 facing = cross(across, t);
    float s = v_mode == 2u ? clamp(v_strip, -1.0, 1.0) : 0.0;
    vec3 n = s * across + sqrt(max(0.0, 1.0 - s * s)) * facing;
    float v = fract(atan(dot(n, v_frame_s), dot(n, v_frame_r)) * 0.15915494);
    // Gradients of the continuous (u, s / 4) instead of v: no mip seam where v wraps.
    vec2 g = vec2(v_uv.x, 0.25 * v_strip);
    o.albedo = textureGrad(u_texture, vec2(v_uv.x, v), dFdx(g), dFdy(g)).rgb * u_tint;
    o.n = n, o.to_eye = to_eye, o.alpha = v_alpha;
    return o;
  }
  o.n = normalize(v_normal);
  if (!gl_FrontFacing) o.n = -o.n;  // wireframe and cut-away views see back faces
  o.albedo = texture(u_texture, v_uv).rgb * u_tint;
  o.to_eye = normalize(-v_rel_m), o.alpha = 1.0;
  return o;
}
)";

constexpr std::string_view kColorMain = R"(
void main() {
  Surface o = surface();
  wire_shadow = shadow_visibility(v_rel_m, o.n);
  o_color = vec4(shade(o.albedo, o.n, o.to_eye), o.alpha);
}
)";

constexpr std::string_view kGbufferMain = R"(
void main() {
  Surface o = surface();
  write_gbuffer(o.albedo, o.n, v_rel_m, u_roughness);
}
)";

// Depth only. A phone-wire line (drawn at least one pixel of this view across, opacity = true width / drawn width)
// keeps that share of its fragments (interleaved gradient noise against the opacity): a depth map cannot hold a
// partial cover, but a filtered lookup over the dithered texels darkens by the line's true width on average.
constexpr std::string_view kDepthFragment = R"(#version 450 core
in float v_alpha;
void main() {
  if (v_alpha < 1.0) {
    float noise = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
    if (noise >= v_alpha) discard;
  }
}
)";

}  // namespace

std::string vertex_source(bool cpu_mesh, bool draw_parameters) {
    std::string s(kHeader);
    s += draw_parameters && !cpu_mesh ? kDrawParameters : kDrawAttribute;
    s += kCommon;
    s += cpu_mesh ? kCpuMain : kRingsMain;
    return s;
}

std::string fragment_source(FragmentOutput output, std::string_view shading, std::string_view gbuffer) {
    if (output == FragmentOutput::depth) return std::string(kDepthFragment);
    std::string s(kFragmentHead);
    s += kSurface;
    if (output == FragmentOutput::gbuffer) {
        s += gbuffer.empty() ? kDefaultGbuffer : gbuffer;
        s += kGbufferMain;
        return s;
    }
    s += kColorOutput;
    s += engine::gfx::shadow_glsl();
    s += shading.empty() ? kDefaultShading : shading;
    s += kColorMain;
    return s;
}

}  // namespace wire::render::detail
