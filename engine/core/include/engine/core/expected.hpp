// A value or a failure (engine::Status): how the engine's factories report runtime failures (no exceptions cross
// the API boundary). Programmer mistakes are asserts, not failures.
#pragma once

#include "engine/core/status.hpp"

#include <cassert>
#include <utility>
#include <variant>

namespace engine {

/// Holds a T or a failed Status (its message names what failed).
template <class T>
class [[nodiscard]] Expected {
public:
    /// A value (implicit: `return value;`).
    Expected(T value) : state_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
    /// A failure (implicit: `return Error{"..."};`). Asserts that it is one.
    Expected(Status failure) : state_(std::move(failure)) {  // NOLINT(google-explicit-constructor)
        assert(!std::get<1>(state_).ok() && "Expected from a successful Status");
    }

    /// True when it holds a value.
    bool ok() const { return state_.index() == 0; }
    /// ok().
    explicit operator bool() const { return ok(); }

    /// The value. Asserts ok().
    T& value() & {
        assert(ok() && "Expected::value() on an error");
        return std::get<0>(state_);
    }
    /// The value. Asserts ok().
    const T& value() const& {
        assert(ok() && "Expected::value() on an error");
        return std::get<0>(state_);
    }
    /// The value, moved out. Asserts ok().
    T&& value() && {
        assert(ok() && "Expected::value() on an error");
        return std::get<0>(std::move(state_));
    }
    /// Member access to the value. Asserts ok().
    T* operator->() { return &value(); }
    /// Member access to the value. Asserts ok().
    const T* operator->() const { return &value(); }
    /// The value. Asserts ok().
    T& operator*() & { return value(); }

    /// The failure. Asserts !ok().
    const Status& error() const {
        assert(!ok() && "Expected::error() on a value");
        return std::get<1>(state_);
    }

private:
    std::variant<T, Status> state_;
};

}  // namespace engine
