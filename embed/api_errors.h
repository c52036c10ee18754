// The API's error boundary: internal Status values become api::Error, and
// no exception (std::bad_alloc from a vector, a bug) crosses into the host.
#pragma once

#include <exception>
#include <new>
#include <string>
#include <type_traits>
#include <utility>

#include "runtime/core/status.h"
#include "sinew/result.h"

namespace sinew::api::detail {

Error to_api_error(const sinew::Status& status);
Status to_api_status(const sinew::Status& status);

inline Error api_error(ErrorCode code, std::string message) { return Error{code, std::move(message)}; }

// Runs `body` (returning a Status or Result<T>), turning anything thrown
// into an error of the same type.
template <class Body>
auto guarded(const char* what, Body&& body) noexcept -> decltype(body()) {
  using Out = decltype(body());
  try {
    return body();
  } catch (const std::bad_alloc&) {
    return Out(Error{ErrorCode::kOutOfMemory, std::string(what) + ": out of memory"});
  } catch (const std::exception& e) {
    return Out(Error{ErrorCode::kInternal, std::string(what) + ": " + e.what()});
  } catch (...) {
    return Out(Error{ErrorCode::kInternal, std::string(what) + ": unknown exception"});
  }
}

}  // namespace sinew::api::detail

// Inside a function returning api::Status or api::Result<T>: return the
// internal Status `expr` as an api error when it failed.
#define SINEW_RETURN_IF_ERROR_API(expr)                                         \
  do {                                                                          \
    const ::sinew::Status sinew_api_status_ = (expr);                           \
    if (!sinew_api_status_.ok()) return ::sinew::api::detail::to_api_error(sinew_api_status_); \
  } while (false)
