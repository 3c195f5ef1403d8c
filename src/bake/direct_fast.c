/* The lean light loop for the baseline instruction set, and the choice
 * among the builds (direct_fast.h). */
#define LX_FAST_LIGHT_TILE lx_fast_light_tile_base
#include "direct_fast_lanes.h"

#include <stdatomic.h>

/* The widest build this CPU runs; the files for wider sets are empty
 * where the compiler cannot target them (LX_FAST_AVX2, LX_FAST_AVX512 come
 * from the build). */
static lx_fast_light_tile_fn fast_light_tile_pick(void)
{
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __builtin_cpu_init();
#if defined(LX_FAST_AVX512)
    if (__builtin_cpu_supports("avx512f"))
        return lx_fast_light_tile_avx512;
#endif
#if defined(LX_FAST_AVX2)
    if (__builtin_cpu_supports("avx2"))
        return lx_fast_light_tile_avx2;
#endif
#endif
    return lx_fast_light_tile_base;
}

/* threads may race to fill it; they store the same pointer */
static _Atomic(lx_fast_light_tile_fn) chosen;

void lx_fast_light_tile(const lx_tracer *tracer, const fast_light *f, tile_soa *t, lx_sh4 *sh,
                        uint64_t *shadows, uint64_t key)
{
    lx_fast_light_tile_fn fn = atomic_load_explicit(&chosen, memory_order_relaxed);
    if (!fn) {
        fn = fast_light_tile_pick();
        atomic_store_explicit(&chosen, fn, memory_order_relaxed);
    }
    fn(tracer, f, t, sh, shadows, key);
}

int lx_fast_light_tile_builds(lx_fast_light_tile_fn builds[3], const char *names[3])
{
    int n = 0;
    builds[n] = lx_fast_light_tile_base, names[n++] = "baseline";
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
    __builtin_cpu_init();
#if defined(LX_FAST_AVX2)
    if (__builtin_cpu_supports("avx2"))
        builds[n] = lx_fast_light_tile_avx2, names[n++] = "AVX2";
#endif
#if defined(LX_FAST_AVX512)
    if (__builtin_cpu_supports("avx512f"))
        builds[n] = lx_fast_light_tile_avx512, names[n++] = "AVX-512";
#endif
#endif
    return n;
}

void lx_fast_light_tile_use(lx_fast_light_tile_fn fn)
{
    atomic_store_explicit(&chosen, fn, memory_order_relaxed);
}
