#pragma once
/// Result<T>: a value or a one-line error message naming the culprit (file, key, value, limit).

#include <string>
#include <utility>
#include <variant>

#include "core/printable.h"

namespace palpate {

/// An error produced at a boundary (file, scene key, argument, device message); copyable.
struct Error {
  std::string message;  ///< one line, names the culprit and the problem
};

/// Holds either a T or an Error. Check ok() before value(); value() on an error is a programming bug.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}           // NOLINT: implicit by design
  Result(Error error) : v_(std::move(error)) {}       // NOLINT: implicit by design

  /// True when a value is held.
  bool ok() const { return v_.index() == 0; }
  explicit operator bool() const { return ok(); }
  /// The held value; only valid when ok().
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  /// The error; only valid when !ok().
  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

/// Result of an operation that produces no value.
struct Ok {};
using Status = Result<Ok>;

/// Builds an Error from string pieces. Bytes from an input that would not print (control bytes, invalid UTF-8,
/// e.g. in a file name or a JSON parser's "last read") are written as \xNN, so the message stays one readable line.
template <class... Args>
Error make_error(Args&&... parts) {
  std::string s;
  (s += ... += std::string(std::forward<Args>(parts)));
  return Error{printable_text(s)};
}

}  // namespace palpate
