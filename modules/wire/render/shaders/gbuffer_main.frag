void main() {
  Surface o = surface();
  write_gbuffer(o.albedo, o.n, v_rel_m, u_roughness);
}
