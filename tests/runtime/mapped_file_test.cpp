#include <gtest/gtest.h>

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
  EXPECT_EQ(file.status().code(), ErrorCode::kIoError);
}

}  // namespace
}  // namespace sinew
