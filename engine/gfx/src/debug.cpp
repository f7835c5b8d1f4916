// KHR_debug callback: turns driver messages into DebugMessage values for a sink (stderr by default).
#include "engine/gfx/debug.hpp"

#include <epoxy/gl.h>

#include <cstdio>

namespace engine::gfx {
namespace {

struct DebugState {
    DebugOutputDesc desc;
};
DebugState g_state;  // one sink per process; the callback's user pointer points here

DebugSeverity to_severity(GLenum s) {
    switch (s) {
        case GL_DEBUG_SEVERITY_HIGH:
            return DebugSeverity::high;
        case GL_DEBUG_SEVERITY_MEDIUM:
            return DebugSeverity::medium;
        case GL_DEBUG_SEVERITY_LOW:
            return DebugSeverity::low;
        default:
            return DebugSeverity::notification;
    }
}

const char* severity_name(DebugSeverity s) {
    switch (s) {
        case DebugSeverity::high:
            return "high";
        case DebugSeverity::medium:
            return "medium";
        case DebugSeverity::low:
            return "low";
        case DebugSeverity::notification:
            break;
    }
    return "note";
}

const char* source_name(GLenum s) {
    switch (s) {
        case GL_DEBUG_SOURCE_API:
            return "api";
        case GL_DEBUG_SOURCE_WINDOW_SYSTEM:
            return "window system";
        case GL_DEBUG_SOURCE_SHADER_COMPILER:
            return "shader compiler";
        case GL_DEBUG_SOURCE_THIRD_PARTY:
            return "third party";
        case GL_DEBUG_SOURCE_APPLICATION:
            return "application";
        default:
            return "other";
    }
}

const char* type_name(GLenum t) {
    switch (t) {
        case GL_DEBUG_TYPE_ERROR:
            return "error";
        case GL_DEBUG_TYPE_DEPRECATED_BEHAVIOR:
            return "deprecated";
        case GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR:
            return "undefined behavior";
        case GL_DEBUG_TYPE_PORTABILITY:
            return "portability";
        case GL_DEBUG_TYPE_PERFORMANCE:
            return "performance";
        case GL_DEBUG_TYPE_MARKER:
            return "marker";
        case GL_DEBUG_TYPE_PUSH_GROUP:
            return "push group";
        case GL_DEBUG_TYPE_POP_GROUP:
            return "pop group";
        default:
            return "other";
    }
}

void GLAPIENTRY on_debug_message(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                                 const GLchar* text, const void* user) {
    const auto* state = static_cast<const DebugState*>(user);
    DebugMessage m;
    m.severity = to_severity(severity);
    if (static_cast<int>(m.severity) < static_cast<int>(state->desc.min_severity)) return;
    m.id = id;
    m.source = source_name(source);
    m.type = type_name(type);
    m.text = length >= 0 ? std::string(text, static_cast<std::size_t>(length)) : std::string(text);
    if (state->desc.sink) {
        state->desc.sink(m);
    } else {
        std::fprintf(stderr, "gl %s %s %u: %s\n", severity_name(m.severity), m.type.c_str(), m.id,
                     m.text.c_str());
    }
}

}  // namespace

void enable_debug_output(const DebugOutputDesc& desc) {
    g_state.desc = desc;
    glEnable(GL_DEBUG_OUTPUT);
    if (desc.synchronous) {
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    } else {
        glDisable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    }
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
    glDebugMessageCallback(on_debug_message, &g_state);
}

std::string buffer_label(unsigned name) {
    if (!glIsBuffer(name)) return {};
    GLsizei length = 0;
    glGetObjectLabel(GL_BUFFER, name, 0, &length, nullptr);
    std::string label(static_cast<std::size_t>(length) + 1, '\0');
    glGetObjectLabel(GL_BUFFER, name, static_cast<GLsizei>(label.size()), &length, label.data());
    label.resize(static_cast<std::size_t>(length));
    return label;
}

void disable_debug_output() {
    glDebugMessageCallback(nullptr, nullptr);
    glDisable(GL_DEBUG_OUTPUT);
}

}  // namespace engine::gfx
