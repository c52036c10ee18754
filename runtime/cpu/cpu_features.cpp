#include "runtime/cpu/cpu_features.h"

#include <string>

#ifndef SINEW_ISA_NAME
#define SINEW_ISA_NAME "unknown"
#endif

namespace sinew {

CpuFeatures detect_cpu_features() {
  CpuFeatures f;
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
  f.sse42 = __builtin_cpu_supports("sse4.2");
  f.avx2 = __builtin_cpu_supports("avx2");
  f.fma = __builtin_cpu_supports("fma");
  f.bmi2 = __builtin_cpu_supports("bmi2");
  f.avx512f = __builtin_cpu_supports("avx512f");
#endif
  return f;
}

std::string_view build_isa() { return SINEW_ISA_NAME; }

Status check_cpu_supports_build() {
  const CpuFeatures f = detect_cpu_features();
  const std::string_view isa = build_isa();
  auto missing = [&](std::string_view feature) {
    return make_error(ErrorCode::kUnsupportedVersion, "", "cpu", std::string(feature),
                      "this build targets " + std::string(isa) +
                          " but the CPU lacks it; rebuild with the portable baseline: "
                          "cmake -DSINEW_ISA=x86-64-v2");
  };
  if (isa == "x86-64-v3") {
    if (!f.avx2) return missing("avx2");
    if (!f.fma) return missing("fma");
    if (!f.bmi2) return missing("bmi2");
  }
  if ((isa == "x86-64-v3" || isa == "x86-64-v2") && !f.sse42) return missing("sse4.2");
  return {};
}

}  // namespace sinew
