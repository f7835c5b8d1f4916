// Component storage: a sparse set of entities with the components packed in the same dense order, plus
// a change log (stamps sorted by tick, one live entry per component) so systems can visit only what changed
// since they last ran.
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
// out, saving the per-component log index and the change log (16 B per stamp):
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
                if (s_->log_[pos_].pos != SparseSet::npos) {
                    entity_ = s_->at(s_->log_[pos_].pos);
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
        if constexpr (track_changes_v<T>) log_pos_.push_back(npos);
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
        return log_[log_pos_[index_of(e)]].tick;
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
        }
        if constexpr (track_changes_v<T>) {
            // The removed component's log entry dies; the moved one's entry follows it to `pos`.
            log_[log_pos_[pos]].pos = npos;
            if (pos + 1 != log_pos_.size()) {
                log_pos_[pos] = log_pos_.back();
                log_[log_pos_[pos]].pos = static_cast<std::uint32_t>(pos);
            }
            log_pos_.pop_back();
        }
        components_.pop_back();
        pop_swap(pos);
        return true;
    }
    void clear() final {
        SparseSet::clear();
        components_.clear();
        log_pos_.clear();
        log_.clear();
        ++log_generation_;
    }
    void reserve(std::size_t n) final {
        SparseSet::reserve(n);
        components_.reserve(n);
        if constexpr (track_changes_v<T>) log_pos_.reserve(n);
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
    // One stamp: the dense position of the component it stamped (kept up to date by swap-remove), or npos
    // once superseded by a newer stamp or by removal.
    struct LogEntry {
        std::uint32_t pos;
        std::uint64_t tick;
    };

    void stamp(std::size_t pos) {
        if constexpr (track_changes_v<T>) {
            const std::uint64_t t = ++*clock_;
            const std::uint32_t old = log_pos_[pos];
            // Dedupe: a component whose entry is the newest just moves that entry to the new tick.
            if (old != npos && old + 1 == log_.size()) {
                log_[old].tick = t;
                return;
            }
            if (old != npos) log_[old].pos = npos;
            log_pos_[pos] = static_cast<std::uint32_t>(log_.size());
            log_.push_back({static_cast<std::uint32_t>(pos), t});
            // Superseded entries are dropped once the log is twice the live size (each component has
            // exactly one live entry), so the cost is amortized O(1) per stamp. The scan is sequential.
            if (log_.size() >= 2 * size() + 64) compact_log();
        } else {
            (void)pos;
        }
    }
    // First log position whose tick is >= tick (the log is sorted by tick).
    [[nodiscard]] std::size_t log_lower_bound(std::uint64_t tick) const noexcept {
        return static_cast<std::size_t>(
            std::partition_point(log_.begin(), log_.end(),
                                 [tick](const LogEntry& le) { return le.tick < tick; }) -
            log_.begin());
    }
    void compact_log() {
        std::size_t w = 0;
        for (const LogEntry& le : log_) {
            if (le.pos == npos) continue;
            log_pos_[le.pos] = static_cast<std::uint32_t>(w);
            log_[w++] = le;
        }
        log_.resize(w);
        ++log_generation_;
    }

    std::vector<T> components_;
    std::vector<std::uint32_t> log_pos_;  // per dense component: index of its live log entry
    std::vector<LogEntry> log_;
    std::uint64_t log_generation_ = 0;
    std::uint64_t own_clock_ = 0;
    std::uint64_t* clock_;
};

}  // namespace engine::ecs
