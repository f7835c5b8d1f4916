// `wiretool bench`: shared helpers (clocks, medians, upload sizes, tables).
#include "bench/common.hpp"

#include <wire/render/upload_plan.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <vector>

namespace wiretool::bench {

double cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double wall_ms() {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    const std::size_t mid = v.size() / 2;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
    if (v.size() % 2 == 1) return v[mid];
    const double hi = v[mid];
    return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
}

// The renderer's own accounting (wire/render/upload_plan.hpp), so computed and drawn bytes agree.
std::size_t cpu_mesh_bytes(std::size_t items, std::size_t vertices, std::size_t indices) {
    if (items == 0) return 0;
    // One command draws every wire of the material; each vertex carries its 4-byte draw index.
    return wire::render::kCommandBytes + items * wire::render::kDrawRecordBytes +
           vertices * (sizeof(wire::TubeVertex) + wire::render::kVertexDrawIndexBytes) + indices * sizeof(uint32_t);
}

std::size_t gpu_nodes_bytes(const wire::WireNodes& nodes, const wire::SplineSettings& spline) {
    wire::DrawList list{.path = wire::UploadPath::gpu_nodes, .items = {}};
    wire::DrawItem item;
    item.wire_id = 1;
    item.nodes = &nodes;
    item.spline = spline;
    list.items.push_back(item);
    wire::render::NodesPlan plan;
    return wire::render::plan_nodes_frame(list, plan);
}

std::size_t upload_bytes(const wire::DrawList& list) {
    return wire::render::streamed_upload_bytes(list);
}

bool selected(const Options& o, const std::string& scene) {
    return o.scenes.empty() || std::find(o.scenes.begin(), o.scenes.end(), scene) != o.scenes.end();
}

bool Table::write_csv(const std::filesystem::path& file) const {
    std::ofstream out(file);
    if (!out) return false;
    auto line = [&](const std::vector<std::string>& cells) {
        for (std::size_t i = 0; i < cells.size(); ++i) out << (i ? "," : "") << cells[i];
        out << '\n';
    };
    line(header);
    for (const auto& r : rows) line(r);
    return static_cast<bool>(out);
}

std::string Table::markdown() const {
    std::string s = "|";
    for (const auto& h : header) s += " " + h + " |";
    s += "\n|";
    for (std::size_t i = 0; i < header.size(); ++i) s += " --- |";
    s += "\n";
    for (const auto& r : rows) {
        s += "|";
        for (const auto& c : r) s += " " + c + " |";
        s += "\n";
    }
    return s;
}

std::string num(double v, int digits) {
    if (!std::isfinite(v)) return "nan";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

std::string num(std::size_t v) {
    return std::to_string(v);
}

bool write_text(const std::filesystem::path& file, const std::string& text) {
    std::ofstream out(file);
    out << text;
    return static_cast<bool>(out);
}

}  // namespace wiretool::bench
