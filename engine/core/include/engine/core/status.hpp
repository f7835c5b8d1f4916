// The one result type of the runtime: success, or a runtime failure with a message naming what is wrong and the
// input item to blame. Every module returns it (wire: a node; curved space: a segment; assets: a file).
#pragma once

#include <cassert>
#include <string>
#include <utility>

namespace engine {

/// Success (an empty message) or a specific runtime failure, e.g. "node 7: position.y is NaN". Functions that
/// return a Status never throw on bad input and never write NaN into their outputs. Programmer mistakes are
/// asserts, not Statuses (STYLE.md). Test it as `if (status)` / `status.ok()`.
struct Status {
    std::string message{};  ///< empty on success; otherwise names what failed and why
    int index = -1;         ///< the input item to blame (a wire's node, a chain's segment), -1 when none

    /// True on success.
    [[nodiscard]] bool ok() const { return message.empty(); }
    /// ok().
    [[nodiscard]] explicit operator bool() const { return ok(); }
    /// A success.
    [[nodiscard]] static Status success() { return {}; }
    /// A failure with `message` (not empty), blaming input item `item` (-1: none).
    [[nodiscard]] static Status error(std::string message, int item = -1) {
        assert(!message.empty() && "a failure names what is wrong");
        return Status{std::move(message), item};
    }
};

/// How a failure is returned where a value is expected: `return Error{"EGL: no surfaceless Mesa platform"};`.
using Error = Status;

}  // namespace engine
