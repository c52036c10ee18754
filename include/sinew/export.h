// SINEW_API marks what libsinew exports. The library is built with hidden
// visibility: nothing else in it (runtime, animation, raytrace internals,
// TBB glue) is visible to a host, so no internal symbol can clash with the
// host's own.
#pragma once

#if defined(__GNUC__) || defined(__clang__)
#define SINEW_API __attribute__((visibility("default")))
#else
#define SINEW_API
#endif
