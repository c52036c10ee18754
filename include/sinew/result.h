// Errors as values: no exception ever crosses Sinew's API. A call that can
// fail returns a Status (nothing else to return) or a Result<T>; the Error
// inside says what failed in words that name the file, the field and the
// value ("cally.pack: MESH.triangles[12]: index 9999 ...").
#pragma once

#include <cstdlib>
#include <string>
#include <utility>
#include <variant>

namespace sinew::api {

enum class ErrorCode : int {
  kInvalidArgument = 1,  // a bad value from the caller (the message names it)
  kNotFound,             // a file, clip, bone or instance that does not exist
  kIoError,              // the file system refused
  kCorruptData,          // a pack or file that fails its checks
  kUnsupported,          // a format version or feature this library lacks
  kLimitExceeded,        // beyond what the format or memory allows
  kOutOfMemory,
  kInternal,             // a bug in Sinew: please report it
};

struct Error {
  ErrorCode code = ErrorCode::kInternal;
  std::string message;
};

// Success, or an Error.
class [[nodiscard]] Status {
 public:
  Status() = default;  // success
  Status(Error error) : error_(std::move(error)), failed_(true) {}  // NOLINT: implicit by design

  bool ok() const noexcept { return !failed_; }
  explicit operator bool() const noexcept { return ok(); }
  // Precondition: !ok().
  const Error& error() const noexcept { return error_; }

 private:
  Error error_;
  bool failed_ = false;
};

// A T, or an Error.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : state_(std::in_place_index<0>, std::move(value)) {}  // NOLINT: implicit by design
  Result(Error error) : state_(std::in_place_index<1>, std::move(error)) {}  // NOLINT: implicit by design

  bool ok() const noexcept { return state_.index() == 0; }
  explicit operator bool() const noexcept { return ok(); }

  // Preconditions: ok() for value(), !ok() for error(). Calling the wrong
  // one is a programming error and stops the program, like a failed
  // assertion (it is never caused by input data).
  T& value() & noexcept { return *checked(std::get_if<0>(&state_)); }
  const T& value() const& noexcept { return *checked(std::get_if<0>(&state_)); }
  T&& value() && noexcept { return std::move(*checked(std::get_if<0>(&state_))); }
  const Error& error() const noexcept { return *checked(std::get_if<1>(&state_)); }

  T* operator->() noexcept { return &value(); }
  const T* operator->() const noexcept { return &value(); }
  T& operator*() & noexcept { return value(); }
  const T& operator*() const& noexcept { return value(); }

  // The error as a Status (success when ok()).
  Status status() const { return ok() ? Status() : Status(error()); }

 private:
  template <class P>
  static P* checked(P* p) noexcept {
    if (p == nullptr) std::abort();
    return p;
  }
  std::variant<T, Error> state_;
};

}  // namespace sinew::api
