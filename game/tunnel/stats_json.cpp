// stats.json records: see stats_json.hpp.
#include "tunnel/stats_json.hpp"

#include <cmath>

namespace tunnel {

nlohmann::json frame_record(const LevelFrameStats& s, std::span<const engine::ecs::SystemStats> systems,
                            int& non_finite) {
    auto finite = [&](double v) {
        if (std::isfinite(v)) return v;
        ++non_finite;
        return -1.0;
    };
    nlohmann::json systems_ms = nlohmann::json::object();
    for (const engine::ecs::SystemStats& st : systems) systems_ms[st.name] = finite(st.last_ms);
    nlohmann::json levels = nlohmann::json::array();
    for (int n : s.piece_levels) levels.push_back(n);
    return {{"frame", s.frame},
            {"time_s", finite(s.time_s)},
            {"systems_ms", systems_ms},
            {"gpu_ms",
             {{"tunnel.pieces", finite(s.pieces_gpu_ms)},
              {"wire.render", finite(s.wires_gpu_ms)},
              {"frame", s.gpu_ms_frame}}},
            {"wires", s.wires},
            {"wires_drawn", s.wires_drawn},
            {"wire_vertices", s.wire_vertices},
            {"wire_triangles", s.wire_triangles},
            {"piece_vertices", s.piece_vertices},
            {"piece_triangles", s.piece_triangles},
            {"vertices", s.wire_vertices + s.piece_vertices},
            {"bytes_uploaded", s.wire_bytes_uploaded + s.segment_bytes_uploaded},
            {"wire_bytes_uploaded", s.wire_bytes_uploaded},
            {"segment_bytes_uploaded", s.segment_bytes_uploaded},
            {"wire_waited_for_gpu", s.wire_waited_for_gpu},
            {"rope_nodes", s.rope_nodes},
            {"nodes_inserted", s.nodes_inserted},
            {"nodes_removed", s.nodes_removed},
            {"curves_built", s.curves_built},
            {"rings", s.rings},
            {"piece_levels", levels},
            {"rope_max_turn_deg", finite(s.rope_max_turn_deg)},
            {"rope_penetration_m", finite(s.rope_penetration_m)},
            {"piece_max_error_px", finite(s.piece_max_error_px)},
            {"camera_rope_m", finite(s.camera_rope_m)},
            {"camera_cable_m", finite(s.camera_cable_m)}};
}

bool all_finite(const nlohmann::json& doc) {
    if (doc.is_number_float()) return std::isfinite(doc.get<double>());
    if (doc.is_null()) return false;  // nlohmann writes NaN and Inf as null
    if (doc.is_object() || doc.is_array()) {
        for (const auto& v : doc)
            if (!all_finite(v)) return false;
    }
    return true;
}

}  // namespace tunnel
