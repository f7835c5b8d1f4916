// The surface at this fragment: albedo, unit normal (facing the eye), unit direction to the eye, opacity.
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
