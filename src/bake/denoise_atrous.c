/* One pass of the lightmap denoiser's edge-avoiding a-trous transform
 * (Dammertz et al., "Edge-Avoiding A-Trous Wavelet Transform for fast
 * Global Illumination Filtering", HPG 2010; the luminance weight of
 * Schied et al., "Spatiotemporal Variance-Guided Filtering", HPG 2017),
 * row by row; denoise.c has the method and prepares the guides.
 *
 * A row is computed tap by tap: for each of the 24 offsets (i, j), one
 * loop over the row's texels adds that tap's weighted contribution to
 * each texel's sums. The loop has no branches (a tap that fails a test
 * gets weight 0), so the compiler runs it on vector lanes; each texel
 * still sums its taps in the same (j, i) order, one lane each, so the
 * result does not depend on the vector width or on threads. */
#include "denoise_internal.h"

#include <math.h>
#include <string.h>

static const float H[5] = {1.0f / 16.0f, 1.0f / 4.0f, 3.0f / 8.0f, 1.0f / 4.0f, 1.0f / 16.0f};
static const float G[3] = {0.25f, 0.5f, 0.25f};
/* 1 / (i^2 + j^2) for the tap offsets (the centre unused) */
static const float INV_LEN2[5][5] = {
    {1.0f / 8, 1.0f / 5, 1.0f / 4, 1.0f / 5, 1.0f / 8}, {1.0f / 5, 1.0f / 2, 1.0f, 1.0f / 2, 1.0f / 5},
    {1.0f / 4, 1.0f, 0.0f, 1.0f, 1.0f / 4},             {1.0f / 5, 1.0f / 2, 1.0f, 1.0f / 2, 1.0f / 5},
    {1.0f / 8, 1.0f / 5, 1.0f / 4, 1.0f / 5, 1.0f / 8}};
/* the luminance weight's denominator never reaches 0 (SVGF's epsilon) */
#define SD_EPSILON 1e-10f

/* e^-x for x >= 0 (0 from x = 86 on), to 6e-6 relative (the weights need
 * far less), without a call or a branch: x log2 e = k + f with k the
 * nearest integer, 2^-k by the exponent bits, e^-r for r = f ln 2 in
 * [-0.35, 0.35] by its Taylor series to r^5 (error below r^6 / 6! =
 * 2.4e-6), as Estrin's scheme so the chain of dependent operations stays
 * short. The same float operations on every machine. */
/* v where keep is 1, +0 where it is 0: bits, not a branch the compiler
 * could bring back (the loop then stays on vector lanes) */
static inline float keep_if(uint32_t keep, float v)
{
    union {
        float f;
        uint32_t u;
    } b = {.f = v};
    b.u &= 0u - keep;
    return b.f;
}

static inline float exp_neg(float x)
{
    uint32_t live = x < 86.0f;
    x = x < 86.0f ? x : 86.0f;
    float y = x * 1.44269504f; /* in [0, 124.1] */
    int k = (int)(y + 0.5f);   /* nearest for y >= 0 */
    float r = (y - (float)k) * 0.693147181f;
    float r2 = r * r;
    float e = (1.0f - r) + r2 * (0.5f - r * (1.0f / 6.0f)) +
              (r2 * r2) * (1.0f / 24.0f - r * (1.0f / 120.0f));
    union {
        uint32_t u;
        float f;
    } scale = {.u = (uint32_t)(127 - k) << 23};
    return keep_if(live, e * scale.f);
}

/* The tap (i, j) for texels x0..x1-1 of row y (their taps all inside the
 * map). Separate instances with and without albedo and luminance keep
 * the loop free of tests. */
static inline __attribute__((always_inline)) void tap(const lx_dn_guides *g, const lx_dn_planes *src, const float *lum,
                       size_t row, size_t qrow, int shift, int x0, int x1, float hw, float il2,
                       const float *restrict isd, float *restrict acc_r,
                       float *restrict acc_g, float *restrict acc_b, float *restrict wsum,
                       float *restrict vacc, bool use_lum, bool use_alb)
{
    const float *px = g->px + row, *py = g->py + row, *pz = g->pz + row;
    const float *nx = g->nx + row, *ny = g->ny + row, *nz = g->nz + row;
    const float *it = g->inv_t2 + row;
    const uint32_t *sp = g->surface + row;
    const float *qx = g->px + qrow + shift, *qy = g->py + qrow + shift, *qz = g->pz + qrow + shift;
    const float *mx = g->nx + qrow + shift, *my = g->ny + qrow + shift, *mz = g->nz + qrow + shift;
    const float *qt = g->inv_t2 + qrow + shift;
    const uint32_t *sq = g->surface + qrow + shift;
    const float *cr = src->r + row, *cg = src->g + row, *cb = src->b + row;
    const float *dr = src->r + qrow + shift, *dg = src->g + qrow + shift,
                *db = src->b + qrow + shift, *dv = src->v + qrow + shift;
    const float *lp = lum + row, *lq = lum + qrow + shift;
    const lx_vec3 *ap = use_alb ? g->albedo + row : NULL;
    const lx_vec3 *aq = use_alb ? g->albedo + qrow + shift : NULL;
    float cos_cut = g->cos_cut, sigma_n = g->sigma_n, sigma_p = g->sigma_p,
          r_cut2 = g->r_cut2, inv_sa2 = g->inv_sa2;
    for (int x = x0; x < x1; x++) {
        float nd = nx[x] * mx[x] + ny[x] * my[x] + nz[x] * mz[x];
        float inv_t2 = it[x] > qt[x] ? it[x] : qt[x];
        float ddx = px[x] - qx[x], ddy = py[x] - qy[x], ddz = pz[x] - qz[x];
        float r2 = (ddx * ddx + ddy * ddy + ddz * ddz) * il2 * inv_t2;
        uint32_t ok = (uint32_t)(sp[x] == sq[x]) & (uint32_t)(nd >= cos_cut) &
                      (uint32_t)(r2 <= r_cut2);
        float ex = sigma_n * (1.0f - nd);
        /* 0 up to r = 1 (and for taps already out) */
        float rc = r2 < r_cut2 ? r2 : r_cut2;
        float u = (sqrtf(rc > 1.0f ? rc : 1.0f) - 1.0f) / sigma_p;
        ex += u * u;
        if (use_lum)
            ex += fabsf(lp[x] - lq[x]) * isd[x];
        if (use_alb) {
            float ar = ap[x].x - aq[x].x, ag = ap[x].y - aq[x].y, ab = ap[x].z - aq[x].z;
            ex += (ar * ar + ag * ag + ab * ab) * inv_sa2;
        }
        float wq = keep_if(ok, hw * exp_neg(ex));
        acc_r[x] += wq * (dr[x] - cr[x]);
        acc_g[x] += wq * (dg[x] - cg[x]);
        acc_b[x] += wq * (db[x] - cb[x]);
        wsum[x] += wq;
        vacc[x] += wq * wq * dv[x];
    }
}

void lx_dn_atrous_row(const lx_dn_guides *g, const lx_dn_planes *src, const float *lum,
                      const lx_dn_planes *dst, int y, int step, float *scratch)
{
    int w = g->w, h = g->h;
    size_t row = (size_t)y * w;
    float *isd = scratch, *acc_r = scratch + w, *acc_g = scratch + 2 * (size_t)w,
          *acc_b = scratch + 3 * (size_t)w, *wsum = scratch + 4 * (size_t)w,
          *vacc = scratch + 5 * (size_t)w;
    float h2 = H[2] * H[2];
    for (int x = 0; x < w; x++) {
        size_t p = row + x;
        uint32_t s = g->surface[p];
        acc_r[x] = acc_g[x] = acc_b[x] = 0.0f;
        wsum[x] = h2;
        vacc[x] = h2 * h2 * src->v[p];
        isd[x] = 0.0f;
        if (s == LX_DN_NO_SURFACE)
            continue;
        /* p's variance smoothed over its 3x3 neighbours on its surface */
        float vs = 0.0f, gs = 0.0f;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                int qx = x + dx, qy = y + dy;
                if (qx < 0 || qy < 0 || qx >= w || qy >= h)
                    continue;
                size_t q = (size_t)qy * w + qx;
                if (g->surface[q] != s)
                    continue;
                float gw = G[dx + 1] * G[dy + 1];
                vs += gw * src->v[q];
                gs += gw;
            }
        vs /= gs;
        isd[x] = 1.0f / (g->sigma_l * sqrtf(vs) + SD_EPSILON);
    }
    float inv_step2 = 1.0f / (float)(step * step);
    bool lum_on = g->use_luminance, alb_on = g->albedo != NULL;
    for (int j = -2; j <= 2; j++) {
        int qy = y + j * step;
        if (qy < 0 || qy >= h)
            continue;
        for (int i = -2; i <= 2; i++) {
            if (i == 0 && j == 0)
                continue;
            int shift = i * step;
            /* texels whose tap lies inside the row */
            int x0 = shift < 0 ? -shift : 0, x1 = shift > 0 ? w - shift : w;
            if (x0 >= x1)
                continue;
            float hw = H[i + 2] * H[j + 2], il2 = INV_LEN2[j + 2][i + 2] * inv_step2;
            size_t qrow = (size_t)qy * w;
            if (lum_on && !alb_on)
                tap(g, src, lum, row, qrow, shift, x0, x1, hw, il2, isd, acc_r, acc_g, acc_b,
                    wsum, vacc, true, false);
            else if (lum_on)
                tap(g, src, lum, row, qrow, shift, x0, x1, hw, il2, isd, acc_r, acc_g, acc_b,
                    wsum, vacc, true, true);
            else if (alb_on)
                tap(g, src, lum, row, qrow, shift, x0, x1, hw, il2, isd, acc_r, acc_g, acc_b,
                    wsum, vacc, false, true);
            else
                tap(g, src, lum, row, qrow, shift, x0, x1, hw, il2, isd, acc_r, acc_g, acc_b,
                    wsum, vacc, false, false);
        }
    }
    for (int x = 0; x < w; x++) {
        size_t p = row + x;
        if (g->surface[p] == LX_DN_NO_SURFACE)
            continue;
        dst->r[p] = src->r[p] + acc_r[x] / wsum[x];
        dst->g[p] = src->g[p] + acc_g[x] / wsum[x];
        dst->b[p] = src->b[p] + acc_b[x] / wsum[x];
        dst->v[p] = vacc[x] / (wsum[x] * wsum[x]);
    }
}
