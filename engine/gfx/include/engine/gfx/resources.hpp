// Typed, move-only owners of GL objects (buffers, vertex arrays, shader programs, textures) and the functions
// that make them. Each kind is its own type, so passing a Buffer where a Texture is expected does not
// compile. All functions need a current GL 4.5 context (engine::platform::Context); they use direct state
// access.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "engine/core/expected.hpp"

namespace engine::gfx {

using engine::Error;
using engine::Expected;
using engine::Status;

namespace detail {
void delete_buffer(unsigned id);
void delete_vertex_array(unsigned id);
void delete_program(unsigned id);
void delete_texture(unsigned id);

// Owns one GL name; Deleter picks the glDelete* call. Moving transfers ownership, the source becomes empty.
template <void (*Deleter)(unsigned)>
class GlName {
public:
    GlName() = default;
    explicit GlName(unsigned id) : id_(id) {}
    GlName(GlName&& other) noexcept : id_(std::exchange(other.id_, 0u)) {}
    GlName& operator=(GlName&& other) noexcept {
        if (this != &other) {
            reset();
            id_ = std::exchange(other.id_, 0u);
        }
        return *this;
    }
    GlName(const GlName&) = delete;
    GlName& operator=(const GlName&) = delete;
    ~GlName() { reset(); }

    unsigned id() const { return id_; }
    explicit operator bool() const { return id_ != 0; }
    void reset() {
        if (id_ != 0) Deleter(id_);
        id_ = 0;
    }

private:
    unsigned id_ = 0;
};
}  // namespace detail

// ---- Buffers ---------------------------------------------------------------------------------------------

// Zero means default: size_bytes defaults to data.size(); flags default to GL_DYNAMIC_STORAGE_BIT when
// dynamic.
struct BufferDesc {
    std::span<const std::byte> data{};  // initial contents (may be empty if size_bytes > 0: zero-filled)
    std::size_t size_bytes = 0;
    bool dynamic = false;        // allow update() (glNamedBufferSubData)
    unsigned storage_flags = 0;  // extra glBufferStorage flags (e.g. map bits)
    std::string_view label{};    // shown by GL debuggers and in debug output
};

class Buffer {
public:
    Buffer() = default;
    unsigned id() const { return name_.id(); }
    std::size_t size_bytes() const { return size_bytes_; }
    explicit operator bool() const { return static_cast<bool>(name_); }
    // Overwrites [offset, offset + bytes.size()); the buffer must be dynamic and large enough (asserted).
    void update(std::size_t offset_bytes, std::span<const std::byte> bytes);

private:
    friend Expected<Buffer> make_buffer(const BufferDesc& desc);
    detail::GlName<detail::delete_buffer> name_;
    std::size_t size_bytes_ = 0;
    bool dynamic_ = false;
};

// Creates immutable storage. Errors: zero size, or the driver refused the allocation.
Expected<Buffer> make_buffer(const BufferDesc& desc);

template <class T>
Expected<Buffer> make_buffer(std::span<const T> items, std::string_view label = {}, bool dynamic = false) {
    return make_buffer({.data = std::as_bytes(items), .dynamic = dynamic, .label = label});
}

// ---- Vertex arrays ---------------------------------------------------------------------------------------

enum class AttributeType { float32, uint8, uint32 };

struct VertexAttribute {
    unsigned location = 0;
    int components = 3;  // 1..4
    AttributeType type = AttributeType::float32;
    bool normalized = false;  // integer types: map to [0, 1] floats
    unsigned offset_bytes = 0;
};

struct VertexArrayDesc {
    const Buffer* vertex_buffer = nullptr;  // binding 0
    unsigned stride_bytes = 0;
    std::vector<VertexAttribute> attributes{};
    const Buffer* index_buffer = nullptr;  // optional element buffer (uint32 indices)
    std::string_view label{};
};

class VertexArray {
public:
    VertexArray() = default;
    unsigned id() const { return name_.id(); }
    explicit operator bool() const { return static_cast<bool>(name_); }
    void bind() const;

private:
    friend VertexArray make_vertex_array(const VertexArrayDesc& desc);
    detail::GlName<detail::delete_vertex_array> name_;
};

// The buffers must outlive their use through the vertex array.
VertexArray make_vertex_array(const VertexArrayDesc& desc);

// ---- Shader programs -------------------------------------------------------------------------------------

struct ProgramDesc {
    std::string_view vertex{};  // GLSL source, "#version 450 core" first
    std::string_view fragment{};
    std::string_view label{};  // names the program in error messages
    std::string_view compute{};  // set: a compute program (vertex and fragment must then be empty)
};

class Program {
public:
    Program() = default;
    unsigned id() const { return name_.id(); }
    explicit operator bool() const { return static_cast<bool>(name_); }
    void use() const;

    // -1 if the uniform does not exist or was optimized away (setting it is then a no-op, as in GL).
    int uniform_location(const char* name) const;
    void set(const char* name, float v) const;
    void set(const char* name, int v) const;
    void set(const char* name, const glm::vec2& v) const;
    void set(const char* name, const glm::vec3& v) const;
    void set(const char* name, const glm::vec4& v) const;
    void set(const char* name, const glm::mat3& m) const;
    void set(const char* name, const glm::mat4& m) const;
    // Uniform array elements [0, values.size()) at `location` (from uniform_location; -1 is a no-op).
    void set(int location, std::span<const float> values) const;

private:
    friend Expected<Program> make_program(const ProgramDesc& desc);
    detail::GlName<detail::delete_program> name_;
};

// Compiles and links. Errors carry the stage, the label and the driver's info log, e.g.
// "fragment shader of 'lit' failed to compile:\n0:3(2): error: ...".
Expected<Program> make_program(const ProgramDesc& desc);

// ---- Textures --------------------------------------------------------------------------------------------

enum class Filter { linear, nearest };
enum class Wrap { repeat, clamp_to_edge };

struct TextureDesc {
    int width = 0;
    int height = 0;
    std::span<const std::uint8_t> rgba{};  // width * height * 4 bytes, rows bottom to top (GL order)
    bool mipmaps = true;
    Filter filter = Filter::linear;
    Wrap wrap = Wrap::repeat;
    std::string_view label{};
};

class Texture {
public:
    Texture() = default;
    unsigned id() const { return name_.id(); }
    explicit operator bool() const { return static_cast<bool>(name_); }
    int width() const { return width_; }
    int height() const { return height_; }
    void bind(unsigned unit) const;
    // Reads mip level 0 back as RGBA8 (tests, tools).
    std::vector<std::uint8_t> read_rgba() const;

private:
    friend Expected<Texture> make_texture(const TextureDesc& desc);
    detail::GlName<detail::delete_texture> name_;
    int width_ = 0;
    int height_ = 0;
};

// An RGBA8 2D texture. Errors: non-positive size, or pixel count not width * height * 4.
Expected<Texture> make_texture(const TextureDesc& desc);

}  // namespace engine::gfx
