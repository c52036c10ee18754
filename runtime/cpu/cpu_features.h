// The instruction-set baseline a binary was built for (CMake's SINEW_ISA)
// and whether this CPU can run it. Every program calls
// check_cpu_supports_build() first, so a portable-fallback suggestion is
// printed instead of an illegal-instruction crash on an older CPU.
#pragma once

#include <string_view>

#include "runtime/core/status.h"

namespace sinew {

struct CpuFeatures {
  bool sse42 = false;
  bool avx2 = false;
  bool fma = false;
  bool bmi2 = false;
  bool avx512f = false;
};

CpuFeatures detect_cpu_features();

// "x86-64-v3", "x86-64-v2" or "native".
std::string_view build_isa();

// kUnsupportedVersion naming the missing feature and the portable preset.
Status check_cpu_supports_build();

}  // namespace sinew
