/* Private to src/ibl: the one face table (cubemap.c) and what every file
 * derives from it - face vectors in float and double, the texel a
 * direction falls in, the neighbour of a texel across a face edge, exact
 * texel solid angles; argument checks; the parallel loop every filter runs
 * its rows or tiles through (threads, progress, cancellation); the source
 * mip chain; a bilinear cube sampler and Hammersley points; the specular
 * levels' plans (direct convolution with a lobe, GGX importance
 * sampling). */
#ifndef LX_IBL_INTERNAL_H
#define LX_IBL_INTERNAL_H

#include "luxel/ibl.h"

#include <math.h>
#include <stdint.h>
#include <string.h>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

/* Face tiles: the unit of parallel work (and of progress) of the filters. */
#define LX_IBL_TILE 16

/* ---- the face table ------------------------------------------------------ */

/* ibl.h's face table: face f looks along major + sc * right + tc * down,
 * each a signed unit axis (one component +-1, the others 0). */
extern const float lx_ibl_face_axes[6][3][3];

/* The face direction (not normalised) through face coordinates sc, tc in
 * [-1, 1]. */
static inline lx_vec3 lx_ibl_face_vector(int face, float sc, float tc)
{
    const float(*a)[3] = lx_ibl_face_axes[face];
    return lx_v3(a[0][0] + sc * a[1][0] + tc * a[2][0], a[0][1] + sc * a[1][1] + tc * a[2][1],
                 a[0][2] + sc * a[1][2] + tc * a[2][2]);
}

/* The same in double. */
static inline void lx_ibl_face_vector_d(int face, double sc, double tc, double v[3])
{
    const float(*a)[3] = lx_ibl_face_axes[face];
    for (int k = 0; k < 3; k++)
        v[k] = (double)a[0][k] + sc * (double)a[1][k] + tc * (double)a[2][k];
}

/* lx_cube_face_coords, inline for the filters' inner loops. */
static inline void lx_ibl_face_st(lx_vec3 d, int *face, float *s, float *t)
{
    float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
    float sc, tc, ma;
    if (ax >= ay && ax >= az) {
        ma = ax;
        *face = d.x >= 0.0f ? LX_FACE_PX : LX_FACE_NX;
        sc = d.x >= 0.0f ? -d.z : d.z;
        tc = -d.y;
    } else if (ay >= az) {
        ma = ay;
        *face = d.y >= 0.0f ? LX_FACE_PY : LX_FACE_NY;
        sc = d.x;
        tc = d.y >= 0.0f ? d.z : -d.z;
    } else {
        ma = az;
        *face = d.z >= 0.0f ? LX_FACE_PZ : LX_FACE_NZ;
        sc = d.z >= 0.0f ? d.x : -d.x;
        tc = -d.y;
    }
    *s = lx_saturate(0.5f * (sc / ma + 1.0f));
    *t = lx_saturate(0.5f * (tc / ma + 1.0f));
}

/* Texel (x, y) of a size x size face where x or y may lie one step off the
 * face: the texel on the neighbouring face whose centre is nearest the
 * extrapolated direction (*f, *tx, *ty; the texel itself when it is on
 * the face). The tap lx_cubemap_sample takes across an edge. */
void lx_ibl_texel_across(int size, int face, int x, int y, int *f, int *tx, int *ty);

/* ---- four lanes at a time -------------------------------------------------- */

/* Four floats in one vector (GCC's vector extensions, which clang shares),
 * for the hot loops the compiler cannot vectorise alone: square roots
 * (they may set errno) and selects (comparisons may trap). v4_sqrt is
 * SSE's exact square root where there is SSE, the scalar one elsewhere:
 * the same values either way. */
typedef float lx_v4f __attribute__((vector_size(16)));
typedef int32_t lx_v4i __attribute__((vector_size(16)));

static inline lx_v4f lx_v4_sqrt(lx_v4f x)
{
#if defined(__SSE__)
    return (lx_v4f)_mm_sqrt_ps((__m128)x);
#else
    return (lx_v4f){sqrtf(x[0]), sqrtf(x[1]), sqrtf(x[2]), sqrtf(x[3])};
#endif
}

/* mask ? a : b per lane, mask all ones or all zeros (a comparison). */
static inline lx_v4f lx_v4_select(lx_v4i mask, lx_v4f a, lx_v4f b)
{
    return (lx_v4f)(((lx_v4i)a & mask) | ((lx_v4i)b & ~mask));
}

/* |x| and max(x, 0), exactly: bits of the sign cleared, lanes with it set
 * zeroed. */
static inline lx_v4f lx_v4_abs(lx_v4f x)
{
    return (lx_v4f)((lx_v4i)x & 0x7fffffff);
}

static inline lx_v4f lx_v4_pos(lx_v4f x)
{
    return (lx_v4f)((lx_v4i)x & ~((lx_v4i)x < 0));
}

static inline lx_v4f lx_v4_load(const float *p)
{
    lx_v4f v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* ---- solid angles -------------------------------------------------------- */

/* Solid angle of the face rectangle [0, a] x [0, b] seen from the cube
 * centre (face at distance 1), signed: atan(a b / sqrt(a^2 + b^2 + 1)). A
 * texel's is the alternating sum over its four corners. */
static inline double lx_ibl_corner(double a, double b)
{
    return atan2(a * b, sqrt(a * a + b * b + 1.0));
}

/* Exact solid angles of the texels of one face (the same for all six
 * faces), lx_ibl_corner evaluated once per grid point. Only the top-left
 * quadrant is stored (h * h with h = (size + 1) / 2: texel solid angles
 * are symmetric about the face's centre lines); read it with
 * lx_ibl_omega. malloc'd; NULL with LX_ERR_NOMEM set on failure. */
double *lx_ibl_solid_angles(int size);

static inline double lx_ibl_omega(const double *quadrant, int size, int x, int y)
{
    int h = (size + 1) / 2;
    x = x < h ? x : size - 1 - x;
    y = y < h ? y : size - 1 - y;
    return quadrant[(size_t)y * (size_t)h + (size_t)x];
}

/* ---- checks --------------------------------------------------------------- */

/* Checks a cube map argument: present, size in range, data present; with
 * scan, also that every value is finite (the message counts the bad ones).
 * what names the argument in the message ("source cube map"). */
lx_status lx_ibl_check_cubemap(const lx_cubemap *c, const char *what, bool scan);

/* Checks a desc's thread count (0..1024). */
lx_status lx_ibl_check_threads(int threads);

/* Bytes of a cube map of that face size (6 * size^2 RGB floats). */
static inline uint64_t lx_ibl_cube_bytes(int size)
{
    return 72ull * (uint64_t)size * (uint64_t)size;
}

/* Warns (LX_LOG_WARN) when making faces of size texels from a source
 * whose own detail is source_size texels a face upsamples it more than 4x:
 * name says what is made from what ("sky.hdr: 8192 x 8192 faces from a
 * 1024 x 512 equirect"). */
void lx_ibl_warn_upsampling(const char *name, int size, double source_size);

/* ---- the parallel loop ------------------------------------------------------ */

/* Threads and progress of one call: run->threads threads at most; the
 * callback (may be NULL) hears base + span * (work done) / (total). */
typedef struct lx_ibl_run {
    int threads;
    lx_progress_fn progress;
    void *user;
    float base, span;
} lx_ibl_run;

/* The run of a call's desc fields (threads 0 = all cores), base 0, span 1. */
lx_ibl_run lx_ibl_run_make(int threads, lx_progress_fn progress, void *user);

/* The part [from, to) of a run's span, for a call made of several loops. */
lx_ibl_run lx_ibl_run_part(const lx_ibl_run *run, double from, double to);

/* One item of work; false means out of memory. */
typedef bool (*lx_ibl_item_fn)(void *ctx, int item);

/* Runs fn(ctx, i) for every i in [0, count) on at most run->threads
 * threads (OpenMP, dynamic schedule): each item must write only outputs of
 * its own, so results do not depend on the thread count. After each item
 * the thread that finished it calls the progress callback, unless another
 * thread is in it (so one thread at a time, never a smaller fraction than
 * the last), with the work done so far (cost[i] per item, or 1 each when
 * cost is NULL). Once the callback returns false or an item fails, the
 * items not started are skipped. Returns LX_OK, LX_ERR_CANCELLED ("<what>
 * cancelled") or LX_ERR_NOMEM ("<what>: out of memory"); on LX_OK the
 * callback has heard base + span. */
lx_status lx_ibl_for(const lx_ibl_run *run, int count, const double *cost, lx_ibl_item_fn fn,
                     void *ctx, const char *what);

/* ---- resampling and the mip chain ---------------------------------------- */

/* The face size lx_cubemap_downsample's halving reaches from size when
 * halved until it is at most limit (at least 1). */
int lx_ibl_halved_size(int size, int limit);

/* Downsamples src to size texels a face (at most src's) in one pass: each
 * texel the solid-angle weighted mean of the source texels it covers,
 * partly covered ones weighted by the covered fraction. dst is allocated.
 * The same as halving repeatedly when the sizes divide. */
lx_status lx_ibl_downsample(const lx_cubemap *src, int size, const lx_ibl_run *run,
                            lx_cubemap *dst);

/* A cube map and its successive halvings down to min_size (at least 1):
 * level[0] borrows the source, the others are owned. */
typedef struct lx_ibl_chain {
    int count;
    lx_cubemap level[LX_MAX_CUBE_MIPS + 1];
} lx_ibl_chain;

/* The face sizes of the chain of a source of size (sizes[0] = size);
 * returns the count. */
int lx_ibl_chain_sizes(int size, int min_size, int sizes[LX_MAX_CUBE_MIPS + 1]);
/* Bytes the chain's owned levels take. */
uint64_t lx_ibl_chain_bytes(int size, int min_size);

lx_status lx_ibl_chain_build(const lx_cubemap *src, int min_size, const lx_ibl_run *run,
                             lx_ibl_chain *out);
void lx_ibl_chain_free(lx_ibl_chain *chain);

/* ---- layouts (env_resample.c, ktx.c) ----------------------------------------- */

/* The conversions of ibl.h without their argument checks, on a run. */
lx_status lx_ibl_cube_from_equirect(const lx_image *eq, int size, const lx_ibl_run *run,
                                    lx_cubemap *out);
lx_status lx_ibl_cube_to_equirect(const lx_cubemap *c, int width, const lx_ibl_run *run,
                                  lx_image *out);
/* A cube map of another size: each texel the box-filtered mean of c. */
lx_status lx_ibl_cube_resample(const lx_cubemap *c, int size, const lx_ibl_run *run,
                               lx_cubemap *out);
/* The face size of a cross image and whether it is vertical; false if it
 * has neither 4:3 nor 3:4 proportions with whole faces. */
bool lx_ibl_cross_shape(int w, int h, int *size, bool *vertical);
lx_status lx_ibl_cube_from_cross(const lx_image *cross, const lx_ibl_run *run, lx_cubemap *out);
lx_status lx_ibl_cube_to_cross(const lx_cubemap *c, bool vertical, const lx_ibl_run *run,
                               lx_image *out);
/* lx_ktx_write_cubemap reporting its progress on a run. */
lx_status lx_ibl_ktx_write(const char *path, const lx_cubemap *levels, int count, bool half,
                           const lx_ibl_run *run);

/* ---- sampling --------------------------------------------------------------- */

/* Bilinear sample with taps across face edges: the same values as
 * lx_cubemap_sample, with a fast path for taps inside one face. */
void lx_ibl_sample(const lx_cubemap *c, lx_vec3 dir, float out[3]);

/* A cube map with a one-texel border around each face holding the texel
 * across the edge (the tap lx_cubemap_sample takes there), so bilinear
 * reads need no edge tests: (size + 2)^2 texels per face. */
typedef struct lx_ibl_padded {
    int size;
    float *data;
} lx_ibl_padded;

static inline uint64_t lx_ibl_padded_bytes(int size)
{
    return 72ull * (uint64_t)(size + 2) * (uint64_t)(size + 2);
}

lx_status lx_ibl_pad(const lx_cubemap *c, lx_ibl_padded *out);
void lx_ibl_padded_free(lx_ibl_padded *p);

/* Bilinear read at face coordinates (s, t): lx_cubemap_sample's value. */
static inline void lx_ibl_padded_bilinear(const lx_ibl_padded *p, int face, float s, float t,
                                          float out[3])
{
    int n = p->size, w = n + 2;
    float fx = s * (float)n - 0.5f, fy = t * (float)n - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float wx = fx - x0f, wy = fy - y0f;
    /* x0 >= -1 and x0 + 1 <= n: inside the border */
    const float *a =
        p->data + (((size_t)face * w + (size_t)(y0f + 1.0f)) * w + (size_t)(x0f + 1.0f)) * 3;
    const float *e = a + 3 * (size_t)w;
    for (int k = 0; k < 3; k++) {
        float top = a[k] + (a[k + 3] - a[k]) * wx;
        float bottom = e[k] + (e[k + 3] - e[k]) * wx;
        out[k] = top + (bottom - top) * wy;
    }
}

/* Point i of the n-point Hammersley set in [0,1)^2 (van der Corput radical
 * inverse in base 2 for the second coordinate). */
static inline void lx_ibl_hammersley(uint32_t i, uint32_t n, float *u, float *v)
{
    uint32_t b = i;
    b = (b << 16) | (b >> 16);
    b = ((b & 0x55555555u) << 1) | ((b & 0xAAAAAAAAu) >> 1);
    b = ((b & 0x33333333u) << 2) | ((b & 0xCCCCCCCCu) >> 2);
    b = ((b & 0x0F0F0F0Fu) << 4) | ((b & 0xF0F0F0F0u) >> 4);
    b = ((b & 0x00FF00FFu) << 8) | ((b & 0xFF00FF00u) >> 8);
    *u = ((float)i + 0.5f) / (float)n;
    *v = (float)((double)b * (1.0 / 4294967296.0));
}

/* An orthonormal frame (t, b, n) around unit n, as Karis 2013 builds it:
 * t = normalize(up x n) with up = +Z, or +X within 2.6 degrees of +-Z. It
 * turns continuously everywhere but inside those two small caps, so a
 * fixed sample pattern leaves no seam-like lines across the faces. */
static inline void lx_ibl_frame(lx_vec3 n, lx_vec3 *t, lx_vec3 *b)
{
    lx_vec3 up = fabsf(n.z) < 0.999f ? lx_v3(0.0f, 0.0f, 1.0f) : lx_v3(1.0f, 0.0f, 0.0f);
    *t = lx_normalize(lx_cross(up, n));
    *b = lx_cross(n, *t);
}

/* ---- specular prefiltering (prefilter.c drives, one file per lobe) ---- */

/* A lobe w(r.l) of the angle between the output direction r and the light
 * direction l, for the direct convolution of prefilter_conv.c. */
typedef enum lx_lobe_kind { LX_LOBE_PHONG, LX_LOBE_GGX } lx_lobe_kind;

typedef struct lx_lobe {
    lx_lobe_kind kind;
    float param;       /* PHONG: the exponent n; GGX: alpha^2 */
    float cos_cut;     /* r.l below it is left out (PHONG: each light; GGX: whole nodes) */
    double half_width; /* angle (radians) where the lobe falls to half its peak */
    double texels;     /* the source mip's mean texel angle is at most half_width / texels */
    double far;        /* 0, or: a node at least far x its radius away from r is one light */
} lx_lobe;

/* Phong's pow(max(0, r.l), n) (prefilter_phong.c). */
lx_lobe lx_phong_lobe(float exponent);
/* GGX's D(h) (n.l) with N = V = R (prefilter_ggx.c). */
lx_lobe lx_ggx_lobe(float roughness);

/* The work of one level of lx_prefilter by direct convolution with a
 * lobe, in two steps: lx_conv_plan_create builds the tree of nodes over
 * the source mip the lobe needs from the chain's sizes alone (no texel
 * data) and measures its cost, the nodes and lights a texel tests; above
 * max_cost it stops there and *out is NULL (with LX_OK).
 * lx_conv_plan_bytes is what lx_conv_plan_fill will add: the lights, from
 * the chain's data. lx_conv_tile then fills texels [x0,x1) x [y0,y1) of
 * one face of out (false when out of memory). out_size: the face size of
 * the level it fills (bounds the tile test). */
typedef struct lx_conv_plan lx_conv_plan;
lx_status lx_conv_plan_create(const int *chain_sizes, int chain_count, const lx_lobe *lobe,
                              int out_size, double max_cost, lx_conv_plan **out);
double lx_conv_plan_cost(const lx_conv_plan *p);
uint64_t lx_conv_plan_bytes(const lx_conv_plan *p);
/* The chain level the plan reads. */
int lx_conv_plan_level(const lx_conv_plan *p);
/* The flux vectors of chain level `level` > 0: per texel, the sum of
 * luminance x solid angle x direction over the level 0 texels under it
 * (the direction of its light is their centroid); summed from the flux
 * vectors `finer` of a finer level when not NULL and the sizes nest.
 * *out is malloc'd, 3 doubles per texel, face-major. */
lx_status lx_conv_flux(const lx_ibl_chain *chain, int level, const double *finer, int finer_level,
                       const lx_ibl_run *run, double **out);
/* Makes the lights from the chain and, when the plan's level is above 0,
 * that level's flux vectors. */
lx_status lx_conv_plan_fill(lx_conv_plan *p, const lx_ibl_chain *chain, const double *flux);
bool lx_conv_tile(const lx_conv_plan *p, lx_cubemap *out, int face, int x0, int y0, int x1, int y1);
void lx_conv_plan_free(lx_conv_plan *p);

/* GGX by importance sampling (prefilter_ggx.c): lx_ggx_tile fills a tile
 * like lx_conv_tile; pads: the chain's levels, padded (lx_ibl_pad). The
 * cost is the samples per texel. */
typedef struct lx_ggx_plan lx_ggx_plan;
lx_status lx_ggx_plan_build(const int *chain_sizes, int chain_count, float roughness, int samples,
                            lx_ggx_plan **out);
double lx_ggx_plan_cost(const lx_ggx_plan *p);
void lx_ggx_tile(const lx_ggx_plan *p, const lx_ibl_padded *pads, lx_cubemap *out, int face, int x0,
                 int y0, int x1, int y1);
void lx_ggx_plan_free(lx_ggx_plan *p);

/* One GGX level: a direct convolution (*conv, not yet filled) where it
 * costs at most what samples importance samples per texel do, else
 * importance sampling (*is); the other is NULL. *cost: per texel, in
 * importance samples. */
lx_status lx_ggx_level_plan(const int *chain_sizes, int chain_count, float roughness, int samples,
                            int out_size, lx_conv_plan **conv, lx_ggx_plan **is, double *cost);

#endif
