// Content-pack round trips: what PackWriter writes, PackReader gives back
// byte for byte, in place, 64-byte aligned, and deterministically.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <unistd.h>
#include <vector>

#include "runtime/io/mapped_file.h"
#include "runtime/pack/checksum.h"
#include "runtime/pack/pack_format.h"
#include "runtime/pack/pack_reader.h"
#include "runtime/pack/pack_writer.h"

namespace sinew {
namespace {

using ::testing::ElementsAreArray;
using ::testing::HasSubstr;

// A deterministic, section-specific byte pattern (no two sections alike).
std::vector<std::byte> pattern(std::size_t size, std::uint32_t seed) {
  std::vector<std::byte> out(size);
  std::uint64_t state = 0x9e3779b97f4a7c15ull * (seed + 1);
  for (auto& b : out) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    b = static_cast<std::byte>(state >> 24);
  }
  return out;
}

struct TestSection {
  SectionId id;
  std::uint32_t version;
  std::vector<std::byte> payload;
};

// Sizes around the alignment boundary, an empty one and a large one.
std::vector<TestSection> varied_sections() {
  return {
      {make_section_id("EMPT"), 1, {}},
      {make_section_id("ONE_"), 2, pattern(1, 1)},
      {make_section_id("S063"), 3, pattern(63, 2)},
      {make_section_id("S064"), 4, pattern(64, 3)},
      {make_section_id("S065"), 0xfffffffeu, pattern(65, 4)},
      {make_section_id("MIB1"), 7, pattern(std::size_t{1} << 20, 5)},
  };
}

// Byte-exact comparison; gmock's ElementsAreArray is too slow for a MiB under ASan.
::testing::AssertionResult same_bytes(std::span<const std::byte> actual,
                                      std::span<const std::byte> expected) {
  if (actual.size() != expected.size()) {
    return ::testing::AssertionFailure()
           << "size " << actual.size() << ", expected " << expected.size();
  }
  const auto [a, e] = std::mismatch(actual.begin(), actual.end(), expected.begin());
  if (a != actual.end()) {
    return ::testing::AssertionFailure() << "first difference at byte " << (a - actual.begin());
  }
  return ::testing::AssertionSuccess();
}

PackWriter writer_for(const std::vector<TestSection>& sections) {
  PackWriter writer;
  for (const auto& s : sections) {
    EXPECT_TRUE(writer.add_section(s.id, s.version, s.payload).ok());
  }
  return writer;
}

std::vector<std::byte> serialize_ok(const PackWriter& writer) {
  auto bytes = writer.serialize();
  EXPECT_TRUE(bytes.ok()) << (bytes.ok() ? "" : bytes.status().message());
  return bytes.ok() ? std::move(bytes).value() : std::vector<std::byte>{};
}

void expect_sections_match(const PackReader& reader, const std::vector<TestSection>& expected) {
  ASSERT_EQ(reader.section_count(), expected.size());
  EXPECT_EQ(reader.version(), (PackVersion{kPackVersionMajor, kPackVersionMinor}));
  std::uint64_t previous_end = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    SCOPED_TRACE("section " + section_id_name(expected[i].id));
    const SectionInfo& info = reader.sections()[i];
    EXPECT_EQ(info.id, expected[i].id);
    EXPECT_EQ(info.version, expected[i].version);
    EXPECT_EQ(info.size, expected[i].payload.size());
    EXPECT_EQ(info.offset % kSectionAlignment, 0u);
    EXPECT_GE(info.offset, previous_end) << "sections are laid out in insertion order";
    previous_end = info.offset + info.size;

    const SectionInfo* found = reader.find(expected[i].id);
    ASSERT_NE(found, nullptr);
    EXPECT_EQ(found, &info);

    auto bytes = reader.section_bytes(expected[i].id);
    ASSERT_TRUE(bytes.ok()) << bytes.status().message();
    EXPECT_TRUE(same_bytes(*bytes, expected[i].payload));
    // In place: the span points into the pack at the recorded offset.
    EXPECT_EQ(bytes->data(), reader.bytes().data() + info.offset);
    EXPECT_EQ((bytes->data() - reader.bytes().data()) % kSectionAlignment, 0);
  }
}

class PackRoundTripTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(::testing::TempDir()) /
           ("sinew_pack_roundtrip_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  std::filesystem::path dir_;
};

TEST(PackFormatTest, SectionIdsAreFourCcInFileOrder) {
  constexpr SectionId id = make_section_id("SKEL");
  EXPECT_EQ(static_cast<std::uint32_t>(id), 0x4c454b53u);  // 'S' 'K' 'E' 'L' little-endian
  EXPECT_EQ(section_id_name(id), "SKEL");
  EXPECT_EQ(section_id_name(SectionId{0x2a}), "0x0000002a");
  EXPECT_EQ(section_id_name(SectionId{0xffffffffu}), "0xffffffff");
}

TEST(PackFormatTest, ChecksumIsXxh3OfTheBytes) {
  // XXH3_64 of the empty input with seed 0 (a published test vector).
  EXPECT_EQ(checksum64({}), 0x2d06800538d394c2ull);
  const auto data = pattern(100, 9);
  EXPECT_EQ(checksum64(data), checksum64(std::span(data)));
  auto other = data;
  other[50] ^= std::byte{1};
  EXPECT_NE(checksum64(data), checksum64(other));
}

TEST_F(PackRoundTripTest, RoundTripThroughBytes) {
  const auto sections = varied_sections();
  const auto bytes = serialize_ok(writer_for(sections));
  auto reader = PackReader::from_bytes(bytes, "memory.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->name(), "memory.pack");
  EXPECT_EQ(reader->bytes().data(), bytes.data()) << "from_bytes views, does not copy";
  EXPECT_EQ(reader->bytes().size(), bytes.size());
  expect_sections_match(*reader, sections);
}

TEST_F(PackRoundTripTest, RoundTripThroughFile) {
  const auto sections = varied_sections();
  const PackWriter writer = writer_for(sections);
  const std::string file = path("varied.pack");
  ASSERT_TRUE(writer.write(file).ok());

  auto reader = PackReader::open(file);
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->name(), file);
  expect_sections_match(*reader, sections);
  // The mapping is page aligned, so file-relative alignment is also absolute.
  for (const SectionInfo& info : reader->sections()) {
    const auto span = reader->section_bytes(info);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(span.data()) % kSectionAlignment, 0u);
  }

  // The streamed file and serialize() agree byte for byte.
  auto mapped = MappedFile::open(file);
  ASSERT_TRUE(mapped.ok());
  EXPECT_TRUE(same_bytes(mapped->bytes(), serialize_ok(writer)));
}

TEST_F(PackRoundTripTest, ReaderStaysValidWhenMoved) {
  const auto sections = varied_sections();
  const std::string file = path("moved.pack");
  ASSERT_TRUE(writer_for(sections).write(file).ok());
  auto opened = PackReader::open(file);
  ASSERT_TRUE(opened.ok());
  PackReader reader = std::move(opened).value();
  PackReader moved = std::move(reader);
  expect_sections_match(moved, sections);
}

TEST_F(PackRoundTripTest, EmptyPackRoundTrips) {
  const PackWriter writer;
  const auto bytes = serialize_ok(writer);
  EXPECT_EQ(bytes.size(), kHeaderSize);
  auto reader = PackReader::from_bytes(bytes, "empty.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->section_count(), 0u);
  EXPECT_EQ(reader->find(make_section_id("SKEL")), nullptr);

  const std::string file = path("empty.pack");
  ASSERT_TRUE(writer.write(file).ok());
  EXPECT_TRUE(PackReader::open(file).ok());
}

TEST_F(PackRoundTripTest, EmptySectionsAtTheEndRoundTrip) {
  // A trailing empty section still sits at an aligned offset inside the file.
  const std::vector<TestSection> sections = {
      {make_section_id("DATA"), 1, pattern(5, 1)},
      {make_section_id("NIL1"), 1, {}},
      {make_section_id("NIL2"), 1, {}},
  };
  const auto bytes = serialize_ok(writer_for(sections));
  auto reader = PackReader::from_bytes(bytes, "tail.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  expect_sections_match(*reader, sections);
  EXPECT_LE(reader->sections()[2].offset, bytes.size());
}

TEST_F(PackRoundTripTest, LayoutIsHeaderTableThenAlignedPayloads) {
  const auto sections = varied_sections();
  const auto bytes = serialize_ok(writer_for(sections));
  const PackHeader header = load_pack_header(std::span(bytes).first<kHeaderSize>());
  EXPECT_EQ(header.table_offset, kHeaderSize);
  EXPECT_EQ(header.section_count, sections.size());
  EXPECT_EQ(header.file_size, bytes.size());
  auto reader = PackReader::from_bytes(bytes, "layout.pack");
  ASSERT_TRUE(reader.ok());
  const std::uint64_t table_end = kHeaderSize + sections.size() * kSectionEntrySize;
  EXPECT_EQ(reader->sections()[0].offset, (table_end + 63) / 64 * 64);
  // Each section starts at the first aligned offset after the previous one.
  for (std::size_t i = 1; i < sections.size(); ++i) {
    const SectionInfo& prev = reader->sections()[i - 1];
    EXPECT_EQ(reader->sections()[i].offset, (prev.offset + prev.size + 63) / 64 * 64);
  }
}

TEST_F(PackRoundTripTest, OutputIsDeterministic) {
  const auto sections = varied_sections();
  const PackWriter writer = writer_for(sections);
  const auto first = serialize_ok(writer);
  const auto second = serialize_ok(writer);
  EXPECT_EQ(first, second);
  // A second writer fed the same sections (through the moving overload).
  PackWriter other;
  for (auto s : varied_sections()) {
    ASSERT_TRUE(other.add_section(s.id, s.version, std::move(s.payload)).ok());
  }
  EXPECT_EQ(serialize_ok(other), first);

  const std::string a = path("a.pack");
  const std::string b = path("b.pack");
  ASSERT_TRUE(writer.write(a).ok());
  ASSERT_TRUE(other.write(b).ok());
  auto fa = MappedFile::open(a);
  auto fb = MappedFile::open(b);
  ASSERT_TRUE(fa.ok() && fb.ok());
  EXPECT_TRUE(same_bytes(fa->bytes(), fb->bytes()));
}

TEST_F(PackRoundTripTest, WriterRejectsDuplicateIds) {
  PackWriter writer;
  const auto payload = pattern(10, 1);
  ASSERT_TRUE(writer.add_section(make_section_id("SKEL"), 1, payload).ok());
  const Status copy = writer.add_section(make_section_id("SKEL"), 2, payload);
  EXPECT_EQ(copy.code(), ErrorCode::kDuplicate);
  EXPECT_THAT(copy.message(), HasSubstr("'SKEL'"));
  const Status moved = writer.add_section(make_section_id("SKEL"), 2, pattern(3, 2));
  EXPECT_EQ(moved.code(), ErrorCode::kDuplicate);
  EXPECT_EQ(writer.section_count(), 1u) << "a rejected section leaves the writer unchanged";

  const auto bytes = serialize_ok(writer);
  auto reader = PackReader::from_bytes(bytes, "dup.pack");
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->sections()[0].version, 1u);
}

TEST_F(PackRoundTripTest, WriterEnforcesTheSectionLimit) {
  PackWriter writer;
  for (std::uint32_t i = 0; i < kMaxSections; ++i) {
    ASSERT_TRUE(writer.add_section(SectionId{i}, 0, std::span<const std::byte>()).ok());
  }
  const Status over = writer.add_section(SectionId{kMaxSections}, 0, std::span<const std::byte>());
  EXPECT_EQ(over.code(), ErrorCode::kLimitExceeded);
  // The largest legal pack reads back.
  const auto bytes = serialize_ok(writer);
  auto reader = PackReader::from_bytes(bytes, "max.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->section_count(), kMaxSections);
  EXPECT_NE(reader->find(SectionId{kMaxSections - 1}), nullptr);
}

TEST_F(PackRoundTripTest, MissingSectionIsNotFound) {
  const auto bytes = serialize_ok(writer_for(varied_sections()));
  auto reader = PackReader::from_bytes(bytes, "memory.pack");
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->find(make_section_id("NOPE")), nullptr);
  EXPECT_FALSE(reader->contains(make_section_id("NOPE")));
  EXPECT_TRUE(reader->contains(make_section_id("S064")));
  auto missing = reader->section_bytes(make_section_id("NOPE"));
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_THAT(missing.status().message(), HasSubstr("'NOPE'"));
  EXPECT_THAT(missing.status().message(), HasSubstr("memory.pack"));
  auto as_ints = reader->section_as<std::uint32_t>(make_section_id("NOPE"));
  ASSERT_FALSE(as_ints.ok());
  EXPECT_EQ(as_ints.status().code(), ErrorCode::kNotFound);
}

TEST_F(PackRoundTripTest, SectionInfoByIndex) {
  const auto bytes = serialize_ok(writer_for(varied_sections()));
  auto reader = PackReader::from_bytes(bytes, "memory.pack");
  ASSERT_TRUE(reader.ok());
  auto info = reader->section_info(3);
  ASSERT_TRUE(info.ok());
  EXPECT_EQ(info->id, make_section_id("S064"));
  auto past = reader->section_info(6);
  ASSERT_FALSE(past.ok());
  EXPECT_EQ(past.status().code(), ErrorCode::kOutOfBounds);
}

TEST_F(PackRoundTripTest, SectionAsViewsTypedArraysInPlace) {
  std::vector<std::uint32_t> ints(100);
  for (std::uint32_t i = 0; i < ints.size(); ++i) ints[i] = i * 2654435761u;
  std::vector<double> doubles = {1.5, -2.25, 1e300};
  PackWriter writer;
  ASSERT_TRUE(writer.add_section(make_section_id("INTS"), 1, std::as_bytes(std::span(ints))).ok());
  ASSERT_TRUE(
      writer.add_section(make_section_id("DBLS"), 1, std::as_bytes(std::span(doubles))).ok());
  ASSERT_TRUE(writer.add_section(make_section_id("ODD_"), 1, pattern(7, 3)).ok());
  ASSERT_TRUE(writer.add_section(make_section_id("NONE"), 1, std::span<const std::byte>()).ok());
  const std::string file = path("typed.pack");
  ASSERT_TRUE(writer.write(file).ok());
  auto reader = PackReader::open(file);
  ASSERT_TRUE(reader.ok()) << reader.status().message();

  auto view = reader->section_as<std::uint32_t>(make_section_id("INTS"));
  ASSERT_TRUE(view.ok()) << view.status().message();
  EXPECT_THAT(*view, ElementsAreArray(ints));
  EXPECT_EQ(static_cast<const void*>(view->data()),
            static_cast<const void*>(reader->section_bytes(make_section_id("INTS"))->data()));

  auto dbl = reader->section_as<double>(make_section_id("DBLS"));
  ASSERT_TRUE(dbl.ok());
  EXPECT_THAT(*dbl, ElementsAreArray(doubles));

  auto empty = reader->section_as<double>(make_section_id("NONE"));
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(empty->empty());

  // 7 bytes are not a whole number of uint32_t.
  auto odd = reader->section_as<std::uint32_t>(make_section_id("ODD_"));
  ASSERT_FALSE(odd.ok());
  EXPECT_EQ(odd.status().code(), ErrorCode::kInvalidData);
  EXPECT_THAT(odd.status().message(), HasSubstr("section[2].size"));
  EXPECT_THAT(odd.status().message(), HasSubstr("'ODD_'"));
  EXPECT_TRUE(reader->section_as<std::uint8_t>(make_section_id("ODD_")).ok());
}

TEST_F(PackRoundTripTest, SectionAsChecksMemoryAlignment) {
  std::vector<double> doubles = {1.0, 2.0};
  PackWriter writer;
  ASSERT_TRUE(
      writer.add_section(make_section_id("DBLS"), 1, std::as_bytes(std::span(doubles))).ok());
  const auto bytes = serialize_ok(writer);
  // The same pack one byte into an 8-aligned buffer: valid, but the payload
  // is not aligned for double in memory.
  std::vector<double> storage(bytes.size() / sizeof(double) + 2);
  auto* base = reinterpret_cast<std::byte*>(storage.data()) + 1;
  std::copy(bytes.begin(), bytes.end(), base);
  auto reader = PackReader::from_bytes(std::span<const std::byte>(base, bytes.size()), "shifted");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  auto view = reader->section_as<double>(make_section_id("DBLS"));
  ASSERT_FALSE(view.ok());
  EXPECT_EQ(view.status().code(), ErrorCode::kMisaligned);
  EXPECT_TRUE(reader->section_as<std::uint8_t>(make_section_id("DBLS")).ok());
}

TEST_F(PackRoundTripTest, OpeningAMissingFileIsNotFound) {
  const std::string file = path("does_not_exist.pack");
  auto reader = PackReader::open(file);
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.status().code(), ErrorCode::kNotFound);
  EXPECT_THAT(reader.status().message(), HasSubstr("does_not_exist.pack"));
}

TEST_F(PackRoundTripTest, WriteReplacesAnExistingPackAtomically) {
  const std::string file = path("replace.pack");
  PackWriter first;
  ASSERT_TRUE(first.add_section(make_section_id("OLD_"), 1, pattern(100, 1)).ok());
  ASSERT_TRUE(first.write(file).ok());
  PackWriter second;
  ASSERT_TRUE(second.add_section(make_section_id("NEW_"), 1, pattern(200, 2)).ok());
  ASSERT_TRUE(second.write(file).ok());
  auto reader = PackReader::open(file);
  ASSERT_TRUE(reader.ok());
  EXPECT_TRUE(reader->contains(make_section_id("NEW_")));
  EXPECT_FALSE(reader->contains(make_section_id("OLD_")));
  // No temporary files are left beside it.
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir_)) ++entries;
  EXPECT_EQ(entries, 1u);
}

TEST_F(PackRoundTripTest, WriteIntoAMissingFolderFails) {
  PackWriter writer;
  ASSERT_TRUE(writer.add_section(make_section_id("DATA"), 1, pattern(10, 1)).ok());
  const std::string file = path("no/such/folder/x.pack");
  const Status status = writer.write(file);
  EXPECT_FALSE(status.ok());
  EXPECT_EQ(status.code(), ErrorCode::kIoError);
  EXPECT_FALSE(std::filesystem::exists(file));
}

}  // namespace
}  // namespace sinew
