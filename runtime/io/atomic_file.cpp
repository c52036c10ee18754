#include "runtime/io/atomic_file.h"

#include "runtime/io/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <utility>

namespace sinew {
namespace {

std::string folder_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

Status io_error(const std::string& path, std::string_view what, int err) {
  return make_error(ErrorCode::kIoError, path, "", "",
                    std::string(what) + ": " + std::strerror(err));
}

// Makes a completed rename durable: the new directory entry must reach disk.
Status fsync_folder(const std::string& path) {
  const std::string folder = folder_of(path);
  const int dir_fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd < 0) return io_error(folder, "cannot open folder for fsync", errno);
  const int rc = ::fsync(dir_fd);
  const int err = errno;
  ::close(dir_fd);
  // Some file systems (tmpfs in containers) refuse fsync on folders; the
  // rename has happened, so this is not a reason to report failure.
  if (rc != 0 && err != EINVAL && err != EROFS) return io_error(folder, "cannot fsync folder", err);
  return {};
}

}  // namespace

std::string temp_path_beside(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const auto slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const auto dot = name.find_last_of('.');
  const std::string stem = (dot == std::string::npos || dot == 0) ? name : name.substr(0, dot);
  const std::string ext = (dot == std::string::npos || dot == 0) ? "" : name.substr(dot);
  return folder + "." + stem + ".tmp-" + std::to_string(::getpid()) + "-" +
         std::to_string(counter.fetch_add(1)) + ext;
}

Expected<AtomicFileWriter> AtomicFileWriter::create(const std::string& path) {
  if (path.empty()) return invalid_argument("path", "\"\"", "empty output path");
  AtomicFileWriter writer;
  writer.path_ = path;
  writer.temp_path_ = temp_path_beside(path);
  writer.fd_ = ::open(writer.temp_path_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (writer.fd_ < 0) {
    const int err = errno;
    writer.temp_path_.clear();
    return io_error(path, "cannot create temporary file in '" + folder_of(path) + "'", err);
  }
  return writer;
}

AtomicFileWriter::AtomicFileWriter(AtomicFileWriter&& other) noexcept
    : path_(std::move(other.path_)),
      temp_path_(std::move(other.temp_path_)),
      fd_(std::exchange(other.fd_, -1)) {
  other.temp_path_.clear();
}

AtomicFileWriter& AtomicFileWriter::operator=(AtomicFileWriter&& other) noexcept {
  if (this != &other) {
    discard();
    path_ = std::move(other.path_);
    temp_path_ = std::move(other.temp_path_);
    fd_ = std::exchange(other.fd_, -1);
    other.temp_path_.clear();
  }
  return *this;
}

AtomicFileWriter::~AtomicFileWriter() { discard(); }

void AtomicFileWriter::discard() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!temp_path_.empty()) ::unlink(temp_path_.c_str());
  temp_path_.clear();
}

Status AtomicFileWriter::write(std::span<const std::byte> bytes) {
  if (fd_ < 0) return make_error(ErrorCode::kInvalidArgument, path_, "", "", "writer is closed");
  const std::byte* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      discard();
      return io_error(path_, "write failed", err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return {};
}

Status AtomicFileWriter::write(std::string_view text) {
  return write(std::as_bytes(std::span<const char>(text.data(), text.size())));
}

Status AtomicFileWriter::commit() {
  if (fd_ < 0) return make_error(ErrorCode::kInvalidArgument, path_, "", "", "writer is closed");
  if (::fsync(fd_) != 0) {
    const int err = errno;
    discard();
    return io_error(path_, "fsync failed", err);
  }
  const int rc = ::close(fd_);
  fd_ = -1;
  if (rc != 0) {
    const int err = errno;
    discard();
    return io_error(path_, "close failed", err);
  }
  if (::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    discard();
    return io_error(path_, "cannot rename temporary file into place", err);
  }
  temp_path_.clear();
  return fsync_folder(path_);
}

Status write_file_atomic(const std::string& path, std::span<const std::byte> bytes) {
  SINEW_ASSIGN_OR_RETURN(AtomicFileWriter writer, AtomicFileWriter::create(path));
  SINEW_RETURN_IF_ERROR(writer.write(bytes));
  return writer.commit();
}

Status write_file_atomic(const std::string& path, std::string_view text) {
  return write_file_atomic(path, std::as_bytes(std::span<const char>(text.data(), text.size())));
}

Status replace_file_atomic(const std::string& temp_path, const std::string& path) {
  const int fd = ::open(temp_path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return io_error(temp_path, "cannot open temporary file", errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) {
    ::unlink(temp_path.c_str());
    return io_error(path, "fsync failed", err);
  }
  if (::rename(temp_path.c_str(), path.c_str()) != 0) {
    const int rename_err = errno;
    ::unlink(temp_path.c_str());
    return io_error(path, "cannot rename temporary file into place", rename_err);
  }
  return fsync_folder(path);
}

Expected<std::string> read_file_text(const std::string& path) {
  SINEW_RETURN_IF_ERROR(check_regular_file(path));
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    const int err = errno;
    return make_error(err == ENOENT ? ErrorCode::kNotFound : ErrorCode::kIoError, path, "", "",
                      std::string("cannot open: ") + std::strerror(err));
  }
  std::string text;
  char buffer[1 << 16];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) return make_error(ErrorCode::kIoError, path, "", "", "read failed");
  return text;
}

}  // namespace sinew
