// RangeAllocator: two indexes over the free ranges (by offset for coalescing, by size for best fit).
#include "engine/gfx/range_allocator.hpp"

#include <algorithm>
#include <cassert>

namespace engine::gfx {

RangeAllocator::RangeAllocator(std::size_t capacity, std::size_t alignment)
    : alignment_(alignment > 0 ? alignment : 1) {
    grow(capacity / alignment_ * alignment_);
}

std::size_t RangeAllocator::rounded(std::size_t bytes) const {
    return std::max<std::size_t>(1, (bytes + alignment_ - 1) / alignment_) * alignment_;
}

std::size_t RangeAllocator::largest_free() const {
    return by_size_.empty() ? 0 : by_size_.rbegin()->first;
}

void RangeAllocator::insert_free(std::size_t offset, std::size_t size) {
    by_offset_.emplace(offset, size);
    by_size_.emplace(size, offset);
}

void RangeAllocator::erase_free(std::map<std::size_t, std::size_t>::iterator it) {
    by_size_.erase({it->second, it->first});
    by_offset_.erase(it);
}

std::optional<std::size_t> RangeAllocator::allocate(std::size_t bytes) {
    const std::size_t size = rounded(bytes);
    const auto fit = by_size_.lower_bound({size, 0});
    if (fit == by_size_.end()) return std::nullopt;
    const auto [free_size, offset] = *fit;
    erase_free(by_offset_.find(offset));
    if (free_size > size) insert_free(offset + size, free_size - size);
    used_ += size;
    return offset;
}

void RangeAllocator::free(std::size_t offset, std::size_t bytes) {
    std::size_t size = rounded(bytes);
    assert(offset % alignment_ == 0 && offset + size <= capacity_ && size <= used_);
    auto next = by_offset_.lower_bound(offset);
    assert((next == by_offset_.end() || next->first >= offset + size) && "freeing a free range");
    used_ -= size;
    if (next != by_offset_.end() && next->first == offset + size) {
        size += next->second;
        auto after = std::next(next);
        erase_free(next);
        next = after;
    }
    if (next != by_offset_.begin()) {
        auto prev = std::prev(next);
        assert(prev->first + prev->second <= offset && "freeing a free range");
        if (prev->first + prev->second == offset) {
            offset = prev->first;
            size += prev->second;
            erase_free(prev);
        }
    }
    insert_free(offset, size);
}

void RangeAllocator::grow(std::size_t new_capacity) {
    new_capacity = new_capacity / alignment_ * alignment_;
    if (new_capacity <= capacity_) return;
    std::size_t offset = capacity_;
    std::size_t size = new_capacity - capacity_;
    capacity_ = new_capacity;
    if (!by_offset_.empty()) {
        auto last = std::prev(by_offset_.end());
        if (last->first + last->second == offset) {
            offset = last->first;
            size += last->second;
            erase_free(last);
        }
    }
    insert_free(offset, size);
}

}  // namespace engine::gfx
