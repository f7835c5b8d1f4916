// The default G-buffer layout: 0 normal (world, * 0.5 + 0.5), 1 albedo, 2 (roughness, 0, 0, 1).
layout(location = 0) out vec4 o_normal;
layout(location = 1) out vec4 o_albedo;
layout(location = 2) out vec4 o_material;
void write_gbuffer(vec3 albedo, vec3 n, vec3 rel_m, float roughness) {
  o_normal = vec4(n * 0.5 + 0.5, 1.0);
  o_albedo = vec4(albedo, 1.0);
  o_material = vec4(roughness, 0.0, 0.0, 1.0);
}
