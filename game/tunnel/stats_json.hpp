// stats.json of `tunnel --headless`: one record per frame (per-system milliseconds from the ECS schedule,
// wires drawn, vertices, bytes uploaded, rope node changes, subdivision levels) plus the run's summary.
//   {"frames": [{"frame": 0, "time_s": 0.033, "systems_ms": {"tunnel.animate": 0.02, ...},
//                "gpu_ms": {"tunnel.pieces": ms, "wire.render": ms, "frame": f},  (GPU timer queries of frame f,
//                          a few frames back: read without stalling; f = -1 and 0 ms before the first result)
//                "wires": 43, "wires_drawn": 38, "wire_vertices": 51234, "wire_triangles": ...,
//                "piece_triangles": ..., "piece_vertices": ..., "bytes_uploaded": ..., "wire_bytes_uploaded":
//                ..., "segment_bytes_uploaded": ..., "rope_nodes": ..., "nodes_inserted": 1, "nodes_removed":
//                0, "curves_built": ..., "rings": ..., "piece_levels": [0, 3, 2, 1, 0, 0, 0, 0],
//                "rope_max_turn_deg": 12.1, "rope_penetration_m": 0.001, "piece_max_error_px": 0.41,
//                "camera_rope_m": 1.3, "camera_cable_m": 2.0}, ...],
//    "summary": {"frames": 120, "width": 1280, "height": 720, "dt_s": 0.0333, "systems_mean_ms": {...},
//                "systems_max_ms": {...}, "frame_ms_mean": ..., "nodes_inserted": ..., "nodes_removed": ...,
//                "rope_max_turn_deg": (max over frames), "rope_penetration_m": (max), "rope_radius_min_m": ...,
//                "piece_max_error_px": (max), "piece_tolerance_px": 0.5, "piece_triangles_max": ...,
//                "camera_rope_min_m": ..., "camera_cable_min_m": ..., "close_up_frames": [...],
//                "gl_renderer": "llvmpipe ..."}}
// Every number is finite (a non-finite value is written as -1 and counted in "non_finite").
#pragma once

#include "tunnel/level.hpp"

#include <nlohmann/json.hpp>

#include <span>
#include <string>

namespace tunnel {

/// One frame's record (see above). `non_finite` counts values that were not finite.
[[nodiscard]] nlohmann::json frame_record(const LevelFrameStats& stats,
                                          std::span<const engine::ecs::SystemStats> systems, int& non_finite);

/// True if every number in `doc` (recursively) is finite.
[[nodiscard]] bool all_finite(const nlohmann::json& doc);

}  // namespace tunnel
