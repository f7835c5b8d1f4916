// Draw calls and the pipeline state around them, for renderers that bring their own programs and meshes
// (LitRenderer, the tunnel's pieces): the GL they need stays inside engine/gfx. Needs a current GL 4.5
// context.
#pragma once

#include <cstddef>

#include "engine/gfx/resources.hpp"

namespace engine::gfx {

/// Opaque geometry: depth test on (GL_LESS), back faces culled, counter-clockwise front faces.
void set_opaque_state();

/// Rasterizes triangles as their outlines (true) or filled (false, GL's default), front and back faces.
void set_wireframe(bool on);

/// Binds bytes [offset_bytes, offset_bytes + size_bytes) of `buffer` to shader storage binding point
/// `binding`: a shader's unsized array there has length() = size_bytes / element size.
void bind_storage_range(unsigned binding, const Buffer& buffer, std::size_t offset_bytes,
                        std::size_t size_bytes);

/// Draws the first index_count uint32 indices of `vertex_array` (its element buffer, as triangles)
/// instance_count times (gl_InstanceID 0 .. instance_count - 1) with the program in use.
void draw_instanced(const VertexArray& vertex_array, std::size_t index_count, std::size_t instance_count);

/// Leaves no vertex array bound (later GL calls cannot change the last one drawn).
void unbind_vertex_array();

}  // namespace engine::gfx
