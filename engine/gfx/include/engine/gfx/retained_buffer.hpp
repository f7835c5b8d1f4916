// Long-lived ranges in one persistently mapped GL buffer: data that stays valid across frames (a wire's ring
// records) is written once into its range and read by many frames' draws. A range that is freed goes back to
// the allocator only after a fence placed at the end of the frame that freed it has signalled, so the GPU never
// reads a range the CPU is overwriting. When no free range is large enough the buffer grows without a stall:
// a bigger buffer is made, the live ranges are copied into it on the GPU (glCopyNamedBufferSubData, same
// offsets), and the old one is retired until a fence after its last use signals.
//
//   auto buf = engine::gfx::RetainedBuffer::create({.initial_bytes = 1 << 20, .label = "rings"});
//   buf->begin_frame();                               // releases ranges whose fences signalled
//   Expected<RetainedRange> r = buf->allocate(bytes);  // write r->data with memcpy, once
//   ... draw, binding buf->buffer() ...
//   buf->free(*r);                                     // when the data is no longer wanted
//   buf->end_frame();                                  // fences this frame's frees
#pragma once

#include "engine/gfx/range_allocator.hpp"
#include "engine/gfx/resources.hpp"
#include "engine/core/expected.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace engine::gfx {

/// Zero means default.
struct RetainedBufferDesc {
    std::size_t initial_bytes = 0;  ///< 0 -> 1 MiB
    float growth = 0.0f;            ///< a full buffer grows to max(needed, growth * size); 0 -> 2
    std::size_t alignment = 0;      ///< range offsets and sizes are multiples of this; 0 -> 16
    std::string label{};            ///< GL object label
};

/// One allocation. `data` points into the mapped buffer (write only: the memory may be uncached) and is valid
/// until the next allocate() (which may grow the buffer and move the mapping); `offset_bytes` stays valid until
/// the range is freed.
struct RetainedRange {
    std::size_t offset_bytes = 0;
    std::size_t size_bytes = 0;  ///< as requested
    std::byte* data = nullptr;
    bool grew = false;  ///< this allocation grew the buffer
};

class RetainedBuffer {
public:
    static Expected<RetainedBuffer> create(const RetainedBufferDesc& desc = {});

    RetainedBuffer();
    RetainedBuffer(RetainedBuffer&&) noexcept;
    RetainedBuffer& operator=(RetainedBuffer&&) noexcept;
    ~RetainedBuffer();

    /// Releases the ranges and retired buffers whose fences have signalled (never waits).
    void begin_frame();
    /// A range of `bytes`; grows the buffer when needed. Errors: the allocation or mapping of a bigger buffer
    /// failed (the old buffer and its ranges stay usable).
    Expected<RetainedRange> allocate(std::size_t bytes);
    /// Gives a range back; it is reused only after the fence of the frame that freed it has signalled.
    void free(const RetainedRange& range);
    /// Places the fence guarding the ranges freed since the last end_frame() (none if nothing was freed).
    void end_frame();

    /// Pointer to `offset_bytes` in the current mapping (write only).
    [[nodiscard]] std::byte* data(std::size_t offset_bytes) const;
    /// GL name of the current buffer (bind it for draws; it changes when the buffer grows).
    [[nodiscard]] unsigned buffer() const;
    [[nodiscard]] std::size_t capacity_bytes() const;
    /// Bytes in live ranges (allocated and not freed).
    [[nodiscard]] std::size_t live_bytes() const;
    /// Bytes freed whose fences have not signalled yet.
    [[nodiscard]] std::size_t pending_bytes() const;
    /// GL buffers alive: the current one plus retired ones waiting for their fences.
    [[nodiscard]] std::size_t live_buffers() const;
    /// GL names of every buffer this object allocated (tests check the retired ones were deleted).
    [[nodiscard]] const std::vector<unsigned>& allocated_buffers() const;
    [[nodiscard]] const RangeAllocator& allocator() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace engine::gfx
