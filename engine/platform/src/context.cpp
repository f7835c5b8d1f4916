// Backend choice: a window where there is a display, headless EGL otherwise.
#include <epoxy/gl.h>

#include <cstdio>
#include <cstdlib>

#include "context_impl.hpp"
#include "engine/platform/context.hpp"

namespace engine::platform {
namespace {

std::string gl_string(GLenum name) {
    const auto* s = reinterpret_cast<const char*>(glGetString(name));
    return s != nullptr ? std::string(s) : std::string();
}

bool env_set(const char* name) {
    const char* v = std::getenv(name);
    return v != nullptr && v[0] != '\0';
}

}  // namespace

std::string Context::gl_version() const {
    return gl_string(GL_VERSION);
}
std::string Context::gl_renderer() const {
    return gl_string(GL_RENDERER);
}

bool display_available() {
    return env_set("DISPLAY") || env_set("WAYLAND_DISPLAY");
}

Expected<std::unique_ptr<Context>> create_context(const ContextDesc& desc) {
    switch (desc.backend) {
        case Backend::window:
            return create_window_context(desc);
        case Backend::headless:
            return create_headless_context(desc);
        case Backend::automatic:
            break;
    }
    if (!display_available()) {
        if (!desc.quiet)
            std::fprintf(stderr, "platform: no display (DISPLAY/WAYLAND_DISPLAY unset), running headless\n");
        return create_headless_context(desc);
    }
    Expected<std::unique_ptr<Context>> window = create_window_context(desc);
    if (window) return window;
    if (!desc.quiet)
        std::fprintf(stderr, "platform: %s; falling back to headless\n", window.error().message.c_str());
    return create_headless_context(desc);
}

}  // namespace engine::platform
