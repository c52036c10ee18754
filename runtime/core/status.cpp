#include "runtime/core/status.h"

#include <algorithm>
#include <cstdint>

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

namespace {

// The length of the valid UTF-8 sequence at s[i] (a printable code point:
// not a C1 control, not a surrogate, not an overlong form), or 0.
std::size_t utf8_sequence(std::string_view s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char b = byte(i);
  std::size_t n = 0;
  std::uint32_t cp = 0;
  if (b >= 0xC2 && b <= 0xDF) {
    n = 2;
    cp = b & 0x1Fu;
  } else if (b >= 0xE0 && b <= 0xEF) {
    n = 3;
    cp = b & 0x0Fu;
  } else if (b >= 0xF0 && b <= 0xF4) {
    n = 4;
    cp = b & 0x07u;
  } else {
    return 0;
  }
  if (i + n > s.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((byte(i + k) & 0xC0u) != 0x80u) return 0;
    cp = cp << 6 | (byte(i + k) & 0x3Fu);
  }
  const std::uint32_t min[5] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < min[n] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF) || cp <= 0x9F) return 0;
  return n;
}

}  // namespace

std::string printable(std::string_view text, std::size_t max_bytes) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(std::min(text.size(), max_bytes) + 8);
  std::size_t i = 0;
  for (; i < text.size() && i < max_bytes;) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
      ++i;
    } else if (const std::size_t n = c >= 0x80 ? utf8_sequence(text, i) : 0; n != 0) {
      out.append(text.substr(i, n));
      i += n;
    } else if (c == '\n') {
      out += "\\n";
      ++i;
    } else if (c == '\t') {
      out += "\\t";
      ++i;
    } else {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15u];
      ++i;
    }
  }
  if (i < text.size()) out += "...";
  return out;
}

namespace {

// The longest message, in bytes (docs/ROBUSTNESS.md, "Hostile input"), and
// each part's share of it.
constexpr std::size_t kMaxMessageBytes = 300;
constexpr std::size_t kMaxPartBytes = 100;

// `text` cut to at most `max` bytes between UTF-8 sequences, from its start
// (keep_end false) or its end.
std::string cut_between_sequences(std::string text, std::size_t max, bool keep_end) {
  if (text.size() <= max) return text;
  const auto continuation = [&](std::size_t at) { return (static_cast<unsigned char>(text[at]) & 0xC0u) == 0x80u; };
  if (!keep_end) {
    std::size_t end = max;
    while (end > 0 && continuation(end)) --end;
    return text.substr(0, end);
  }
  std::size_t begin = text.size() - max;
  while (begin < text.size() && continuation(begin)) ++begin;
  return text.substr(begin);
}

// A part of a message through printable(), at most kMaxPartBytes: a longer
// one keeps its start and its end (a path's file name), "..." between.
std::string part(std::string_view text) {
  std::string whole = printable(text, std::string_view::npos);
  if (whole.size() <= kMaxPartBytes) return whole;
  const std::size_t head = (kMaxPartBytes - 3) / 2;
  const std::size_t tail = kMaxPartBytes - 3 - head;
  return cut_between_sequences(whole, head, false) + "..." + cut_between_sequences(whole, tail, true);
}

}  // namespace

std::string Status::message() const {
  if (!info_) return "ok";
  // File, field and value have their share of the line, and the line as a
  // whole is cut at kMaxMessageBytes (between UTF-8 sequences): no input,
  // however long (a data URI, a path), makes a message longer.
  std::string out;
  if (!info_->file.empty()) out += part(info_->file);
  if (!info_->field.empty()) {
    if (!out.empty()) out += ": ";
    out += part(info_->field);
    if (!info_->value.empty()) out += " = " + part(info_->value);
  } else if (!info_->value.empty()) {
    if (!out.empty()) out += ": ";
    out += "value " + part(info_->value);
  }
  if (!out.empty()) out += ": ";
  out += info_->detail.empty() ? std::string(error_code_name(info_->code)) : printable(info_->detail, kMaxMessageBytes);
  if (out.size() > kMaxMessageBytes) out = cut_between_sequences(std::move(out), kMaxMessageBytes - 3, false) + "...";
  return out;
}

Status Status::with_file(std::string_view file) const {
  Status copy(*this);
  if (copy.info_ && copy.info_->file.empty()) copy.info_->file = std::string(file);
  return copy;
}

}  // namespace sinew
