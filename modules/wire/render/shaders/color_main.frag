void main() {
  Surface o = surface();
  wire_shadow = shadow_visibility(v_rel_m, o.n);
  o_color = vec4(shade(o.albedo, o.n, o.to_eye), o.alpha);
}
