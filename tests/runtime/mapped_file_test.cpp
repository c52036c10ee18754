#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstring>
#include <string>

#include "runtime/io/atomic_file.h"
#include "runtime/io/mapped_file.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

TEST(MappedFile, MapsContents) {
  testing_support::TempDir dir;
  const std::string path = dir.file("data.bin");
  ASSERT_TRUE(write_file_atomic(path, std::string_view("hello, sinew")).ok());
  auto file = MappedFile::open(path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  ASSERT_EQ(file->size(), 12u);
  EXPECT_EQ(std::memcmp(file->bytes().data(), "hello, sinew", 12), 0);
  // Moving keeps the mapping valid.
  MappedFile moved = std::move(file).value();
  EXPECT_EQ(std::memcmp(moved.bytes().data(), "hello, sinew", 12), 0);
}

TEST(MappedFile, EmptyFileIsEmptySpan) {
  testing_support::TempDir dir;
  const std::string path = dir.file("empty.bin");
  ASSERT_TRUE(write_file_atomic(path, std::string_view()).ok());
  auto file = MappedFile::open(path);
  ASSERT_TRUE(file.ok()) << file.status().message();
  EXPECT_EQ(file->size(), 0u);
  EXPECT_TRUE(file->bytes().empty());
}

TEST(MappedFile, MissingFileIsNotFoundAndNamesThePath) {
  auto file = MappedFile::open("/nonexistent/sinew/none.pack");
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.status().code(), ErrorCode::kNotFound);
  EXPECT_EQ(file.status().file(), "/nonexistent/sinew/none.pack");
}

TEST(MappedFile, FolderIsRejected) {
  testing_support::TempDir dir;
  auto file = MappedFile::open(dir.path().string());
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(file.status().message().find("is a directory, not a regular file"), std::string::npos)
      << file.status().message();
}

// A FIFO is refused from its kind, before any open() that would wait for
// a writer (the test would hang there); so is it by read_file_text.
TEST(MappedFile, FifoIsRefusedWithoutOpeningIt) {
  testing_support::TempDir dir;
  const std::string path = dir.file("pipe.pack");
  ASSERT_EQ(::mkfifo(path.c_str(), 0600), 0);
  auto file = MappedFile::open(path);
  ASSERT_FALSE(file.ok());
  EXPECT_EQ(file.status().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(file.status().file(), path);
  EXPECT_NE(file.status().message().find("FIFO"), std::string::npos) << file.status().message();
  auto text = read_file_text(path);
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.status().message().find("FIFO"), std::string::npos) << text.status().message();
}

}  // namespace
}  // namespace sinew
