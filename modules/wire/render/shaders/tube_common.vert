// invariant: the cpu-mesh and ring programs compute gl_Position from the same values the same way; without it GL
// does not promise the same positions from two programs (their shared edges and depth ties could differ).
invariant gl_Position;
layout(std430, binding = 0) readonly buffer Draws { GpuDraw draws[]; };
// 2: camera-facing strip, 1: phone-wire line, 0: tube.
uint strip_mode(GpuDraw d) { return (d.flags & kDrawStrip) != 0u ? 2u : (d.flags & kDrawLine) != 0u ? 1u : 0u; }
uniform mat4 u_clip_from_rel;   // projection * camera rotation: positions are camera-relative
uniform vec2 u_viewport_px;     // viewport size (phone-wire lines are sized in pixels)
uniform bool u_push_back;       // shadow casters: strips and lines at the tube's far side from the eye (the light)
uniform float u_focal_px;       // (viewport height / 2) * projection[1][1]: pixels per metre at depth 1
out vec3 v_normal;
out vec2 v_uv;
out vec3 v_rel_m;               // fragment position minus camera position
// Strips and phone-wire lines (GpuDraw.sides 2 and 1; 0 for tubes): the ring frame and the strip coordinate,
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
void strip_vertex(GpuDraw d, uint mode, vec3 centre, vec3 r, vec3 s, vec3 t, float radius, float u, float side) {
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
