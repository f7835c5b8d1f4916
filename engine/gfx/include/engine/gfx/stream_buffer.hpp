// A persistently mapped GL buffer split into regions for the frames in flight, each guarded by a fence: the
// CPU writes a frame's data with memcpy into the region the GPU finished with. Grows without stalling the
// frame. Generic GL (the wire renderer streams its per-frame draw records through it).
#pragma once

#include "engine/gfx/resources.hpp"
#include "engine/core/expected.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace engine::gfx {

using engine::Error;
using engine::Expected;

/// Zero means default.
struct StreamBufferDesc {
    uint32_t regions = 0;          ///< frames in flight; 0 -> 3
    std::size_t region_bytes = 0;  ///< initial capacity of one region; 0 -> 1 MiB
    float growth = 0.0f;           ///< a region that is too small grows to max(needed, growth * size); 0 -> 2
    std::size_t alignment =
        0;                ///< region sizes are multiples of this; 0 -> 256 (>= any SSBO offset alignment)
    std::string label{};  ///< GL object label
};

/// One frame's slice of the buffer, mapped for writing (write only: the memory may be uncached).
struct StreamRegion {
    std::byte* data = nullptr;     ///< mapped pointer to the region's first byte
    std::size_t offset_bytes = 0;  ///< of the region inside the GL buffer (for binding ranges, draw offsets)
    std::size_t size_bytes = 0;
    unsigned buffer = 0;  ///< GL name of the buffer holding the region
    bool grew = false;    ///< this call allocated a bigger buffer
    bool waited = false;  ///< this call had to wait for the GPU (the region's fence was not signalled)
};

class StreamBuffer {
public:
    /// Allocates and maps regions * region_bytes. Needs a current GL 4.5 context. Errors name the label.
    static Expected<StreamBuffer> create(const StreamBufferDesc& desc = {});

    StreamBuffer();
    StreamBuffer(StreamBuffer&&) noexcept;
    StreamBuffer& operator=(StreamBuffer&&) noexcept;
    ~StreamBuffer();

    /// The next region, holding at least `bytes`. Waits on the region's fence only if the GPU still reads it
    /// (frames_in_flight frames ago). If `bytes` exceeds the region size, a bigger buffer is allocated and
    /// the old one is retired: kept alive until a fence placed after its last use signals, then deleted
    /// (checked at every begin()). Errors: the allocation or the mapping failed (the old buffer stays
    /// usable).
    Expected<StreamRegion> begin(std::size_t bytes);
    /// Fences the region returned by the last begin(): call after the draws that read it are issued.
    void end();

    [[nodiscard]] std::size_t region_bytes() const;
    [[nodiscard]] uint32_t regions() const;
    /// GL buffers alive: the current one plus the retired ones whose fences have not signalled yet.
    [[nodiscard]] std::size_t live_buffers() const;
    /// GL names of every buffer this object ever allocated (tests check the retired ones were deleted).
    [[nodiscard]] const std::vector<unsigned>& allocated_buffers() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace engine::gfx
