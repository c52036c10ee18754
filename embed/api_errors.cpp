#include "embed/api_errors.h"

namespace sinew::api::detail {

Error to_api_error(const sinew::Status& status) {
  ErrorCode code = ErrorCode::kInternal;
  switch (status.code()) {
    case sinew::ErrorCode::kInvalidArgument: code = ErrorCode::kInvalidArgument; break;
    case sinew::ErrorCode::kNotFound: code = ErrorCode::kNotFound; break;
    case sinew::ErrorCode::kIoError: code = ErrorCode::kIoError; break;
    case sinew::ErrorCode::kUnsupportedVersion: code = ErrorCode::kUnsupported; break;
    case sinew::ErrorCode::kLimitExceeded: code = ErrorCode::kLimitExceeded; break;
    case sinew::ErrorCode::kTruncated:
    case sinew::ErrorCode::kBadMagic:
    case sinew::ErrorCode::kChecksumMismatch:
    case sinew::ErrorCode::kOutOfBounds:
    case sinew::ErrorCode::kOverlap:
    case sinew::ErrorCode::kMisaligned:
    case sinew::ErrorCode::kDuplicate:
    case sinew::ErrorCode::kInvalidData: code = ErrorCode::kCorruptData; break;
    case sinew::ErrorCode::kOk:
    case sinew::ErrorCode::kCancelled:
    case sinew::ErrorCode::kInternal: code = ErrorCode::kInternal; break;
  }
  return Error{code, status.message()};
}

Status to_api_status(const sinew::Status& status) {
  if (status.ok()) return {};
  return to_api_error(status);
}

}  // namespace sinew::api::detail
