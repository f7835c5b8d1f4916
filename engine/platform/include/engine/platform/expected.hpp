// A value or a specific error message: how platform and gfx report runtime failures (no exceptions cross
// the API boundary). Programmer mistakes are asserts, not Errors.
#pragma once

#include <cassert>
#include <string>
#include <utility>
#include <variant>

namespace engine::platform {

struct Error {
    std::string message{};
};

// Expected<T>: holds a T or an Error. Expected<void> is a plain status.
template <class T>
class [[nodiscard]] Expected {
public:
    Expected(T value) : state_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
    Expected(Error error) : state_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

    bool ok() const { return state_.index() == 0; }
    explicit operator bool() const { return ok(); }

    T& value() & {
        assert(ok() && "Expected::value() on an error");
        return std::get<0>(state_);
    }
    const T& value() const& {
        assert(ok() && "Expected::value() on an error");
        return std::get<0>(state_);
    }
    T&& value() && {
        assert(ok() && "Expected::value() on an error");
        return std::get<0>(std::move(state_));
    }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }

    const Error& error() const {
        assert(!ok() && "Expected::error() on a value");
        return std::get<1>(state_);
    }

private:
    std::variant<T, Error> state_;
};

template <>
class [[nodiscard]] Expected<void> {
public:
    Expected() = default;
    Expected(Error error) : error_(std::move(error)), ok_(false) {}  // NOLINT(google-explicit-constructor)

    bool ok() const { return ok_; }
    explicit operator bool() const { return ok_; }
    const Error& error() const {
        assert(!ok_ && "Expected::error() on success");
        return error_;
    }

private:
    Error error_;
    bool ok_ = true;
};

using Status = Expected<void>;

}  // namespace engine::platform
