// Views: entities that have all of several component types. A view walks the smallest of its storages
// (back to front) and checks membership in the others; components come back as references.
#pragma once

#include <engine/ecs/storage.hpp>

#include <cstddef>
#include <tuple>
#include <type_traits>

namespace engine::ecs {

// The storage a view of C reads: Storage<T> for C = T, const Storage<T> for C = const T.
template <class C>
using StorageFor = std::conditional_t<std::is_const_v<C>, const Storage<std::remove_const_t<C>>,
                                      Storage<std::remove_const_t<C>>>;

// A view over the entities that have every one of Cs (a const C gives read-only access).
//
// Iteration rules (the same for each(), range-for and each() ranges):
// - The lead (smallest) storage is chosen when iteration starts and walked from its last member to its first.
// - Inside the loop, removing components of the current entity, or destroying it, is safe: the member
//   swapped into its place has already been visited. Removing components of other entities is not
//   (an unvisited entity can be skipped or an entity visited twice).
// - Emplacing components is safe for the walk (new members of the lead storage are not visited), but it
//   can invalidate references to components of the same type handed out earlier.
template <class... Cs>
class View {
    static_assert(sizeof...(Cs) > 0, "a view needs at least one component type");

public:
    explicit View(StorageFor<Cs>&... storages) noexcept : pools_{&storages...} {}

    // Calls fn(Entity, Cs&...) or fn(Cs&...) for every entity that has all of Cs.
    template <class Fn>
    void each(Fn&& fn) const {
        const SparseSet* lead = smallest();
        for (std::size_t i = lead->size(); i-- > 0;) {
            if (i >= lead->size()) continue;  // the callback removed more than the current entity
            const Entity e = lead->at(i);
            if (!all_contain(e, lead)) continue;
            if constexpr (std::is_invocable_v<Fn&, Entity, Cs&...>) {
                fn(e, fetch<Cs>(e, i, lead)...);
            } else {
                fn(fetch<Cs>(e, i, lead)...);
            }
        }
    }

    // Forward iterator over matching entities (a range-for yields Entity).
    class Iterator {
    public:
        using value_type = Entity;
        using difference_type = std::ptrdiff_t;
        Iterator() = default;
        Iterator(const View* v, const SparseSet* lead, std::size_t next) : v_{v}, lead_{lead}, next_{next} {
            settle();
        }
        Entity operator*() const noexcept { return lead_->at(pos_); }
        Iterator& operator++() noexcept {
            settle();
            return *this;
        }
        Iterator operator++(int) noexcept {
            Iterator old = *this;
            settle();
            return old;
        }
        bool operator==(const Iterator& o) const noexcept {
            return v_ == o.v_ && (v_ == nullptr || pos_ == o.pos_);
        }
        // Dense position of the current entity in the lead storage.
        [[nodiscard]] std::size_t position() const noexcept { return pos_; }
        [[nodiscard]] const SparseSet* lead() const noexcept { return lead_; }
        [[nodiscard]] const View* view() const noexcept { return v_; }

    private:
        void settle() noexcept {
            while (next_-- > 0) {
                if (next_ >= lead_->size()) continue;
                if (v_->all_contain(lead_->at(next_), lead_)) {
                    pos_ = next_;
                    return;
                }
            }
            v_ = nullptr;
        }
        const View* v_ = nullptr;
        const SparseSet* lead_ = nullptr;
        std::size_t next_ = 0;  // positions below this are still to visit
        std::size_t pos_ = 0;
    };

    [[nodiscard]] Iterator begin() const {
        const SparseSet* lead = smallest();
        return Iterator{this, lead, lead->size()};
    }
    [[nodiscard]] Iterator end() const noexcept { return Iterator{}; }

    // A range of std::tuple<Entity, Cs&...>, for `for (auto [e, a, b] : view.each())`.
    class EachRange {
    public:
        class Iterator {
        public:
            using value_type = std::tuple<Entity, Cs&...>;
            using difference_type = std::ptrdiff_t;
            Iterator() = default;
            explicit Iterator(typename View::Iterator it) : it_{it} {}
            value_type operator*() const {
                const Entity e = *it_;
                return value_type{e, it_.view()->template fetch<Cs>(e, it_.position(), it_.lead())...};
            }
            Iterator& operator++() noexcept {
                ++it_;
                return *this;
            }
            bool operator==(const Iterator& o) const noexcept { return it_ == o.it_; }

        private:
            typename View::Iterator it_;
        };
        explicit EachRange(const View& v) : v_{&v} {}
        [[nodiscard]] Iterator begin() const { return Iterator{v_->begin()}; }
        [[nodiscard]] Iterator end() const { return Iterator{}; }

    private:
        const View* v_;
    };
    [[nodiscard]] EachRange each() const { return EachRange{*this}; }

    // True iff e has all of Cs.
    [[nodiscard]] bool contains(Entity e) const noexcept {
        return (std::get<StorageFor<Cs>*>(pools_)->contains(e) && ...);
    }
    // e's C. Asserts e has it.
    template <class C>
    [[nodiscard]] C& get(Entity e) const noexcept {
        return std::get<StorageFor<C>*>(pools_)->get(e);
    }
    // An upper bound on the number of matches: the size of the smallest storage.
    [[nodiscard]] std::size_t size_hint() const noexcept { return smallest()->size(); }

    // The storage of C backing this view.
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
    [[nodiscard]] bool all_contain(Entity e, const SparseSet* lead) const noexcept {
        return std::apply(
            [e, lead](auto*... p) {
                return ((static_cast<const SparseSet*>(p) == lead || p->contains(e)) && ...);
            },
            pools_);
    }
    // The lead storage's component is read by position; the others go through the sparse index.
    template <class C>
    [[nodiscard]] C& fetch(Entity e, std::size_t lead_pos, const SparseSet* lead) const noexcept {
        auto* p = std::get<StorageFor<C>*>(pools_);
        return static_cast<const SparseSet*>(p) == lead ? p->at_position(lead_pos) : p->get(e);
    }

    std::tuple<StorageFor<Cs>*...> pools_;
};

}  // namespace engine::ecs
