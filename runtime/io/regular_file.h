// Input files must be regular files: opening a FIFO for reading blocks
// until some writer appears (forever, for a stray named pipe), and a
// device or a directory is never an asset. Every reader of input files
// asks here first, without opening the path.
#pragma once

#include <string>

#include "runtime/core/status.h"

namespace sinew {

// OK for a regular file (symbolic links followed). Otherwise kNotFound
// when nothing is at `path`, or kInvalidArgument naming what is there
// ("a FIFO", "a directory", ...).
Status check_regular_file(const std::string& path);

}  // namespace sinew
