// Views: entities that have all of several component types. A view walks the smallest of its storages
// (back to front) and checks membership in the others; components come back as references.
#pragma once

#include <engine/ecs/storage.hpp>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <type_traits>
#include <utility>

namespace engine::ecs {

/// The storage a view of C reads: Storage<T> for C = T, const Storage<T> for C = const T.
template <class C>
using StorageFor = std::conditional_t<std::is_const_v<C>, const Storage<std::remove_const_t<C>>,
                                      Storage<std::remove_const_t<C>>>;

/// A view over the entities that have every one of Cs (a const C gives read-only access).
///
/// Iteration rules (the same for each(), range-for and each() ranges):
/// - The lead (smallest) storage is chosen when iteration starts and walked from last member to first.
/// - Inside the loop, removing components of the current entity, or destroying it, is safe: the member
///   swapped into its place has already been visited. Removing components of other entities is not
///   (an unvisited entity can be skipped or an entity visited twice).
/// - Emplacing components is safe for the walk (new members of the lead storage are not visited), but it
///   can invalidate references to components of the same type handed out earlier.
template <class... Cs>
class View {
    static_assert(sizeof...(Cs) > 0, "a view needs at least one component type");

public:
    /// Dense positions of one entity's components in each storage, in the order of Cs.
    using Positions = std::array<std::uint32_t, sizeof...(Cs)>;

    /// A view over these storages (Registry::view<Cs...>() makes one).
    explicit View(StorageFor<Cs>&... storages) noexcept : pools_{&storages...} {}

    /// Calls fn(Entity, Cs&...) or fn(Cs&...) for every entity that has all of Cs.
    template <class Fn>
    void each(Fn&& fn) const {
        const SparseSet* lead = smallest();
        for (std::size_t i = lead->size(); i-- > 0;) {
            if (i >= lead->size()) continue;  // the callback removed more than the current entity
            const Entity e = lead->at(i);
            // One sparse lookup per non-lead storage gives both membership and the component's position.
            const Positions pos = locate_all(e, i, lead);
            if (!all_found(pos)) continue;
            invoke(fn, e, pos, std::index_sequence_for<Cs...>{});
        }
    }

    /// Forward iterator over matching entities (a range-for yields Entity).
    class Iterator {
    public:
        using value_type = Entity;               ///< what *it yields
        using difference_type = std::ptrdiff_t;  ///< for std::forward_iterator
        Iterator() = default;                    ///< the end iterator
        /// Starts below lead position `next` of `lead`, at the first matching entity (see View::begin()).
        Iterator(const View* v, const SparseSet* lead, std::size_t next) : v_{v}, lead_{lead}, next_{next} {
            settle();
        }
        /// The current entity.
        Entity operator*() const noexcept { return lead_->at(at_); }
        /// Moves to the next matching entity.
        Iterator& operator++() noexcept {
            settle();
            return *this;
        }
        /// Moves to the next matching entity; returns the old position.
        Iterator operator++(int) noexcept {
            Iterator old = *this;
            settle();
            return old;
        }
        /// Same view and entity, or both at the end.
        bool operator==(const Iterator& o) const noexcept {
            return v_ == o.v_ && (v_ == nullptr || at_ == o.at_);
        }
        /// Dense positions of the current entity's components, in the order of Cs.
        [[nodiscard]] const Positions& positions() const noexcept { return pos_; }
        /// The view iterated (nullptr at the end).
        [[nodiscard]] const View* view() const noexcept { return v_; }

    private:
        void settle() noexcept {
            while (next_-- > 0) {
                if (next_ >= lead_->size()) continue;
                pos_ = v_->locate_all(lead_->at(next_), next_, lead_);
                if (all_found(pos_)) {
                    at_ = next_;
                    return;
                }
            }
            v_ = nullptr;
        }
        const View* v_ = nullptr;
        const SparseSet* lead_ = nullptr;
        std::size_t next_ = 0;  ///< lead positions below this are still to visit
        std::size_t at_ = 0;    ///< lead position of the current entity
        Positions pos_{};
    };

    /// The first matching entity (the lead storage is chosen here).
    [[nodiscard]] Iterator begin() const {
        const SparseSet* lead = smallest();
        return Iterator{this, lead, lead->size()};
    }
    /// The end of the iteration.
    [[nodiscard]] Iterator end() const noexcept { return Iterator{}; }

    /// A range of std::tuple<Entity, Cs&...>, for `for (auto [e, a, b] : view.each())`.
    class EachRange {
    public:
        /// Iterator yielding std::tuple<Entity, Cs&...>.
        class Iterator {
        public:
            using value_type = std::tuple<Entity, Cs&...>;  ///< what *it yields
            using difference_type = std::ptrdiff_t;         ///< for std::forward_iterator
            Iterator() = default;                           ///< the end iterator
            /// Wraps an entity iterator of the view.
            explicit Iterator(typename View::Iterator it) : it_{it} {}
            /// The current entity and references to its components.
            value_type operator*() const {
                return it_.view()->tuple_at(*it_, it_.positions(), std::index_sequence_for<Cs...>{});
            }
            /// Moves to the next matching entity.
            Iterator& operator++() noexcept {
                ++it_;
                return *this;
            }
            /// Same position.
            bool operator==(const Iterator& o) const noexcept { return it_ == o.it_; }

        private:
            typename View::Iterator it_;
        };
        explicit EachRange(const View& v) : v_{&v} {}                           ///< the range of `v`
        [[nodiscard]] Iterator begin() const { return Iterator{v_->begin()}; }  ///< first match
        [[nodiscard]] Iterator end() const { return Iterator{}; }               ///< end

    private:
        const View* v_;
    };
    /// The view as a range of std::tuple<Entity, Cs&...> (see EachRange).
    [[nodiscard]] EachRange each() const { return EachRange{*this}; }

    /// True iff e has all of Cs.
    [[nodiscard]] bool contains(Entity e) const noexcept {
        return (std::get<StorageFor<Cs>*>(pools_)->contains(e) && ...);
    }
    /// e's C. Asserts e has it.
    template <class C>
    [[nodiscard]] C& get(Entity e) const noexcept {
        return std::get<StorageFor<C>*>(pools_)->get(e);
    }
    /// An upper bound on the number of matches: the size of the smallest storage.
    [[nodiscard]] std::size_t size_hint() const noexcept { return smallest()->size(); }

    /// The storage of C backing this view.
    template <class C>
    [[nodiscard]] StorageFor<C>& storage() const noexcept {
        return *std::get<StorageFor<C>*>(pools_);
    }

private:
    [[nodiscard]] const SparseSet* smallest() const noexcept {
        const SparseSet* best = std::get<0>(pools_);
        std::apply([&best](auto*... p) { ((best = p->size() < best->size() ? p : best), ...); }, pools_);
        return best;
    }
    /// Position of e's C: the lead's is known, the others take one sparse lookup (npos if e lacks C).
    template <class C>
    [[nodiscard]] std::uint32_t locate(Entity e, std::size_t lead_pos, const SparseSet* lead) const noexcept {
        const auto* p = std::get<StorageFor<C>*>(pools_);
        return static_cast<const SparseSet*>(p) == lead ? static_cast<std::uint32_t>(lead_pos) : p->find(e);
    }
    [[nodiscard]] Positions locate_all(Entity e, std::size_t lead_pos, const SparseSet* lead) const noexcept {
        return Positions{locate<Cs>(e, lead_pos, lead)...};
    }
    [[nodiscard]] static bool all_found(const Positions& pos) noexcept {
        return std::find(pos.begin(), pos.end(), SparseSet::npos) == pos.end();
    }
    template <class Fn, std::size_t... I>
    void invoke(Fn& fn, Entity e, const Positions& pos, std::index_sequence<I...>) const {
        if constexpr (std::is_invocable_v<Fn&, Entity, Cs&...>) {
            fn(e, std::get<I>(pools_)->at_position(pos[I])...);
        } else {
            fn(std::get<I>(pools_)->at_position(pos[I])...);
        }
    }
    template <std::size_t... I>
    [[nodiscard]] std::tuple<Entity, Cs&...> tuple_at(Entity e, const Positions& pos,
                                                      std::index_sequence<I...>) const {
        return {e, std::get<I>(pools_)->at_position(pos[I])...};
    }

    std::tuple<StorageFor<Cs>*...> pools_;
};

}  // namespace engine::ecs
