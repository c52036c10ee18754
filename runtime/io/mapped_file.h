// MappedFile: a read-only memory mapping of a whole file.
//
// Content packs are used in place: loaders hand out spans into the mapping
// instead of copying (docs/DESIGN.md section 2). The mapping lives as long as the
// MappedFile; spans taken from bytes() must not outlive it. Move-only.
// An empty file maps to an empty span (mmap itself refuses length 0).
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include "runtime/core/expected.h"

namespace sinew {

class MappedFile {
 public:
  MappedFile() = default;
  MappedFile(MappedFile&& other) noexcept;
  MappedFile& operator=(MappedFile&& other) noexcept;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile();

  // Maps `path` read-only. Errors: kNotFound, kIoError (names the path and
  // the operating system's reason).
  static Expected<MappedFile> open(const std::string& path);

  std::span<const std::byte> bytes() const { return {data_, size_}; }
  std::size_t size() const { return size_; }
  const std::string& path() const { return path_; }

 private:
  void release();

  const std::byte* data_ = nullptr;
  std::size_t size_ = 0;
  std::string path_;
};

}  // namespace sinew
