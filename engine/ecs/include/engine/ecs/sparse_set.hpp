// Sparse set of entities: a dense packed array of entities plus a paged sparse array (slot index -> dense
// position). The entity half of every component storage: O(1) insert, remove (swap with last), contains.
#pragma once

#include <engine/ecs/config.hpp>
#include <engine/ecs/entity.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace engine::ecs {

class SparseSet {
public:
    // Sparse pages hold 4096 positions (16 KiB); a page is allocated the first time one of its slots is used.
    static constexpr std::uint32_t page_size = 4096;
    static constexpr std::uint32_t npos = 0xFFFFFFFFu;

    SparseSet() = default;
    SparseSet(const SparseSet&) = delete;
    SparseSet& operator=(const SparseSet&) = delete;
    virtual ~SparseSet() = default;

    // True iff this exact handle (index and version) is in the set. Safe for any handle, stale or null.
    [[nodiscard]] bool contains(Entity e) const noexcept {
        const std::uint32_t pos = position_of_index(to_index(e));
        return pos != npos && dense_[pos] == e;
    }

    // Dense position of e, or npos if this exact handle is not in the set. One sparse lookup: views use it
    // to test membership and find the component at once.
    [[nodiscard]] std::uint32_t find(Entity e) const noexcept {
        const std::uint32_t pos = position_of_index(to_index(e));
        return pos != npos && dense_[pos] == e ? pos : npos;
    }

    // Dense position of e. Asserts that e is in the set.
    [[nodiscard]] std::size_t index_of(Entity e) const noexcept {
        ENGINE_ECS_ASSERT(contains(e),
                          "index_of: entity is not in this set (stale handle or missing component)");
        return position_of_index(to_index(e));
    }

    [[nodiscard]] std::size_t size() const noexcept { return dense_.size(); }
    [[nodiscard]] bool empty() const noexcept { return dense_.empty(); }
    // The entity at dense position pos (< size()).
    [[nodiscard]] Entity at(std::size_t pos) const noexcept { return dense_[pos]; }
    // All members in dense order (the order views walk them, back to front).
    [[nodiscard]] std::span<const Entity> entities() const noexcept { return dense_; }

    // Removes e if present (swapping the last member into its place); returns whether it was present.
    // Virtual so the registry can strip a destroyed entity from every storage without knowing the types.
    virtual bool remove(Entity e) {
        if (!contains(e)) return false;
        pop_swap(position_of_index(to_index(e)));
        return true;
    }
    virtual void clear() {
        for (const Entity e : dense_) sparse_[to_index(e) / page_size][to_index(e) % page_size] = npos;
        dense_.clear();
    }
    virtual void reserve(std::size_t n) { dense_.reserve(n); }

protected:
    [[nodiscard]] std::uint32_t position_of_index(std::uint32_t index) const noexcept {
        const std::size_t page = index / page_size;
        return page < sparse_.size() && sparse_[page] ? sparse_[page][index % page_size] : npos;
    }

    // Appends e at the back of the dense array; returns its position. Asserts its slot is not already in.
    std::size_t push(Entity e) {
        std::uint32_t& slot = assure_slot(to_index(e));
        ENGINE_ECS_ASSERT(slot == npos, "emplace: entity already has this component");
        slot = static_cast<std::uint32_t>(dense_.size());
        dense_.push_back(e);
        return slot;
    }

    // Moves the last member into position pos and drops the last; derived storages move their data first.
    void pop_swap(std::size_t pos) noexcept {
        const Entity removed = dense_[pos];
        const Entity last = dense_.back();
        dense_[pos] = last;
        sparse_[to_index(last) / page_size][to_index(last) % page_size] = static_cast<std::uint32_t>(pos);
        sparse_[to_index(removed) / page_size][to_index(removed) % page_size] = npos;
        dense_.pop_back();
    }

private:
    std::uint32_t& assure_slot(std::uint32_t index) {
        const std::size_t page = index / page_size;
        if (page >= sparse_.size()) sparse_.resize(page + 1);
        if (!sparse_[page]) {
            sparse_[page] = std::make_unique<std::uint32_t[]>(page_size);
            std::fill_n(sparse_[page].get(), page_size, npos);
        }
        return sparse_[page][index % page_size];
    }

    std::vector<Entity> dense_;
    std::vector<std::unique_ptr<std::uint32_t[]>> sparse_;
};

}  // namespace engine::ecs
