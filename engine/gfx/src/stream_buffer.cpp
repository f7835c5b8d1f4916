// StreamBuffer: glBufferStorage(MAP_WRITE | MAP_PERSISTENT | MAP_COHERENT), mapped once; glFenceSync per
// region.
#include "engine/gfx/stream_buffer.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <utility>

namespace engine::gfx {

namespace {
constexpr GLbitfield kMapFlags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
constexpr GLuint64 kWaitStepNs = 1'000'000'000;  // 1 s per wait call; we loop until signalled or failed

std::size_t round_up(std::size_t v, std::size_t a) {
    return (v + a - 1) / a * a;
}

/// True when the fence has signalled (a null fence has nothing pending).
bool signalled(GLsync fence) {
    if (fence == nullptr) return true;
    // With the flush bit: a fence never flushed may never report signalled to a poll on some drivers.
    const GLenum r = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 0);
    return r == GL_ALREADY_SIGNALED || r == GL_CONDITION_SATISFIED;
}

/// Blocks until the fence signals; returns true if it had to wait.
bool wait(GLsync fence) {
    if (fence == nullptr) return false;
    GLenum r = glClientWaitSync(fence, 0, 0);
    if (r == GL_ALREADY_SIGNALED || r == GL_CONDITION_SATISFIED) return false;
    do {
        r = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, kWaitStepNs);
    } while (r == GL_TIMEOUT_EXPIRED);
    return true;
}
}  // namespace

struct StreamBuffer::State {
    struct Retired {
        Buffer buffer;
        GLsync fence = nullptr;  ///< placed after the buffer's last use
    };
    StreamBufferDesc desc;
    Buffer buffer;
    std::byte* mapped = nullptr;
    std::size_t region_bytes = 0;
    std::vector<GLsync> fences;  ///< one per region, null when the region has no pending GPU work
    uint32_t next = 0;           ///< region the next begin() returns
    uint32_t current = 0;        ///< region of the last begin()
    bool open = false;
    std::vector<Retired> retired;
    std::vector<unsigned> allocated;

    ~State() {
        for (GLsync f : fences) {
            if (f != nullptr) glDeleteSync(f);
        }
        for (Retired& r : retired) {
            if (r.fence != nullptr) glDeleteSync(r.fence);
        }
        if (buffer) glUnmapNamedBuffer(buffer.id());
    }

    Status allocate(std::size_t new_region_bytes) {
        const std::size_t total = new_region_bytes * desc.regions;
        Expected<Buffer> made =
            make_buffer({.size_bytes = total, .storage_flags = kMapFlags, .label = desc.label});
        if (!made) return made.error();
        auto* ptr = static_cast<std::byte*>(
            glMapNamedBufferRange(made->id(), 0, static_cast<GLsizeiptr>(total), kMapFlags));
        if (ptr == nullptr) {
            return Error{"stream buffer '" + desc.label + "': mapping " + std::to_string(total) +
                         " bytes failed"};
        }
        if (buffer) {
            // Retire the old buffer: one fence after everything issued so far covers all its regions.
            glUnmapNamedBuffer(buffer.id());
            retired.push_back({std::move(buffer), glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0)});
            for (GLsync& f : fences) {
                if (f != nullptr) glDeleteSync(f);
                f = nullptr;
            }
        }
        allocated.push_back(made->id());
        buffer = std::move(made).value();
        mapped = ptr;
        region_bytes = new_region_bytes;
        return {};
    }

    void collect_retired() {
        std::erase_if(retired, [](Retired& r) {
            if (!signalled(r.fence)) return false;
            glDeleteSync(r.fence);
            return true;  // the Buffer's destructor deletes the GL buffer
        });
    }
};

StreamBuffer::StreamBuffer() = default;
StreamBuffer::StreamBuffer(StreamBuffer&&) noexcept = default;
StreamBuffer& StreamBuffer::operator=(StreamBuffer&&) noexcept = default;
StreamBuffer::~StreamBuffer() = default;

Expected<StreamBuffer> StreamBuffer::create(const StreamBufferDesc& desc) {
    StreamBuffer sb;
    sb.state_ = std::make_unique<State>();
    State& s = *sb.state_;
    s.desc = desc;
    if (s.desc.regions == 0) s.desc.regions = 3;
    if (s.desc.region_bytes == 0) s.desc.region_bytes = std::size_t{1} << 20;
    if (!(s.desc.growth > 1.0f)) s.desc.growth = 2.0f;
    if (s.desc.alignment == 0) s.desc.alignment = 256;
    if (s.desc.label.empty()) s.desc.label = "stream buffer";
    s.fences.assign(s.desc.regions, nullptr);
    if (Status st = s.allocate(round_up(s.desc.region_bytes, s.desc.alignment)); !st)
        return st;
    return sb;
}

Expected<StreamRegion> StreamBuffer::begin(std::size_t bytes) {
    assert(state_ && "StreamBuffer used after move");
    State& s = *state_;
    assert(!s.open && "StreamBuffer::begin twice without end");
    s.collect_retired();
    StreamRegion region;
    if (bytes > s.region_bytes) {
        const auto grown =
            static_cast<std::size_t>(std::ceil(static_cast<double>(s.region_bytes) * s.desc.growth));
        const std::size_t size = round_up(std::max(bytes, grown), s.desc.alignment);
        if (Status st = s.allocate(size); !st) return st;
        region.grew = true;
    }
    const uint32_t r = s.next;
    region.waited = wait(s.fences[r]);
    if (s.fences[r] != nullptr) {
        glDeleteSync(s.fences[r]);
        s.fences[r] = nullptr;
    }
    s.current = r;
    s.next = (r + 1) % s.desc.regions;
    s.open = true;
    region.offset_bytes = std::size_t{r} * s.region_bytes;
    region.data = s.mapped + region.offset_bytes;
    region.size_bytes = s.region_bytes;
    region.buffer = s.buffer.id();
    return region;
}

void StreamBuffer::end() {
    assert(state_ && state_->open && "StreamBuffer::end without begin");
    State& s = *state_;
    s.fences[s.current] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    s.open = false;
}

std::size_t StreamBuffer::region_bytes() const {
    return state_ ? state_->region_bytes : 0;
}
uint32_t StreamBuffer::regions() const {
    return state_ ? state_->desc.regions : 0;
}
std::size_t StreamBuffer::live_buffers() const {
    return state_ ? 1 + state_->retired.size() : 0;
}
const std::vector<unsigned>& StreamBuffer::allocated_buffers() const {
    static const std::vector<unsigned> none;
    return state_ ? state_->allocated : none;
}

}  // namespace engine::gfx
