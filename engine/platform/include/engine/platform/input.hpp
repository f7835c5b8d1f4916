// Keyboard and mouse state of a window, sampled by Context::poll_events(). Headless contexts keep it empty.
#pragma once

#include <array>
#include <cstdint>

namespace engine::platform {

/// Key codes are GLFW's (printable keys are their upper-case ASCII codes).
enum class Key : int {
    space = 32,
    a = 65,
    d = 68,
    e = 69,
    p = 80,
    q = 81,
    s = 83,
    w = 87,
    escape = 256,
    enter = 257,
    tab = 258,
    right = 262,
    left = 263,
    down = 264,
    up = 265,
    f1 = 290,
    f12 = 301,
    left_shift = 340,
    left_control = 341,
};

/// Mouse buttons (GLFW's numbers).
enum class MouseButton : int { left = 0, right = 1, middle = 2 };

/// Input state of one frame (Context::input()).
struct Input {
    static constexpr int key_count = 512;   ///< size of the key arrays (GLFW key codes are below it)
    static constexpr int button_count = 8;  ///< size of the button array

    std::array<bool, key_count> keys_down{};        ///< held now
    std::array<bool, key_count> keys_pressed{};     ///< went down since the previous poll_events()
    std::array<bool, button_count> buttons_down{};  ///< held now
    double mouse_x_px = 0.0;                        ///< cursor x in window pixels, from the left
    double mouse_y_px = 0.0;                        ///< cursor y in window pixels, from the top
    double mouse_dx_px = 0.0;                       ///< motion since the previous poll_events()
    double mouse_dy_px = 0.0;                       ///< vertical motion since the previous poll_events()
    double scroll_y = 0.0;                          ///< scroll since the previous poll_events()

    /// Key `k` is held.
    bool down(Key k) const { return keys_down[static_cast<std::size_t>(k)]; }
    /// Key `k` went down since the previous poll_events() (once per press).
    bool pressed(Key k) const { return keys_pressed[static_cast<std::size_t>(k)]; }
    /// Mouse button `b` is held.
    bool down(MouseButton b) const { return buttons_down[static_cast<std::size_t>(b)]; }
};

}  // namespace engine::platform
