/* The lean light loop's shared pieces (bake/direct.c, direct_fast*.c):
 * point, spot and directional lights without a photometric profile, the
 * bulk of a bake, skip lx_light_evaluate's general path: what does not
 * change per texel is worked out once per light, a tile's texels are
 * shaded 16 at a time in structure-of-arrays form (vectorized), and their
 * shadow rays go to the tracer as one coherent packet. Every operation is
 * lx_light_evaluate's and lx_shadow_ray's, in their order, so the results
 * are the same bits. */
#ifndef LX_BAKE_DIRECT_FAST_H
#define LX_BAKE_DIRECT_FAST_H

#include "bake_internal.h"

typedef struct fast_light {
    bool directional, classic, spot, spot_hard, shadowed;
    float px, py, pz; /* position; directional: the unit vector to the light */
    float ax, ay, az; /* spot axis (the light's direction) */
    float intensity, range, range_sq;
    float cos_outer, spot_scale, spot_offset;
    float cr, cg, cb; /* colour */
    float mr, mg, mb; /* ambient */
} fast_light;

enum { TILE_TEXELS = LX_TILE * LX_TILE };

/* A tile's texels in structure-of-arrays form, one lane per place in the
 * 8x8 tile, ordered by 4x4 block: a packet of 16 rays starts from a square
 * of texels, not two rows (10% more rays per second on bench_bake's
 * scene). Places without a texel (chart borders) are lanes that repeat
 * another lane's data and are never traced or stored. */
typedef struct tile_soa {
    int32_t texel[TILE_TEXELS];                  /* index from the tile's first texel, -1: none */
    uint32_t lanes[TILE_TEXELS / LX_RAY_PACKET]; /* per packet: lanes with a texel */
    float px[TILE_TEXELS], py[TILE_TEXELS], pz[TILE_TEXELS];
    float nx[TILE_TEXELS], ny[TILE_TEXELS], nz[TILE_TEXELS];
    float gx[TILE_TEXELS], gy[TILE_TEXELS], gz[TILE_TEXELS];
    float bias[TILE_TEXELS]; /* lx_shadow_ray's origin offset */
    bool lifted;             /* the map has lifts (lx_lift_shadow_ray) ... */
    float lfx[TILE_TEXELS], lfy[TILE_TEXELS], lfz[TILE_TEXELS]; /* ... these */
    float acc[3][TILE_TEXELS];
} tile_soa;

/* One fast light on a tile: its light and shadow rays added to t->acc,
 * and (sh not NULL, by texel of the tile) their directions; shadows (NULL:
 * none) gets `key` at each texel where the light is blocked. Built for
 * AVX-512, AVX2 and the baseline (direct_fast_lanes.h, one file each) and
 * picked at run time: the same bits on every one. */
void lx_fast_light_tile(const lx_tracer *tracer, const fast_light *f, tile_soa *t, lx_sh4 *sh,
                        uint64_t *shadows, uint64_t key);

typedef void (*lx_fast_light_tile_fn)(const lx_tracer *tracer, const fast_light *f, tile_soa *t,
                                      lx_sh4 *sh, uint64_t *shadows, uint64_t key);
void lx_fast_light_tile_base(const lx_tracer *tracer, const fast_light *f, tile_soa *t,
                             lx_sh4 *sh, uint64_t *shadows, uint64_t key);
void lx_fast_light_tile_avx2(const lx_tracer *tracer, const fast_light *f, tile_soa *t,
                             lx_sh4 *sh, uint64_t *shadows, uint64_t key);
void lx_fast_light_tile_avx512(const lx_tracer *tracer, const fast_light *f, tile_soa *t,
                               lx_sh4 *sh, uint64_t *shadows, uint64_t key);

/* For tests: the builds this CPU runs (baseline first; returns how many)
 * and their names, and the one the bake is to use from now on (NULL: the
 * widest again). */
int lx_fast_light_tile_builds(lx_fast_light_tile_fn builds[3], const char *names[3]);
void lx_fast_light_tile_use(lx_fast_light_tile_fn fn);

#endif
