/// \file
/// A value or a specific error message: how platform and gfx report runtime failures (no exceptions cross
/// the API boundary). Programmer mistakes are asserts, not Errors.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace engine::platform {

/// A runtime failure: what failed and why, e.g. "EGL: no surfaceless Mesa platform".
struct Error {
    std::string message{};  ///< names what failed
};

/// Expected<T>: holds a T or an Error. Expected<void> is a plain status.
template <class T>
class [[nodiscard]] Expected {
public:
    /// A value (implicit: `return value;`).
    Expected(T value) : state_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
    /// An error (implicit: `return Error{"..."};`).
    Expected(Error error) : state_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

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

    /// The error. Asserts !ok().
    const Error& error() const {
        assert(!ok() && "Expected::error() on a value");
        return std::get<1>(state_);
    }

private:
    std::variant<T, Error> state_;
};

/// Success or an Error (Status).
template <>
class [[nodiscard]] Expected<void> {
public:
    Expected() = default;
    /// A failure (implicit: `return Error{"..."};`).
    Expected(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT(google-explicit-constructor)

    /// True on success.
    bool ok() const { return ok_; }
    /// ok().
    explicit operator bool() const { return ok_; }
    /// The error. Asserts !ok().
    const Error& error() const {
        assert(!ok_ && "Expected::error() on success");
        return error_;
    }

private:
    Error error_;
    bool ok_ = true;
};

/// Success or an Error.
using Status = Expected<void>;

}  // namespace engine::platform
