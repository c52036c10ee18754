// The process's memory as benchmarks report it: the resident set (VmRSS in
// /proc/self/status: pages actually touched) and the heap in use (glibc's
// mallinfo2: bytes handed out by malloc and not freed, whatever pages they
// sit in). Before a reading, the heap's free pages go back to the system
// (malloc_trim), so memory a bake freed and nothing reuses is not counted
// as resident.
#pragma once

#include <malloc.h>

#include <cstdint>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

namespace sinew::bench {

struct ProcessMemory {
  std::int64_t resident_kib = 0;
  std::int64_t heap_in_use_kib = 0;
};

// Empty where /proc/self/status has no VmRSS line (not Linux).
inline std::optional<ProcessMemory> read_process_memory() {
  malloc_trim(0);
  std::ifstream in("/proc/self/status");
  std::string line;
  std::optional<ProcessMemory> memory;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) != 0) continue;
    std::istringstream fields(line.substr(6));
    std::int64_t kib = 0;
    std::string unit;
    if (fields >> kib >> unit && unit == "kB") memory = ProcessMemory{kib, 0};
    break;
  }
  if (!memory) return std::nullopt;
  const struct mallinfo2 heap = mallinfo2();
  memory->heap_in_use_kib = static_cast<std::int64_t>((heap.uordblks + heap.hblkhd) / 1024);
  return memory;
}

}  // namespace sinew::bench
