/* The lean light loop built for AVX-512F (direct_fast.h); CMakeLists.txt
 * compiles this file with -mavx512f and defines LX_FAST_AVX512 where it
 * can. */
#if defined(LX_FAST_AVX512)
#define LX_FAST_LIGHT_TILE lx_fast_light_tile_avx512
#include "direct_fast_lanes.h"
#else
typedef int lx_fast_avx512_unused; /* ISO C wants a declaration in every file */
#endif
