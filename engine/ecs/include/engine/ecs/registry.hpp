// The registry: creates and destroys entities and owns one storage per component type. Most calls forward
// to Storage<T>; the registry adds handle checks and one shared change clock for all storages.
#pragma once

#include <engine/ecs/config.hpp>
#include <engine/ecs/entity.hpp>
#include <engine/ecs/sparse_set.hpp>
#include <engine/ecs/storage.hpp>
#include <engine/ecs/view.hpp>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace engine::ecs {

namespace detail {
inline std::size_t next_type_index() noexcept {
    static std::atomic<std::size_t> next{0};
    return next.fetch_add(1, std::memory_order_relaxed);
}
/// A dense, process-wide index per component type, assigned on first use.
template <class T>
std::size_t type_index() noexcept {
    static const std::size_t index = next_type_index();
    return index;
}
}  // namespace detail

/// Entity handles and errors:
/// - Handles are 32-bit: 20-bit index, 12-bit version (entity.hpp). destroy() bumps the slot's version, so
///   every older handle to it is stale: valid() is false, has()/try_get() report nothing.
/// - A slot whose version reaches 4095 is retired when destroyed (never reused), so a stale handle can never
///   become valid again through version wrap-around. This costs one of the 2^20 - 1 slots per 4096 lifetimes.
/// - A registry is not thread-safe: one thread at a time may use it (and its storages and views).
/// - Calling emplace/replace/get/patch/mark_changed/remove/destroy with a stale or null handle is a
///   programmer's mistake: it asserts with a message (ENGINE_ECS_ASSERT: debug builds, or when
///   ENGINE_ECS_ENABLE_ASSERTS is defined). Without asserts such calls are undefined; valid(), has() and
///   try_get() are always safe to call with any handle.
class Registry {
public:
    Registry() : clock_{std::make_unique<std::uint64_t>(0)} {}
    Registry(Registry&&) noexcept = default;             ///< moves every entity and storage
    Registry& operator=(Registry&&) noexcept = default;  ///< moves every entity and storage
    Registry(const Registry&) = delete;
    Registry& operator=(const Registry&) = delete;

    // ---- entities ----

    /// A new live entity with no components. Asserts that fewer than max_entities slots are in use.
    [[nodiscard]] Entity create() {
        if (free_head_ != entity_index_mask) {
            const std::uint32_t index = free_head_;
            free_head_ = to_index(slots_[index]);  // dead slots hold the next free index
            slots_[index] = make_entity(index, to_version(slots_[index]));
            ++alive_;
            return slots_[index];
        }
        ENGINE_ECS_ASSERT(slots_.size() < max_entities, "create: out of entity slots (2^20 - 1)");
        const Entity e = make_entity(static_cast<std::uint32_t>(slots_.size()), 0);
        slots_.push_back(e);
        ++alive_;
        return e;
    }

    /// Removes all of e's components and frees its slot; e and all copies of it become stale.
    /// Asserts valid(e).
    void destroy(Entity e) {
        ENGINE_ECS_ASSERT(valid(e), "destroy: stale or null entity handle");
        for (auto& pool : pools_)
            if (pool) pool->remove(e);
        const std::uint32_t index = to_index(e);
        const std::uint32_t version = to_version(e);
        --alive_;
        if (version == entity_version_mask) {
            slots_[index] = make_entity(entity_index_mask, version);  // retired: not on the free list
            ++retired_;
            return;
        }
        slots_[index] = make_entity(free_head_, version + 1);
        free_head_ = index;
    }

    /// Reserves room for n entity slots (no entities are created).
    void reserve(std::size_t n) { slots_.reserve(n); }

    /// True iff e was returned by create() and not destroyed since. Safe for any handle.
    [[nodiscard]] bool valid(Entity e) const noexcept {
        const std::uint32_t index = to_index(e);
        return index < slots_.size() && slots_[index] == e;
    }
    /// Number of live entities.
    [[nodiscard]] std::size_t alive() const noexcept { return alive_; }
    /// Number of slots retired by version exhaustion.
    [[nodiscard]] std::size_t retired() const noexcept { return retired_; }
    /// Calls fn(Entity) for every live entity, in slot order.
    template <class Fn>
    void each_entity(Fn&& fn) const {
        for (std::uint32_t i = 0; i < slots_.size(); ++i)
            if (to_index(slots_[i]) == i) fn(slots_[i]);
    }

    // ---- components ----

    /// Adds a T built from args to e (aggregate or constructor) and stamps it as changed.
    /// Asserts valid(e) and that e has no T.
    template <class T, class... Args>
    T& emplace(Entity e, Args&&... args) {
        ENGINE_ECS_ASSERT(valid(e), "emplace: stale or null entity handle");
        return storage<T>().emplace(e, std::forward<Args>(args)...);
    }
    /// Replaces e's T with one built from args and stamps it. Asserts valid(e) and has<T>(e).
    template <class T, class... Args>
    T& replace(Entity e, Args&&... args) {
        ENGINE_ECS_ASSERT(valid(e), "replace: stale or null entity handle");
        return storage<T>().replace(e, std::forward<Args>(args)...);
    }
    /// emplace() if e has no T, else replace(). Asserts valid(e).
    template <class T, class... Args>
    T& emplace_or_replace(Entity e, Args&&... args) {
        ENGINE_ECS_ASSERT(valid(e), "emplace_or_replace: stale or null entity handle");
        Storage<T>& s = storage<T>();
        return s.contains(e) ? s.replace(e, std::forward<Args>(args)...)
                             : s.emplace(e, std::forward<Args>(args)...);
    }
    /// Removes e's T if it has one; returns whether it had. Asserts valid(e).
    template <class T>
    bool remove(Entity e) {
        ENGINE_ECS_ASSERT(valid(e), "remove: stale or null entity handle");
        Storage<T>* s = find<T>();
        return s != nullptr && s->remove(e);
    }
    /// e's T. Asserts valid(e) and has<T>(e). Writes through it are not changes: use patch().
    template <class T>
    [[nodiscard]] T& get(Entity e) {
        ENGINE_ECS_ASSERT(valid(e), "get: stale or null entity handle");
        Storage<T>* s = find<T>();
        ENGINE_ECS_ASSERT(s != nullptr && s->contains(e), "get: entity has no such component");
        return s->get(e);
    }
    /// e's T, read-only. Asserts valid(e) and has<T>(e).
    template <class T>
    [[nodiscard]] const T& get(Entity e) const {
        ENGINE_ECS_ASSERT(valid(e), "get: stale or null entity handle");
        const Storage<T>* s = find<T>();
        ENGINE_ECS_ASSERT(s != nullptr && s->contains(e), "get: entity has no such component");
        return s->get(e);
    }
    /// e's T, or nullptr if e has none or is stale/null. Safe for any handle.
    template <class T>
    [[nodiscard]] T* try_get(Entity e) noexcept {
        Storage<T>* s = find<T>();
        return s ? s->try_get(e) : nullptr;
    }
    /// e's T read-only, or nullptr if e has none or is stale/null. Safe for any handle.
    template <class T>
    [[nodiscard]] const T* try_get(Entity e) const noexcept {
        const Storage<T>* s = find<T>();
        return s ? s->try_get(e) : nullptr;
    }
    /// True iff e is valid and has every one of Ts. Safe for any handle.
    template <class... Ts>
    [[nodiscard]] bool has(Entity e) const noexcept {
        return ((find<Ts>() != nullptr && find<Ts>()->contains(e)) && ...);
    }

    // ---- change tracking ----

    /// Stamps e's T as changed and returns it for writing. Asserts valid(e) and has<T>(e).
    template <class T>
    T& patch(Entity e) {
        ENGINE_ECS_ASSERT(valid(e), "patch: stale or null entity handle");
        return storage<T>().patch(e);
    }
    /// Calls fn(T&) on e's T, then stamps it. Asserts valid(e) and has<T>(e).
    template <class T, class Fn>
    T& patch(Entity e, Fn&& fn) {
        ENGINE_ECS_ASSERT(valid(e), "patch: stale or null entity handle");
        return storage<T>().patch(e, std::forward<Fn>(fn));
    }
    /// Stamps e's T as changed without writing it. Asserts valid(e) and has<T>(e).
    template <class T>
    void mark_changed(Entity e) {
        ENGINE_ECS_ASSERT(valid(e), "mark_changed: stale or null entity handle");
        storage<T>().mark_changed(e);
    }
    /// The shared change clock: every stamp so far, of any type, has a tick <= tick(), later ones are
    /// greater. A system remembers tick() after it runs and passes it as `since` next time.
    [[nodiscard]] std::uint64_t tick() const noexcept { return *clock_; }
    /// Entities whose T was emplaced/replaced/patched/marked after tick `since` (each once, in stamp order);
    /// entities that have since lost T are not listed. Cost follows the number of stamps since `since`.
    template <class T>
    [[nodiscard]] ChangedRange<T> changed(std::uint64_t since) {
        return storage<T>().changed(since);
    }

    // ---- storages and views ----

    /// The storage of T, created empty on first use.
    template <class T>
    [[nodiscard]] Storage<T>& storage() {
        static_assert(!std::is_const_v<T> && !std::is_reference_v<T>, "storage<T>: T must be a plain type");
        const std::size_t id = detail::type_index<T>();
        if (id >= pools_.size()) pools_.resize(id + 1);
        if (!pools_[id]) pools_[id] = std::make_unique<Storage<T>>(clock_.get());
        return static_cast<Storage<T>&>(*pools_[id]);
    }
    /// The storage of T, or nullptr if none was made yet.
    template <class T>
    [[nodiscard]] Storage<T>* find() noexcept {
        const std::size_t id = detail::type_index<T>();
        return id < pools_.size() ? static_cast<Storage<T>*>(pools_[id].get()) : nullptr;
    }
    /// The storage of T read-only, or nullptr if none was made yet.
    template <class T>
    [[nodiscard]] const Storage<T>* find() const noexcept {
        const std::size_t id = detail::type_index<T>();
        return id < pools_.size() ? static_cast<const Storage<T>*>(pools_[id].get()) : nullptr;
    }

    /// A view over the entities that have all of Cs (const Cs are read-only). Creates missing storages.
    template <class... Cs>
    [[nodiscard]] View<Cs...> view() {
        return View<Cs...>{storage<std::remove_const_t<Cs>>()...};
    }

private:
    std::vector<Entity> slots_;  ///< live: the handle itself; dead: (next free index, next version)
    std::uint32_t free_head_ = entity_index_mask;
    std::size_t alive_ = 0;
    std::size_t retired_ = 0;
    std::vector<std::unique_ptr<SparseSet>> pools_;
    std::unique_ptr<std::uint64_t> clock_;  ///< on the heap so storages keep a valid pointer when we move
};

}  // namespace engine::ecs
