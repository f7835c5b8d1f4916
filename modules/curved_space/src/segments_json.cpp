// SEGS.json reader: the segment list of `wiretool bend`, with messages naming the file, segment and key.
#include "curved_space/segments_json.hpp"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "curved_space/chain.hpp"

namespace curved_space {
namespace {

using nlohmann::json;

std::string type_name(const json& value) { return value.type_name(); }

}  // namespace

Status parse_segments_json(std::string_view text, const std::string& name, std::vector<Segment>& out) {
    const std::string prefix = name + ": ";
    json root;
    try {
        root = json::parse(text.begin(), text.end());
    } catch (const json::exception& e) {
        return Status::error(prefix + "invalid JSON: " + e.what());
    }
    if (!root.is_object()) return Status::error(prefix + "expected an object {\"segments\": [...]}, got " + type_name(root));
    const auto list = root.find("segments");
    if (list == root.end()) return Status::error(prefix + "missing key \"segments\"");
    if (!list->is_array()) return Status::error(prefix + "\"segments\" must be an array, got " + type_name(*list));
    if (list->empty()) return Status::error(prefix + "\"segments\" is empty (at least one segment is needed)");

    std::vector<Segment> segments;
    segments.reserve(list->size());
    for (std::size_t i = 0; i < list->size(); ++i) {
        const json& item = (*list)[i];
        const std::string where = prefix + "segment " + std::to_string(i) + ": ";
        const int index = static_cast<int>(i);
        if (!item.is_object())
            return Status::error(where + "expected an object {\"length\", \"angle\", \"direction\"}, got " + type_name(item),
                                 index);
        for (const auto& [key, value] : item.items()) {
            if (key != "length" && key != "angle" && key != "direction")
                return Status::error(where + "unknown key \"" + key + "\" (expected length, angle, direction)", index);
            if (!value.is_number())
                return Status::error(where + key + " must be a number, got " + type_name(value), index);
        }
        Segment s;
        for (const char* key : {"length", "angle"})
            if (!item.contains(key)) return Status::error(where + "missing key \"" + key + "\"", index);
        s.length_m = item.at("length").get<double>();
        s.angle_rad = item.at("angle").get<double>();
        s.direction_rad = item.contains("direction") ? item.at("direction").get<double>() : 0.0;
        segments.push_back(s);
    }
    if (Status status = validate(segments); !status) return Status::error(prefix + status.message, status.index);
    out = std::move(segments);
    return Status::success();
}

Status read_segments_json(const std::string& path, std::vector<Segment>& out) {
    std::ifstream file(path, std::ios::binary);
    if (!file) return Status::error(path + ": cannot open the file");
    std::ostringstream text;
    text << file.rdbuf();
    if (file.bad()) return Status::error(path + ": read error");
    return parse_segments_json(text.str(), path, out);
}

}  // namespace curved_space
