// Offsets into one large buffer, handed out and taken back: a best-fit free list with coalescing. Plain CPU
// bookkeeping (no GL), so it is tested on its own; engine::gfx::RetainedBuffer puts a GL buffer and fences
// around it.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <set>
#include <utility>

namespace engine::gfx {

class RangeAllocator {
public:
    /// `capacity` bytes, handed out in multiples of `alignment` (> 0) at offsets that are multiples of it.
    explicit RangeAllocator(std::size_t capacity = 0, std::size_t alignment = 16);

    /// The offset of `bytes` (rounded up to the alignment; 0 bytes take one alignment unit), or nullopt when no
    /// free range is large enough (then grow() and try again). Best fit: the smallest free range that holds it,
    /// lowest offset among equals, so the result is deterministic.
    [[nodiscard]] std::optional<std::size_t> allocate(std::size_t bytes);
    /// Returns a range from allocate() (offset and the same `bytes`); merges it with free neighbours. Freeing a
    /// range that is not allocated is a bug (asserted).
    void free(std::size_t offset, std::size_t bytes);
    /// Adds [capacity(), new_capacity) to the free space (merged with a free range ending at the old end).
    void grow(std::size_t new_capacity);

    [[nodiscard]] std::size_t capacity() const { return capacity_; }
    [[nodiscard]] std::size_t alignment() const { return alignment_; }
    [[nodiscard]] std::size_t used_bytes() const { return used_; }
    [[nodiscard]] std::size_t free_bytes() const { return capacity_ - used_; }
    [[nodiscard]] std::size_t free_ranges() const { return by_offset_.size(); }
    [[nodiscard]] std::size_t largest_free() const;
    /// `bytes` as allocate() rounds it.
    [[nodiscard]] std::size_t rounded(std::size_t bytes) const;
    /// Free ranges as (offset, size), in offset order (tests check they never overlap and are coalesced).
    [[nodiscard]] const std::map<std::size_t, std::size_t>& free_list() const { return by_offset_; }

private:
    void insert_free(std::size_t offset, std::size_t size);
    void erase_free(std::map<std::size_t, std::size_t>::iterator it);

    std::size_t capacity_ = 0;
    std::size_t alignment_ = 16;
    std::size_t used_ = 0;
    std::map<std::size_t, std::size_t> by_offset_;         ///< free ranges: offset -> size
    std::set<std::pair<std::size_t, std::size_t>> by_size_;  ///< free ranges: (size, offset)
};

}  // namespace engine::gfx
