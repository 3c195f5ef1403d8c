/* The lean light loop built for AVX2 (direct_fast.h); CMakeLists.txt
 * compiles this file with -mavx2 and defines LX_FAST_AVX2 where it can. */
#if defined(LX_FAST_AVX2)
#define LX_FAST_LIGHT_TILE lx_fast_light_tile_avx2
#include "direct_fast_lanes.h"
#else
typedef int lx_fast_avx2_unused; /* ISO C wants a declaration in every file */
#endif
