// A value, or the message saying why there is none: what a function outside the core returns
// when it can fail (docs/architecture.md, "Errors outside the core"). Result<void> is success or
// a message. std::expected is C++23; this is the small part of it Motwin needs. A leaf header:
// the standard library only.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

namespace motwin {

// Why something failed, in words for a person: "cannot listen on 127.0.0.1:5000: Address
// already in use".
struct Error {
  std::string message;

  // The same failure told one level up: Error{"expected HOST:PORT"}.with_context("--can: ").
  Error with_context(std::string_view context) const { return Error{std::string(context) + message}; }
};

namespace result_detail {

// Reading the value of a failure is a bug in the caller: stop at once and say so, rather than
// throw (no exceptions below main) or read garbage.
[[noreturn]] inline void value_of_failure() {
  std::fprintf(stderr, "motwin: internal error: value() of a failed Result\n");
  std::abort();
}

inline const std::string& no_message() {
  static const std::string empty;
  return empty;
}

}  // namespace result_detail

template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}      // NOLINT: implicit, like std::expected
  Result(Error error) : state_(std::in_place_index<1>, std::move(error)) {}  // NOLINT

  bool ok() const { return state_.index() == 0; }
  explicit operator bool() const { return ok(); }

  // Only when ok().
  const T& value() const& { return *checked_value(); }
  T& value() & { return *checked_value(); }
  T&& value() && { return std::move(*checked_value()); }
  const T* operator->() const { return checked_value(); }
  T* operator->() { return checked_value(); }
  const T& operator*() const& { return *checked_value(); }
  T& operator*() & { return *checked_value(); }

  // The message; empty when ok().
  const std::string& error() const { return ok() ? result_detail::no_message() : std::get_if<1>(&state_)->message; }
  // The failure with `context` in front, to return from the caller: "--can: " + error().
  Error error_with_context(std::string_view context) const { return Error{error()}.with_context(context); }

 private:
  T* checked_value() {
    if (!ok()) result_detail::value_of_failure();
    return std::get_if<0>(&state_);
  }
  const T* checked_value() const {
    if (!ok()) result_detail::value_of_failure();
    return std::get_if<0>(&state_);
  }

  std::variant<T, Error> state_;
};

// Success (`return {};`) or a message (`return Error{...};`).
template <>
class [[nodiscard]] Result<void> {
 public:
  Result() = default;
  Result(Error error) : error_(std::move(error)) {}  // NOLINT: implicit, like std::expected

  bool ok() const { return !error_.has_value(); }
  explicit operator bool() const { return ok(); }

  // The message; empty when ok().
  const std::string& error() const { return ok() ? result_detail::no_message() : error_->message; }
  Error error_with_context(std::string_view context) const { return Error{error()}.with_context(context); }

 private:
  std::optional<Error> error_;
};

}  // namespace motwin
