// GL debug output (KHR_debug, core in 4.3): driver messages to stderr or a sink of your choice.
#pragma once

#include <functional>
#include <string>

namespace engine::gfx {

enum class DebugSeverity { notification, low, medium, high };

struct DebugMessage {
    DebugSeverity severity = DebugSeverity::notification;
    unsigned id = 0;
    std::string source{};  // "api", "shader compiler", "application", ...
    std::string type{};    // "error", "performance", "marker", ...
    std::string text{};
};

struct DebugOutputDesc {
    DebugSeverity min_severity = DebugSeverity::low;  // messages below are dropped
    std::function<void(const DebugMessage&)>
        sink{};               // default: one line "gl <severity> <type> <id>: <text>" to stderr
    bool synchronous = true;  // messages arrive on the calling thread, inside the GL call
};

// Enables GL_DEBUG_OUTPUT on the current context. Replaces a previously installed sink.
void enable_debug_output(const DebugOutputDesc& desc = {});
void disable_debug_output();

// The KHR_debug label of the buffer object `name` ("" when it is no buffer or has no label). Drivers recycle
// deleted names, so a test that a buffer was deleted checks that its name is gone or now labels another object.
std::string buffer_label(unsigned name);

}  // namespace engine::gfx
