// The bulk node stream (node_stream.hpp) and the nodes path's part that emits its wires (node_path.hpp).
#include "wire/render/node_stream.hpp"

#include "node_path.hpp"
#include "gpu_wire_data.hpp"

#include "wire/packed_nodes.hpp"

#include "engine/gfx/stream_buffer.hpp"

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <mutex>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace wire::render {
namespace detail {

namespace gfx = engine::gfx;
constexpr double kMaxCoordinate_m = 1e12;  // check_nodes' range (the second look applies it exactly)

/// The stream's wires and this frame's region (NodeStream's state; the nodes path reads it at draw()).
struct StreamState {
    /// Per wire, what a frame reads and writes (dense by StreamWire::index).
    struct Wire {
        uint32_t node_first = 0, count = 0;  ///< this frame's write: first node in the region, curve nodes (merged)
        uint32_t written = 0;                ///< frame of the last accepted write (0: none)
        uint32_t slot = UINT32_MAX, segment_first = 0, segments = 0;
        uint32_t sent_count = 0;             ///< curve nodes of the last upload the GPU got
        float origin[3] = {0, 0, 0};         ///< this write's origin (a float point)
        float centre[3] = {0, 0, 0};         ///< the last write's box centre as a float point (the next origin)
        uint32_t material = 0;               ///< StreamStyle::material (read by every frame's pass over the wires)
        bool has_centre = false, live = false, built = false, unmerged = false, sent_unmerged = false;
    };
    static_assert(sizeof(Wire) <= 64, "a wire's per-frame record in one cache line");
    std::vector<Wire> wires;
    std::vector<StreamStyle> styles;
    std::vector<uint32_t> free;
    std::size_t live = 0;

    gfx::StreamBuffer buffer;
    bool buffer_made = false;
    gfx::StreamRegion region{};
    bool active = false;      ///< begin() was called and the frame not drawn yet
    uint32_t frame = 0;       ///< begin() count (Wire::written compares to it)
    std::size_t header_capacity = 0, node_capacity = 0, header_at = 0, node_at = 0;
    std::atomic<std::size_t> cursor{0};  ///< nodes used of the region's room
    std::size_t headers = 0;             ///< headers emitted this frame
    /// Wires written this frame that need a slot or another segment count (the draw allocates them serially).
    std::vector<uint32_t> pending;
    std::mutex pending_mutex;
    void accepted(Wire& w, uint32_t index) {
        w.written = frame;
        const uint32_t segments = styles[index].closed ? w.count : w.count - 1;
        if (w.slot != UINT32_MAX && segments == w.segments) return;
        std::lock_guard lock(pending_mutex);
        pending.push_back(index);
    }

    mutable std::mutex error_mutex;
    std::vector<StreamError> errors;

    NodePath* path = nullptr;  ///< the renderer's nodes path (null: not made)
    Status unusable = Status::error("the node stream is not attached to a renderer (WireRenderer::node_stream())");

    void refuse(uint32_t wire, int node, std::string message) {
        std::lock_guard lock(error_mutex);
        errors.push_back({StreamWire{wire}, node, "stream wire " + std::to_string(wire) + ": " + std::move(message)});
    }
};

namespace {

constexpr std::size_t kAlign = 256;
std::size_t align_up(std::size_t v) { return (v + kAlign - 1) / kAlign * kAlign; }

SplineSettings spline_of(const StreamStyle& s) {
    SplineSettings spline;
    spline.kind = s.kind;
    spline.alpha = s.alpha;
    spline.tension = s.tension, spline.bias = s.bias, spline.continuity = s.continuity;
    spline.closed = s.closed;
    spline.radius_m = s.radius_m;
    return spline;
}

Status check_style(const StreamStyle& s) {
    if (!gpu_builds(s.kind)) return Status::error("style: the GPU builds linear, Catmull-Rom, c2 and automatic wires");
    WireNodes probe;
    probe.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    if (Status st = check_curve_input(probe, spline_of(s)); !st) {
        return Status::error("style: " + st.message);
    }
    return Status::success();
}

/// What the copying pass measured: the offsets' box, the shortest chord (squared), whether every value passed.
struct Measure {
    glm::vec3 lo{FLT_MAX}, hi{-FLT_MAX};
    float min_chord2 = FLT_MAX;
    bool ok = true;
};

/// The one pass: node j's offset from `offset(j)` (its range check folded into ok), its radius, written as the
/// curve pass reads it; the box and the shortest chord on the way.
template <class Offset>
Measure copy_nodes(std::size_t n, Offset offset, const float* radius, std::size_t radius_stride, float wire_radius,
                   bool closed, glm::vec4* dst) {
    Measure m;
    glm::vec3 prev{};
    bool ok = true;
    for (std::size_t j = 0; j < n; ++j) {
        bool in_range = true;
        const glm::vec3 o = offset(j, in_range);
        float r = wire_radius;
        if (radius != nullptr) {
            const float given = *reinterpret_cast<const float*>(reinterpret_cast<const char*>(radius) + j * radius_stride);
            // Finite and >= 0, and 0 or at least the smallest radius (check_nodes'); NaN fails both.
            in_range &= given >= 0.0f && given <= FLT_MAX && (given == 0.0f || given >= 1e-6f);
            r = given > 0.0f ? given : wire_radius;
        }
        ok &= in_range;
        dst[j] = glm::vec4(o, r);
        m.lo = glm::min(m.lo, o), m.hi = glm::max(m.hi, o);
        if (j > 0) {
            const glm::vec3 d = o - prev;
            m.min_chord2 = std::min(m.min_chord2, glm::dot(d, d));
        }
        prev = o;
    }
    if (closed && n >= 2) {
        const glm::vec3 d = glm::vec3(dst[0]) - prev;
        m.min_chord2 = std::min(m.min_chord2, glm::dot(d, d));
    }
    m.ok = ok;
    return m;
}

#if defined(__SSE2__)
/// copy_nodes for nodes without per-node radius, four lanes a node (x, y, z, radius): the offsets, their box and
/// chords in SSE registers, the range test a mask (NaN fails it), no branch per node. `load(j, ok)` gives node j's
/// offset with lane 3 zero and ANDs its range test into `ok`.
template <class Load>
Measure copy_nodes_sse(std::size_t n, Load load, float wire_radius, bool closed, glm::vec4* dst) {
    Measure m;
    if (n == 0) return m;
    const __m128 radius = _mm_set_ps(wire_radius, 0.0f, 0.0f, 0.0f);
    __m128 lo = _mm_set1_ps(FLT_MAX), hi = _mm_set1_ps(-FLT_MAX), chord = _mm_set1_ps(FLT_MAX);
    __m128d ok = _mm_castsi128_pd(_mm_set1_epi32(-1));
    const auto squared = [](__m128 d) {  // |d|^2 in every lane (lane 3 of d is zero)
        const __m128 d2 = _mm_mul_ps(d, d);
        const __m128 s = _mm_add_ps(d2, _mm_shuffle_ps(d2, d2, _MM_SHUFFLE(2, 3, 0, 1)));
        return _mm_add_ps(s, _mm_shuffle_ps(s, s, _MM_SHUFFLE(1, 0, 3, 2)));
    };
    const __m128 first = load(0, ok);
    __m128 prev = first;
    _mm_store_ps(&dst[0].x, _mm_or_ps(first, radius));
    lo = _mm_min_ps(lo, first), hi = _mm_max_ps(hi, first);
    for (std::size_t j = 1; j < n; ++j) {
        const __m128 o = load(j, ok);
        _mm_store_ps(&dst[j].x, _mm_or_ps(o, radius));
        lo = _mm_min_ps(lo, o), hi = _mm_max_ps(hi, o);
        chord = _mm_min_ps(chord, squared(_mm_sub_ps(o, prev)));
        prev = o;
    }
    if (closed && n >= 2) chord = _mm_min_ps(chord, squared(_mm_sub_ps(first, prev)));
    alignas(16) float l[4], h[4];
    _mm_store_ps(l, lo), _mm_store_ps(h, hi);
    m.lo = glm::vec3(l[0], l[1], l[2]), m.hi = glm::vec3(h[0], h[1], h[2]);
    m.min_chord2 = _mm_cvtss_f32(chord);
    // NaN offsets leave the min/max alone: the range mask caught them (a NaN compares false).
    m.ok = _mm_movemask_pd(ok) == 3;
    return m;
}
#endif

/// Whether nothing the merge rule (merge_nodes: eps = max(1e-9 diag, 64 DBL_EPSILON max |p|)) could join lies
/// in the float offsets: the shortest chord clears eps by more than the offsets' rounding.
bool clears_merge(const Measure& m, const glm::dvec3& origin, std::size_t n, bool closed) {
    if (!m.ok || n < (closed ? 3u : 2u)) return false;
    const glm::dvec3 lo(m.lo), hi(m.hi);
    const double diag = glm::length(hi - lo);
    const double max_abs = std::max(glm::length(origin + lo), glm::length(origin + hi));
    const double eps = std::max(1e-9 * diag, 64.0 * DBL_EPSILON * max_abs);
    const double reach = std::max(glm::length(lo), glm::length(hi));
    const double margin = eps + 4e-7 * reach + 1e-30;  // float offsets: 2^-24 relative, a chord two of them
    return static_cast<double>(m.min_chord2) > margin * margin;
}

}  // namespace
}  // namespace detail

using detail::StreamState;
using detail::kMaxCoordinate_m;
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
    s.node_at = detail::align_up(std::max<std::size_t>(s.header_capacity, 1) * sizeof(GpuCurveHeader));
    s.node_capacity = nodes;
    Expected<gfx::StreamRegion> region =
        s.buffer.begin(s.node_at + detail::align_up(std::max<std::size_t>(nodes, 1) * sizeof(glm::vec4)));
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
    if (Status st = pack_nodes(nodes, detail::spline_of(s.styles[index]), packed); !st) {
        s.refuse(index, st.index, st.message);
        return false;
    }
    std::memcpy(dst, packed.nodes.data(), packed.nodes.size() * sizeof(glm::vec4));
    w.count = static_cast<uint32_t>(packed.nodes.size());
    w.unmerged = packed.nodes.size() == n;
    for (int a = 0; a < 3; ++a) w.origin[a] = static_cast<float>(packed.origin_m[a]);
    for (int a = 0; a < 3; ++a) w.centre[a] = static_cast<float>(packed.origin_m[a]);  // a float point
    w.has_centre = true;
    return true;
}

bool refuse_room(StreamState& s, uint32_t index, std::size_t count) {
    s.refuse(index, -1, s.active ? "no room for its " + std::to_string(count) + " nodes (begin() reserved " +
                                      std::to_string(s.node_capacity) + " for the frame)"
                                : "written outside a frame (call begin() first)");
    return false;
}

bool write_double(StreamState& s, uint32_t index, const double* xyz, std::size_t n, std::size_t stride,
                  const float* radius, std::size_t radius_stride, std::optional<std::size_t> first) {
    StreamState::Wire& w = s.wires[index];
    const StreamStyle& style = s.styles[index];
    if (!first) return refuse_room(s, index, n);
    auto* dst = reinterpret_cast<glm::vec4*>(s.region.data + s.node_at) + *first;
    const auto at = [&](std::size_t j) {
        const auto* p = reinterpret_cast<const double*>(reinterpret_cast<const char*>(xyz) + j * stride);
        return glm::dvec3(p[0], p[1], p[2]);
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
                const __m128d xy = _mm_loadu_pd(p), z = _mm_load_sd(p + 2);
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
    if (!detail::clears_merge(m, origin, n, style.closed)) {
        if (!second_look(s, index, n, at, radius, radius_stride, dst)) return false;
    } else {
        w.count = static_cast<uint32_t>(n);
        w.unmerged = true;
        for (int a = 0; a < 3; ++a) w.origin[a] = static_cast<float>(origin[a]);
        const glm::dvec3 centre = float_point(origin + 0.5 * (glm::dvec3(m.lo) + glm::dvec3(m.hi)));
        for (int a = 0; a < 3; ++a) w.centre[a] = static_cast<float>(centre[a]);
        w.has_centre = true;
    }
    w.node_first = static_cast<uint32_t>(*first);
    s.accepted(w, index);
    return true;
}

bool write_float(StreamState& s, uint32_t index, const glm::dvec3& given_origin, const float* xyz, std::size_t n,
                 std::size_t stride, const float* radius, std::size_t radius_stride, std::optional<std::size_t> first) {
    StreamState::Wire& w = s.wires[index];
    const StreamStyle& style = s.styles[index];
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
                const __m128 xy = _mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(p)));
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
    if (!detail::clears_merge(m, origin, n, style.closed)) {
        if (!second_look(s, index, n, at, radius, radius_stride, dst)) return false;
    } else {
        w.count = static_cast<uint32_t>(n);
        w.unmerged = true;
        for (int a = 0; a < 3; ++a) w.origin[a] = static_cast<float>(origin[a]);
    }
    w.node_first = static_cast<uint32_t>(*first);
    s.accepted(w, index);
    return true;
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

namespace detail {

void attach_stream(NodePath& path, NodeStream& stream) {
    StreamState& s = stream.state();
    s.path = &path;
    path.attach(&s);
}
void detach_stream(NodeStream& stream, const Status& why) {
    StreamState& s = stream.state();
    if (s.path != nullptr) s.path->attach(nullptr);
    s.path = nullptr;
    s.unusable = why;
}
bool stream_active(NodeStream& stream) { return stream.state().active; }
void end_stream_frame(NodeStream& stream) {
    StreamState& s = stream.state();
    if (!s.active) return;
    s.buffer.end();
    s.active = false;
}

std::size_t NodePath::emit_stream(std::size_t materials, std::size_t& segments_visible, DrawStats& stats) {
    StreamState& s = *stream_;
    stream_wires_.clear();
    stream_bytes_ = 0;
    const uint32_t frame = s.active ? s.frame : 0;  // 0: nothing written this frame
    const auto wire_count = static_cast<uint32_t>(s.wires.size());
    // What a wire does this frame: 0 nothing, 1 its written nodes go to the GPU, 2 it is listed (drawn from its
    // state on the GPU), 3 skipped (its material is out of range).
    const auto role = [&](const StreamState::Wire& w, uint32_t) -> int {
        if (!w.live) return 0;
        if (w.material >= materials) return 3;
        if (w.written == frame && frame != 0) return 1;
        return w.built ? 2 : 0;
    };
    // (1) Serially, the few written wires that need a slot or another segment count (GL calls, the allocator).
    for (uint32_t i : s.pending) {
        StreamState::Wire& w = s.wires[i];
        if (role(w, i) != 1) continue;
        if (w.slot == UINT32_MAX) {
            const std::optional<uint32_t> slot = acquire_slot();
            if (!slot) {
                w.written = 0;
                ++stats.wires_skipped;
                continue;
            }
            w.slot = *slot;
            w.built = false;
        }
        const uint32_t segments = s.styles[i].closed ? w.count : w.count - 1;
        if (segments == w.segments) continue;
        free_segments(w.segment_first, w.segments);
        w.segments = 0;
        uint32_t first = 0;
        if (!allocate_segments(segments, first)) {
            w.built = false, w.written = 0;
            ++stats.wires_skipped;
            continue;
        }
        w.segment_first = first, w.segments = segments;
        glClearNamedBufferSubData(slot_state_.id(), GL_R32UI, static_cast<GLintptr>(w.slot) * 32, 16, GL_RED_INTEGER,
                                  GL_UNSIGNED_INT, nullptr);  // the LOD starts afresh (SlotState::lod)
    }
    s.pending.clear();
    // (2) Per block of wires, in parallel: how many it sends and lists; then (3) each block writes its headers and
    // list entries at its offsets (prefix sums), so the order is the wires' whatever the threads.
    constexpr uint32_t kBlock = 4096;
    const uint32_t blocks = (wire_count + kBlock - 1) / kBlock;
    struct Block {
        std::size_t changed = 0, listed = 0, segments = 0, bytes = 0;
        uint32_t bad_material = UINT32_MAX;
        std::vector<uint8_t> used;
    };
    std::vector<Block> block(blocks);
    const auto over_blocks = [&](auto&& body) {
        if (wire_count >= 2 * kBlock) {
            tbb::parallel_for(uint32_t{0}, blocks, [&](uint32_t b) { body(b); });
        } else {
            for (uint32_t b = 0; b < blocks; ++b) body(b);
        }
    };
    over_blocks([&](uint32_t b) {
        Block& k = block[b];
        for (uint32_t i = b * kBlock; i < std::min(wire_count, (b + 1) * kBlock); ++i) {
            const int r = role(s.wires[i], i);
            k.changed += r == 1, k.listed += r == 2;
            if (r == 3 && k.bad_material == UINT32_MAX) k.bad_material = i;
        }
    });
    std::size_t changed = 0, listed = 0;
    std::vector<std::size_t> changed_at(blocks), listed_at(blocks);
    for (uint32_t b = 0; b < blocks; ++b) {
        changed_at[b] = changed, listed_at[b] = listed;
        changed += block[b].changed, listed += block[b].listed;
        if (block[b].bad_material != UINT32_MAX && stats.status.ok()) {
            const uint32_t i = block[b].bad_material;
            stats.status = Status::error("stream wire " + std::to_string(i) + ": material " +
                                         std::to_string(s.styles[i].material) + " is out of range (" +
                                         std::to_string(materials) + " materials): not drawn");
        }
    }
    const std::size_t visible_before = visible_slots_.size(), listed_before = listed_.size();
    visible_slots_.resize(visible_before + listed);
    listed_.resize(listed_before + listed);
    stream_wires_.resize(changed);
    auto* headers = s.active ? reinterpret_cast<GpuCurveHeader*>(s.region.data + s.header_at) : nullptr;
    over_blocks([&](uint32_t b) {
        Block& k = block[b];
        k.used.assign(materials, 0);
        std::size_t c = changed_at[b], l = listed_at[b];
        for (uint32_t i = b * kBlock; i < std::min(wire_count, (b + 1) * kBlock); ++i) {
            StreamState::Wire& w = s.wires[i];
            const int r = role(w, i);
            if (r == 0 || r == 3) continue;
            const StreamStyle& style = s.styles[i];
            const Dispatched d{NodeStream::wire_id(StreamWire{i}), w.slot, w.segment_first, w.segments};
            if (r == 1) {
                const uint32_t kind = style.kind == SplineKind::linear      ? kKindLinear
                                      : style.kind == SplineKind::c2        ? kKindC2
                                      : style.kind == SplineKind::automatic ? kKindAutomatic
                                                                            : kKindCatmullRom;
                const uint32_t sides = style.max_sides ? std::max<uint32_t>(style.max_sides, 3) : 16u;
                // The GPU fits the motion by index where the last upload had these nodes' count and neither merged.
                const bool fit = w.built && w.sent_count == w.count && w.sent_unmerged && w.unmerged;
                GpuCurveHeader h;
                h.node_first = w.node_first;
                h.node_count = w.count;
                h.segment_first = w.segment_first;
                h.flags = (style.closed ? kHeaderClosed : 0u) | (kind << kHeaderKindShift) |
                          (style.caps ? kHeaderCaps : 0u) | (fit ? kHeaderFitMotion : 0u) |
                          (std::min<uint32_t>(sides, 255u) << 8) | (style.material << kHeaderMaterialShift);
                h.alpha = static_cast<float>(style.alpha), h.tension = static_cast<float>(style.tension);
                h.bias = static_cast<float>(style.bias), h.continuity = static_cast<float>(style.continuity);
                h.slot = w.slot;
                std::memcpy(h.origin_m, w.origin, sizeof h.origin_m);
                std::memcpy(headers + c, &h, sizeof h);  // mapped memory: written once, never read
                w.built = true;
                w.sent_count = w.count;
                w.sent_unmerged = w.unmerged;
                stream_wires_[c++] = d;
                k.bytes += sizeof(GpuCurveHeader) + std::size_t{w.count} * sizeof(glm::vec4);
            } else {
                visible_slots_[visible_before + l] = w.slot;
                listed_[listed_before + l] = d;
                ++l;
            }
            k.segments += w.segments;
            k.used[style.material] = 1;
        }
    });
    for (const Block& k : block) {
        segments_visible += k.segments;
        stream_bytes_ += k.bytes;
        for (std::size_t m = 0; m < k.used.size(); ++m) material_used_[m] |= k.used[m];
    }
    s.headers = changed;
    return changed;
}

NodePath::StreamLayout NodePath::stream_layout() const {
    const StreamState& s = *stream_;
    StreamLayout l;
    l.buffer = s.region.buffer;
    l.header_at = s.region.offset_bytes + s.header_at;
    l.header_bytes = std::max<std::size_t>(s.headers, 1) * sizeof(GpuCurveHeader);
    l.node_at = s.region.offset_bytes + s.node_at;
    l.node_bytes = std::max<std::size_t>(std::min(s.cursor.load(), s.node_capacity), 1) * sizeof(glm::vec4);
    return l;
}

std::size_t NodePath::stream_nodes() const { return std::min(stream_->cursor.load(), stream_->node_capacity); }
std::size_t NodePath::stream_wires() const { return stream_->wires.size(); }

void NodePath::unbuild_stream() {
    StreamState& s = *stream_;
    for (const Dispatched& d : stream_wires_) s.wires[static_cast<uint32_t>(d.wire_id)].built = false;
}

}  // namespace detail
}  // namespace wire::render
