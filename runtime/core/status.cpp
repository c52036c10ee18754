#include "runtime/core/status.h"

namespace sinew {

std::string_view error_code_name(ErrorCode code) {
  switch (code) {
    case ErrorCode::kOk: return "ok";
    case ErrorCode::kInvalidArgument: return "invalid argument";
    case ErrorCode::kNotFound: return "not found";
    case ErrorCode::kIoError: return "i/o error";
    case ErrorCode::kTruncated: return "truncated";
    case ErrorCode::kBadMagic: return "bad magic";
    case ErrorCode::kUnsupportedVersion: return "unsupported version";
    case ErrorCode::kChecksumMismatch: return "checksum mismatch";
    case ErrorCode::kOutOfBounds: return "out of bounds";
    case ErrorCode::kOverlap: return "overlap";
    case ErrorCode::kMisaligned: return "misaligned";
    case ErrorCode::kDuplicate: return "duplicate";
    case ErrorCode::kLimitExceeded: return "limit exceeded";
    case ErrorCode::kInvalidData: return "invalid data";
    case ErrorCode::kCancelled: return "cancelled";
    case ErrorCode::kInternal: return "internal error";
  }
  return "unknown error";
}

Status::Status(ErrorCode code, std::string file, std::string field, std::string value,
               std::string detail) {
  // An "error" with kOk would make ok() lie; treat it as a caller bug and
  // keep it visible as an internal error rather than silently succeeding.
  if (code == ErrorCode::kOk) {
    code = ErrorCode::kInternal;
    detail = "error constructed with code ok: " + detail;
  }
  info_ = std::make_unique<Info>(
      Info{code, std::move(file), std::move(field), std::move(value), std::move(detail)});
}

Status::Status(const Status& other)
    : info_(other.info_ ? std::make_unique<Info>(*other.info_) : nullptr) {}

Status& Status::operator=(const Status& other) {
  if (this != &other) info_ = other.info_ ? std::make_unique<Info>(*other.info_) : nullptr;
  return *this;
}

std::string Status::message() const {
  if (!info_) return "ok";
  std::string out;
  if (!info_->file.empty()) out += info_->file;
  if (!info_->field.empty()) {
    if (!out.empty()) out += ": ";
    out += info_->field;
    if (!info_->value.empty()) out += " = " + info_->value;
  } else if (!info_->value.empty()) {
    if (!out.empty()) out += ": ";
    out += "value " + info_->value;
  }
  if (!out.empty()) out += ": ";
  out += info_->detail.empty() ? std::string(error_code_name(info_->code)) : info_->detail;
  return out;
}

Status Status::with_file(std::string_view file) const {
  Status copy(*this);
  if (copy.info_ && copy.info_->file.empty()) copy.info_->file = std::string(file);
  return copy;
}

}  // namespace sinew
