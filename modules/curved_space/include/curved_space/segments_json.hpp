// The segment-list file format of `wiretool bend` (SEGS.json):
//   {"segments": [{"length": 4.0, "angle": 0.5, "direction": 0.0}, ...]}
// length in metres (> 0), angle and direction in radians (direction optional, default 0). A contract: see
// docs/wiretool.md.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "curved_space/bend.hpp"
#include "curved_space/status.hpp"

namespace curved_space {

/// Parses SEGS.json text. `name` prefixes every message, e.g. "segs.json: segment 2: missing key \"angle\"",
/// "segs.json: segment 0: length must be positive, got -1", "segs.json: invalid JSON: ...". Rejects a
/// missing or empty "segments" array, non-object entries, non-number values, unknown keys and every segment
/// validate() rejects. On error `out` is left unchanged.
[[nodiscard]] Status parse_segments_json(std::string_view text, const std::string& name, std::vector<Segment>& out);

/// Reads and parses the file at `path` (messages name the path; an unreadable file is an error too).
[[nodiscard]] Status read_segments_json(const std::string& path, std::vector<Segment>& out);

}  // namespace curved_space
