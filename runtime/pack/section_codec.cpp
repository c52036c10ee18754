#include "runtime/pack/section_codec.h"

namespace sinew {

void SectionEncoder::put_string(const std::string& text) {
  put(static_cast<std::uint32_t>(text.size()));
  const auto* p = reinterpret_cast<const std::byte*>(text.data());
  bytes_.insert(bytes_.end(), p, p + text.size());
}

Status SectionDecoder::error(std::string_view field, std::string_view value, std::string_view detail,
                             ErrorCode code) const {
  return make_error(code, pack_, section_ + "." + std::string(field), value, detail);
}

Status SectionDecoder::need(std::size_t element_size, std::uint64_t count, std::string_view field) const {
  const std::size_t left = bytes_.size() - pos_;
  // count * element_size <= left, without overflowing the product.
  if (count > left / element_size) {
    return error(field, "count " + std::to_string(count) + " x " + std::to_string(element_size) + " bytes",
                 "past the end of the section (" + std::to_string(left) + " bytes left)", ErrorCode::kTruncated);
  }
  return {};
}

Status SectionDecoder::get_string(std::string& out, std::string_view field) {
  std::uint32_t length = 0;
  SINEW_RETURN_IF_ERROR(get(length, field));
  if (length > kMaxSectionString) {
    return error(field, std::to_string(length), "string longer than " + std::to_string(kMaxSectionString) + " bytes",
                 ErrorCode::kLimitExceeded);
  }
  SINEW_RETURN_IF_ERROR(need(1, length, field));
  out.assign(reinterpret_cast<const char*>(bytes_.data() + pos_), length);
  pos_ += length;
  return {};
}

Status SectionDecoder::finish() const {
  if (pos_ == bytes_.size()) return {};
  return error("size", std::to_string(bytes_.size()),
               std::to_string(bytes_.size() - pos_) + " bytes after the last field");
}

}  // namespace sinew
