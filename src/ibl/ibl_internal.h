/* Private to src/ibl: the face table (cubemap.c) and, for the filters
 * (mips.c, irradiance.c, sh.c, prefilter*.c, dfg.c), exact texel
 * solid-angle tables, argument checks, the progress and cancel bookkeeping
 * of the tiled OpenMP loops, the source mip chain, a bilinear cube sampler
 * and Hammersley points; the specular levels' plans (direct convolution
 * with a lobe, GGX importance sampling). */
#ifndef LX_IBL_INTERNAL_H
#define LX_IBL_INTERNAL_H

#include "luxel/ibl.h"

#include <math.h>
#include <stdint.h>

/* Face tiles: the unit of parallel work (and of progress) of every filter. */
#define LX_IBL_TILE 16

/* Exact solid angles of the texels of one face (the same for all six
 * faces), from the corner function F(a, b) = atan(ab / sqrt(a^2 + b^2 + 1))
 * evaluated once per grid point. Only the top-left quadrant is stored
 * (h * h with h = (size + 1) / 2: texel solid angles are symmetric about
 * the face's centre lines); read it with lx_ibl_omega. malloc'd; NULL with
 * LX_ERR_NOMEM set on failure. */
double *lx_ibl_solid_angles(int size);

static inline double lx_ibl_omega(const double *quadrant, int size, int x, int y)
{
    int h = (size + 1) / 2;
    x = x < h ? x : size - 1 - x;
    y = y < h ? y : size - 1 - y;
    return quadrant[(size_t)y * (size_t)h + (size_t)x];
}

/* The face direction (not normalised) through face coordinates sc, tc in
 * [-1, 1] (ibl.h's table). */
lx_vec3 lx_ibl_face_vector(int face, float sc, float tc);

/* Checks a cube map argument: present, size in range, data present; with
 * scan, also that every value is finite (the message counts the bad ones).
 * what names the argument in the message ("source cube map"). */
lx_status lx_ibl_check_cubemap(const lx_cubemap *c, const char *what, bool scan);

/* Checks a desc's thread count (0..1024). */
lx_status lx_ibl_check_threads(int threads);

/* Progress of a tiled parallel loop. lx_ibl_progress_add is called by every
 * thread after each tile; only thread 0 calls the user's callback, so it is
 * called from one thread at a time. Once the callback returns false,
 * cancelled is set and the remaining tiles are skipped. */
typedef struct lx_ibl_progress {
    lx_progress_fn fn;
    void *user;
    double total;
    double done;
    float base, span; /* reported fraction = base + span * done / total */
    volatile int cancelled;
} lx_ibl_progress;

void lx_ibl_progress_init(lx_ibl_progress *p, lx_progress_fn fn, void *user, double total,
                          float base, float span);
void lx_ibl_progress_add(lx_ibl_progress *p, double work);
/* Reports base + span (unless cancelled); returns false when cancelled. */
bool lx_ibl_progress_end(lx_ibl_progress *p);

/* Downsamples with a bounded number of threads (lx_cubemap_downsample is
 * this with all cores). */
lx_status lx_ibl_downsample(const lx_cubemap *src, lx_cubemap *dst, int threads);

/* A cube map and its successive downsamples down to min_size (at least 1):
 * level[0] borrows the source, the others are owned. */
typedef struct lx_ibl_chain {
    int count;
    lx_cubemap level[LX_MAX_CUBE_MIPS + 1];
} lx_ibl_chain;

lx_status lx_ibl_chain_build(const lx_cubemap *src, int min_size, int threads, lx_ibl_chain *out);
void lx_ibl_chain_free(lx_ibl_chain *chain);

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

lx_status lx_ibl_pad(const lx_cubemap *c, lx_ibl_padded *out);
void lx_ibl_padded_free(lx_ibl_padded *p);

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
 * lobe: lx_conv_tile fills texels [x0,x1) x [y0,y1) of one face of out
 * (returns false when out of memory). out_size: the face size of the level
 * it fills (bounds the tile test). The cost is the nodes and lights a
 * texel tests, measured on the tree before the lights are made: above
 * max_cost the build stops there and *out is NULL (with LX_OK). */
typedef struct lx_conv_plan lx_conv_plan;
lx_status lx_conv_plan_build(const lx_ibl_chain *chain, const lx_lobe *lobe, int out_size,
                             double max_cost, lx_conv_plan **out);
double lx_conv_plan_cost(const lx_conv_plan *p);
bool lx_conv_tile(const lx_conv_plan *p, lx_cubemap *out, int face, int x0, int y0, int x1, int y1);
void lx_conv_plan_free(lx_conv_plan *p);

/* GGX by importance sampling (prefilter_ggx.c): lx_ggx_tile fills a tile
 * like lx_conv_tile; pads: the chain's levels, padded (lx_ibl_pad). The
 * cost is the samples per texel. */
typedef struct lx_ggx_plan lx_ggx_plan;
lx_status lx_ggx_plan_build(const lx_ibl_chain *chain, float roughness, int samples,
                            lx_ggx_plan **out);
double lx_ggx_plan_cost(const lx_ggx_plan *p);
void lx_ggx_tile(const lx_ggx_plan *p, const lx_ibl_padded *pads, lx_cubemap *out, int face, int x0,
                 int y0, int x1, int y1);
void lx_ggx_plan_free(lx_ggx_plan *p);

/* One GGX level: a direct convolution (*conv) where it costs at most what
 * samples importance samples per texel do, else importance sampling
 * (*is); the other is NULL. *cost: per texel, in importance samples. */
lx_status lx_ggx_level_build(const lx_ibl_chain *chain, float roughness, int samples, int out_size,
                             lx_conv_plan **conv, lx_ggx_plan **is, double *cost);

#endif
