/* Private to src/light2d: the context of 2D shadowed lights, the per-light
 * polar shadow maps (polar.c) and the shading of rows (shade.c). */
#ifndef LX_LIGHT2D_INTERNAL_H
#define LX_LIGHT2D_INTERNAL_H

#include "luxel/light2d.h"

#include <stdint.h>

/* min and max without libm's NaN rules (a call each otherwise); the
 * values here are never NaN */
static inline float l2_min(float a, float b)
{
    return a < b ? a : b;
}
static inline float l2_max(float a, float b)
{
    return a > b ? a : b;
}

/* Levels of the lit side's horizons of a soft light (polar.c). */
#define L2_HZ 8

/* Boundary caster pixels are bucketed in square tiles of this many pixels,
 * so a light visits only the tiles under its reach. */
#define L2_TILE 32

/* Frames are shaded in bands of this many rows, and each light first
 * drops the blocks of L2_BLOCK x L2_BLOCK pixels it leaves wholly dark. */
#define L2_BLOCK 16

/* The per-pixel passes of a span run over whole vectors of 8 pixels: the
 * caster mask and the normal planes are allocated with this many spare
 * (zero) values after them, and the scratch arrays of a span are
 * l2_scratch_stride floats apart. Lanes past the span are computed and
 * dropped. */
#define L2_PAD 8
static inline size_t l2_scratch_stride(int width)
{
    return ((size_t)width + L2_PAD + 7) & ~(size_t)7;
}

/* Which 4-neighbours of a boundary pixel are free (not casters, or outside
 * the image). */
enum { L2_FREE_LEFT = 1, L2_FREE_RIGHT = 2, L2_FREE_UP = 4, L2_FREE_DOWN = 8 };

typedef struct l2_edge {
    uint16_t x, y;
    uint8_t free;
} l2_edge;

/* A boundary pixel, kept for the pass that finds where rays leave their
 * first caster run: the rays [b0, b1] (b1 may pass n: wrap) whose
 * sampled line crosses it, its square relative to the light (ax, ay: the
 * corner nearest the origin of the image, side 1) and its free sides; or,
 * for a square no sampled line crosses (b0 > b1 on entry: the bins it
 * touches), the distance of its far corner in df. */
typedef struct l2_exit {
    int b0, b1;
    float ax, ay, df;
    uint8_t free;
    bool sampled;
} l2_exit;

/* A light's polar shadow map: n rays over the pseudo-angle p in [0, 8)
 * (the point where the ray meets the unit square around the light, walked
 * counter-clockwise: p = 1 + dy/dx on the +x face, 3 - dx/dy on +y, 5 +
 * dy/dx on -x, 7 - dx/dy on -y). Ray b holds the pixels whose centres'
 * p lies in [b, b + 1) x 8/n and is sampled along the line through its
 * middle, p = (b + 0.5) x 8/n: occ[b], the distance at which that line
 * enters its first caster pixel; ex[b], where it leaves the caster run it
 * entered there. For soft lights, sparse tables of the minimum and
 * maximum of occ over 2^l rays. */
typedef struct l2_polar {
    int n;
    float bins_per_p; /* n / 8 */
    float *occ, *ex;
    /* the sampled lines' unit directions as 1/x and 1/y (never 0: no
     * line lies on an axis), for ray_n = n rays */
    float *inv_ux, *inv_uy;
    int ray_n;
    float *occx; /* occ three times over: occx[n + b] = occ[b mod n] for b
                    in [-n, 2n), so that windows need no wrapping */
    /* soft lights: the horizons' reach (horizons in polar.c), as an
     * inverse distance per ray: a pixel on ray b at distance d with
     * d * lit[b] < 1 lies in no occluder's penumbra (fully lit) */
    float *lit;
    /* soft lights: the ray boundaries' angles (n + 1, radians, for n =
     * theta_n) and the lit side's horizons, 2 L2_HZ floats a ray
     * (horizons in polar.c), with their levels' r_k / softness */
    float *theta;
    int theta_n;
    float *hz;
    float hz_inv[L2_HZ];
    /* soft lights: 1 / max(occ, 0.5) per ray, and per depth level l (the
     * distances from L2_DEPTH0 x 2^(l/2) on) the whole bins between each
     * ray and the nearest ray whose occluder lies at that distance or
     * beyond (65535 when none): a point of ray b in hard shadow at a
     * distance of level l whose penumbra window is at most gap[l][b] bins
     * wide on each side sees no open ray (fully shadowed) */
    float *qocc;
    float *gap; /* depth_levels x n, whole numbers (floats, for gathers) */
    int depth_levels;
    int gap_capacity;
    float *tmin, *tmax; /* levels x n */
    int levels;
    l2_exit *exits; /* scratch of l2_polar_build */
    size_t exit_capacity;
    int capacity; /* floats allocated per array (occ, ex: n; tables: levels*n) */
    int table_capacity;
} l2_polar;

/* With GCC on x86-64 Linux, AVX2 clones of the per-pixel passes and of the
 * penumbra filter are picked at load time where the CPU has it: 8 lanes a
 * vector instead of 4. The operations are the same IEEE ones in the same
 * order (no contraction, sums in order), so are the bytes. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(L2_NO_CLONES)
#define L2_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define L2_CLONES
#endif

/* AVX2 gathers, written out (GCC's generic tuning never vectorizes with
 * them), where the CPU has them (GCC or clang on x86-64): the same IEEE
 * operations in the same order as the scalar loops they stand for. */
#if defined(__GNUC__) && defined(__x86_64__) && !defined(L2_NO_CLONES)
#define L2_GATHER 1
static inline int l2_gather_ok(void)
{
    return __builtin_cpu_supports("avx2");
}
#endif

/* floor(x) for |x| < 2^31, inline (floorf is a call without SSE4.1). */
static inline int l2_floor(float x)
{
    int i = (int)x;
    return i - (x < (float)i);
}

/* The first distance of the depth levels of l2_polar.gap. */
#define L2_DEPTH0 1.0f

/* The depth level of a distance d >= L2_DEPTH0: floor(2 log2(d / L2_DEPTH0))
 * from the float's bits (exact: no libm rounding), at most top. */
static inline int l2_depth_level(float d, int top)
{
    union {
        float f;
        uint32_t u;
    } v = {d / L2_DEPTH0};
    int e = (int)(v.u >> 23) - 127;
    /* the mantissa against sqrt(2) = 1.0110101000001001111001...b */
    int l = 2 * e + ((v.u & 0x7fffff) >= 0x3504f3u ? 1 : 0);
    return l < top ? l : top;
}

/* A light prepared for a frame. */
typedef struct l2_prep {
    lx_light2d_light l;
    int x0, y0, x1, y1; /* pixels under its reach, clipped: [x0,x1) x [y0,y1) */
    float r2, inv_r, inv_r2;
    lx_vec3 rgb; /* colour x intensity */
    bool spot;
    float dir_x, dir_y, cos_outer, cos_inner, inv_fade;
    bool relight; /* computed this frame (dynamic, or a cache to refill) */
    float *cache; /* static lights: (x1-x0)*(y1-y0)*3 floats */
    l2_polar polar;
} l2_prep;

struct lx_light2d {
    int width, height;
    int channels;
    bool mask;
    float threshold;
    int threads;
    int polar_resolution;
    uint8_t *caster; /* width*height, 1 for casters */
    int tiles_x, tiles_y;
    uint32_t *tile_start; /* tiles_x*tiles_y + 1 offsets into edges */
    l2_edge *edges;
    int blocks_x, blocks_y;
    uint8_t *block_caster; /* blocks_x*blocks_y: 1 when the block holds a caster */
    float *normals; /* unit vectors in pixel space (x right, y down, z
                       towards the viewer) as three planes of width*height
                       floats (x, y, z), or NULL */
    l2_prep *preps;
    int count, prep_capacity;
    int relit;
    float *work; /* the render's bands and scratch, kept between frames */
    size_t work_size;
};

/* Rebuilds the tile lists of boundary caster pixels (context.c). */
lx_status l2_build_edges(lx_light2d *ctx);

/* Rays for a light of this radius (or the context's fixed resolution). */
int l2_ray_count(const lx_light2d *ctx, float radius);

/* The bytes l2_polar_build reserves for the light's polar map. */
uint64_t l2_polar_bytes(const lx_light2d *ctx, const lx_light2d_light *l);

/* Fills p->polar for the light (allocating as needed). */
lx_status l2_polar_build(const lx_light2d *ctx, l2_prep *p);
void l2_polar_free(l2_polar *pm);

/* The penumbra pixels of a span of a soft light (polar.c): fa[i] times
 * the pixel's visibility where code[i] (n8 bytes, a multiple of 8) says
 * 1 or 2. code 1, a pixel its own ray reaches (da before the ray's
 * occluder, or dea on a lit face): the mean of the shares of the light's
 * two sides it sees past the occluders beside it (the horizons of
 * l2_polar.hz). code 2, a pixel in its ray's hard shadow: the
 * percentage-closer filter over its occluder's window [c - k, c + k] (ka,
 * in bins, 0.5 <= k < n/2), the fraction of its rays that reach past da;
 * k = min(s (1/max(o, 0.5) - 1/d) x scale, n/2 - 1), scale the bins per
 * radian there. ca: the pixels' continuous bins. */
void l2_penumbrae(const l2_polar *pm, int n8, const uint8_t *code, const float *ca,
                  const float *dea, const float *da, const float *ka, float *fa);

/* What the light does to the pixels of the block [x0, x1) x [y0, y1),
 * exactly as shading them would find (polar.c): L2_BLOCK_DARK, it leaves
 * every one dark (out of reach, or in a hard shadow whose penumbra window
 * holds no open ray, and no caster pixel within a ray's first caster
 * run); L2_BLOCK_LIT, its shadows leave every one its full light (each
 * before its ray's occluder and, for soft lights, in no occluder's
 * penumbra wedge), so that shading may skip the shadow pass; else
 * L2_BLOCK_MIXED. has_caster: the block holds a caster pixel. */
enum { L2_BLOCK_DARK = 0, L2_BLOCK_LIT = 1, L2_BLOCK_MIXED = 2 };
int l2_block_kind(const l2_prep *p, int x0, int y0, int x1, int y1, bool has_caster);

#endif
