// Ring packing, draw counts and the residency bookkeeping of the wire renderer (no GL).
#include "wire/render/upload_plan.hpp"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace wire::render {
namespace {

constexpr uint32_t kFixedMax = (1u << 20) - 1;
constexpr double kInvSqrt2 = 0.70710678118654752440;

uint32_t encode(double v) {
    const double k = std::round((v / kInvSqrt2 * 0.5 + 0.5) * kFixedMax);
    return static_cast<uint32_t>(std::clamp(k, 0.0, static_cast<double>(kFixedMax)));
}

float decode(uint32_t k) {
    return (static_cast<float>(k) / static_cast<float>(kFixedMax) * 2.0f - 1.0f) * 0.70710678f;
}

}  // namespace

PackedRing pack_ring(const Ring& ring) {
    PackedRing p{};
    p.centre_m[0] = ring.centre_m.x;
    p.centre_m[1] = ring.centre_m.y;
    p.centre_m[2] = ring.centre_m.z;
    p.radius_m = ring.radius_m;
    p.u = ring.u;
    // Rotation matrix with columns r, s, t -> quaternion (x, y, z, w), branch on the largest diagonal term.
    const glm::dvec3 r(ring.normal), s(ring.binormal);
    const glm::dvec3 t = glm::cross(r, s);
    const double m00 = r.x, m10 = r.y, m20 = r.z, m01 = s.x, m11 = s.y, m21 = s.z, m02 = t.x, m12 = t.y,
                 m22 = t.z;
    double q[4];  // x, y, z, w
    const double trace = m00 + m11 + m22;
    if (trace > 0.0) {
        const double k = 2.0 * std::sqrt(trace + 1.0);
        q[3] = 0.25 * k, q[0] = (m21 - m12) / k, q[1] = (m02 - m20) / k, q[2] = (m10 - m01) / k;
    } else if (m00 > m11 && m00 > m22) {
        const double k = 2.0 * std::sqrt(std::max(1e-300, 1.0 + m00 - m11 - m22));
        q[3] = (m21 - m12) / k, q[0] = 0.25 * k, q[1] = (m01 + m10) / k, q[2] = (m02 + m20) / k;
    } else if (m11 > m22) {
        const double k = 2.0 * std::sqrt(std::max(1e-300, 1.0 + m11 - m00 - m22));
        q[3] = (m02 - m20) / k, q[0] = (m01 + m10) / k, q[1] = 0.25 * k, q[2] = (m12 + m21) / k;
    } else {
        const double k = 2.0 * std::sqrt(std::max(1e-300, 1.0 + m22 - m00 - m11));
        q[3] = (m10 - m01) / k, q[0] = (m02 + m20) / k, q[1] = (m12 + m21) / k, q[2] = 0.25 * k;
    }
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    int largest = 0;
    for (int i = 0; i < 4; ++i) {
        q[i] /= norm;
        if (std::abs(q[i]) > std::abs(q[largest])) largest = i;
    }
    const double sign = q[largest] < 0.0 ? -1.0 : 1.0;
    uint64_t bits = static_cast<uint64_t>(largest);
    int shift = 2;
    for (int i = 0; i < 4; ++i) {
        if (i == largest) continue;
        bits |= static_cast<uint64_t>(encode(sign * q[i])) << shift;
        shift += 20;
    }
    p.frame[0] = static_cast<uint32_t>(bits);
    p.frame[1] = static_cast<uint32_t>(bits >> 32);
    return p;
}

void pack_rings(std::span<const Ring> rings, PackedRing* out) {
    for (std::size_t i = 0; i < rings.size(); ++i) out[i] = pack_ring(rings[i]);
}

DecodedFrame unpack_frame(const PackedRing& ring) {
    // Mirrors ring_frame() in shaders.cpp, in float.
    const uint32_t w0 = ring.frame[0], w1 = ring.frame[1];
    const uint32_t largest = w0 & 3u;
    const uint32_t k[3] = {(w0 >> 2) & kFixedMax, ((w0 >> 22) | (w1 << 10)) & kFixedMax, (w1 >> 10) & kFixedMax};
    float q[4];
    float sum = 0.0f;
    for (uint32_t i = 0, j = 0; i < 4; ++i) {
        if (i == largest) continue;
        q[i] = decode(k[j++]);
        sum += q[i] * q[i];
    }
    q[largest] = std::sqrt(std::max(0.0f, 1.0f - sum));
    const float x = q[0], y = q[1], z = q[2], w = q[3];
    DecodedFrame f;
    f.normal = {1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y + w * z), 2.0f * (x * z - w * y)};
    f.binormal = {2.0f * (x * y - w * z), 1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z + w * x)};
    f.tangent = {2.0f * (x * z + w * y), 2.0f * (y * z - w * x), 1.0f - 2.0f * (x * x + y * y)};
    return f;
}

uint32_t band_count(const DrawItem& item) {
    const auto rings = static_cast<uint32_t>(item.rings.size());
    if (rings == 0) return 0;
    return rings - 1 + (item.closed ? 1u : 0u);
}

bool has_geometry(const DrawItem& item, UploadPath path) {
    if (path == UploadPath::cpu_mesh) return !item.vertices.empty() && !item.indices.empty();
    if (item.rings.empty()) return false;
    if (item.sides <= 2) return band_count(item) > 0;  // strips and lines have no caps
    return band_count(item) > 0 || (!item.closed && item.caps);
}

std::array<uint32_t, kChunkKinds> chunk_counts(const DrawItem& item) {
    std::array<uint32_t, kChunkKinds> counts{};
    if (!has_geometry(item, UploadPath::gpu_rings)) return counts;
    counts[0] = item.sides > 2 && !item.closed && item.caps ? 1u : 0u;
    const uint32_t bands = band_count(item);
    counts[1] = bands / kChunkBands;
    for (uint32_t kind = 2; kind < kChunkKinds; ++kind)
        counts[kind] = (bands & chunk_kind_bands(kind)) != 0 ? 1u : 0u;  // the remainder's binary digits
    return counts;
}

uint32_t chunk_count(const DrawItem& item) {
    const std::array<uint32_t, kChunkKinds> counts = chunk_counts(item);
    uint32_t sum = 0;
    for (uint32_t c : counts) sum += c;
    return sum;
}

namespace {

std::size_t count_commands(std::span<const DrawItem> items, UploadPath path) {
    // Keys of the runs the renderer draws: (blended, material) on cpu-mesh, plus (side count, kind) on gpu-rings.
    std::vector<uint64_t> keys;
    for (const DrawItem& item : items) {
        if (!has_geometry(item, path)) continue;
        const uint64_t run = (item.sides == 1 ? uint64_t{1} << 63 : 0u) | (uint64_t{item.material} << 32);
        if (path == UploadPath::cpu_mesh) {
            keys.push_back(run);
            continue;
        }
        const std::array<uint32_t, kChunkKinds> counts = chunk_counts(item);
        for (uint32_t kind = 0; kind < kChunkKinds; ++kind)
            if (counts[kind] != 0) keys.push_back(run | (uint64_t{item.sides} << 8) | kind);
    }
    std::sort(keys.begin(), keys.end());
    return static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

}  // namespace

std::size_t draw_commands(const DrawList& list) {
    return count_commands(list.items, list.path);
}

uint32_t expanded_vertices(const DrawItem& item) {
    if (!has_geometry(item, UploadPath::gpu_rings)) return 0;
    const uint32_t rows = static_cast<uint32_t>(item.rings.size()) + (item.closed ? 1u : 0u);
    if (item.sides <= 2) return rows * 2;  // wire::strip_counts
    const uint32_t caps = !item.closed && item.caps ? 2u : 0u;
    return (rows + caps) * (item.sides + 1);
}

uint32_t expanded_triangles(const DrawItem& item) {
    if (!has_geometry(item, UploadPath::gpu_rings)) return 0;
    if (item.sides <= 2) return band_count(item) * 2;
    const uint32_t caps = !item.closed && item.caps ? 2u : 0u;
    return (band_count(item) * 2 + caps) * item.sides;
}

std::size_t streamed_upload_bytes(const DrawList& list) {
    std::size_t bytes = draw_commands(list) * kCommandBytes;
    for (const DrawItem& item : list.items) {
        if (!has_geometry(item, list.path)) continue;
        if (list.path == UploadPath::cpu_mesh) {
            bytes += kDrawRecordBytes + item.vertices.size() * (sizeof(TubeVertex) + kVertexDrawIndexBytes) +
                     item.indices.size_bytes();
        } else {
            bytes += kDrawRecordBytes + chunk_count(item) * kChunkRecordBytes + item.rings.size() * sizeof(PackedRing);
        }
    }
    return bytes;
}

RingResidency::Touch RingResidency::touch(const DrawItem& item) {
    Touch t;
    auto [it, inserted] = entries_.try_emplace(item.wire_id);
    Residency& e = it->second;
    if (!inserted && (item.rings_generation == 0 || e.generation != item.rings_generation)) t.replaced = e;
    t.upload = inserted || t.replaced.has_value();
    if (t.upload) {
        e = Residency{};
        e.wire_id = item.wire_id;
        e.generation = item.rings_generation;
        e.rings = static_cast<uint32_t>(item.rings.size());
    }
    e.last_frame = frame_;
    t.entry = &e;
    return t;
}

std::vector<Residency> RingResidency::evict() {
    std::vector<Residency> out;
    for (auto it = entries_.begin(); it != entries_.end();) {
        if (frame_ - it->second.last_frame > retain_frames_) {
            out.push_back(it->second);
            it = entries_.erase(it);
        } else {
            ++it;
        }
    }
    // Deterministic order for the caller (the map's order is not).
    std::sort(out.begin(), out.end(), [](const Residency& a, const Residency& b) { return a.wire_id < b.wire_id; });
    return out;
}

const Residency* RingResidency::find(uint64_t wire_id) const {
    const auto it = entries_.find(wire_id);
    return it == entries_.end() ? nullptr : &it->second;
}

RetainedFrame plan_retained_frame(const DrawList& list, RingResidency& residency) {
    RetainedFrame f;
    residency.begin_frame();
    f.bytes = count_commands(list.items, UploadPath::gpu_rings) * kCommandBytes;
    for (const DrawItem& item : list.items) {
        if (!has_geometry(item, UploadPath::gpu_rings)) continue;
        f.bytes += kDrawRecordBytes + chunk_count(item) * kChunkRecordBytes;
        if (residency.touch(item).upload) {
            f.ring_bytes += item.rings.size() * sizeof(PackedRing);
            ++f.wires_uploaded;
        }
    }
    f.wires_evicted = residency.evict().size();
    f.bytes += f.ring_bytes;
    return f;
}

}  // namespace wire::render
