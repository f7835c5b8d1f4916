// Draw calls and pipeline state (see draw.hpp).
#include "engine/gfx/draw.hpp"

#include <epoxy/gl.h>

namespace engine::gfx {

void set_opaque_state() {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
}

void set_wireframe(bool on) {
    glPolygonMode(GL_FRONT_AND_BACK, on ? GL_LINE : GL_FILL);
}

void bind_storage_range(unsigned binding, const Buffer& buffer, std::size_t offset_bytes,
                        std::size_t size_bytes) {
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, binding, buffer.id(), static_cast<GLintptr>(offset_bytes),
                      static_cast<GLsizeiptr>(size_bytes));
}

void draw_instanced(const VertexArray& vertex_array, std::size_t index_count, std::size_t instance_count) {
    vertex_array.bind();
    glDrawElementsInstanced(GL_TRIANGLES, static_cast<GLsizei>(index_count), GL_UNSIGNED_INT, nullptr,
                            static_cast<GLsizei>(instance_count));
}

void unbind_vertex_array() {
    glBindVertexArray(0);
}

}  // namespace engine::gfx
