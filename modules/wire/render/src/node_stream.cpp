// The bulk node stream (node_stream.hpp): its wires, frames and writes. The pass each node goes through is in
// node_stream_pass.hpp; what draw() does with the stream's wires in node_stream_emit.cpp.
#include "wire/render/node_stream.hpp"

#include "node_path.hpp"
#include "node_stream_pass.hpp"
#include "node_stream_state.hpp"
#include "gpu_wire_data.hpp"

#include "wire/packed_nodes.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <optional>

namespace wire::render {
namespace {
constexpr std::size_t kAlign = 256;
std::size_t align_up(std::size_t v) { return (v + kAlign - 1) / kAlign * kAlign; }
}  // namespace

using detail::GpuCurveHeader;
using detail::StreamState;
namespace gfx = engine::gfx;

NodeStream::NodeStream() : state_(std::make_unique<StreamState>()) {}
NodeStream::~NodeStream() {
    if (state_->path != nullptr) state_->path->attach(nullptr);
}

Expected<StreamWire> NodeStream::add(const StreamStyle& style) {
    if (Status st = detail::check_style(style); !st) return Error{st.message};
    StreamState& s = *state_;
    uint32_t index = 0;
    if (!s.free.empty()) {
        index = s.free.back();
        s.free.pop_back();
    } else {
        index = static_cast<uint32_t>(s.wires.size());
        s.wires.emplace_back();
        s.styles.emplace_back();
    }
    s.wires[index] = StreamState::Wire{};
    s.wires[index].live = true;
    s.wires[index].material = style.material;
    s.styles[index] = style;
    ++s.live;
    return StreamWire{index};
}

Status NodeStream::set_style(StreamWire wire, const StreamStyle& style) {
    if (!live(wire)) return Status::error("stream wire " + std::to_string(wire.index) + " is not live");
    if (Status st = detail::check_style(style); !st) return st;
    state_->styles[wire.index] = style;
    state_->wires[wire.index].material = style.material;
    return Status::success();
}

void NodeStream::remove(StreamWire wire) {
    if (!live(wire)) return;
    StreamState& s = *state_;
    StreamState::Wire& w = s.wires[wire.index];
    if (w.slot != UINT32_MAX && s.path != nullptr) s.path->release_slot(w.slot, w.segment_first, w.segments);
    w = StreamState::Wire{};
    s.free.push_back(wire.index);
    --s.live;
}

bool NodeStream::live(StreamWire wire) const {
    return wire.index < state_->wires.size() && state_->wires[wire.index].live;
}
std::size_t NodeStream::size() const { return state_->live; }

Status NodeStream::usable() const { return state_->path != nullptr ? Status::success() : state_->unusable; }

Status NodeStream::begin(std::size_t nodes) {
    StreamState& s = *state_;
    if (s.path == nullptr) return s.unusable;
    if (s.active) s.buffer.end();  // begun and not drawn: dropped (fenced, as if drawn)
    s.active = false;
    if (!s.buffer_made) {
        Expected<gfx::StreamBuffer> made = gfx::StreamBuffer::create({.label = "wire node stream"});
        if (!made) return Status::error("node stream: " + made.error().message);
        s.buffer = std::move(*made);
        s.buffer_made = true;
    }
    s.header_capacity = s.wires.size();
    s.header_at = 0;
    s.node_at = align_up(std::max<std::size_t>(s.header_capacity, 1) * sizeof(GpuCurveHeader));
    s.node_capacity = nodes;
    Expected<gfx::StreamRegion> region =
        s.buffer.begin(s.node_at + align_up(std::max<std::size_t>(nodes, 1) * sizeof(glm::vec4)));
    if (!region) return Status::error("node stream: " + region.error().message);
    s.region = *region;
    s.active = true;
    ++s.frame;
    s.cursor.store(0, std::memory_order_relaxed);
    s.headers = 0;
    s.pending.clear();
    {
        std::lock_guard lock(s.error_mutex);
        s.errors.clear();
    }
    return Status::success();
}

namespace {

/// Room for `count` nodes in the frame's region (nullopt: out of room, or no frame).
std::optional<std::size_t> reserve_nodes(StreamState& s, std::size_t count) {
    if (!s.active) return std::nullopt;
    const std::size_t first = s.cursor.fetch_add(count, std::memory_order_relaxed);
    if (first + count > s.node_capacity) return std::nullopt;
    return first;
}

/// The second look at a wire the pass refused (or that may merge): its nodes in double as WireNodes, checked and
/// packed as the ECS path does (wire::pack_nodes: the same messages, the same merge). On success the merged
/// nodes replace the pass's at `dst`.
template <class Position>
bool second_look(StreamState& s, uint32_t index, std::size_t n, Position position, const float* radius,
                 std::size_t radius_stride, glm::vec4* dst) {
    StreamState::Wire& w = s.wires[index];
    thread_local WireNodes nodes;
    thread_local PackedNodes packed;
    nodes.positions.resize(n);
    for (std::size_t j = 0; j < n; ++j) nodes.positions[j] = position(j);
    nodes.radius_m.clear();
    if (radius != nullptr) {
        nodes.radius_m.resize(n);
        for (std::size_t j = 0; j < n; ++j) {
            nodes.radius_m[j] = *reinterpret_cast<const float*>(reinterpret_cast<const char*>(radius) + j * radius_stride);
        }
    }
    if (Status st = pack_nodes(nodes, detail::spline_of(s.styles[index]), packed, NodeFormat::floats); !st) {
        s.refuse(index, st.index, st.message);
        return false;
    }
    std::memcpy(dst, packed.records.data(), packed.records.size() * sizeof(packed.records[0]));  // float records
    w.count = static_cast<uint32_t>(packed.node_count);
    w.unmerged = packed.node_count == n;
    for (int a = 0; a < 3; ++a) w.origin[a] = static_cast<float>(packed.origin_m[a]);
    for (int a = 0; a < 3; ++a) w.centre[a] = static_cast<float>(packed.origin_m[a]);  // a float point
    w.has_centre = true;
    return true;
}

bool refuse_length(StreamState& s, uint32_t index, std::size_t count) {
    s.refuse(index, -1, std::to_string(count) + " nodes; the nodes path draws at most " +
                            std::to_string(kNodesPathMaxNodes) + " a wire");
    return false;
}

bool refuse_room(StreamState& s, uint32_t index, std::size_t count) {
    s.refuse(index, -1, s.active ? "no room for its " + std::to_string(count) + " nodes (begin() reserved " +
                                      std::to_string(s.node_capacity) + " for the frame)"
                                : "written outside a frame (call begin() first)");
    return false;
}

/// After the pass: the wire as measured (origin, count, the next double write's origin), or, where the pass could
/// not clear it, as the second look finds it (refused, or merged).
template <class Position>
bool finish_write(StreamState& s, uint32_t index, std::size_t first, std::size_t n, const detail::Measure& m,
                  const glm::dvec3& origin, Position at, const float* radius, std::size_t radius_stride,
                  glm::vec4* dst) {
    StreamState::Wire& w = s.wires[index];
    if (!detail::clears_merge(m, origin, n, s.styles[index].closed)) {
        if (!second_look(s, index, n, at, radius, radius_stride, dst)) return false;
    } else {
        w.count = static_cast<uint32_t>(n);
        w.unmerged = true;
        for (int a = 0; a < 3; ++a) w.origin[a] = static_cast<float>(origin[a]);
        const glm::dvec3 centre = float_point(origin + 0.5 * (glm::dvec3(m.lo) + glm::dvec3(m.hi)));
        for (int a = 0; a < 3; ++a) w.centre[a] = static_cast<float>(centre[a]);
        w.has_centre = true;
    }
    w.node_first = static_cast<uint32_t>(2 * first);  // 8-byte units: a float record is two
    s.accepted(w, index);
    return true;
}

bool write_double(StreamState& s, uint32_t index, const double* xyz, std::size_t n, std::size_t stride,
                  const float* radius, std::size_t radius_stride, std::optional<std::size_t> first) {
    StreamState::Wire& w = s.wires[index];
    const StreamStyle& style = s.styles[index];
    if (n > kNodesPathMaxNodes) return refuse_length(s, index, n);
    if (!first) return refuse_room(s, index, n);
    auto* dst = reinterpret_cast<glm::vec4*>(s.region.data + s.node_at) + *first;
    const auto at = [&](std::size_t j) {  // the caller's doubles need not be 8-byte aligned (any stride)
        glm::dvec3 p;
        std::memcpy(&p.x, reinterpret_cast<const char*>(xyz) + j * stride, sizeof p);
        return p;
    };
    // The origin: last frame's box centre (a moving wire moves little in a frame), else the first node.
    glm::dvec3 origin = w.has_centre ? glm::dvec3(w.centre[0], w.centre[1], w.centre[2]) : (n ? at(0) : glm::dvec3(0));
    if (!std::isfinite(origin.x + origin.y + origin.z) || glm::length(origin) > kMaxCoordinate_m) origin = glm::dvec3(0);
    origin = float_point(origin);
    const float wire_radius = style.radius_m > 0.0f ? style.radius_m : kDefaultWireRadius_m;
    detail::Measure m;
#if defined(__SSE2__)
    if (radius == nullptr) {
        const __m128d oxy = _mm_set_pd(origin.y, origin.x), oz = _mm_set_sd(origin.z);
        const __m128d limit = _mm_set1_pd(kMaxCoordinate_m), sign = _mm_set1_pd(-0.0);
        const auto* base = reinterpret_cast<const char*>(xyz);
        m = detail::copy_nodes_sse(
            n,
            [&](std::size_t j, __m128d& ok) {
                const auto* p = reinterpret_cast<const double*>(base + j * stride);
                double pz;  // a caller's doubles need not be 8-byte aligned (any stride): loaded unaligned
                std::memcpy(&pz, p + 2, sizeof pz);
                const __m128d xy = _mm_loadu_pd(p), z = _mm_set_sd(pz);
                ok = _mm_and_pd(ok, _mm_cmple_pd(_mm_andnot_pd(sign, xy), limit));
                ok = _mm_and_pd(ok, _mm_unpacklo_pd(_mm_cmple_sd(_mm_andnot_pd(sign, z), limit), ok));
                return _mm_movelh_ps(_mm_cvtpd_ps(_mm_sub_pd(xy, oxy)), _mm_cvtpd_ps(_mm_sub_sd(z, oz)));
            },
            wire_radius, style.closed, dst);
    } else
#endif
    m = detail::copy_nodes(
        n,
        [&](std::size_t j, bool& in_range) {
            const glm::dvec3 p = at(j);
            in_range = std::abs(p.x) <= kMaxCoordinate_m && std::abs(p.y) <= kMaxCoordinate_m &&
                       std::abs(p.z) <= kMaxCoordinate_m;
            return glm::vec3(p - origin);
        },
        radius, radius_stride, wire_radius, style.closed, dst);
    return finish_write(s, index, *first, n, m, origin, at, radius, radius_stride, dst);
}

bool write_float(StreamState& s, uint32_t index, const glm::dvec3& given_origin, const float* xyz, std::size_t n,
                 std::size_t stride, const float* radius, std::size_t radius_stride, std::optional<std::size_t> first) {
    const StreamStyle& style = s.styles[index];
    if (n > kNodesPathMaxNodes) return refuse_length(s, index, n);
    if (!first) return refuse_room(s, index, n);
    auto* dst = reinterpret_cast<glm::vec4*>(s.region.data + s.node_at) + *first;
    const auto offset_at = [&](std::size_t j) {
        const auto* p = reinterpret_cast<const float*>(reinterpret_cast<const char*>(xyz) + j * stride);
        return glm::vec3(p[0], p[1], p[2]);
    };
    const auto at = [&](std::size_t j) { return given_origin + glm::dvec3(offset_at(j)); };
    const bool origin_ok = std::isfinite(given_origin.x + given_origin.y + given_origin.z);
    // The GPU's origin is a float point: the rest of the given origin is added to each offset (0 when the given
    // origin is a float point already, as a float engine's is).
    const glm::dvec3 origin = origin_ok ? float_point(given_origin) : glm::dvec3(0);
    const glm::vec3 rest(given_origin - origin);
    const auto limit = static_cast<float>(kMaxCoordinate_m);
    const float wire_radius = style.radius_m > 0.0f ? style.radius_m : kDefaultWireRadius_m;
    detail::Measure m;
#if defined(__SSE2__)
    if (radius == nullptr) {
        const __m128 add = _mm_set_ps(0.0f, rest.z, rest.y, rest.x);
        const __m128 lim = _mm_set1_ps(limit), sign = _mm_set1_ps(-0.0f);
        const auto* base = reinterpret_cast<const char*>(xyz);
        m = detail::copy_nodes_sse(
            n,
            [&](std::size_t j, __m128d& ok) {
                const auto* p = reinterpret_cast<const float*>(base + j * stride);
                // 12 bytes (a 16-byte load could read past the caller's last node).
                const __m128 xy = _mm_castsi128_ps(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p)));  // unaligned
                const __m128 o = _mm_add_ps(_mm_movelh_ps(xy, _mm_load_ss(p + 2)), add);
                // Each half's sign bit (what movemask_pd reads) the AND of its two lanes' tests.
                const __m128 in = _mm_cmple_ps(_mm_andnot_ps(sign, o), lim);
                ok = _mm_and_pd(ok, _mm_castps_pd(_mm_and_ps(in, _mm_shuffle_ps(in, in, _MM_SHUFFLE(2, 3, 0, 1)))));
                return o;
            },
            wire_radius, style.closed, dst);
    } else
#endif
    m = detail::copy_nodes(
        n,
        [&](std::size_t j, bool& in_range) {
            const glm::vec3 o = offset_at(j) + rest;
            in_range = std::abs(o.x) <= limit && std::abs(o.y) <= limit && std::abs(o.z) <= limit;
            return o;
        },
        radius, radius_stride, wire_radius, style.closed, dst);
    // Near the +-1e12 m edge the float test is not the double one: the second look decides there.
    m.ok &= origin_ok && glm::length(origin) + glm::length(glm::max(glm::abs(glm::dvec3(m.lo)), glm::abs(glm::dvec3(m.hi)))) <
                             0.5 * kMaxCoordinate_m;
    return finish_write(s, index, *first, n, m, origin, at, radius, radius_stride, dst);
}

bool check_wire(StreamState& s, StreamWire wire) {
    if (wire.index < s.wires.size() && s.wires[wire.index].live && wire.index < s.header_capacity) return true;
    s.refuse(wire.index, -1,
             wire.index < s.wires.size() && s.wires[wire.index].live
                 ? "added after begin(): written from the next frame"
                 : "not a live wire");
    return false;
}

}  // namespace

bool NodeStream::write(StreamWire wire, const double* xyz, std::size_t count, std::size_t stride, const float* radius,
                       std::size_t radius_stride) {
    StreamState& s = *state_;
    if (!check_wire(s, wire)) return false;
    return write_double(s, wire.index, xyz, count, stride, radius, radius_stride, reserve_nodes(s, count));
}

bool NodeStream::write(StreamWire wire, const glm::dvec3& origin_m, const float* xyz, std::size_t count,
                       std::size_t stride, const float* radius, std::size_t radius_stride) {
    StreamState& s = *state_;
    if (!check_wire(s, wire)) return false;
    return write_float(s, wire.index, origin_m, xyz, count, stride, radius, radius_stride, reserve_nodes(s, count));
}

namespace {
/// write_many's frame: one reservation for all, then the wires in blocks on worker threads (each wire's nodes
/// contiguous in the caller's array and in the region).
template <class One>
std::size_t write_blocks(StreamState& s, std::size_t wires, std::size_t count, One one) {
    const std::optional<std::size_t> first = reserve_nodes(s, wires * count);
    std::atomic<std::size_t> written{0};
    const auto block = [&](std::size_t lo, std::size_t hi) {
        std::size_t here = 0;
        for (std::size_t k = lo; k < hi; ++k) {
            here += one(k, first ? std::optional<std::size_t>(*first + k * count) : std::nullopt) ? 1 : 0;
        }
        written.fetch_add(here, std::memory_order_relaxed);
    };
    // Blocks of ~64 KB of nodes: enough to pay for a task, small enough to share 100,000 wires evenly.
    const std::size_t grain = std::max<std::size_t>(1, 4096 / std::max<std::size_t>(count, 1));
    if (wires * count >= 16384) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, wires, grain),
                          [&](const tbb::blocked_range<std::size_t>& r) { block(r.begin(), r.end()); });
    } else {
        block(0, wires);
    }
    return written.load();
}
}  // namespace

std::size_t NodeStream::write_many(std::span<const StreamWire> wires, const double* xyz, std::size_t count) {
    StreamState& s = *state_;
    return write_blocks(s, wires.size(), count, [&](std::size_t k, std::optional<std::size_t> first) {
        if (!check_wire(s, wires[k])) return false;
        return write_double(s, wires[k].index, xyz + 3 * k * count, count, 24, nullptr, 4, first);
    });
}

std::size_t NodeStream::write_many(std::span<const StreamWire> wires, std::span<const glm::dvec3> origins_m,
                                   const float* xyz, std::size_t count) {
    StreamState& s = *state_;
    if (origins_m.size() < wires.size()) {
        s.refuse(wires.empty() ? 0 : wires[0].index, -1,
                 "write_many: " + std::to_string(origins_m.size()) + " origins for " + std::to_string(wires.size()) +
                     " wires");
        return 0;
    }
    return write_blocks(s, wires.size(), count, [&](std::size_t k, std::optional<std::size_t> first) {
        if (!check_wire(s, wires[k])) return false;
        return write_float(s, wires[k].index, origins_m[k], xyz + 3 * k * count, count, 12, nullptr, 4, first);
    });
}

std::size_t NodeStream::state_bytes() const {
    const StreamState& s = *state_;
    return sizeof(StreamState) + s.wires.capacity() * sizeof(StreamState::Wire) +
           s.styles.capacity() * sizeof(StreamStyle) + s.free.capacity() * sizeof(uint32_t);
}
std::size_t NodeStream::mapped_bytes() const {
    const StreamState& s = *state_;
    return s.buffer_made ? std::size_t{s.buffer.regions()} * s.buffer.region_bytes() : 0;
}

std::vector<StreamError> NodeStream::errors() const {
    std::lock_guard lock(state_->error_mutex);
    return state_->errors;
}

std::size_t NodeStream::nodes_written() const {
    return std::min(state_->cursor.load(std::memory_order_relaxed), state_->node_capacity);
}

}  // namespace wire::render
