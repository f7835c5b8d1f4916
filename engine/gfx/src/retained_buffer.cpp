// RetainedBuffer: RangeAllocator over a glBufferStorage(MAP_WRITE | MAP_PERSISTENT | MAP_COHERENT) buffer;
// freed ranges wait in fenced batches; growth copies the live ranges on the GPU.
#include "engine/gfx/retained_buffer.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <deque>
#include <map>
#include <utility>

namespace engine::gfx {
namespace {
constexpr GLbitfield kMapFlags = GL_MAP_WRITE_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;

bool signalled(GLsync fence) {
    if (fence == nullptr) return true;
    // With the flush bit: a fence never flushed may never report signalled to a poll on some drivers.
    const GLenum r = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 0);
    return r == GL_ALREADY_SIGNALED || r == GL_CONDITION_SATISFIED;
}
}  // namespace

struct RetainedBuffer::State {
    struct Freed {
        std::size_t offset, size;
    };
    struct Batch {
        GLsync fence = nullptr;
        std::vector<Freed> ranges;
    };
    struct Retired {
        Buffer buffer;
        GLsync fence = nullptr;
    };
    RetainedBufferDesc desc;
    Buffer buffer;
    std::byte* mapped = nullptr;
    RangeAllocator allocator;
    std::map<std::size_t, std::size_t> live;  ///< offset -> rounded size (for the copy on growth)
    std::vector<Freed> freed_this_frame;
    std::deque<Batch> batches;  ///< oldest first
    std::size_t pending = 0;
    std::vector<Retired> retired;
    std::vector<unsigned> allocated;

    ~State() {
        for (Batch& b : batches)
            if (b.fence != nullptr) glDeleteSync(b.fence);
        for (Retired& r : retired)
            if (r.fence != nullptr) glDeleteSync(r.fence);
        if (buffer) glUnmapNamedBuffer(buffer.id());
    }

    Status reallocate(std::size_t bytes) {
        Expected<Buffer> made =
            make_buffer({.size_bytes = bytes, .storage_flags = kMapFlags, .label = desc.label});
        if (!made) return made.error();
        auto* ptr = static_cast<std::byte*>(
            glMapNamedBufferRange(made->id(), 0, static_cast<GLsizeiptr>(bytes), kMapFlags));
        if (ptr == nullptr) {
            return Error{"retained buffer '" + desc.label + "': mapping " + std::to_string(bytes) +
                         " bytes failed"};
        }
        if (buffer) {
            // Copy the live ranges (runs of adjacent ones in one call) at the same offsets. Only live ranges:
            // a freed range may be reallocated and written by the CPU in the new buffer this very frame.
            for (auto it = live.begin(); it != live.end();) {
                const std::size_t first = it->first;
                std::size_t end = it->first + it->second;
                for (++it; it != live.end() && it->first == end; ++it) end += it->second;
                glCopyNamedBufferSubData(buffer.id(), made->id(), static_cast<GLintptr>(first),
                                         static_cast<GLintptr>(first), static_cast<GLsizeiptr>(end - first));
            }
            glUnmapNamedBuffer(buffer.id());
            retired.push_back({std::move(buffer), glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0)});
        }
        allocated.push_back(made->id());
        buffer = std::move(made).value();
        mapped = ptr;
        allocator.grow(bytes);
        return {};
    }
};

RetainedBuffer::RetainedBuffer() = default;
RetainedBuffer::RetainedBuffer(RetainedBuffer&&) noexcept = default;
RetainedBuffer& RetainedBuffer::operator=(RetainedBuffer&&) noexcept = default;
RetainedBuffer::~RetainedBuffer() = default;

Expected<RetainedBuffer> RetainedBuffer::create(const RetainedBufferDesc& desc) {
    RetainedBuffer rb;
    rb.state_ = std::make_unique<State>();
    State& s = *rb.state_;
    s.desc = desc;
    if (s.desc.initial_bytes == 0) s.desc.initial_bytes = std::size_t{1} << 20;
    if (!(s.desc.growth > 1.0f)) s.desc.growth = 2.0f;
    if (s.desc.alignment == 0) s.desc.alignment = 16;
    if (s.desc.label.empty()) s.desc.label = "retained buffer";
    s.allocator = RangeAllocator(0, s.desc.alignment);
    const std::size_t initial = s.allocator.rounded(s.desc.initial_bytes);
    if (Status st = s.reallocate(initial); !st) return st;
    return rb;
}

void RetainedBuffer::begin_frame() {
    State& s = *state_;
    while (!s.batches.empty() && signalled(s.batches.front().fence)) {
        State::Batch& b = s.batches.front();
        if (b.fence != nullptr) glDeleteSync(b.fence);
        for (const State::Freed& f : b.ranges) {
            s.allocator.free(f.offset, f.size);
            s.pending -= s.allocator.rounded(f.size);
        }
        s.batches.pop_front();
    }
    std::erase_if(s.retired, [](State::Retired& r) {
        if (!signalled(r.fence)) return false;
        glDeleteSync(r.fence);
        return true;  // Buffer's destructor deletes the GL buffer
    });
}

Expected<RetainedRange> RetainedBuffer::allocate(std::size_t bytes) {
    State& s = *state_;
    RetainedRange range;
    std::optional<std::size_t> offset = s.allocator.allocate(bytes);
    if (!offset) {
        const std::size_t cap = s.allocator.capacity();
        const auto grown = static_cast<std::size_t>(std::ceil(static_cast<double>(cap) * s.desc.growth));
        // Enough for the request even if the free space at the end is not usable.
        const std::size_t size = s.allocator.rounded(std::max(grown, cap + s.allocator.rounded(bytes)));
        if (Status st = s.reallocate(size); !st) return st;
        offset = s.allocator.allocate(bytes);
        assert(offset && "grown buffer must hold the request");
        range.grew = true;
    }
    s.live.emplace(*offset, s.allocator.rounded(bytes));
    range.offset_bytes = *offset;
    range.size_bytes = bytes;
    range.data = s.mapped + *offset;
    return range;
}

void RetainedBuffer::free(const RetainedRange& range) {
    State& s = *state_;
    [[maybe_unused]] const std::size_t erased = s.live.erase(range.offset_bytes);
    assert(erased == 1 && "RetainedBuffer::free of a range that is not live");
    s.freed_this_frame.push_back({range.offset_bytes, range.size_bytes});
    s.pending += s.allocator.rounded(range.size_bytes);
}

void RetainedBuffer::end_frame() {
    State& s = *state_;
    if (s.freed_this_frame.empty()) return;
    s.batches.push_back({glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0), std::move(s.freed_this_frame)});
    s.freed_this_frame.clear();
}

std::byte* RetainedBuffer::data(std::size_t offset_bytes) const {
    return state_->mapped + offset_bytes;
}
unsigned RetainedBuffer::buffer() const {
    return state_ ? state_->buffer.id() : 0;
}
std::size_t RetainedBuffer::capacity_bytes() const {
    return state_ ? state_->allocator.capacity() : 0;
}
std::size_t RetainedBuffer::live_bytes() const {
    return state_ ? state_->allocator.used_bytes() - state_->pending : 0;
}
std::size_t RetainedBuffer::pending_bytes() const {
    return state_ ? state_->pending : 0;
}
std::size_t RetainedBuffer::live_buffers() const {
    return state_ ? 1 + state_->retired.size() : 0;
}
const std::vector<unsigned>& RetainedBuffer::allocated_buffers() const {
    static const std::vector<unsigned> none;
    return state_ ? state_->allocated : none;
}
const RangeAllocator& RetainedBuffer::allocator() const {
    return state_->allocator;
}

}  // namespace engine::gfx
