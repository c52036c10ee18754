// The one build-time SIMD switch. SINEW_AVX2 is 1 where the build targets
// AVX2 and FMA (x86-64-v3, the release preset) and 0 otherwise (the
// portable x86-64-v2 preset), where every eight-lane type and kernel runs
// the same arithmetic lane by lane. Raw intrinsics appear only in the lane
// types (float8.h; float4.h, SSE4.1 in every target) and in kernels whose
// file names say so; kernels chosen
// at run time from the CPU (skinning_avx2.cpp, srgb_encode.cpp) compile
// their own target instead.
#pragma once

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#define SINEW_AVX2 1
#else
#define SINEW_AVX2 0
#endif
