// The tunnel's debug panel in a window: Dear ImGui (GLFW + OpenGL 3 backends of libimgui-dev) when the build
// found it, otherwise a once-a-second stats line on stdout. Switches spline type, LOD tolerance, upload path,
// wireframe, camera mode; shows per-system frame times from the ECS schedule and counts; a screenshot button.
#pragma once

#include "tunnel/level.hpp"

#include <engine/platform/context.hpp>

#include <memory>

namespace tunnel {

struct UiRequests {
    bool screenshot = false;
};

class DebugUi {
public:
    virtual ~DebugUi() = default;
    /// Needs the window context current. Never fails: falls back to the stdout panel.
    static std::unique_ptr<DebugUi> create(engine::platform::Context& context);
    /// Builds and draws the panel over the frame just rendered (call before end_frame()).
    virtual void draw(Level& level, double frame_ms, UiRequests& requests) = 0;
    /// The panel has the mouse / keyboard: the game should not use them this frame.
    [[nodiscard]] virtual bool wants_mouse() const = 0;
    [[nodiscard]] virtual bool wants_keyboard() const = 0;
    [[nodiscard]] virtual const char* kind() const = 0;
};

/// The panel without Dear ImGui: one stats line on stdout per 60 frames. `kind` says why it is used.
[[nodiscard]] std::unique_ptr<DebugUi> make_text_ui(const char* kind);

}  // namespace tunnel
