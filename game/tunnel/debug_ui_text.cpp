// Debug panel without Dear ImGui: one stats line on stdout per 60 frames (the fallback when ImGui is not built
// or there is no GLFW window).
#include "tunnel/debug_ui.hpp"

#include <cstdio>

namespace tunnel {

namespace {

class TextUi final : public DebugUi {
public:
    void draw(Level& level, double frame_ms, UiRequests&) override {
        if (++frames_ % 60 != 0) return;
        const LevelFrameStats& s = level.stats();
        std::printf(
            "frame %llu: %.1f ms, %zu/%zu wires, %zu wire vertices, %zu tunnel triangles, %zu rope nodes\n",
            static_cast<unsigned long long>(s.frame), frame_ms, s.wires_drawn, s.wires, s.wire_vertices,
            s.piece_triangles, s.rope_nodes);
    }
    bool wants_mouse() const override { return false; }
    bool wants_keyboard() const override { return false; }
    const char* kind() const override { return kind_; }
    explicit TextUi(const char* kind) : kind_(kind) {}

private:
    const char* kind_;
    unsigned long long frames_ = 0;
};

}  // namespace

std::unique_ptr<DebugUi> make_text_ui(const char* kind) { return std::make_unique<TextUi>(kind); }

#ifndef TUNNEL_HAVE_IMGUI
std::unique_ptr<DebugUi> DebugUi::create(engine::platform::Context&) { return make_text_ui("stdout"); }
#endif

}  // namespace tunnel
