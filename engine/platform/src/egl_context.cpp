// Headless OpenGL 4.5 core context drawing into an RGBA8 + depth24 framebuffer object of the requested size.
// The EGL display: a hardware EGL device when one exists (EGL_EXT_device_enumeration + EGL_EXT_platform_device:
// the first device that is not Mesa's software device and gives an OpenGL 4.5 core context), otherwise Mesa's
// surfaceless platform (no display, no GPU needed; llvmpipe renders). The choice is logged once (unless quiet)
// and returned by headless_display(). WIRE_EGL_PLATFORM=surfaceless or =device forces one.
#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>
#include <vector>

#include "context_impl.hpp"

namespace engine::platform {
namespace {

std::string egl_error_name(EGLint code) {
    switch (code) {
        case EGL_SUCCESS:
            return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED:
            return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS:
            return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC:
            return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE:
            return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONFIG:
            return "EGL_BAD_CONFIG";
        case EGL_BAD_CONTEXT:
            return "EGL_BAD_CONTEXT";
        case EGL_BAD_DISPLAY:
            return "EGL_BAD_DISPLAY";
        case EGL_BAD_MATCH:
            return "EGL_BAD_MATCH";
        case EGL_BAD_PARAMETER:
            return "EGL_BAD_PARAMETER";
        case EGL_BAD_SURFACE:
            return "EGL_BAD_SURFACE";
        default:
            return "EGL error 0x" + [code] {
                char buf[16];
                std::snprintf(buf, sizeof buf, "%x", static_cast<unsigned>(code));
                return std::string(buf);
            }();
    }
}

Error egl_failure(const std::string& what) {
    return Error{"EGL: " + what + " (" + egl_error_name(eglGetError()) + ")"};
}

// Mesa hands out one EGLDisplay per platform; eglTerminate would destroy every context on it, so the
// display is initialized once per process and terminated when the last headless context goes away.
struct SharedDisplay {
    std::mutex mutex;
    EGLDisplay display = EGL_NO_DISPLAY;
    int users = 0;
    std::string chosen;  ///< what headless_display() reports
};
SharedDisplay& shared_display() {
    static SharedDisplay d;
    return d;
}

bool has_extension(const char* list, const char* name) {
    if (list == nullptr) return false;
    const std::string all = std::string(" ") + list + " ";
    return all.find(std::string(" ") + name + " ") != std::string::npos;
}

using GetPlatformDisplay = EGLDisplay (*)(EGLenum, void*, const EGLint*);
using QueryDevices = EGLBoolean (*)(EGLint, void**, EGLint*);
using QueryDeviceString = const char* (*)(void*, EGLint);

/// A display that can make an OpenGL 4.5 core context (checked by making one and destroying it).
bool can_make_gl45(EGLDisplay display) {
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) return false;
    const EGLint config_attribs[] = {EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (eglChooseConfig(display, config_attribs, &config, 1, &count) != EGL_TRUE || count == 0) return false;
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    EGLContext ctx = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
    if (ctx == EGL_NO_CONTEXT) return false;
    eglDestroyContext(display, ctx);
    return true;
}

/// The first hardware EGL device that initializes and makes a GL 4.5 context; EGL_NO_DISPLAY if none.
/// `tried` collects one line per device looked at (for the log and the error message).
EGLDisplay hardware_device_display(const char* client_ext, GetPlatformDisplay get_platform_display,
                                   std::string& chosen, std::string& tried) {
    if (!(has_extension(client_ext, "EGL_EXT_device_enumeration") ||
          has_extension(client_ext, "EGL_EXT_device_base")) ||
        !has_extension(client_ext, "EGL_EXT_platform_device")) {
        tried = "no EGL device enumeration (EGL_EXT_device_enumeration / EGL_EXT_platform_device)";
        return EGL_NO_DISPLAY;
    }
    auto query_devices = reinterpret_cast<QueryDevices>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto query_string = reinterpret_cast<QueryDeviceString>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    if (query_devices == nullptr || query_string == nullptr) {
        tried = "eglQueryDevicesEXT is not available";
        return EGL_NO_DISPLAY;
    }
    EGLint count = 0;
    if (query_devices(0, nullptr, &count) != EGL_TRUE || count <= 0) {
        tried = "no EGL devices";
        return EGL_NO_DISPLAY;
    }
    std::vector<void*> devices(static_cast<std::size_t>(count));
    if (query_devices(count, devices.data(), &count) != EGL_TRUE) {
        tried = "eglQueryDevicesEXT failed";
        return EGL_NO_DISPLAY;
    }
    for (EGLint i = 0; i < count; ++i) {
        void* device = devices[static_cast<std::size_t>(i)];
        const char* ext = query_string(device, EGL_EXTENSIONS);
        std::string name = "EGL device " + std::to_string(i);
        if (has_extension(ext, "EGL_EXT_device_drm")) {
            if (const char* file = query_string(device, EGL_DRM_DEVICE_FILE_EXT))
                name += " (" + std::string(file) + ")";
        }
        if (has_extension(ext, "EGL_MESA_device_software")) {
            tried += name + ": software, skipped; ";
            continue;
        }
        EGLDisplay display = get_platform_display(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
        EGLint major = 0, minor = 0;
        if (display == EGL_NO_DISPLAY || eglInitialize(display, &major, &minor) != EGL_TRUE) {
            tried += name + ": eglInitialize failed; ";
            continue;
        }
        if (!can_make_gl45(display)) {
            tried += name + ": no OpenGL 4.5 core context; ";
            eglTerminate(display);
            continue;
        }
        chosen = "hardware " + name;
        return display;
    }
    if (tried.empty()) tried = "no hardware EGL device";
    return EGL_NO_DISPLAY;
}

Expected<EGLDisplay> acquire_display(bool quiet) {
    SharedDisplay& shared = shared_display();
    std::lock_guard lock(shared.mutex);
    if (shared.users > 0) {
        ++shared.users;
        return shared.display;
    }
    // Without any display, epoxy cannot know the EGL version yet: check the client extension string first.
    const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    auto get_platform_display =
        reinterpret_cast<GetPlatformDisplay>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) return Error{"EGL: eglGetPlatformDisplayEXT is not available"};
    const char* forced_env = std::getenv("WIRE_EGL_PLATFORM");
    const std::string forced = forced_env != nullptr ? forced_env : "";
    if (!forced.empty() && forced != "device" && forced != "surfaceless") {
        return Error{"EGL: WIRE_EGL_PLATFORM must be 'device' or 'surfaceless', got '" + forced + "'"};
    }

    std::string chosen, tried;
    EGLDisplay display = EGL_NO_DISPLAY;
    if (forced != "surfaceless") display = hardware_device_display(client_ext, get_platform_display, chosen, tried);
    if (display == EGL_NO_DISPLAY && forced == "device") {
        return Error{"EGL: WIRE_EGL_PLATFORM=device but no hardware EGL device works (" + tried + ")"};
    }
    if (display == EGL_NO_DISPLAY) {
        if (!has_extension(client_ext, "EGL_MESA_platform_surfaceless")) {
            return Error{"EGL: no hardware EGL device (" + tried +
                         ") and the surfaceless Mesa platform (EGL_MESA_platform_surfaceless) is not available"};
        }
        display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (display == EGL_NO_DISPLAY) return egl_failure("no surfaceless display");
        EGLint major = 0;
        EGLint minor = 0;
        if (eglInitialize(display, &major, &minor) != EGL_TRUE) return egl_failure("eglInitialize failed");
        chosen = forced == "surfaceless" ? "Mesa surfaceless (forced by WIRE_EGL_PLATFORM)"
                                         : "Mesa surfaceless (" + tried + ")";
    }
    if (!quiet) std::fprintf(stderr, "headless EGL: %s\n", chosen.c_str());
    shared.display = display;
    shared.users = 1;
    shared.chosen = chosen;
    return display;
}

void release_display() {
    SharedDisplay& shared = shared_display();
    std::lock_guard lock(shared.mutex);
    if (shared.users > 0 && --shared.users == 0) {
        eglTerminate(shared.display);
        eglReleaseThread();
        shared.display = EGL_NO_DISPLAY;
    }
}

class EglContext final : public Context {
public:
    EglContext(EGLDisplay display, EGLContext context) : display_(display), context_(context) {}

    ~EglContext() override {
        if (eglGetCurrentContext() != context_)
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_);
        destroy_targets();
        eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display_, context_);
        release_display();
    }

    Status create_targets(int width, int height) {
        destroy_targets();
        width_ = width;
        height_ = height;
        glCreateRenderbuffers(1, &color_);
        glNamedRenderbufferStorage(color_, GL_RGBA8, width, height);
        glCreateRenderbuffers(1, &depth_);
        glNamedRenderbufferStorage(depth_, GL_DEPTH_COMPONENT24, width, height);
        glCreateFramebuffers(1, &fbo_);
        glNamedFramebufferRenderbuffer(fbo_, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
        glNamedFramebufferRenderbuffer(fbo_, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth_);
        const GLenum status = glCheckNamedFramebufferStatus(fbo_, GL_FRAMEBUFFER);
        if (status != GL_FRAMEBUFFER_COMPLETE) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "0x%x", status);
            return Error{"EGL: off-screen framebuffer " + std::to_string(width) + "x" +
                         std::to_string(height) + " is incomplete (status " + buf + ")"};
        }
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
        return {};
    }

    Backend backend() const override { return Backend::headless; }
    Extent framebuffer_size() const override { return {width_, height_}; }
    unsigned framebuffer() const override { return fbo_; }
    void make_current() override { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_); }
    bool should_close() const override { return close_requested_; }
    void request_close() override { close_requested_ = true; }
    void poll_events() override {}
    const Input& input() const override { return input_; }
    void set_resize_callback(ResizeCallback callback) override { on_resize_ = std::move(callback); }

    void resize(int width_px, int height_px) override {
        assert(width_px > 0 && height_px > 0 && "resize to an empty framebuffer");
        if (width_px == width_ && height_px == height_) return;
        if (Status s = create_targets(width_px, height_px); !s) {
            std::fprintf(stderr, "%s\n", s.message.c_str());
            return;
        }
        if (on_resize_) on_resize_(width_, height_);
    }

    void begin_frame() override {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
        glViewport(0, 0, width_, height_);
        glDisable(GL_DITHER);  // on by default; a driver that dithers would make equal colours differ
    }
    void end_frame() override { glFlush(); }

private:
    void destroy_targets() {
        if (fbo_ != 0) glDeleteFramebuffers(1, &fbo_);
        if (color_ != 0) glDeleteRenderbuffers(1, &color_);
        if (depth_ != 0) glDeleteRenderbuffers(1, &depth_);
        fbo_ = color_ = depth_ = 0;
    }

    EGLDisplay display_;
    EGLContext context_;
    GLuint fbo_ = 0;
    GLuint color_ = 0;
    GLuint depth_ = 0;
    int width_ = 0;
    int height_ = 0;
    bool close_requested_ = false;
    Input input_;
    ResizeCallback on_resize_;
};

}  // namespace

std::string headless_display() {
    SharedDisplay& shared = shared_display();
    std::lock_guard lock(shared.mutex);
    return shared.chosen;
}

Expected<std::unique_ptr<Context>> create_headless_context(const ContextDesc& desc_in) {
    const ContextDesc desc = with_defaults(desc_in);
    Expected<EGLDisplay> display = acquire_display(desc.quiet);
    if (!display) return display.error();
    EGLDisplay dpy = *display;

    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
        release_display();
        return egl_failure("eglBindAPI(EGL_OPENGL_API) failed: desktop OpenGL not supported");
    }
    // Surfaceless: no surface type needed; ask for 8-bit RGBA so the config matches our FBO format.
    const EGLint config_attribs[] = {EGL_SURFACE_TYPE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                     EGL_RED_SIZE,     8, EGL_GREEN_SIZE,      8,
                                     EGL_BLUE_SIZE,    8, EGL_ALPHA_SIZE,      8,
                                     EGL_NONE};
    EGLConfig config = nullptr;
    EGLint config_count = 0;
    if (eglChooseConfig(dpy, config_attribs, &config, 1, &config_count) != EGL_TRUE || config_count == 0) {
        release_display();
        return egl_failure("no EGL config for desktop OpenGL");
    }
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                      4,
                                      EGL_CONTEXT_MINOR_VERSION,
                                      5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_CONTEXT_OPENGL_DEBUG,
                                      desc.debug ? EGL_TRUE : EGL_FALSE,
                                      EGL_NONE};
    EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, context_attribs);
    if (ctx == EGL_NO_CONTEXT) {
        release_display();
        return egl_failure("could not create an OpenGL 4.5 core context");
    }
    if (eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx) != EGL_TRUE) {
        eglDestroyContext(dpy, ctx);
        release_display();
        return egl_failure("eglMakeCurrent without a surface failed");
    }
    auto context = std::make_unique<EglContext>(dpy, ctx);  // owns dpy reference and ctx from here on
    if (Status s = context->create_targets(desc.width, desc.height); !s) return s;
    context->begin_frame();
    return std::unique_ptr<Context>(std::move(context));
}

}  // namespace engine::platform
