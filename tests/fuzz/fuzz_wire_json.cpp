// libFuzzer target: parse_wire_json on arbitrary bytes; accepted scenes run through WirePipeline (every frame,
// every wire, small ring counts). Property: a rejection carries a message; an accepted wire either fails in the
// curve stage with a message or yields finite curve, rings and mesh with indices in range.
#include "fuzz_checks.hpp"

#include <wire/io/wire_json.hpp>
#include <wire/pipeline.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    wire::io::SceneSpec scene;
    const engine::Status st = wire::io::parse_wire_json(text, "fuzz.json", scene);
    if (!st.ok()) {
        wire_fuzz::require(!st.message.empty(), "rejected wire JSON without a message");
        wire_fuzz::require(st.message.rfind("fuzz.json", 0) == 0, "wire JSON message does not name the file");
        wire_fuzz::require(scene.frames.empty(), "rejected wire JSON left frames in the output");
        return 0;
    }
    wire_fuzz::require(!scene.frames.empty(), "accepted wire JSON without frames");
    std::vector<wire::WirePipeline> pipelines(scene.frames.front().wires.size());
    for (const wire::io::FrameSpec& frame : scene.frames) {
        for (std::size_t w = 0; w < frame.wires.size() && w < pipelines.size(); ++w) {
            const wire::io::WireSpec& spec = frame.wires[w];
            if (spec.positions.size() > 4096) continue;  // keep one run fast; size is not the property here
            // The file's settings as wiretool resolves them, with small ring and side counts (speed).
            wire::io::SettingsOverrides small;
            small.rings_per_segment = 2;
            small.sides = static_cast<uint32_t>(std::min(spec.sides.value_or(6), 8));
            wire::PipelineSettings settings;
            const engine::Status rs = wire::io::resolve_settings(spec, small, settings);
            if (!rs.ok()) {
                wire_fuzz::require(!rs.message.empty(), "resolve_settings error without a message");
                continue;
            }
            const engine::Status ps = pipelines[w].update(wire::io::to_wire_nodes(spec), settings);
            if (!ps.ok()) {
                wire_fuzz::require(!ps.message.empty(), "pipeline error without a message");
                continue;
            }
            wire_fuzz::check_pipeline_outputs(pipelines[w]);
        }
    }
    return 0;
}
