// Reader for wire description files (JSON): one wire, a list of wires, or successive frames of wires.
// The format is a contract (docs/wiretool.md, `wiretool mesh`); this reader only parses and checks the form:
// the geometry checks (fewer than 2 distinct nodes, degenerate loops) belong to wire::build_curve.
#pragma once

#include <wire/status.hpp>

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace wire::io {

/// Physics data a node may carry for the thesis' curvature-driven tension.
struct NodePhysics {
    double theta = 0, Iz = 0, L = 0, dL = 0, A = 0;
};

/// One wire as written in the file. Optional settings are unset when the file does not give them, so
/// that command-line options can override the file and the file can override the defaults.
struct WireSpec {
    std::vector<glm::dvec3> positions;
    std::vector<uint32_t> ids;       ///< file ids, or the node's index when the file gives none
    std::vector<float> stretch;      ///< 1 when not given
    std::vector<float> radius;       ///< per-node radius, -1 when not given (use the wire's)
    std::vector<NodePhysics> physics;  ///< empty unless some node gives "physics"
    std::vector<glm::dvec3> tcb;     ///< per-node (tension, bias, continuity); empty unless some node gives one

    std::optional<double> radius_m;
    std::optional<bool> closed;
    std::optional<bool> caps;
    std::optional<std::string> spline_type;  ///< uniform|centripetal|chordal|c2|auto|linear|catmull-rom
    std::optional<double> alpha, tension, bias, continuity;
    std::optional<bool> curvature_tension;
    std::optional<int> sides;
};

/// A frame's camera ({"eye", "target", "up", "fov_deg"}): read by `wiretool view` (other readers ignore it).
/// The reader checks the form: finite numbers, eye != target, up not parallel to the view direction, fov in
/// (0, 180) degrees.
struct CameraSpec {
    glm::dvec3 eye_m{};
    glm::dvec3 target_m{};
    std::optional<glm::dvec3> up;
    std::optional<double> fov_deg;  ///< vertical field of view
};

struct FrameSpec {
    std::vector<WireSpec> wires;
    std::optional<CameraSpec> camera;  ///< only in the {"frames": [...]} form
};

/// A parsed file: always one or more frames (a single wire or a wire list is one frame).
struct SceneSpec {
    std::vector<FrameSpec> frames;
};

/// Parses `text`. On error the message starts with `source` (a file name) and names the frame, wire and
/// node and what is wrong, e.g. "cable.json: wire 1, node 4: coordinate z is not a number".
/// `out` is cleared first and left empty on error.
Status parse_wire_json(std::string_view text, const std::string& source, SceneSpec& out);

/// Reads and parses a file; a missing or unreadable file is an error naming it.
Status load_wire_json(const std::string& path, SceneSpec& out);

}  // namespace wire::io

#include <wire/pipeline.hpp>

namespace wire::io {

/// Settings given outside the file (e.g. on a command line); set fields override the file's.
struct SettingsOverrides {
    std::optional<std::string> spline_type;
    std::optional<double> alpha;
    std::optional<double> tension;
    std::optional<uint32_t> rings_per_segment;
    std::optional<double> tolerance_m;  ///< adaptive ring placement; excludes rings_per_segment
    std::optional<uint32_t> sides;
    std::optional<bool> caps;
};

/// Default ring count and side count of a wire whose file and overrides give none.
inline constexpr uint32_t default_rings_per_segment = 8;
inline constexpr uint32_t default_sides = 12;

/// The pipeline settings of one wire: overrides over the file over the defaults, field by field. A spline type
/// named in the overrides implies its alpha (uniform 0, centripetal 0.5, chordal 1) unless an alpha override is
/// given too. Errors (without a location; the caller adds file and wire): an unknown spline type, an alpha
/// override for a spline kind that has none.
[[nodiscard]] Status resolve_settings(const WireSpec& spec, const SettingsOverrides& overrides, PipelineSettings& out);

/// The wire's nodes as the curve stage takes them (a radius not given becomes 0: "use the wire's radius").
[[nodiscard]] WireNodes to_wire_nodes(const WireSpec& spec);

}  // namespace wire::io
