// Component storage: a sparse set of entities with the components packed in the same dense order, plus
// per-component change ticks and a change log so systems can visit only what changed since they last ran.
#pragma once

#include <engine/ecs/sparse_set.hpp>

#include <algorithm>
#include <cstdint>
#include <span>
#include <type_traits>
#include <utility>
#include <vector>

namespace engine::ecs {

template <class T>
class Storage;

// Whether stamps of T are recorded (true by default). A high-churn component that no system watches can opt
// out, saving the per-component tick and the change log (16 B per stamp):
//   template <> inline constexpr bool engine::ecs::track_changes_v<ScratchData> = false;
// Stamping calls then do nothing, and changed<T>() / changed_tick() do not compile.
template <class T>
inline constexpr bool track_changes_v = true;

// Entities whose T component was stamped (emplace, replace, patch, mark_changed) after tick `since` and up to
// the clock value when the range was made; each entity at most once, in stamp order. Entities that lost the
// component since are skipped. Stamping T while walking the range is allowed; those new stamps are outside
// this pass (they are newer than its end) and show up for the next `since`.
template <class T>
class ChangedRange {
public:
    class Iterator {
    public:
        using value_type = Entity;
        using difference_type = std::ptrdiff_t;
        Iterator() = default;
        Iterator(const Storage<T>* s, std::size_t pos, std::uint64_t end_tick)
            : s_{s}, pos_{pos}, end_tick_{end_tick}, gen_{s ? s->log_generation_ : 0} {
            if (s_) settle();
        }
        Entity operator*() const noexcept { return entity_; }
        Iterator& operator++() {
            if (gen_ != s_->log_generation_) {  // the log was compacted under us: find our place again
                pos_ = s_->log_lower_bound(tick_ + 1);
                gen_ = s_->log_generation_;
            } else {
                ++pos_;
            }
            settle();
            return *this;
        }
        Iterator operator++(int) {
            Iterator old = *this;
            ++*this;
            return old;
        }
        bool operator==(const Iterator& o) const noexcept { return done() == o.done(); }

    private:
        [[nodiscard]] bool done() const noexcept { return s_ == nullptr; }
        void settle() {
            for (; pos_ < s_->log_.size() && s_->log_[pos_].tick <= end_tick_; ++pos_) {
                if (s_->log_entry_live(s_->log_[pos_])) {
                    entity_ = s_->log_[pos_].entity;
                    tick_ = s_->log_[pos_].tick;
                    return;
                }
            }
            s_ = nullptr;
        }
        const Storage<T>* s_ = nullptr;
        std::size_t pos_ = 0;
        std::uint64_t end_tick_ = 0;
        std::uint64_t gen_ = 0;
        Entity entity_ = null_entity;  // the current entry, kept so a compaction cannot lose our place
        std::uint64_t tick_ = 0;
    };

    ChangedRange(const Storage<T>& s, std::uint64_t since) : s_{&s}, since_{since}, end_{s.clock()} {}
    [[nodiscard]] Iterator begin() const {
        const std::size_t first = s_->log_lower_bound(since_ + 1);
        return Iterator{s_, first, end_};
    }
    [[nodiscard]] Iterator end() const { return Iterator{}; }

private:
    const Storage<T>* s_;
    std::uint64_t since_;
    std::uint64_t end_;
};

template <class T>
class Storage final : public SparseSet {
public:
    using value_type = T;

    // clock: the tick counter to stamp changes with (the registry passes its shared one so one
    // last_run_tick covers all component types); nullptr means a private counter.
    explicit Storage(std::uint64_t* clock = nullptr) : clock_{clock ? clock : &own_clock_} {}

    // Adds a T to e built from args (aggregate or constructor) and stamps it as changed. Asserts e lacks T.
    // Invalidates references to other T components (the dense array may grow).
    template <class... Args>
    T& emplace(Entity e, Args&&... args) {
        if constexpr (std::is_aggregate_v<T>) {
            components_.push_back(T{std::forward<Args>(args)...});
        } else {
            components_.emplace_back(std::forward<Args>(args)...);
        }
        if constexpr (track_changes_v<T>) ticks_.push_back(0);
        const std::size_t pos = push(e);
        stamp(pos);
        return components_[pos];
    }

    // Replaces e's T with one built from args and stamps it. Asserts e has T.
    template <class... Args>
    T& replace(Entity e, Args&&... args) {
        const std::size_t pos = index_of(e);
        if constexpr (std::is_aggregate_v<T>) {
            components_[pos] = T{std::forward<Args>(args)...};
        } else {
            components_[pos] = T(std::forward<Args>(args)...);
        }
        stamp(pos);
        return components_[pos];
    }

    // e's T. Asserts e has T. Writing through this reference is not a change: use patch() for that.
    [[nodiscard]] T& get(Entity e) noexcept { return components_[index_of(e)]; }
    [[nodiscard]] const T& get(Entity e) const noexcept { return components_[index_of(e)]; }
    // e's T, or nullptr if e has none (or is stale).
    [[nodiscard]] T* try_get(Entity e) noexcept {
        const std::uint32_t pos = find(e);
        return pos != npos ? &components_[pos] : nullptr;
    }
    [[nodiscard]] const T* try_get(Entity e) const noexcept {
        const std::uint32_t pos = find(e);
        return pos != npos ? &components_[pos] : nullptr;
    }

    // Stamps e's T as changed now and returns it for writing. Asserts e has T.
    T& patch(Entity e) {
        const std::size_t pos = index_of(e);
        stamp(pos);
        return components_[pos];
    }
    // Calls fn(T&) on e's T, then stamps it. Asserts e has T.
    template <class Fn>
    T& patch(Entity e, Fn&& fn) {
        const std::size_t pos = index_of(e);
        std::forward<Fn>(fn)(components_[pos]);
        stamp(pos);
        return components_[pos];
    }
    // Stamps e's T as changed without touching it. Asserts e has T.
    void mark_changed(Entity e) { stamp(index_of(e)); }

    // The tick of e's T's latest stamp. Asserts e has T.
    [[nodiscard]] std::uint64_t changed_tick(Entity e) const noexcept {
        static_assert(track_changes_v<T>, "changed_tick: change tracking is off for this component type");
        return ticks_[index_of(e)];
    }
    // The clock's current value: every stamp so far has a tick <= clock(). A system stores it after running.
    [[nodiscard]] std::uint64_t clock() const noexcept { return *clock_; }
    // Entities whose T was stamped after `since`; cost is proportional to the stamps since then, not size().
    [[nodiscard]] ChangedRange<T> changed(std::uint64_t since) const {
        static_assert(track_changes_v<T>, "changed: change tracking is off for this component type");
        return ChangedRange<T>{*this, since};
    }

    // Removes e's T if present, swapping the last component into its place. Returns whether it was present.
    bool remove(Entity e) final {
        const std::uint32_t found = find(e);
        if (found == npos) return false;
        const std::size_t pos = found;
        if (pos + 1 != components_.size()) {
            components_[pos] = std::move(components_.back());
            if constexpr (track_changes_v<T>) ticks_[pos] = ticks_.back();
        }
        components_.pop_back();
        if constexpr (track_changes_v<T>) ticks_.pop_back();
        pop_swap(pos);
        return true;
    }
    void clear() final {
        SparseSet::clear();
        components_.clear();
        ticks_.clear();
        log_.clear();
        ++log_generation_;
    }
    void reserve(std::size_t n) final {
        SparseSet::reserve(n);
        components_.reserve(n);
        if constexpr (track_changes_v<T>) ticks_.reserve(n);
    }

    // Components in dense order (parallel to entities()).
    [[nodiscard]] std::span<T> components() noexcept { return components_; }
    [[nodiscard]] std::span<const T> components() const noexcept { return components_; }
    // The component at dense position pos (< size()); views use this to skip the sparse lookup.
    [[nodiscard]] T& at_position(std::size_t pos) noexcept { return components_[pos]; }
    [[nodiscard]] const T& at_position(std::size_t pos) const noexcept { return components_[pos]; }
    // Length of the change log (live plus superseded entries); for tests and stats.
    [[nodiscard]] std::size_t change_log_size() const noexcept { return log_.size(); }

private:
    friend class ChangedRange<T>;
    struct LogEntry {
        Entity entity;
        std::uint64_t tick;
    };

    void stamp(std::size_t pos) {
        if constexpr (track_changes_v<T>) {
            const std::uint64_t t = ++*clock_;
            const Entity e = at(pos);
            // Dedupe: the same component stamped twice in a row keeps one log entry, moved to the new tick.
            if (!log_.empty() && log_.back().entity == e && log_.back().tick == ticks_[pos]) {
                log_.back().tick = t;
            } else {
                log_.push_back({e, t});
            }
            ticks_[pos] = t;
            // Superseded entries (component restamped or removed) are dropped once the log is twice the live
            // size: each entity then has at most one entry, so the cost is amortized O(1) per stamp.
            if (log_.size() >= 2 * size() + 64) compact_log();
        } else {
            (void)pos;
        }
    }
    [[nodiscard]] bool log_entry_live(const LogEntry& le) const noexcept {
        const std::uint32_t pos = find(le.entity);
        return pos != npos && ticks_[pos] == le.tick;
    }
    // First log position whose tick is >= tick (the log is sorted by tick).
    [[nodiscard]] std::size_t log_lower_bound(std::uint64_t tick) const noexcept {
        return static_cast<std::size_t>(
            std::partition_point(log_.begin(), log_.end(),
                                 [tick](const LogEntry& le) { return le.tick < tick; }) -
            log_.begin());
    }
    void compact_log() {
        std::erase_if(log_, [this](const LogEntry& le) { return !log_entry_live(le); });
        ++log_generation_;
    }

    std::vector<T> components_;
    std::vector<std::uint64_t> ticks_;
    std::vector<LogEntry> log_;
    std::uint64_t log_generation_ = 0;
    std::uint64_t own_clock_ = 0;
    std::uint64_t* clock_;
};

}  // namespace engine::ecs
