vec3 shade(vec3 albedo, vec3 n, vec3 to_eye) {
  float diffuse = max(dot(n, u_to_light), 0.0) * wire_shadow;
  vec3 h = normalize(u_to_light + to_eye);
  float spec = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) * wire_shadow : 0.0;
  return (albedo * (u_ambient + (1.0 - u_ambient) * diffuse) + u_specular * spec) * u_light_color;
}
