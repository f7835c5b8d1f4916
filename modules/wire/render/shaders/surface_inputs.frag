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
