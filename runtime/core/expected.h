// Expected<T>: a value or the Status saying why there is none.
//
// C++20 has no std::expected; this is the small subset Sinew needs. Accessing
// the value of an error (or the error of a value) is a programming bug, not an
// input-data problem, so it is checked with a hard stop in every build type.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <type_traits>
#include <utility>
#include <variant>

#include "runtime/core/status.h"

namespace sinew {

namespace detail {
[[noreturn]] inline void expected_misuse(const char* what) {
  std::fprintf(stderr, "sinew: Expected misuse: %s\n", what);
  std::abort();
}
}  // namespace detail

template <typename T>
class [[nodiscard]] Expected {
  static_assert(!std::is_same_v<std::decay_t<T>, Status>, "Expected<Status> is meaningless");

 public:
  // Implicit from a value and from an error, so `return value;` and
  // `return make_error(...);` both read naturally.
  Expected(T value) : storage_(std::in_place_index<0>, std::move(value)) {}  // NOLINT
  Expected(Status error) : storage_(std::in_place_index<1>, std::move(error)) {  // NOLINT
    if (std::get<1>(storage_).ok()) {
      std::get<1>(storage_) = make_error(ErrorCode::kInternal, "", "", "",
                                         "Expected constructed from an ok Status without a value");
    }
  }

  bool ok() const { return storage_.index() == 0; }
  explicit operator bool() const { return ok(); }

  T& value() & {
    if (!ok()) detail::expected_misuse(std::get<1>(storage_).message().c_str());
    return std::get<0>(storage_);
  }
  const T& value() const& {
    if (!ok()) detail::expected_misuse(std::get<1>(storage_).message().c_str());
    return std::get<0>(storage_);
  }
  T&& value() && {
    if (!ok()) detail::expected_misuse(std::get<1>(storage_).message().c_str());
    return std::get<0>(std::move(storage_));
  }

  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T&& operator*() && { return std::move(*this).value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Status& status() const& {
    if (ok()) detail::expected_misuse("status() of a value");
    return std::get<1>(storage_);
  }
  Status status() && {
    if (ok()) detail::expected_misuse("status() of a value");
    return std::get<1>(std::move(storage_));
  }

 private:
  std::variant<T, Status> storage_;
};

}  // namespace sinew

#define SINEW_CONCAT_INNER_(a, b) a##b
#define SINEW_CONCAT_(a, b) SINEW_CONCAT_INNER_(a, b)

// `SINEW_ASSIGN_OR_RETURN(auto file, MappedFile::open(path));` declares `file`
// from the value, or returns the error from the calling function.
#define SINEW_ASSIGN_OR_RETURN(decl, expr) \
  SINEW_ASSIGN_OR_RETURN_IMPL_(SINEW_CONCAT_(sinew_expected_, __LINE__), decl, expr)
#define SINEW_ASSIGN_OR_RETURN_IMPL_(tmp, decl, expr) \
  auto tmp = (expr);                                  \
  if (!tmp.ok()) return std::move(tmp).status();      \
  decl = std::move(tmp).value()
