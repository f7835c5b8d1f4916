// record_index(): cpu-mesh, the vertex's draw index (a per-vertex attribute); the rings, the chunk's index
// (the command's base instance plus the instance), from ARB_shader_draw_parameters or from the instanced
// attribute whose buffer holds 0, 1, 2, ...
#extension GL_ARB_shader_draw_parameters : require
uint record_index() { return uint(gl_BaseInstanceARB + gl_InstanceID); }
