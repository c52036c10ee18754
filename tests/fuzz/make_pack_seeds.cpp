// Writes the seed corpus for sinew_fuzz_pack_reader: a few small, valid packs
// that show the fuzzer every structure the reader knows (no sections, empty
// sections, sections needing padding, typed arrays). The committed files in
// tests/fuzz/corpus/pack_reader/ come from this program; rerun it when the format
// changes:
//
//     sinew_make_pack_seeds tests/fuzz/corpus/pack_reader
//
// Every seed is kept well under 10 KB so the corpus stays cheap to commit.
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include "runtime/pack/pack_reader.h"
#include "runtime/pack/pack_writer.h"

namespace {

using sinew::make_section_id;
using sinew::PackWriter;
using sinew::Status;

std::vector<std::byte> counting(std::size_t size, unsigned start) {
  std::vector<std::byte> out(size);
  for (std::size_t i = 0; i < size; ++i) out[i] = static_cast<std::byte>(start + i * 7);
  return out;
}

bool emit(const std::string& dir, const std::string& name, const PackWriter& writer) {
  const std::string path = dir + "/" + name;
  if (const Status written = writer.write(path); !written.ok()) {
    std::fprintf(stderr, "%s\n", written.message().c_str());
    return false;
  }
  // A seed that does not open would only teach the fuzzer a dead end.
  auto reader = sinew::PackReader::open(path);
  if (!reader.ok()) {
    std::fprintf(stderr, "%s\n", reader.status().message().c_str());
    return false;
  }
  std::printf("%s: %zu sections, %zu bytes\n", path.c_str(), reader->section_count(),
              reader->bytes().size());
  return true;
}

bool add(PackWriter& writer, const char (&id)[5], std::uint32_t version,
         std::vector<std::byte> payload) {
  const Status added = writer.add_section(make_section_id(id), version, std::move(payload));
  if (!added.ok()) std::fprintf(stderr, "%s\n", added.message().c_str());
  return added.ok();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <output folder>\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  bool ok = true;

  ok = ok && emit(dir, "empty.pack", PackWriter{});

  PackWriter one;
  ok = ok && add(one, "SKEL", 1, counting(40, 1));
  ok = ok && emit(dir, "one_section.pack", one);

  PackWriter several;
  ok = ok && add(several, "SKEL", 1, counting(200, 2));
  ok = ok && add(several, "MESH", 2, counting(300, 3));
  ok = ok && add(several, "CLIP", 1, counting(64, 4));
  ok = ok && add(several, "LIMS", 3, counting(17, 5));
  ok = ok && add(several, "TREE", 1, counting(129, 6));
  ok = ok && emit(dir, "five_sections.pack", several);

  PackWriter empties;
  ok = ok && add(empties, "NIL1", 1, {});
  ok = ok && add(empties, "DATA", 1, counting(1, 7));
  ok = ok && add(empties, "NIL2", 1, {});
  ok = ok && emit(dir, "empty_sections.pack", empties);

  PackWriter typed;
  std::vector<std::uint32_t> words(64);
  for (std::uint32_t i = 0; i < words.size(); ++i) words[i] = i * 0x01010101u;
  ok = ok && add(typed, "WORD", 1,
                 std::vector<std::byte>(std::as_bytes(std::span(words)).begin(),
                                        std::as_bytes(std::span(words)).end()));
  ok = ok && add(typed, "ODD_", 1, counting(7, 8));
  ok = ok && emit(dir, "typed.pack", typed);

  return ok ? 0 : 1;
}
