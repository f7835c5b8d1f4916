// An OpenGL 4.5 core context with a frame loop: a GLFW window, or headless EGL (Mesa surfaceless) rendering
// into an off-screen framebuffer. GL calls go through libepoxy in both cases.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "engine/core/expected.hpp"
#include "engine/platform/input.hpp"

/// GL 4.5 context (GLFW window or headless EGL), input, frame capture and PNG files, Expected/Error.
namespace engine::platform {

/// Which kind of context create_context() makes.
enum class Backend {
    automatic,  ///< window if a display is available and GLFW works, else headless (with a one-line notice)
    window,     ///< GLFW window only; fails if there is no display
    headless,   ///< EGL surfaceless only
};

/// Zero or empty fields take the defaults listed here.
struct ContextDesc {
    Backend backend = Backend::automatic;  ///< window, headless, or window when a display works
    int width = 0;        ///< default 1280 (window: initial client size; headless: framebuffer size)
    int height = 0;       ///< default 720
    std::string title{};  ///< default "wires"
    bool vsync = true;    ///< window only
    bool debug = false;   ///< request a debug context (KHR_debug output is more complete)
    bool quiet = false;   ///< do not print the fallback notice
};

/// A size in pixels.
struct Extent {
    int width = 0;   ///< pixels
    int height = 0;  ///< pixels
};

/// A current OpenGL 4.5 core context and its frame loop (made by create_context()). One per thread; GL calls
/// of the engine and the wire renderer need one current.
class Context {
public:
    /// Called with the new framebuffer size.
    using ResizeCallback = std::function<void(int width_px, int height_px)>;

    /// Destroying a context releases its GL objects; afterwards no context is current on this thread.
    virtual ~Context() = default;
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    virtual Backend backend() const = 0;  ///< window or headless, never automatic
    /// backend() == Backend::headless.
    bool headless() const { return backend() == Backend::headless; }

    /// Size of the framebuffer rendered into, in pixels.
    virtual Extent framebuffer_size() const = 0;
    /// GL name of the framebuffer a frame renders into: 0 for a window, an FBO (RGBA8 + depth24) headless.
    virtual unsigned framebuffer() const = 0;

    /// Makes this context current on the calling thread.
    virtual void make_current() = 0;
    /// Window: the user asked to close (or request_close() was called). Headless: only after request_close().
    virtual bool should_close() const = 0;
    /// Makes should_close() true (e.g. on Esc).
    virtual void request_close() = 0;
    /// Pumps window events and refreshes input(); no-op headless.
    virtual void poll_events() = 0;
    /// Keyboard and mouse state as of the last poll_events() (all up headless).
    virtual const Input& input() const = 0;
    /// Called when the framebuffer size changes (window resize, or headless resize()).
    virtual void set_resize_callback(ResizeCallback callback) = 0;
    /// Headless: reallocates the FBO. Window: resizes the window.
    virtual void resize(int width_px, int height_px) = 0;

    /// Binds framebuffer() and sets the viewport to its full size.
    virtual void begin_frame() = 0;
    /// Window: swaps buffers. Headless: glFlush (pixels stay readable until the next frame draws).
    virtual void end_frame() = 0;

    /// "4.5 (Core Profile) Mesa ..." and "llvmpipe (...)" for example; valid once created.
    std::string gl_version() const;
    /// GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    std::string gl_renderer() const;

protected:
    Context() = default;
};

/// True when DISPLAY or WAYLAND_DISPLAY is set.
bool display_available();

/// Creates a context per desc.backend and makes it current. Errors name what failed (e.g. "EGL: no
/// surfaceless Mesa platform", "GLFW: could not create a 4.5 core window").
Expected<std::unique_ptr<Context>> create_context(const ContextDesc& desc = {});
/// create_context() with Backend::headless: EGL (see headless_display()), rendering into an off-screen FBO.
Expected<std::unique_ptr<Context>> create_headless_context(const ContextDesc& desc = {});
/// The EGL display the headless backend chose, e.g. "hardware EGL device 1 (/dev/dri/renderD128)" or "Mesa
/// surfaceless (EGL device 0: software, skipped; )"; empty before the first headless context. A hardware EGL
/// device is preferred when one exists; WIRE_EGL_PLATFORM=surfaceless|device forces one (device: fail if
/// none). Logged to stderr once per process unless ContextDesc::quiet.
std::string headless_display();
/// create_context() with Backend::window: a GLFW window; fails without a display.
Expected<std::unique_ptr<Context>> create_window_context(const ContextDesc& desc = {});

}  // namespace engine::platform
