// Windowed OpenGL 4.5 core context through GLFW, with keyboard/mouse state and a resize callback.
#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <cstdio>
#include <string>

#include "context_impl.hpp"

namespace engine::platform {
namespace {

std::string glfw_error_text() {
    const char* description = nullptr;
    const int code = glfwGetError(&description);
    if (code == GLFW_NO_ERROR) return "no GLFW error reported";
    return description != nullptr ? std::string(description) : "GLFW error " + std::to_string(code);
}

// GLFW is initialized with the first window and terminated with the last one.
int g_glfw_users = 0;

class GlfwContext final : public Context {
public:
    explicit GlfwContext(GLFWwindow* window) : window_(window) {
        glfwSetWindowUserPointer(window_, this);
        glfwSetFramebufferSizeCallback(window_, [](GLFWwindow* w, int width, int height) {
            auto* self = static_cast<GlfwContext*>(glfwGetWindowUserPointer(w));
            if (self->on_resize_ && width > 0 && height > 0) self->on_resize_(width, height);
        });
        glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int /*scancode*/, int action, int /*mods*/) {
            auto* self = static_cast<GlfwContext*>(glfwGetWindowUserPointer(w));
            if (key < 0 || key >= Input::key_count) return;
            const auto k = static_cast<std::size_t>(key);
            if (action == GLFW_PRESS) {
                self->input_.keys_down[k] = true;
                self->input_.keys_pressed[k] = true;
            } else if (action == GLFW_RELEASE) {
                self->input_.keys_down[k] = false;
            }
        });
        glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int /*mods*/) {
            auto* self = static_cast<GlfwContext*>(glfwGetWindowUserPointer(w));
            if (button < 0 || button >= Input::button_count) return;
            self->input_.buttons_down[static_cast<std::size_t>(button)] = action == GLFW_PRESS;
        });
        glfwSetScrollCallback(window_, [](GLFWwindow* w, double /*dx*/, double dy) {
            static_cast<GlfwContext*>(glfwGetWindowUserPointer(w))->input_.scroll_y += dy;
        });
        glfwGetCursorPos(window_, &input_.mouse_x_px, &input_.mouse_y_px);
    }

    ~GlfwContext() override {
        glfwDestroyWindow(window_);
        if (--g_glfw_users == 0) glfwTerminate();
    }

    Backend backend() const override { return Backend::window; }
    Extent framebuffer_size() const override {
        Extent e;
        glfwGetFramebufferSize(window_, &e.width, &e.height);
        return e;
    }
    unsigned framebuffer() const override { return 0; }
    void make_current() override { glfwMakeContextCurrent(window_); }
    bool should_close() const override { return glfwWindowShouldClose(window_) != 0; }
    void request_close() override { glfwSetWindowShouldClose(window_, GLFW_TRUE); }

    void poll_events() override {
        input_.keys_pressed.fill(false);
        input_.scroll_y = 0.0;
        const double old_x = input_.mouse_x_px;
        const double old_y = input_.mouse_y_px;
        glfwPollEvents();
        glfwGetCursorPos(window_, &input_.mouse_x_px, &input_.mouse_y_px);
        input_.mouse_dx_px = input_.mouse_x_px - old_x;
        input_.mouse_dy_px = input_.mouse_y_px - old_y;
    }

    const Input& input() const override { return input_; }
    void set_resize_callback(ResizeCallback callback) override { on_resize_ = std::move(callback); }
    void resize(int width_px, int height_px) override { glfwSetWindowSize(window_, width_px, height_px); }

    void begin_frame() override {
        const Extent e = framebuffer_size();
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glViewport(0, 0, e.width, e.height);
        glDisable(GL_DITHER);  // on by default; a driver that dithers would make equal colours differ
    }
    void end_frame() override { glfwSwapBuffers(window_); }

private:
    GLFWwindow* window_;
    Input input_;
    ResizeCallback on_resize_;
};

}  // namespace

Expected<std::unique_ptr<Context>> create_window_context(const ContextDesc& desc_in) {
    const ContextDesc desc = with_defaults(desc_in);
    if (!display_available()) return Error{"GLFW: no display (neither DISPLAY nor WAYLAND_DISPLAY is set)"};
    if (g_glfw_users == 0 && glfwInit() != GLFW_TRUE) return Error{"GLFW: init failed: " + glfw_error_text()};
    ++g_glfw_users;
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, desc.debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_SRGB_CAPABLE, GLFW_FALSE);
    GLFWwindow* window = glfwCreateWindow(desc.width, desc.height, desc.title.c_str(), nullptr, nullptr);
    if (window == nullptr) {
        std::string text = glfw_error_text();
        if (--g_glfw_users == 0) glfwTerminate();
        return Error{"GLFW: could not create a 4.5 core window: " + text};
    }
    glfwMakeContextCurrent(window);
    glfwSwapInterval(desc.vsync ? 1 : 0);
    auto context = std::make_unique<GlfwContext>(window);
    context->begin_frame();
    return std::unique_ptr<Context>(std::move(context));
}

}  // namespace engine::platform
