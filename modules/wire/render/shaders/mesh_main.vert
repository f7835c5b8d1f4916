layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv;
void main() {
  GpuDraw d = draws[record_index()];
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
