/* Private to src/bake: the denoiser's a-trous pass (denoise_atrous.c),
 * called row by row by denoise.c, which prepares its guides. */
#ifndef LX_DENOISE_INTERNAL_H
#define LX_DENOISE_INTERNAL_H

#include "luxel/denoise.h"

#include <stdbool.h>
#include <stdint.h>

#define LX_DN_NO_SURFACE UINT32_MAX

/* A signal as planes: RGB and the luminance variance, a float a texel
 * each. */
typedef struct lx_dn_planes {
    float *r, *g, *b, *v;
} lx_dn_planes;

/* What the passes read of the guides, as planes (the rows' loops then run
 * over contiguous floats). */
typedef struct lx_dn_guides {
    int w, h;
    float *px, *py, *pz; /* world position */
    float *nx, *ny, *nz; /* unit normal */
    float *inv_t2;       /* 1 / (texel world size)^2, FLT_MAX for size 0 */
    uint32_t *surface;   /* surface label, LX_DN_NO_SURFACE when invalid */
    const lx_vec3 *albedo; /* NULL: no albedo weight */
    float cos_cut, sigma_n, sigma_p, r_cut2, sigma_l, inv_sa2;
    bool use_luminance;
} lx_dn_guides;

/* Scratch floats lx_dn_atrous_row needs for a row of w texels. */
#define LX_DN_ROW_SCRATCH(w) (6 * (size_t)(w))

/* Row y of one pass with holes of `step`: every valid texel of dst from
 * src (whose luminance is lum); invalid texels of src must hold finite
 * values (zeros), which get weight 0. scratch holds
 * LX_DN_ROW_SCRATCH(w) floats. */
void lx_dn_atrous_row(const lx_dn_guides *g, const lx_dn_planes *src, const float *lum,
                      const lx_dn_planes *dst, int y, int step, float *scratch);

#endif
