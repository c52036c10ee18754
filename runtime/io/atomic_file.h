// Atomic file replacement: every file Sinew writes goes through here.
//
// Data is written to a temporary file in the destination's folder (same file
// system, so rename is atomic), flushed with fsync, then renamed over the
// destination, and the folder is fsynced so the rename itself is durable.
// Until commit() succeeds the destination keeps its old contents; a writer
// destroyed without commit() (an error, an exception, an interrupted bake)
// removes its temporary file and leaves the old file untouched.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>

#include "runtime/core/expected.h"

namespace sinew {

class AtomicFileWriter {
 public:
  // Creates the temporary file beside `path`. Errors: kIoError naming the
  // folder (missing, not writable).
  static Expected<AtomicFileWriter> create(const std::string& path);

  AtomicFileWriter(AtomicFileWriter&& other) noexcept;
  AtomicFileWriter& operator=(AtomicFileWriter&& other) noexcept;
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;
  ~AtomicFileWriter();  // discards the temporary file unless committed

  // Appends bytes to the temporary file.
  Status write(std::span<const std::byte> bytes);
  Status write(std::string_view text);

  // fsync, rename over the destination, fsync the folder. After an error the
  // destination is unchanged and the temporary file is gone.
  Status commit();

  // Drops the temporary file; the destination is unchanged.
  void discard();

  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_path_; }

 private:
  AtomicFileWriter() = default;

  std::string path_;
  std::string temp_path_;
  int fd_ = -1;
};

// One-shot helpers.
Status write_file_atomic(const std::string& path, std::span<const std::byte> bytes);
Status write_file_atomic(const std::string& path, std::string_view text);

// Renames an already written and closed `temp_path` over `path` with the
// same durability steps as commit(); used when a library (OpenImageIO)
// insists on writing the file itself. `temp_path` must be in `path`'s folder.
Status replace_file_atomic(const std::string& temp_path, const std::string& path);

// A unique temporary name in `path`'s folder that keeps `path`'s extension
// (OpenImageIO picks the format from it): "dir/.name.tmp-<pid>-<n>.ext".
std::string temp_path_beside(const std::string& path);

// Reads a whole file into memory. Errors: kNotFound, kIoError.
Expected<std::string> read_file_text(const std::string& path);

}  // namespace sinew
