// Corrupted content packs: every way a pack can be damaged yields its own
// specific error naming the field, never a crash or an out-of-bounds read
// (this suite also runs under ASan + UBSan).
//
// To reach each validation step rather than always tripping the first
// checksum, mutations edit a field and then re-seal the checksums that cover
// it (edit_header / edit_entry below); "raw" mutations leave them stale.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <ostream>
#include <span>
#include <string>
#include <unistd.h>
#include <vector>

#include "runtime/io/atomic_file.h"
#include "runtime/pack/checksum.h"
#include "runtime/pack/pack_format.h"
#include "runtime/pack/pack_reader.h"
#include "runtime/pack/pack_writer.h"

namespace sinew {
namespace {

using ::testing::HasSubstr;
using Bytes = std::vector<std::byte>;

constexpr std::uint64_t kU64Max = std::numeric_limits<std::uint64_t>::max();

Bytes pattern(std::size_t size, std::uint32_t seed) {
  Bytes out(size);
  std::uint32_t state = 2463534242u + seed * 7919u;
  for (auto& b : out) {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    b = static_cast<std::byte>(state | 1u);  // never zero: a payload byte is never "padding"
  }
  return out;
}

// Five sections of uneven sizes, so the file has padding between some of
// them and none between others:
//   [0] SKEL 200 B   [1] MESH 1000 B   [2] CLIP 64 B   [3] LIMS 17 B   [4] TREE 300 B
const Bytes& base_pack() {
  static const Bytes bytes = [] {
    PackWriter writer;
    const char* ids[] = {"SKEL", "MESH", "CLIP", "LIMS", "TREE"};
    const std::size_t sizes[] = {200, 1000, 64, 17, 300};
    for (std::uint32_t i = 0; i < 5; ++i) {
      const char* s = ids[i];
      const char fourcc[5] = {s[0], s[1], s[2], s[3], '\0'};
      const Status added = writer.add_section(make_section_id(fourcc), i + 1, pattern(sizes[i], i));
      if (!added.ok()) std::abort();
    }
    auto out = writer.serialize();
    if (!out.ok()) std::abort();
    return std::move(out).value();
  }();
  return bytes;
}

// --- raw field access and re-sealing --------------------------------------------

PackHeader header_of(const Bytes& b) { return load_pack_header(std::span(b).first<kHeaderSize>()); }

void put_header(Bytes& b, const PackHeader& h) {
  store_pack_header(h, std::span(b).first<kHeaderSize>());
}

// Entries of the base pack's table (at kHeaderSize), regardless of what the
// (possibly edited) header says.
SectionEntry entry_of(const Bytes& b, std::size_t i) {
  return load_section_entry(
      std::span(b).subspan(kHeaderSize + i * kSectionEntrySize).first<kSectionEntrySize>());
}

void put_entry(Bytes& b, std::size_t i, const SectionEntry& e) {
  store_section_entry(
      e, std::span(b).subspan(kHeaderSize + i * kSectionEntrySize).first<kSectionEntrySize>());
}

// Recomputes the table checksum (when the header's table lies in the file)
// and then the header checksum, so the edited pack passes both and the
// reader's deeper checks get to judge the edit.
void reseal(Bytes& b) {
  if (b.size() < kHeaderSize) return;
  PackHeader h = header_of(b);
  const std::uint64_t table_size = std::uint64_t{h.section_count} * kSectionEntrySize;
  if (h.section_count <= kMaxSections && h.table_offset <= b.size() &&
      table_size <= b.size() - h.table_offset) {
    h.table_checksum = checksum64(std::span(b).subspan(h.table_offset, table_size));
  }
  h.header_checksum = pack_header_checksum(h);
  put_header(b, h);
}

template <typename F>
void edit_header(Bytes& b, F edit) {
  PackHeader h = header_of(b);
  edit(h);
  put_header(b, h);
  reseal(b);
}

template <typename F>
void edit_header_raw(Bytes& b, F edit) {
  PackHeader h = header_of(b);
  edit(h);
  put_header(b, h);
}

template <typename F>
void edit_entry(Bytes& b, std::size_t i, F edit) {
  SectionEntry e = entry_of(b, i);
  edit(e);
  put_entry(b, i, e);
  reseal(b);
}

void flip(Bytes& b, std::size_t offset, std::uint8_t mask = 0x01) {
  b.at(offset) ^= std::byte{mask};
}

// --- the table of corrupted variants ----------------------------------------------

struct Corruption {
  std::string name;
  std::function<void(Bytes&)> mutate;
  ErrorCode code;
  std::string field;       // exact Status::field(), also required in message()
  std::string detail = {};  // optional substring of message()
};

void PrintTo(const Corruption& c, std::ostream* os) { *os << c.name; }

std::vector<Corruption> corruptions() {
  const Bytes& base = base_pack();
  const PackHeader h0 = header_of(base);
  const std::uint64_t size = base.size();
  const std::uint64_t table_end = h0.table_offset + 5 * kSectionEntrySize;
  SectionEntry e[5];
  for (std::size_t i = 0; i < 5; ++i) e[i] = entry_of(base, i);

  using E = ErrorCode;
  std::vector<Corruption> cases = {
      // Too short for a header, or not a pack at all.
      {"EmptyFile", [](Bytes& b) { b.clear(); }, E::kTruncated, "header", "0 bytes"},
      {"OnlyTheMagic", [](Bytes& b) { b.resize(8); }, E::kTruncated, "header"},
      {"HeaderMinusOneByte", [](Bytes& b) { b.resize(kHeaderSize - 1); }, E::kTruncated,
       "header"},
      {"AllZeros", [](Bytes& b) { b.assign(4096, std::byte{0}); }, E::kBadMagic, "header.magic"},
      {"PngFile",
       [](Bytes& b) {
         b.assign(200, std::byte{0});
         const unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
         for (std::size_t i = 0; i < 8; ++i) b[i] = std::byte{png[i]};
       },
       E::kBadMagic, "header.magic", "\\x89PNG"},
      {"MagicFirstByteFlipped", [](Bytes& b) { flip(b, 0, 0x20); }, E::kBadMagic,
       "header.magic"},
      {"MagicTerminatorNotZero", [](Bytes& b) { b[7] = std::byte{'X'}; }, E::kBadMagic,
       "header.magic"},

      // Byte order and version.
      {"EndianTagByteSwapped", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.endian_tag = kEndianTagSwapped; }); },
       E::kUnsupportedVersion, "header.endian_tag", "big-endian"},
      {"EndianTagGarbage", [](Bytes& b) { edit_header_raw(b, [](PackHeader& h) {
         h.endian_tag = 0xdeadbeef; }); },
       E::kBadMagic, "header.endian_tag", "0xdeadbeef"},
      {"MajorVersion2", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.version_major = 2; }); },
       E::kUnsupportedVersion, "header.version", "= 2.0"},
      {"MajorVersion0Unsealed", [](Bytes& b) { edit_header_raw(b, [](PackHeader& h) {
         h.version_major = 0; }); },
       E::kUnsupportedVersion, "header.version", "= 0.0"},
      {"MajorVersionHighBitFlipped", [](Bytes& b) { flip(b, 13, 0x80); },
       E::kUnsupportedVersion, "header.version", "= 32769.0"},

      // Header checksum and the fields it protects.
      {"MinorVersionFlippedUnsealed", [](Bytes& b) { flip(b, 14); }, E::kChecksumMismatch,
       "header.header_checksum"},
      {"HeaderChecksumFlipped", [](Bytes& b) { flip(b, 48, 0x10); }, E::kChecksumMismatch,
       "header.header_checksum"},
      {"SectionCountFlippedUnsealed", [](Bytes& b) { flip(b, 20, 0x02); },
       E::kChecksumMismatch, "header.header_checksum"},
      {"HeaderSize128", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.header_size = 128; }); },
       E::kInvalidData, "header.header_size", "= 128"},
      {"HeaderReservedNotZero", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.reserved = 1; }); },
       E::kInvalidData, "header.reserved"},

      // Declared size against the real one.
      {"FileSizeOneTooLarge", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.file_size += 1; }); },
       E::kTruncated, "header.file_size", "only " + std::to_string(size) + " bytes"},
      {"FileSizeOneTooSmall", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.file_size -= 1; }); },
       E::kInvalidData, "header.file_size", "1 trailing bytes"},
      {"FileSizeHuge", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.file_size = kU64Max; }); },
       E::kTruncated, "header.file_size", std::to_string(kU64Max)},
      {"TrailingGarbage", [](Bytes& b) { b.insert(b.end(), 16, std::byte{0xab}); },
       E::kInvalidData, "header.file_size", "16 trailing bytes"},
      {"TrailingZeroByte", [](Bytes& b) { b.push_back(std::byte{0}); }, E::kInvalidData,
       "header.file_size"},

      // Section count and table placement.
      {"SectionCountHuge", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.section_count = 0xffffffffu; }); },
       E::kLimitExceeded, "header.section_count", "4294967295"},
      {"SectionCountOverLimit", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.section_count = kMaxSections + 1; }); },
       E::kLimitExceeded, "header.section_count"},
      {"SectionCountAtLimitTableTooLong", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.section_count = kMaxSections; }); },
       E::kOutOfBounds, "header.table_offset", "4096 entries"},
      {"SectionCountOneLessLeavesPayloadAsPadding",
       [](Bytes& b) { edit_header(b, [](PackHeader& h) { h.section_count = 4; }); },
       E::kInvalidData, "padding at offset " + std::to_string(table_end - kSectionEntrySize)},
      {"TableOffsetZero", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.table_offset = 0; }); },
       E::kOverlap, "header.table_offset", "overlaps the header"},
      {"TableOffsetInsideHeader", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.table_offset = 32; }); },
       E::kOverlap, "header.table_offset"},
      {"TableOffsetMisaligned", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.table_offset = 72; }); },
       E::kMisaligned, "header.table_offset"},
      {"TableOffsetOverflows", [](Bytes& b) { edit_header(b, [](PackHeader& h) {
         h.table_offset = kU64Max - 63; }); },
       E::kOutOfBounds, "header.table_offset"},
      {"TableOffsetPastEnd", [size](Bytes& b) { edit_header(b, [size](PackHeader& h) {
         h.table_offset = (size + 63) / 64 * 64; }); },
       E::kOutOfBounds, "header.table_offset"},
      {"TableRunsOffTheEnd", [size](Bytes& b) { edit_header(b, [size](PackHeader& h) {
         h.table_offset = size / 64 * 64 - 64; }); },
       E::kOutOfBounds, "header.table_offset"},

      // Table checksum.
      {"TableChecksumFlipped", [](Bytes& b) { edit_header_raw(b, [](PackHeader& h) {
         h.table_checksum ^= 0x04;
         h.header_checksum = pack_header_checksum(h); }); },
       E::kChecksumMismatch, "header.table_checksum"},
      {"TableEntryOffsetFlippedUnsealed",
       [](Bytes& b) { flip(b, kHeaderSize + 2 * kSectionEntrySize + 8, 0x40); },
       E::kChecksumMismatch, "header.table_checksum"},
      {"TableLastByteFlippedUnsealed", [table_end](Bytes& b) { flip(b, table_end - 1); },
       E::kChecksumMismatch, "header.table_checksum"},

      // One section entry at a time (re-sealed).
      {"AlignmentField32", [](Bytes& b) { edit_entry(b, 2, [](SectionEntry& s) {
         s.alignment = 32; }); },
       E::kMisaligned, "section[2].alignment", "= 32"},
      {"AlignmentFieldZero", [](Bytes& b) { edit_entry(b, 0, [](SectionEntry& s) {
         s.alignment = 0; }); },
       E::kMisaligned, "section[0].alignment"},
      {"AlignmentField128", [](Bytes& b) { edit_entry(b, 1, [](SectionEntry& s) {
         s.alignment = 128; }); },
       E::kMisaligned, "section[1].alignment"},
      {"OffsetMisalignedBy8", [](Bytes& b) { edit_entry(b, 3, [](SectionEntry& s) {
         s.offset += 8; }); },
       E::kMisaligned, "section[3].offset"},
      {"OffsetMisalignedByMinus1", [](Bytes& b) { edit_entry(b, 3, [](SectionEntry& s) {
         s.offset -= 1; }); },
       E::kMisaligned, "section[3].offset"},
      {"UnknownFlag", [](Bytes& b) { edit_entry(b, 4, [](SectionEntry& s) {
         s.flags = 1; }); },
       E::kInvalidData, "section[4].flags"},
      {"EntryReservedNotZero", [](Bytes& b) { edit_entry(b, 0, [](SectionEntry& s) {
         s.reserved = 0x100; }); },
       E::kInvalidData, "section[0].reserved"},
      {"OffsetHuge", [](Bytes& b) { edit_entry(b, 1, [](SectionEntry& s) {
         s.offset = kU64Max - 63; }); },
       E::kOutOfBounds, "section[1].offset", "past the end"},
      {"OffsetNearTopMisaligned", [](Bytes& b) { edit_entry(b, 1, [](SectionEntry& s) {
         s.offset = kU64Max - 31; }); },
       E::kMisaligned, "section[1].offset", "18446744073709551584"},
      {"OffsetPastEnd", [size](Bytes& b) { edit_entry(b, 1, [size](SectionEntry& s) {
         s.offset = (size + 63) / 64 * 64 + 64; }); },
       E::kOutOfBounds, "section[1].offset"},
      {"OffsetPlusSizeOverflows", [](Bytes& b) { edit_entry(b, 2, [](SectionEntry& s) {
         s.size = kU64Max - 31; }); },
       E::kOutOfBounds, "section[2].size"},
      {"OffsetAndSizeBothHuge", [](Bytes& b) { edit_entry(b, 2, [](SectionEntry& s) {
         s.offset = 1ull << 63; s.size = 1ull << 63; }); },
       E::kOutOfBounds, "section[2].offset"},
      {"SizeOneBytePastEnd", [size](Bytes& b) { edit_entry(b, 4, [size](SectionEntry& s) {
         s.size = size - s.offset + 1; }); },
       E::kOutOfBounds, "section[4].size", "ends past the end"},
      {"SizeHuge", [](Bytes& b) { edit_entry(b, 4, [](SectionEntry& s) {
         s.size = 1ull << 63; }); },
       E::kOutOfBounds, "section[4].size"},
      {"SectionOverlapsHeader", [](Bytes& b) { edit_entry(b, 0, [](SectionEntry& s) {
         s.offset = 0; }); },
       E::kOverlap, "section[0].offset", "overlaps the header"},
      {"SectionOverlapsTable", [](Bytes& b) { edit_entry(b, 0, [](SectionEntry& s) {
         s.offset = 256; }); },
       E::kOverlap, "section[0].offset", "overlaps the section table"},
      {"EmptySectionInsideTable", [](Bytes& b) { edit_entry(b, 3, [](SectionEntry& s) {
         s.offset = 128; s.size = 0; }); },
       E::kOverlap, "section[3].offset"},
      {"SectionStartsWhereAnotherStarts", [e](Bytes& b) { edit_entry(b, 2, [e](SectionEntry& s) {
         s.offset = e[1].offset; }); },
       E::kOverlap, "section[2].offset", "overlaps section[1] 'MESH'"},
      {"SectionGrowsIntoTheNext", [](Bytes& b) { edit_entry(b, 1, [](SectionEntry& s) {
         s.size += 50; }); },
       E::kOverlap, "section[2].offset", "overlaps section[1]"},
      {"LastSectionMovedOntoFirst", [e](Bytes& b) { edit_entry(b, 4, [e](SectionEntry& s) {
         s.offset = e[0].offset; }); },
       E::kOverlap, "section[4].offset", "overlaps section[0] 'SKEL'"},
      {"SectionInsideAnother", [e](Bytes& b) { edit_entry(b, 3, [e](SectionEntry& s) {
         s.offset = e[1].offset + 128; }); },
       E::kOverlap, "section[3].offset", "overlaps section[1]"},
      {"DuplicateId", [e](Bytes& b) { edit_entry(b, 3, [e](SectionEntry& s) {
         s.id = e[1].id; }); },
       E::kDuplicate, "section[3].id", "same id as section[1]"},
      {"DuplicateIdFirstAndLast", [e](Bytes& b) { edit_entry(b, 4, [e](SectionEntry& s) {
         s.id = e[0].id; }); },
       E::kDuplicate, "section[4].id", "'SKEL'"},
      {"ShrunkSectionLeavesPayloadAsPadding", [](Bytes& b) { edit_entry(b, 3, [](SectionEntry& s) {
         s.size = 0; }); },
       E::kInvalidData, "padding at offset " + std::to_string(e[3].offset)},
      {"EntryChecksumFlipped", [](Bytes& b) { edit_entry(b, 1, [](SectionEntry& s) {
         s.checksum ^= 1; }); },
       E::kChecksumMismatch, "section[1].checksum", "'MESH'"},

      // Padding must be zero.
      {"PaddingAfterTable", [table_end](Bytes& b) { flip(b, table_end); }, E::kInvalidData,
       "padding at offset " + std::to_string(table_end)},
      {"PaddingBetweenSections", [e](Bytes& b) { flip(b, e[0].offset + e[0].size, 0x80); },
       E::kInvalidData, "padding at offset " + std::to_string(e[0].offset + e[0].size),
       "= 0x80"},
      {"PaddingJustBeforeSection", [e](Bytes& b) { flip(b, e[4].offset - 1); },
       E::kInvalidData, "padding at offset " + std::to_string(e[4].offset - 1)},
  };

  // A flipped byte in each payload: first, middle and last bytes.
  for (std::size_t i = 0; i < 5; ++i) {
    const std::string id = section_id_name(SectionId{e[i].id});
    const std::string field = "section[" + std::to_string(i) + "].checksum";
    const std::uint64_t first = e[i].offset;
    const std::uint64_t middle = e[i].offset + e[i].size / 2;
    const std::uint64_t last = e[i].offset + e[i].size - 1;
    cases.push_back({"PayloadFirstByteFlipped_" + id, [first](Bytes& b) { flip(b, first); },
                     E::kChecksumMismatch, field, "'" + id + "'"});
    cases.push_back({"PayloadMiddleByteFlipped_" + id, [middle](Bytes& b) { flip(b, middle); },
                     E::kChecksumMismatch, field});
    cases.push_back({"PayloadLastByteFlipped_" + id, [last](Bytes& b) { flip(b, last, 0x80); },
                     E::kChecksumMismatch, field});
  }
  return cases;
}

class PackCorruptionTest : public ::testing::TestWithParam<Corruption> {};

TEST_P(PackCorruptionTest, YieldsTheSpecificError) {
  const Corruption& c = GetParam();
  Bytes bytes = base_pack();
  c.mutate(bytes);
  auto reader = PackReader::from_bytes(bytes, "corrupt.pack");
  ASSERT_FALSE(reader.ok()) << "the corrupted pack was accepted";
  const Status& status = reader.status();
  EXPECT_EQ(status.code(), c.code) << status.message();
  EXPECT_EQ(status.field(), c.field) << status.message();
  EXPECT_THAT(status.message(), HasSubstr(c.field));
  EXPECT_THAT(status.message(), HasSubstr("corrupt.pack"));
  EXPECT_FALSE(status.value().empty()) << "errors name the bad value: " << status.message();
  if (!c.detail.empty()) {
    EXPECT_THAT(status.message(), HasSubstr(c.detail));
  }
}

INSTANTIATE_TEST_SUITE_P(Variants, PackCorruptionTest, ::testing::ValuesIn(corruptions()),
                         [](const auto& test) { return test.param.name; });

TEST(PackCorruptionCountTest, AtLeastThirtyDistinctVariants) {
  EXPECT_GE(corruptions().size(), 30u);
}

// --- sanity of the base pack and of the re-sealing helper ------------------------------

TEST(PackCorruptionHelpersTest, BasePackIsValidAndResealIsANoOp) {
  Bytes bytes = base_pack();
  auto reader = PackReader::from_bytes(bytes, "base.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->section_count(), 5u);
  reseal(bytes);
  EXPECT_EQ(bytes, base_pack());
}

TEST(PackCorruptionHelpersTest, MessageFormat) {
  Bytes bytes = base_pack();
  edit_entry(bytes, 2, [](SectionEntry& s) { s.offset += 8; });
  auto reader = PackReader::from_bytes(bytes, "cally.pack");
  ASSERT_FALSE(reader.ok());
  const SectionEntry e = entry_of(bytes, 2);
  EXPECT_EQ(reader.status().message(),
            "cally.pack: section[2].offset = " + std::to_string(e.offset) +
                ": not a multiple of the section alignment 64");
}

// --- truncation -------------------------------------------------------------------------

TEST(PackTruncationTest, InsideTheHeaderAtEveryByte) {
  for (std::size_t n = 0; n < kHeaderSize; ++n) {
    SCOPED_TRACE("length " + std::to_string(n));
    const Bytes cut(base_pack().begin(), base_pack().begin() + static_cast<std::ptrdiff_t>(n));
    auto reader = PackReader::from_bytes(cut, "cut.pack");
    ASSERT_FALSE(reader.ok());
    EXPECT_EQ(reader.status().code(), ErrorCode::kTruncated);
    EXPECT_EQ(reader.status().field(), "header");
  }
}

TEST(PackTruncationTest, AtEveryTableAndSectionBoundary) {
  const Bytes& base = base_pack();
  const PackHeader h = header_of(base);
  std::vector<std::uint64_t> cuts;
  for (std::uint64_t k = 0; k <= h.section_count; ++k) {
    cuts.push_back(h.table_offset + k * kSectionEntrySize);  // entry boundaries
  }
  for (std::size_t i = 0; i < h.section_count; ++i) {
    const SectionEntry e = entry_of(base, i);
    cuts.push_back(e.offset);               // section start
    cuts.push_back(e.offset + e.size / 2);  // inside it
    cuts.push_back(e.offset + e.size);      // section end
  }
  for (std::uint64_t cut : cuts) {
    if (cut >= base.size()) continue;  // the last section ends at the end of the file
    SCOPED_TRACE("cut at " + std::to_string(cut));
    const Bytes cutb(base.begin(), base.begin() + static_cast<std::ptrdiff_t>(cut));
    auto reader = PackReader::from_bytes(cutb, "cut.pack");
    ASSERT_FALSE(reader.ok());
    EXPECT_EQ(reader.status().code(), ErrorCode::kTruncated);
    EXPECT_EQ(reader.status().field(), "header.file_size");
    EXPECT_THAT(reader.status().message(), HasSubstr("only " + std::to_string(cut) + " bytes"));
  }
}

TEST(PackTruncationTest, AtEveryLength) {
  const Bytes& base = base_pack();
  for (std::size_t n = 0; n < base.size(); ++n) {
    auto reader = PackReader::from_bytes(std::span(base).first(n), "cut.pack");
    ASSERT_FALSE(reader.ok()) << "length " << n;
    ASSERT_EQ(reader.status().code(), ErrorCode::kTruncated) << "length " << n;
  }
}

// --- accepted variations ---------------------------------------------------------------

TEST(PackVersioningTest, NewerMinorVersionIsAccepted) {
  Bytes bytes = base_pack();
  edit_header(bytes, [](PackHeader& h) { h.version_minor = kPackVersionMinor + 7; });
  auto reader = PackReader::from_bytes(bytes, "newer.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->version(), (PackVersion{kPackVersionMajor, kPackVersionMinor + 7}));
  EXPECT_EQ(reader->section_count(), 5u);
}

TEST(PackVersioningTest, SectionVersionIsOpaqueToTheContainer) {
  Bytes bytes = base_pack();
  edit_entry(bytes, 2, [](SectionEntry& s) { s.version = 0xffffffffu; });
  auto reader = PackReader::from_bytes(bytes, "sections.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  EXPECT_EQ(reader->sections()[2].version, 0xffffffffu);
}

TEST(PackLayoutTest, TableAfterAGapIsAcceptedWhenThePaddingIsZero) {
  // A pack need not be laid out exactly as PackWriter does: a table at 128
  // with zero bytes before it is valid.
  const Bytes& base = base_pack();
  const PackHeader h = header_of(base);
  const std::size_t shift = 64;
  Bytes bytes(base.size() + shift, std::byte{0});
  std::copy(base.begin(), base.begin() + kHeaderSize, bytes.begin());
  std::copy(base.begin() + kHeaderSize, base.end(), bytes.begin() + kHeaderSize + shift);
  for (std::size_t i = 0; i < h.section_count; ++i) {
    SectionEntry e = load_section_entry(
        std::span(bytes).subspan(kHeaderSize + shift + i * kSectionEntrySize)
            .first<kSectionEntrySize>());
    e.offset += shift;
    store_section_entry(e, std::span(bytes).subspan(kHeaderSize + shift + i * kSectionEntrySize)
                               .first<kSectionEntrySize>());
  }
  edit_header(bytes, [&](PackHeader& hh) {
    hh.table_offset = kHeaderSize + shift;
    hh.file_size = bytes.size();
  });
  auto reader = PackReader::from_bytes(bytes, "gap.pack");
  ASSERT_TRUE(reader.ok()) << reader.status().message();
  // ...but not when a byte in the gap is set.
  flip(bytes, kHeaderSize + 3);
  auto dirty = PackReader::from_bytes(bytes, "gap.pack");
  ASSERT_FALSE(dirty.ok());
  EXPECT_EQ(dirty.status().code(), ErrorCode::kInvalidData);
  EXPECT_EQ(dirty.status().field(), "padding at offset 67");
}

// --- sweeps -------------------------------------------------------------------------------

// Checksums cover the header, the table and the payloads, and all other bytes
// must be zero: no single bit of a pack can change unnoticed.
TEST(PackSweepTest, EveryBitFlipIsRejected) {
  const Bytes& base = base_pack();
  Bytes bytes = base;
  for (std::size_t at = 0; at < base.size(); ++at) {
    for (int bit = 0; bit < 8; ++bit) {
      const auto mask = static_cast<std::byte>(1u << bit);
      bytes[at] ^= mask;
      auto reader = PackReader::from_bytes(bytes, "flip.pack");
      bytes[at] ^= mask;
      ASSERT_FALSE(reader.ok()) << "flipping bit " << bit << " of byte " << at
                                << " went unnoticed";
    }
  }
}

// Edits of header and table bytes with the checksums re-sealed reach the
// structural checks with arbitrary values; whatever the outcome, the reader
// must not crash, and a pack it accepts must be fully readable.
TEST(PackSweepTest, ResealedEditsOfHeaderAndTableNeverCrash) {
  const Bytes& base = base_pack();
  const std::uint64_t table_end = kHeaderSize + 5 * kSectionEntrySize;
  std::size_t accepted = 0;
  for (std::size_t at = 0; at < table_end; ++at) {
    if (at >= 40 && at < 56) continue;  // the checksums themselves are re-sealed
    for (const std::uint8_t value : {0x00, 0x01, 0x3f, 0x40, 0x7f, 0x80, 0xff}) {
      Bytes bytes = base;
      bytes[at] = std::byte{value};
      reseal(bytes);
      auto reader = PackReader::from_bytes(bytes, "resealed.pack");
      if (!reader.ok()) {
        EXPECT_NE(reader.status().code(), ErrorCode::kInternal) << reader.status().message();
        EXPECT_FALSE(reader.status().field().empty()) << reader.status().message();
        continue;
      }
      ++accepted;
      std::uint64_t sum = 0;
      for (const SectionInfo& info : reader->sections()) {
        for (std::byte b : reader->section_bytes(info)) sum += std::to_integer<unsigned>(b);
        ASSERT_LE(info.offset + info.size, bytes.size());
      }
      (void)sum;
    }
  }
  // Version minor, section versions and ids can change without breaking a
  // pack, so some edits are legitimately accepted.
  EXPECT_GT(accepted, 0u);
}

// --- through the file system -----------------------------------------------------------------

TEST(PackCorruptionFileTest, OpenNamesThePath) {
  const auto dir = std::filesystem::path(::testing::TempDir()) /
                   ("sinew_pack_corrupt_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "broken.pack").string();
  Bytes bytes = base_pack();
  flip(bytes, entry_of(bytes, 1).offset + 5);
  ASSERT_TRUE(write_file_atomic(path, bytes).ok());
  auto reader = PackReader::open(path);
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.status().code(), ErrorCode::kChecksumMismatch);
  EXPECT_EQ(reader.status().file(), path);
  EXPECT_THAT(reader.status().message(), HasSubstr("broken.pack: section[1].checksum"));

  const std::string empty = (dir / "empty.pack").string();
  ASSERT_TRUE(write_file_atomic(empty, std::span<const std::byte>()).ok());
  auto empty_reader = PackReader::open(empty);
  ASSERT_FALSE(empty_reader.ok());
  EXPECT_EQ(empty_reader.status().code(), ErrorCode::kTruncated);
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
}

}  // namespace
}  // namespace sinew
