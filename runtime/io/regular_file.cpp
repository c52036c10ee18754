#include "runtime/io/regular_file.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstring>

namespace sinew {
namespace {

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

}  // namespace

Status check_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    const int err = errno;
    return make_error(err == ENOENT || err == ENOTDIR ? ErrorCode::kNotFound : ErrorCode::kIoError, path, "", "",
                      err == ENOENT ? "no such file" : std::string("cannot stat: ") + std::strerror(err));
  }
  if (!S_ISREG(st.st_mode)) {
    return make_error(ErrorCode::kInvalidArgument, path, "", "",
                      std::string("is ") + kind_of(st.st_mode) + ", not a regular file");
  }
  return {};
}

}  // namespace sinew
