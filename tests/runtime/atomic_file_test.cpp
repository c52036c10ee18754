#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "runtime/io/atomic_file.h"
#include "tests/support/temp_dir.h"

namespace sinew {
namespace {

namespace fs = std::filesystem;

int files_in(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(AtomicFile, WritesAndReplaces) {
  testing_support::TempDir dir;
  const std::string path = dir.file("out.txt");
  ASSERT_TRUE(write_file_atomic(path, std::string_view("first")).ok());
  EXPECT_EQ(*read_file_text(path), "first");
  ASSERT_TRUE(write_file_atomic(path, std::string_view("second, longer")).ok());
  EXPECT_EQ(*read_file_text(path), "second, longer");
  EXPECT_EQ(files_in(dir.path()), 1) << "no temporary file may be left behind";
}

TEST(AtomicFile, OldFileSurvivesAnAbandonedWrite) {
  testing_support::TempDir dir;
  const std::string path = dir.file("pack.bin");
  ASSERT_TRUE(write_file_atomic(path, std::string_view("good old contents")).ok());
  {
    auto writer = AtomicFileWriter::create(path);
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE(writer->write(std::string_view("half of a new")).ok());
    // While the write is in flight the destination is untouched.
    EXPECT_EQ(*read_file_text(path), "good old contents");
    EXPECT_TRUE(fs::exists(writer->temp_path()));
    // Destroyed without commit(): as when a bake fails or is interrupted.
  }
  EXPECT_EQ(*read_file_text(path), "good old contents");
  EXPECT_EQ(files_in(dir.path()), 1);
}

TEST(AtomicFile, OldFileSurvivesAFailedCommit) {
  testing_support::TempDir dir;
  // The destination is a non-empty folder: rename cannot replace it.
  const std::string path = dir.file("target");
  fs::create_directories(fs::path(path) / "keep");
  auto writer = AtomicFileWriter::create(path);
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer->write(std::string_view("data")).ok());
  Status s = writer->commit();
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_EQ(s.file(), path);
  EXPECT_TRUE(fs::is_directory(fs::path(path) / "keep"));
  EXPECT_EQ(files_in(dir.path()), 1) << "the temporary file must be removed on failure";
}

TEST(AtomicFile, MissingFolderIsAClearError) {
  testing_support::TempDir dir;
  const std::string path = dir.file("no/such/folder/out.bin");
  Status s = write_file_atomic(path, std::string_view("x"));
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.code(), ErrorCode::kIoError);
  EXPECT_THAT(s.message(), ::testing::HasSubstr("no/such/folder"));
}

TEST(AtomicFile, WriteAfterCommitIsRejected) {
  testing_support::TempDir dir;
  auto writer = AtomicFileWriter::create(dir.file("a.bin"));
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer->commit().ok());
  EXPECT_EQ(writer->write(std::string_view("late")).code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(writer->commit().code(), ErrorCode::kInvalidArgument);
}

TEST(AtomicFile, TempNameKeepsExtensionAndFolder) {
  const std::string t = temp_path_beside("out/frames/color.png");
  EXPECT_EQ(t.rfind("out/frames/.color.tmp-", 0), 0u) << t;
  EXPECT_EQ(t.substr(t.size() - 4), ".png");
  EXPECT_NE(temp_path_beside("x.exr"), temp_path_beside("x.exr"));
}

TEST(AtomicFile, ReadMissingFileIsNotFound) {
  EXPECT_EQ(read_file_text("/nonexistent/sinew.txt").status().code(), ErrorCode::kNotFound);
}

}  // namespace
}  // namespace sinew
