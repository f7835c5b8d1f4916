out vec4 o_color;
