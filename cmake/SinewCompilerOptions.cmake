# Warnings and instruction-set flags shared by every Sinew target, carried by
# an INTERFACE target so third-party code is not compiled with them.
add_library(sinew_compile_options INTERFACE)
add_library(sinew::compile_options ALIAS sinew_compile_options)

target_compile_options(sinew_compile_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align
  -Woverloaded-virtual -Wnull-dereference -Wdouble-promotion -Wformat=2
  $<$<BOOL:${SINEW_WERROR}>:-Werror>)
# Floating-point expressions are evaluated as written: no silent fusing of
# a*b + c into an FMA (GCC's C++ default). The 8-wide packet kernels and the
# single-ray code then round every lane exactly alike, so packets return
# bit-identical hits, and results do not hinge on the compiler's contraction
# choices. Kernels that want FMA say so with explicit intrinsics.
target_compile_options(sinew_compile_options INTERFACE -ffp-contract=off)
# GCC 12 reports false -Wrestrict positives inside libstdc++'s
# std::string operator+ at -O2/-O3 (GCC bug 105329), which -Werror would
# turn into build failures on Debian 12's default compiler.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(sinew_compile_options INTERFACE -Wno-restrict)
  # With -fsanitize at -O1 (the asan preset), GCC 12 also reports false
  # -Wmaybe-uninitialized positives inside libstdc++'s <regex> automaton,
  # which the sanitizers' instrumentation hides from its flow analysis.
  if(CMAKE_CXX_FLAGS MATCHES "-fsanitize")
    target_compile_options(sinew_compile_options INTERFACE -Wno-maybe-uninitialized)
  endif()
endif()

# The instruction-set baseline is a deliberate build-time choice. x86-64-v3
# (AVX2, FMA, BMI2: every x86 CPU since Haswell / Zen 1) is what the SIMD
# kernels are tuned for; x86-64-v2 (SSE4.2) is the portable fallback. Programs
# check at start-up that the CPU supports the baseline they were built for
# (runtime/cpu/cpu_features.h) and say so instead of dying on SIGILL.
if(SINEW_ISA STREQUAL "native")
  target_compile_options(sinew_compile_options INTERFACE -march=native)
elseif(SINEW_ISA STREQUAL "x86-64-v3" OR SINEW_ISA STREQUAL "x86-64-v2")
  target_compile_options(sinew_compile_options INTERFACE -march=${SINEW_ISA})
else()
  message(FATAL_ERROR "SINEW_ISA must be x86-64-v3, x86-64-v2 or native, not '${SINEW_ISA}'")
endif()
target_compile_definitions(sinew_compile_options INTERFACE SINEW_ISA_NAME="${SINEW_ISA}")
