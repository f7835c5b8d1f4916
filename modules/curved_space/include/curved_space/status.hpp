// Result of a curved_space operation that can fail on bad input: ok, or a message naming what is wrong.
#pragma once

#include <string>
#include <utility>

namespace curved_space {

/// Success, or a specific error such as "segment 3: length must be positive, got -1".
/// `segment` is the index of the offending input segment (-1 when no single segment is to blame).
struct Status {
    bool ok = true;
    std::string message;
    int segment = -1;

    [[nodiscard]] explicit operator bool() const { return ok; }
    [[nodiscard]] static Status success() { return {}; }
    [[nodiscard]] static Status error(std::string msg, int segment_index = -1) {
        return Status{false, std::move(msg), segment_index};
    }
};

}  // namespace curved_space
