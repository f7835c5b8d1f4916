// GL object creation with direct state access (GL 4.5). The only file of engine/gfx that owns GL names.
#include "engine/gfx/resources.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <vector>
#include <cassert>
#include <cstdlib>
#include <glm/gtc/type_ptr.hpp>

namespace engine::gfx {
namespace detail {
void delete_buffer(unsigned id) {
    glDeleteBuffers(1, &id);
}
void delete_vertex_array(unsigned id) {
    glDeleteVertexArrays(1, &id);
}
void delete_program(unsigned id) {
    glDeleteProgram(id);
}
void delete_texture(unsigned id) {
    glDeleteTextures(1, &id);
}
}  // namespace detail

namespace {

void set_label(GLenum kind, GLuint id, std::string_view label) {
    if (!label.empty()) glObjectLabel(kind, id, static_cast<GLsizei>(label.size()), label.data());
}

// Drains GL errors; returns the first one (GL_NO_ERROR if none).
GLenum take_gl_error() {
    GLenum first = GL_NO_ERROR;
    for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
        if (first == GL_NO_ERROR) first = e;
    }
    return first;
}

std::string quoted_label(std::string_view label) {
    if (label.empty()) return "(unnamed)";
    // Appending (rather than "'" + std::string + "'") avoids GCC 12's -Wrestrict false positive.
    std::string quoted;
    quoted.reserve(label.size() + 2);
    quoted.push_back('\'');
    quoted.append(label);
    quoted.push_back('\'');
    return quoted;
}

}  // namespace

// ---- Buffers ---------------------------------------------------------------------------------------------

Expected<Buffer> make_buffer(const BufferDesc& desc) {
    const std::size_t size = desc.size_bytes != 0 ? desc.size_bytes : desc.data.size();
    if (size == 0) return Error{"buffer " + quoted_label(desc.label) + ": size is zero"};
    assert(desc.data.empty() || desc.data.size() <= size);
    take_gl_error();
    GLuint id = 0;
    glCreateBuffers(1, &id);
    Buffer buffer;
    buffer.name_ = detail::GlName<detail::delete_buffer>(id);
    buffer.size_bytes_ = size;
    buffer.dynamic_ = desc.dynamic;
    const GLbitfield flags = desc.storage_flags | (desc.dynamic ? GL_DYNAMIC_STORAGE_BIT : 0u);
    if (desc.data.size() == size) {
        glNamedBufferStorage(id, static_cast<GLsizeiptr>(size), desc.data.data(), flags);
    } else {
        glNamedBufferStorage(id, static_cast<GLsizeiptr>(size), nullptr, flags | GL_DYNAMIC_STORAGE_BIT);
        // WIRE_GFX_POISON_BUFFERS=1: the unwritten bytes read 0xff, as a hardware driver's pool may hand out stale
        // memory where llvmpipe gives zeros (tests run with it to catch reads of memory never written).
        if (const char* poison = std::getenv("WIRE_GFX_POISON_BUFFERS");
            poison != nullptr && poison[0] == '1' && size % 4 == 0) {
            const GLuint all_ones = 0xffffffffu;
            glClearNamedBufferData(id, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &all_ones);
        }
        if (!desc.data.empty())
            glNamedBufferSubData(id, 0, static_cast<GLsizeiptr>(desc.data.size()), desc.data.data());
    }
    if (GLenum e = take_gl_error(); e != GL_NO_ERROR) {
        return Error{"buffer " + quoted_label(desc.label) + ": allocating " + std::to_string(size) +
                     " bytes failed (GL error " + std::to_string(e) + ")"};
    }
    set_label(GL_BUFFER, id, desc.label);
    return buffer;
}

void Buffer::update(std::size_t offset_bytes, std::span<const std::byte> bytes) {
    assert(dynamic_ && "Buffer::update on a buffer made without .dynamic = true");
    assert(offset_bytes + bytes.size() <= size_bytes_ && "Buffer::update past the end");
    glNamedBufferSubData(id(), static_cast<GLintptr>(offset_bytes), static_cast<GLsizeiptr>(bytes.size()),
                         bytes.data());
}

// ---- Vertex arrays ---------------------------------------------------------------------------------------

VertexArray make_vertex_array(const VertexArrayDesc& desc) {
    GLuint id = 0;
    glCreateVertexArrays(1, &id);
    VertexArray vao;
    vao.name_ = detail::GlName<detail::delete_vertex_array>(id);
    if (desc.vertex_buffer != nullptr) {
        assert(desc.stride_bytes > 0 && "vertex array: stride_bytes is required with a vertex buffer");
        glVertexArrayVertexBuffer(id, 0, desc.vertex_buffer->id(), 0,
                                  static_cast<GLsizei>(desc.stride_bytes));
    }
    for (const VertexAttribute& a : desc.attributes) {
        assert(a.components >= 1 && a.components <= 4);
        glEnableVertexArrayAttrib(id, a.location);
        switch (a.type) {
            case AttributeType::float32:
                glVertexArrayAttribFormat(id, a.location, a.components, GL_FLOAT, GL_FALSE, a.offset_bytes);
                break;
            case AttributeType::uint8:
            case AttributeType::uint32: {
                const GLenum type = a.type == AttributeType::uint8 ? GL_UNSIGNED_BYTE : GL_UNSIGNED_INT;
                if (a.normalized) {
                    glVertexArrayAttribFormat(id, a.location, a.components, type, GL_TRUE, a.offset_bytes);
                } else {
                    glVertexArrayAttribIFormat(id, a.location, a.components, type, a.offset_bytes);
                }
                break;
            }
        }
        glVertexArrayAttribBinding(id, a.location, 0);
    }
    if (desc.index_buffer != nullptr) glVertexArrayElementBuffer(id, desc.index_buffer->id());
    set_label(GL_VERTEX_ARRAY, id, desc.label);
    return vao;
}

void VertexArray::bind() const {
    glBindVertexArray(id());
}

// ---- Shader programs -------------------------------------------------------------------------------------

namespace {

std::string shader_log(GLuint shader) {
    GLint length = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(length > 0 ? length : 0), '\0');
    if (length > 0) glGetShaderInfoLog(shader, length, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return log;
}

std::string program_log(GLuint program) {
    GLint length = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
    std::string log(static_cast<std::size_t>(length > 0 ? length : 0), '\0');
    if (length > 0) glGetProgramInfoLog(program, length, nullptr, log.data());
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return log;
}

Expected<GLuint> compile(GLenum stage, std::string_view source, std::string_view label) {
    const char* stage_name = stage == GL_VERTEX_SHADER ? "vertex" : stage == GL_COMPUTE_SHADER ? "compute" : "fragment";
    if (source.empty())
        return Error{std::string(stage_name) + " shader of " + quoted_label(label) + " has no source"};
    GLuint shader = glCreateShader(stage);
    const char* text = source.data();
    const auto length = static_cast<GLint>(source.size());
    glShaderSource(shader, 1, &text, &length);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        std::string log = shader_log(shader);
        glDeleteShader(shader);
        return Error{std::string(stage_name) + " shader of " + quoted_label(label) + " failed to compile:\n" +
                     log};
    }
    return shader;
}

}  // namespace

Expected<Program> make_program(const ProgramDesc& desc) {
    std::vector<GLuint> shaders;
    const auto fail = [&](Status error) -> Expected<Program> {
        for (const GLuint shader : shaders) glDeleteShader(shader);
        return error;
    };
    if (!desc.compute.empty()) {
        if (!desc.vertex.empty() || !desc.fragment.empty())
            return Error{"program " + quoted_label(desc.label) + " has a compute shader and a vertex or fragment shader"};
        Expected<GLuint> cs = compile(GL_COMPUTE_SHADER, desc.compute, desc.label);
        if (!cs) return cs.error();
        shaders.push_back(*cs);
    } else {
        Expected<GLuint> vs = compile(GL_VERTEX_SHADER, desc.vertex, desc.label);
        if (!vs) return vs.error();
        shaders.push_back(*vs);
        Expected<GLuint> fs = compile(GL_FRAGMENT_SHADER, desc.fragment, desc.label);
        if (!fs) return fail(fs.error());
        shaders.push_back(*fs);
    }
    GLuint id = glCreateProgram();
    Program program;
    program.name_ = detail::GlName<detail::delete_program>(id);
    for (const GLuint shader : shaders) glAttachShader(id, shader);
    glLinkProgram(id);
    for (const GLuint shader : shaders) glDetachShader(id, shader);
    for (const GLuint shader : shaders) glDeleteShader(shader);
    GLint ok = GL_FALSE;
    glGetProgramiv(id, GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE)
        return Error{"program " + quoted_label(desc.label) + " failed to link:\n" + program_log(id)};
    set_label(GL_PROGRAM, id, desc.label);
    return program;
}

void Program::use() const {
    glUseProgram(id());
}
int Program::uniform_location(const char* name) const {
    return glGetUniformLocation(id(), name);
}
void Program::set(const char* name, float v) const {
    glProgramUniform1f(id(), uniform_location(name), v);
}
void Program::set(const char* name, int v) const {
    glProgramUniform1i(id(), uniform_location(name), v);
}
void Program::set(const char* name, const glm::vec2& v) const {
    glProgramUniform2fv(id(), uniform_location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::vec3& v) const {
    glProgramUniform3fv(id(), uniform_location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::vec4& v) const {
    glProgramUniform4fv(id(), uniform_location(name), 1, glm::value_ptr(v));
}
void Program::set(const char* name, const glm::mat3& m) const {
    glProgramUniformMatrix3fv(id(), uniform_location(name), 1, GL_FALSE, glm::value_ptr(m));
}
void Program::set(const char* name, const glm::mat4& m) const {
    glProgramUniformMatrix4fv(id(), uniform_location(name), 1, GL_FALSE, glm::value_ptr(m));
}
void Program::set(int location, std::span<const float> values) const {
    glProgramUniform1fv(id(), location, static_cast<GLsizei>(values.size()), values.data());
}

// ---- Textures --------------------------------------------------------------------------------------------

Expected<Texture> make_texture(const TextureDesc& desc) {
    if (desc.width <= 0 || desc.height <= 0) {
        return Error{"texture " + quoted_label(desc.label) + ": size " + std::to_string(desc.width) + "x" +
                     std::to_string(desc.height) + " is not positive"};
    }
    const std::size_t expected =
        static_cast<std::size_t>(desc.width) * static_cast<std::size_t>(desc.height) * 4;
    if (desc.rgba.size() != expected) {
        return Error{"texture " + quoted_label(desc.label) + ": " + std::to_string(desc.rgba.size()) +
                     " bytes of pixels, expected " + std::to_string(expected) + " (RGBA8)"};
    }
    int levels = 1;
    if (desc.mipmaps) {
        for (int s = std::max(desc.width, desc.height); s > 1; s /= 2) ++levels;
    }
    take_gl_error();
    GLuint id = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &id);
    Texture texture;
    texture.name_ = detail::GlName<detail::delete_texture>(id);
    texture.width_ = desc.width;
    texture.height_ = desc.height;
    glTextureStorage2D(id, levels, GL_RGBA8, desc.width, desc.height);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTextureSubImage2D(id, 0, 0, 0, desc.width, desc.height, GL_RGBA, GL_UNSIGNED_BYTE, desc.rgba.data());
    if (desc.mipmaps) glGenerateTextureMipmap(id);
    const GLint mag = desc.filter == Filter::linear ? GL_LINEAR : GL_NEAREST;
    const GLint min = desc.filter == Filter::linear ? (desc.mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR)
                                                    : (desc.mipmaps ? GL_NEAREST_MIPMAP_NEAREST : GL_NEAREST);
    glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, mag);
    glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, min);
    const GLint wrap = desc.wrap == Wrap::repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
    glTextureParameteri(id, GL_TEXTURE_WRAP_S, wrap);
    glTextureParameteri(id, GL_TEXTURE_WRAP_T, wrap);
    if (GLenum e = take_gl_error(); e != GL_NO_ERROR) {
        return Error{"texture " + quoted_label(desc.label) + ": upload failed (GL error " +
                     std::to_string(e) + ")"};
    }
    set_label(GL_TEXTURE, id, desc.label);
    return texture;
}

void Texture::bind(unsigned unit) const {
    glBindTextureUnit(unit, id());
}

std::vector<std::uint8_t> Texture::read_rgba() const {
    std::vector<std::uint8_t> pixels(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) *
                                     4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTextureImage(id(), 0, GL_RGBA, GL_UNSIGNED_BYTE, static_cast<GLsizei>(pixels.size()), pixels.data());
    return pixels;
}

}  // namespace engine::gfx
