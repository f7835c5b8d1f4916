// Result of a wire-module operation that can fail on bad input: ok, or a message naming what is wrong.
#pragma once

#include <string>
#include <utility>

namespace wire {

/// Success, or a specific error. `node` is the index of the offending INPUT node (-1 when no single node is to blame).
/// Functions returning Status never throw on bad input and never write NaN into their outputs.
struct Status {
    bool ok = true;       ///< success
    std::string message;  ///< empty when ok; otherwise e.g. "node 7: position.y is NaN"
    int node = -1;        ///< offending input node, -1 if none

    /// ok.
    [[nodiscard]] explicit operator bool() const { return ok; }
    /// A success.
    [[nodiscard]] static Status success() { return {}; }
    /// A failure with `msg`, blaming input node `node_index` (-1: none).
    [[nodiscard]] static Status error(std::string msg, int node_index = -1) {
        return Status{false, std::move(msg), node_index};
    }
};

}  // namespace wire
