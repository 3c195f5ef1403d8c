/* luxel/denoise.h - an edge-aware denoiser for lightmaps: a Monte Carlo
 * lightmap (indirect light, soft shadows, sky rays) smoothed in texture
 * space without smearing light across what the texels' world-space guides
 * say are different surfaces. The filter is the edge-avoiding a-trous
 * wavelet transform (Dammertz et al. 2010) steered as SVGF steers it
 * (Schied et al. 2017): five passes of a 5x5 B3-spline kernel with holes
 * (steps 1, 2, 4, 8, 16 texels), each tap weighted by how alike the two
 * texels' normals, world positions, albedos and luminances are.
 * docs/denoise.md describes the filter and its measured figures.
 *
 * CONVENTIONS  Buffers are row-major, row 0 at the top, width*height
 *   texels (bake.h's lightmaps). Colours are 3 floats a texel in any
 *   linear unit (lux, nits); positions in metres, normals unit vectors
 *   (normalized here). A texel's "world size" is the distance in metres
 *   between it and its neighbours on the same surface; unless the caller
 *   passes it, it is measured from the positions. Guarantees, for any
 *   settings:
 *   - a texel whose valid byte is 0 is never read by the filter (its colour,
 *     guides and variance may hold anything, NaN included) and receives
 *     nothing: the output there is the input (lx_denoise) or direct +
 *     indirect (lx_denoise_combine), copied as it is;
 *   - two texels are mixed only when they lie in one surface: a chain of
 *     neighbouring valid texels (8-neighbours) of one chart, each step
 *     between normals within normal_cutoff and no longer in space than
 *     (1 + 3 position_sigma) texel world sizes. Charts adjacent in the
 *     lightmap but apart in space exchange nothing, and a tap between
 *     normals further apart than normal_cutoff has weight 0;
 *   - weights are normalized: a constant signal comes out exactly equal
 *     (the output is c_p + sum w (c_q - c_p) / sum w), and a signal
 *     constant on each surface stays so.
 * ERRORS  LX_ERR_INVALID for a NULL buffer, a size out of range, a desc
 *   field out of range, or a valid texel whose colour, position, normal,
 *   albedo, size or variance is NaN, infinite (or a zero normal, a
 *   negative size or variance); the message names the texel. LX_ERR_NOMEM
 *   when the scratch (80 bytes a texel) does not fit, LX_ERR_CANCELLED
 *   when the progress callback says stop. On any failure out is left as
 *   it was.
 * MEMORY  The guides are borrowed for the call. lx_baker_denoise_guides
 *   allocates its buffers; lx_denoise_guides_free releases them.
 * THREADING  Every function is thread-safe on distinct outputs (the baker
 *   function as the baker's read-only calls are, bake.h). lx_denoise runs
 *   OpenMP over rows, at most desc.threads threads; every texel is a fixed
 *   sum gathered from the previous pass, so results are bit-identical for
 *   any thread count. progress is called from one thread at a time.
 *
 * USAGE
 *   lx_scene *scene;
 *   lx_baker *b;
 *   if (lx_scene_load("room.glb", NULL, &scene) != LX_OK) return 1;
 *   lx_bake_desc d = lx_bake_desc_defaults(NULL);
 *   d.resolution = 64;
 *   lx_status st = lx_baker_create(scene, &d, &b);
 *   lx_scene_destroy(scene);
 *   if (st != LX_OK) return 1;
 *   lx_image img;
 *   lx_denoise_guides g;
 *   if (lx_baker_bake(b) == LX_OK && lx_baker_apply_alloc(b, 0, &img) == LX_OK) {
 *       if (lx_baker_denoise_guides(b, 0, &g) == LX_OK) {
 *           lx_denoise_desc dd = lx_denoise_desc_defaults(NULL);
 *           if (lx_denoise(&g, img.data, img.data, &dd) != LX_OK)   // in place
 *               fprintf(stderr, "%s\n", lx_last_error());
 *           lx_denoise_guides_free(&g);
 *       }
 *       lx_image_free(&img);
 *   }
 *   lx_baker_destroy(b);
 */
#ifndef LUXEL_DENOISE_H
#define LUXEL_DENOISE_H

#include "luxel/bake.h"
#include "luxel/core.h"
#include "luxel/math.h"

#ifdef __cplusplus
extern "C" {
#endif

/* lx_denoise_mode (what a bake's denoising filters) is in bake.h. */

/* "off", "indirect" or "all"; NULL for another value. */
const char *lx_denoise_mode_name(lx_denoise_mode mode);
/* The mode named name (as lx_denoise_mode_name writes it); false when none. */
bool lx_denoise_mode_parse(const char *name, lx_denoise_mode *out);

/* Per-texel guides, width*height entries each, borrowed for the call. */
typedef struct lx_denoise_guides {
    int width, height;       /* 1..65536 each, at most 2^32 - 1 texels */
    const uint8_t *valid;    /* nonzero: covered and valid (required) */
    const lx_vec3 *position; /* world position in metres (required) */
    const lx_vec3 *normal;   /* world normal, any length above 0 (required) */
    const lx_vec3 *albedo;   /* base colour, NULL = none; only for signals that
                                carry it (radiance), not irradiance */
    const uint32_t *chart;   /* chart id, NULL = one chart; texels of different
                                ids are never mixed */
    const float *texel_size; /* world size of a texel in metres, NULL = measured
                                from the positions: the largest distance to an
                                8-neighbour of its chart and facing (diagonals
                                / sqrt 2) within twice the smallest one */
    const float *variance;   /* variance of the filtered signal's luminance
                                (a Monte Carlo estimate: sample variance /
                                samples), NULL = estimated from the 5x5
                                neighbours on the same surface */
} lx_denoise_guides;

typedef struct lx_denoise_desc {
    int iterations;        /* a-trous passes, steps 1, 2, 4, ...: 0 = 5, at most 12 */
    float luminance_sigma; /* luminance edge stop in standard deviations of the
                              local noise, w = exp(-|l_p - l_q| / (sigma sd)): 0 = 4 */
    bool ignore_luminance; /* no luminance weight: the guides alone steer */
    float normal_sigma;    /* w = exp(-sigma (1 - n_p . n_q)): 0 = 64 */
    float normal_cutoff;   /* degrees: normals further apart never mix, 0 = 25 */
    float position_sigma;  /* r = world distance / (texel distance x world size):
                              w = 1 up to r = 1, then exp(-((r - 1) / sigma)^2),
                              0 beyond 1 + 3 sigma: 0 = 0.25 */
    float albedo_sigma;    /* w = exp(-|a_p - a_q|^2 / sigma^2): 0 = 0.1 */
    int threads;           /* 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_denoise_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_denoise_desc lx_denoise_desc_defaults(const lx_denoise_desc *desc);

/* Filters in (width*height*3 floats) into out (the same size; may be in).
 * Invalid texels of out get in's values. desc may be NULL (defaults). */
lx_status lx_denoise(const lx_denoise_guides *guides, const float *in, float *out,
                     const lx_denoise_desc *desc);

/* A lightmap from its direct and indirect parts under mode (see
 * lx_denoise_mode); direct may be NULL (zero), indirect not; out (width*
 * height*3 floats) may be either input. guides->variance, when given, is
 * the filtered signal's: the indirect part's for LX_DENOISE_INDIRECT.
 * LX_DENOISE_OFF only adds. */
lx_status lx_denoise_combine(lx_denoise_mode mode, const lx_denoise_guides *guides,
                             const float *direct, const float *indirect, float *out,
                             const lx_denoise_desc *desc);

/* The guides of a baker's lightmap `map`, allocated into *out (free with
 * lx_denoise_guides_free): the covered texels as valid, their world
 * positions and shading normals (normal map applied, at the nodes'
 * current transforms), the scene node as chart id (nodes sharing an atlas
 * page never mix); no albedo (the baker's buffers are irradiance, albedo
 * multiplies in after), sizes measured, variance estimated. *out is
 * zeroed on failure. */
lx_status lx_baker_denoise_guides(const lx_baker *baker, uint32_t map, lx_denoise_guides *out);
/* Releases what lx_baker_denoise_guides allocated and zeroes *guides;
 * only for guides it made. NULL does nothing. */
void lx_denoise_guides_free(lx_denoise_guides *guides);

#ifdef __cplusplus
}
#endif
#endif
