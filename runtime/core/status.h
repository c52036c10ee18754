// Status: the error value every Sinew library function returns instead of
// throwing, aborting or asserting on input data (docs/DESIGN.md section 7).
//
// An error carries a machine-readable code plus the three facts a user needs
// to fix bad input: the file (or source) it came from, the field inside it,
// and the offending value. `message()` renders them as one line:
//
//     cally.pack: section[3].offset = 4096: past the end of the file (2048 bytes)
//
// A successful Status holds no allocation, so returning `Status{}` on the
// hot path costs a null pointer.
#pragma once

#include <memory>
#include <string>
#include <string_view>

namespace sinew {

enum class ErrorCode : int {
  kOk = 0,
  kInvalidArgument,     // a caller passed a bad parameter (not file data)
  kNotFound,            // a file, section, clip or name does not exist
  kIoError,             // the operating system refused a read or write
  kTruncated,           // data ends before a declared structure does
  kBadMagic,            // not the file type it claims to be
  kUnsupportedVersion,  // a format version this build cannot read
  kChecksumMismatch,    // stored and computed checksums differ
  kOutOfBounds,         // an offset, size or index points outside its range
  kOverlap,             // two regions that must be disjoint intersect
  kMisaligned,          // an offset violates its required alignment
  kDuplicate,           // an id or name that must be unique appears twice
  kLimitExceeded,       // a count or size beyond what the format or memory allows
  kInvalidData,         // a value that is structurally readable but wrong (NaN, ...)
  kCancelled,           // the user interrupted long work
  kInternal,            // a broken invariant inside Sinew (a bug: please report)
};

// Stable, human-readable name of a code ("truncated", "checksum mismatch").
std::string_view error_code_name(ErrorCode code);

class [[nodiscard]] Status {
 public:
  // Success.
  Status() = default;

  // An error. `file` is the file or source the bad data came from (may be
  // empty for caller errors), `field` the path of the field inside it,
  // `value` the offending value as text, `detail` what is wrong with it.
  Status(ErrorCode code, std::string file, std::string field, std::string value,
         std::string detail);

  Status(const Status& other);
  Status& operator=(const Status& other);
  Status(Status&&) noexcept = default;
  Status& operator=(Status&&) noexcept = default;
  ~Status() = default;

  bool ok() const { return info_ == nullptr; }
  explicit operator bool() const { return ok(); }

  ErrorCode code() const { return info_ ? info_->code : ErrorCode::kOk; }
  std::string_view file() const { return info_ ? std::string_view(info_->file) : ""; }
  std::string_view field() const { return info_ ? std::string_view(info_->field) : ""; }
  std::string_view value() const { return info_ ? std::string_view(info_->value) : ""; }
  std::string_view detail() const { return info_ ? std::string_view(info_->detail) : ""; }

  // "file: field = value: detail", omitting empty parts; "ok" on success.
  // Always one line of printable text: each part goes through printable()
  // (a value read from a file may hold any bytes).
  std::string message() const;

  // Returns a copy whose file is `file` when this error names none yet, so a
  // low-level parser can report fields and let its caller name the file.
  Status with_file(std::string_view file) const;

 private:
  struct Info {
    ErrorCode code;
    std::string file;
    std::string field;
    std::string value;
    std::string detail;
  };
  std::unique_ptr<Info> info_;
};

// Shorthand constructors for the common shapes of error.
// `text` as printable UTF-8 on one line: control characters, bytes of
// invalid UTF-8 and C1 controls become \xHH (newline and tab \n and \t),
// valid UTF-8 stays; past `max_bytes` of input the rest is cut to "...".
std::string printable(std::string_view text, std::size_t max_bytes = 512);

inline Status make_error(ErrorCode code, std::string_view file, std::string_view field,
                         std::string_view value, std::string_view detail) {
  return Status(code, std::string(file), std::string(field), std::string(value),
                std::string(detail));
}

// A caller error: no file is involved.
inline Status invalid_argument(std::string_view field, std::string_view value,
                               std::string_view detail) {
  return make_error(ErrorCode::kInvalidArgument, "", field, value, detail);
}

}  // namespace sinew

// Propagates a non-ok Status out of the calling function.
#define SINEW_RETURN_IF_ERROR(expr)                 \
  do {                                              \
    ::sinew::Status sinew_status_ = (expr);         \
    if (!sinew_status_.ok()) return sinew_status_;  \
  } while (false)
