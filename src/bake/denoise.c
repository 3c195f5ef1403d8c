/* Lightmap denoising: the edge-avoiding a-trous wavelet transform of
 * H. Dammertz, D. Sewtz, J. Hanika and H. Lensch, "Edge-Avoiding A-Trous
 * Wavelet Transform for fast Global Illumination Filtering" (HPG 2010),
 * with the variance-guided luminance weight of C. Schied et al.,
 * "Spatiotemporal Variance-Guided Filtering" (SVGF, HPG 2017), moved from
 * screen space to texture space.
 *
 * Each pass gathers, for every valid texel p, the 5x5 taps q = p + step *
 * (i, j) (step 1, 2, 4, ... texels; B3-spline weights h_i h_j, h = 1/16,
 * 1/4, 3/8, 1/4, 1/16) with the weight
 *   w = h_i h_j exp(-(sigma_n (1 - n_p.n_q) + pos + lum + alb))
 * where pos is 0 while the world distance r (in units of the distance
 * the two texels would have on one flat surface: step |(i, j)| times the
 * texels' world size) is at most 1 and ((r - 1) / sigma_p)^2 beyond; lum
 * is |l_p - l_q| / (sigma_l sd_p), sd_p the square root of p's variance
 * smoothed over its 3x3 neighbours (SVGF); alb is |a_p - a_q|^2 /
 * sigma_a^2. The output is c_p + sum w (c_q - c_p) / sum w (normalized,
 * exact for a constant) and the variance goes through as sum w^2 var_q /
 * (sum w)^2 (SVGF), so the luminance weight tightens as the noise drops.
 *
 * Lightmaps differ from screens in one way that matters: texels next to
 * each other in the map can be far apart in space (charts packed side by
 * side). Before the passes, the valid texels are joined into surfaces:
 * two 8-neighbours belong to one when they have one chart id, normals
 * within the cutoff and a distance of at most 1 + 3 sigma_p times the
 * smaller of their world sizes (union-find in raster order, each surface
 * labelled by its first texel, so the labels do not depend on threads).
 * A tap is taken only from the texel's own surface, and within it the
 * normal and distance cutoffs still apply tap by tap. A texel's world
 * size is measured from the positions of its 8-neighbours (distance over
 * the offset's length) that pass the chart and normal tests: the largest
 * of those within twice the smallest, so an anisotropic chart is measured
 * by its longer axis and a far chart next to it in the map is not
 * counted. Using the smaller of two texels' sizes keeps a lone texel
 * that measured itself against a far chart from reaching it.
 *
 * Without a variance guide the variance of each texel's luminance is
 * estimated as the sample variance of the 5x5 texels around it on its
 * surface (SVGF's spatial estimate, where it has no history).
 *
 * Every value a pass writes is a fixed sum over the previous pass's
 * values in a fixed order; rows are shared among threads, so results are
 * bit-identical for any thread count. This file checks the input, builds
 * the guides (sizes, surfaces, variance) and runs the passes;
 * denoise_atrous.c computes a pass's rows. */
#include "core/internal.h"
#include "denoise_internal.h"
#include "luxel/denoise.h"

#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_ITERATIONS 12
#define MAX_SIDE 65536
#define NO_SURFACE LX_DN_NO_SURFACE
/* colours, positions and sizes beyond this are refused: their squares
 * (variances, distances) must stay finite in float */
#define VALUE_LIMIT 1e18f
#define VARIANCE_LIMIT 1e36f
/* scratch bytes a texel at the peak: the guide record (32), the guides
 * as planes (32) and the signal (16) while the planes are made */
#define BYTES_PER_TEXEL (32 + 32 + 16)

lx_denoise_desc lx_denoise_desc_defaults(const lx_denoise_desc *desc)
{
    lx_denoise_desc d = {0};
    if (desc)
        d = *desc;
    if (d.iterations == 0)
        d.iterations = 5;
    if (d.luminance_sigma == 0.0f)
        d.luminance_sigma = 4.0f;
    if (d.normal_sigma == 0.0f)
        d.normal_sigma = 64.0f;
    if (d.normal_cutoff == 0.0f)
        d.normal_cutoff = 25.0f;
    if (d.position_sigma == 0.0f)
        d.position_sigma = 0.25f;
    if (d.albedo_sigma == 0.0f)
        d.albedo_sigma = 0.1f;
    return d;
}

const char *lx_denoise_mode_name(lx_denoise_mode mode)
{
    switch (mode) {
    case LX_DENOISE_OFF:
        return "off";
    case LX_DENOISE_INDIRECT:
        return "indirect";
    case LX_DENOISE_ALL:
        return "all";
    }
    return NULL;
}

bool lx_denoise_mode_parse(const char *name, lx_denoise_mode *out)
{
    for (int m = LX_DENOISE_OFF; m <= LX_DENOISE_ALL; m++)
        if (name && strcmp(name, lx_denoise_mode_name((lx_denoise_mode)m)) == 0) {
            *out = (lx_denoise_mode)m;
            return true;
        }
    return false;
}

/* What a tap reads of a texel's guides, in one place (32 bytes). */
typedef struct guide {
    lx_vec3 p; /* world position */
    float s;   /* while the guides are built: the texel's world size t;
                  for the passes 1 / t^2 (FLT_MAX for t = 0) */
    lx_vec3 n; /* unit normal */
    uint32_t surface; /* label (first texel) of its surface, NO_SURFACE when invalid */
} guide;

typedef struct filter {
    int w, h, threads;
    const uint8_t *valid;
    const lx_vec3 *albedo; /* NULL: no albedo weight */
    const uint32_t *chart; /* NULL: one chart */
    guide *g;
    float *a; /* RGB + luminance variance a texel, until the passes' planes */
    float cos_cut, sigma_n, sigma_p, r_cut, r_cut2, sigma_l, inv_sa2;
    bool use_luminance;
    /* progress: rows done of the current stage, reported by thread 0 */
    lx_progress_fn progress;
    void *user;
    float base, span, last;
    atomic_int rows;
    atomic_bool stop;
} filter;

static inline float lum(const float *c)
{
    return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

static inline float dist2(lx_vec3 a, lx_vec3 b)
{
    lx_vec3 d = lx_sub(a, b);
    return lx_dot(d, d);
}

/* Counts a finished row; thread 0 reports the stage's share (at most
 * every 0.1%) and raises stop when the callback says so. */
static void row_done(filter *f)
{
    int rows = atomic_fetch_add_explicit(&f->rows, 1, memory_order_relaxed) + 1;
    if (!f->progress || omp_get_thread_num() != 0)
        return;
    float fraction = f->base + f->span * (float)rows / (float)f->h;
    if (fraction < f->last + 0.001f)
        return;
    f->last = fraction;
    if (!f->progress(f->user, fraction))
        atomic_store(&f->stop, true);
}

static void stage_begin(filter *f, float base, float span)
{
    atomic_store(&f->rows, 0);
    f->base = base;
    f->span = span;
}

static bool stopped(filter *f)
{
    return atomic_load_explicit(&f->stop, memory_order_relaxed);
}

/* Do p and q (valid) lie on one chart with normals within the cutoff? */
static inline bool alike(const filter *f, size_t p, size_t q, float *nd)
{
    if (f->chart && f->chart[p] != f->chart[q])
        return false;
    *nd = lx_dot(f->g[p].n, f->g[q].n);
    return *nd >= f->cos_cut;
}

/* ---- guides: normals, sizes, surfaces -------------------------------------- */

/* Positions, unit normals and the caller's sizes (0 when none) of the
 * valid texels; zeros elsewhere. */
static void init_guides(filter *f, const lx_denoise_guides *in)
{
    int w = f->w, h = f->h;
#pragma omp parallel for schedule(static) num_threads(f->threads)
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            guide *g = &f->g[p];
            if (!f->valid[p]) {
                *g = (guide){.surface = NO_SURFACE};
                continue;
            }
            g->p = in->position[p];
            g->n = lx_normalize(in->normal[p]);
            g->s = in->texel_size ? in->texel_size[p] : 0.0f;
            g->surface = (uint32_t)p;
        }
    }
}

static void measure_sizes(filter *f)
{
    int w = f->w, h = f->h;
#pragma omp parallel for schedule(dynamic, 16) num_threads(f->threads)
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            if (!f->valid[p])
                continue;
            float cand[8], dmin = INFINITY;
            int k = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= w || qy >= h)
                        continue;
                    size_t q = (size_t)qy * w + qx;
                    float nd;
                    if (!f->valid[q] || !alike(f, p, q, &nd))
                        continue;
                    float d =
                        sqrtf(dist2(f->g[p].p, f->g[q].p)) * (dx && dy ? 0.70710678f : 1.0f);
                    if (d > 0.0f) {
                        cand[k++] = d;
                        dmin = d < dmin ? d : dmin;
                    }
                }
            float t = 0.0f;
            for (int i = 0; i < k; i++)
                if (cand[i] <= 2.0f * dmin && cand[i] > t)
                    t = cand[i];
            f->g[p].s = t;
        }
    }
}

/* Union-find over the surface labels (a texel's label is its parent). */
static uint32_t find(guide *g, uint32_t a)
{
    while (g[a].surface != a) {
        g[a].surface = g[g[a].surface].surface;
        a = g[a].surface;
    }
    return a;
}

/* Joins the surfaces of a and b; the root is always the smaller index, so
 * a surface's label is its first texel in raster order. */
static void unite(guide *g, uint32_t a, uint32_t b)
{
    uint32_t ra = find(g, a), rb = find(g, b);
    if (ra < rb)
        g[rb].surface = ra;
    else if (rb < ra)
        g[ra].surface = rb;
}

static void build_surfaces(filter *f)
{
    int w = f->w, h = f->h;
    guide *g = f->g;
    /* each pair once: right, down-left, down, down-right */
    static const int DX[4] = {1, -1, 0, 1}, DY[4] = {0, 1, 1, 1};
    for (int y = 0; y < h; y++) {
        if (stopped(f))
            return;
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            if (!f->valid[p])
                continue;
            for (int k = 0; k < 4; k++) {
                int qx = x + DX[k], qy = y + DY[k];
                if (qx < 0 || qx >= w || qy >= h)
                    continue;
                size_t q = (size_t)qy * w + qx;
                float nd;
                if (!f->valid[q] || !alike(f, p, q, &nd))
                    continue;
                float t = g[p].s < g[q].s ? g[p].s : g[q].s;
                float len2 = DX[k] && DY[k] ? 2.0f : 1.0f;
                if (dist2(g[p].p, g[q].p) <= f->r_cut2 * len2 * t * t)
                    unite(g, (uint32_t)p, (uint32_t)q);
            }
        }
        row_done(f); /* on the calling thread: thread 0 */
    }
    for (size_t p = 0; p < (size_t)w * h; p++)
        if (g[p].surface != NO_SURFACE) {
            g[p].surface = find(g, (uint32_t)p);
            g[p].s = g[p].s > 0.0f ? 1.0f / (g[p].s * g[p].s) : FLT_MAX;
        }
}

/* Sample variance of the luminance over the 5x5 texels of p's surface
 * around it (uniform weights, double sums in a fixed order). */
static void estimate_variance(filter *f)
{
    int w = f->w, h = f->h;
    float *a = f->a;
#pragma omp parallel for schedule(dynamic, 16) num_threads(f->threads)
    for (int y = 0; y < h; y++) {
        if (stopped(f))
            continue;
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            uint32_t s = f->g[p].surface;
            if (s == NO_SURFACE)
                continue;
            double m1 = 0.0, m2 = 0.0;
            int n = 0;
            for (int dy = -2; dy <= 2; dy++)
                for (int dx = -2; dx <= 2; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= w || qy >= h)
                        continue;
                    size_t q = (size_t)qy * w + qx;
                    float nd;
                    if (f->g[q].surface != s || !alike(f, p, q, &nd))
                        continue;
                    double l = lum(a + 4 * q);
                    m1 += l;
                    m2 += l * l;
                    n++;
                }
            double var = 0.0;
            if (n > 1) {
                double mean = m1 / n;
                var = (m2 / n - mean * mean) * n / (n - 1);
            }
            a[4 * p + 3] = var > 0.0 ? (float)var : 0.0f;
        }
        row_done(f);
    }
}

/* ---- the a-trous passes ------------------------------------------------------ */

/* The passes' planes: the guides as lx_dn_guides (the AoS records are
 * freed), the signal as planes (invalid texels zero in both). */
static bool to_planes(filter *f, lx_dn_guides *dg, lx_dn_planes *src, lx_dn_planes *dst,
                      float **lum)
{
    size_t n = (size_t)f->w * f->h;
    float *gp = malloc(n * 7 * sizeof(float));
    uint32_t *surface = malloc(n * sizeof(uint32_t));
    if (!gp || !surface) {
        free(gp);
        free(surface);
        return false;
    }
    dg->px = gp, dg->py = gp + n, dg->pz = gp + 2 * n;
    dg->nx = gp + 3 * n, dg->ny = gp + 4 * n, dg->nz = gp + 5 * n;
    dg->inv_t2 = gp + 6 * n;
    dg->surface = surface;
#pragma omp parallel for schedule(static) num_threads(f->threads)
    for (int y = 0; y < f->h; y++)
        for (size_t p = (size_t)y * f->w; p < (size_t)(y + 1) * f->w; p++) {
            const guide *g = &f->g[p];
            dg->px[p] = g->p.x, dg->py[p] = g->p.y, dg->pz[p] = g->p.z;
            dg->nx[p] = g->n.x, dg->ny[p] = g->n.y, dg->nz[p] = g->n.z;
            dg->inv_t2[p] = g->s;
            dg->surface[p] = g->surface;
        }
    free(f->g);
    f->g = NULL;
    float *sp = malloc(n * 4 * sizeof(float));
    if (!sp)
        return false;
    src->r = sp, src->g = sp + n, src->b = sp + 2 * n, src->v = sp + 3 * n;
#pragma omp parallel for schedule(static) num_threads(f->threads)
    for (int y = 0; y < f->h; y++)
        for (size_t p = (size_t)y * f->w; p < (size_t)(y + 1) * f->w; p++) {
            src->r[p] = f->a[4 * p], src->g[p] = f->a[4 * p + 1];
            src->b[p] = f->a[4 * p + 2], src->v[p] = f->a[4 * p + 3];
        }
    free(f->a);
    f->a = NULL;
    float *dp = calloc(n * 5, sizeof(float)); /* dst's planes and the luminance */
    if (!dp)
        return false;
    dst->r = dp, dst->g = dp + n, dst->b = dp + 2 * n, dst->v = dp + 3 * n;
    *lum = dp + 4 * n;
    return true;
}

static void atrous_pass(filter *f, const lx_dn_guides *dg, const lx_dn_planes *src,
                        const lx_dn_planes *dst, float *lum, float *scratch, int step)
{
    int w = f->w, h = f->h;
#pragma omp parallel num_threads(f->threads)
    {
#pragma omp for schedule(static)
        for (int y = 0; y < h; y++)
            for (size_t p = (size_t)y * w; p < (size_t)(y + 1) * w; p++)
                lum[p] = 0.2126f * src->r[p] + 0.7152f * src->g[p] + 0.0722f * src->b[p];
        float *mine = scratch + LX_DN_ROW_SCRATCH(w) * (size_t)omp_get_thread_num();
#pragma omp for schedule(dynamic, 4)
        for (int y = 0; y < h; y++) {
            if (stopped(f))
                continue;
            lx_dn_atrous_row(dg, src, lum, dst, y, step, mine);
            row_done(f);
        }
    }
}

/* ---- checks ------------------------------------------------------------------- */

static lx_status check_desc(const lx_denoise_desc *d)
{
    if (d->iterations < 1 || d->iterations > MAX_ITERATIONS)
        return lx_fail(LX_ERR_INVALID, "denoise: iterations %d out of range (1 to %d)",
                       d->iterations, MAX_ITERATIONS);
    struct {
        const char *name;
        float v, hi;
    } f[] = {{"luminance_sigma", d->luminance_sigma, 1e30f},
             {"normal_sigma", d->normal_sigma, 1e30f},
             {"normal_cutoff", d->normal_cutoff, 180.0f},
             {"position_sigma", d->position_sigma, 1e6f},
             {"albedo_sigma", d->albedo_sigma, 1e30f}};
    for (size_t i = 0; i < sizeof f / sizeof f[0]; i++)
        if (!(f[i].v > 0.0f) || !(f[i].v <= f[i].hi))
            return lx_fail(LX_ERR_INVALID, "denoise: %s %g out of range (above 0, at most %g)",
                           f[i].name, (double)f[i].v, (double)f[i].hi);
    if (d->threads < 0)
        return lx_fail(LX_ERR_INVALID, "denoise: thread count %d is negative", d->threads);
    return LX_OK;
}

static bool finite_within(float v, float limit)
{
    return fabsf(v) <= limit; /* false for NaN */
}

static bool vec_within(lx_vec3 v, float limit)
{
    return finite_within(v.x, limit) && finite_within(v.y, limit) && finite_within(v.z, limit);
}

static bool rgb_within(const float *c)
{
    return finite_within(c[0], VALUE_LIMIT) && finite_within(c[1], VALUE_LIMIT) &&
           finite_within(c[2], VALUE_LIMIT);
}

/* Every valid texel's inputs, in raster order: the first bad one is named. */
static lx_status check_texels(const lx_denoise_guides *g, const float *direct,
                              const float *indirect, const char *what_direct,
                              const char *what_indirect, bool sum)
{
    int w = g->width;
    size_t n = (size_t)w * g->height;
    for (size_t p = 0; p < n; p++) {
        if (!g->valid[p])
            continue;
        const char *bad = NULL;
        float sum_rgb[3];
        if (!vec_within(g->position[p], VALUE_LIMIT))
            bad = "position is NaN, infinite or beyond 1e18";
        else if (!vec_within(g->normal[p], VALUE_LIMIT) ||
                 !(lx_dot(g->normal[p], g->normal[p]) > 0.0f))
            bad = "normal is zero, NaN or infinite";
        else if (g->albedo && !vec_within(g->albedo[p], VALUE_LIMIT))
            bad = "albedo is NaN, infinite or beyond 1e18";
        else if (g->texel_size && !(g->texel_size[p] >= 0.0f && g->texel_size[p] <= VALUE_LIMIT))
            bad = "texel size is negative, NaN, infinite or beyond 1e18";
        else if (g->variance && !(g->variance[p] >= 0.0f && g->variance[p] <= VARIANCE_LIMIT))
            bad = "variance is negative, NaN, infinite or beyond 1e36";
        else if (direct && !rgb_within(direct + 3 * p))
            bad = what_direct;
        else if (!rgb_within(indirect + 3 * p))
            bad = what_indirect;
        else if (sum && direct) {
            for (int c = 0; c < 3; c++)
                sum_rgb[c] = direct[3 * p + c] + indirect[3 * p + c];
            if (!rgb_within(sum_rgb))
                bad = "direct + indirect is beyond 1e18";
        }
        if (bad)
            return lx_fail(LX_ERR_INVALID, "denoise: texel (%d, %d): %s", (int)(p % (size_t)w),
                           (int)(p / (size_t)w), bad);
    }
    return LX_OK;
}

/* What out holds where nothing is filtered. */
static inline void passthrough(const float *direct, const float *indirect, float *out, size_t p)
{
    for (int c = 0; c < 3; c++)
        out[3 * p + c] = direct ? direct[3 * p + c] + indirect[3 * p + c] : indirect[3 * p + c];
}

/* ---- the calls ---------------------------------------------------------------- */

static lx_status run(lx_denoise_mode mode, const lx_denoise_guides *g, const float *direct,
                     const float *indirect, float *out, const lx_denoise_desc *in_desc,
                     bool combine)
{
    lx_denoise_desc d = lx_denoise_desc_defaults(in_desc);
    lx_status st = check_desc(&d);
    if (st != LX_OK)
        return st;
    if (!lx_denoise_mode_name(mode))
        return lx_fail(LX_ERR_INVALID, "denoise: unknown mode %d", (int)mode);
    if (!g)
        return lx_fail(LX_ERR_INVALID, "denoise: no guides");
    if (g->width < 1 || g->height < 1 || g->width > MAX_SIDE || g->height > MAX_SIDE ||
        (uint64_t)g->width * (uint64_t)g->height > UINT32_MAX - 1u)
        return lx_fail(LX_ERR_INVALID,
                       "denoise: size %dx%d out of range (1 to %d a side, below 2^32 texels)",
                       g->width, g->height, MAX_SIDE);
    if (!g->valid || !g->position || !g->normal)
        return lx_fail(LX_ERR_INVALID, "denoise: the %s guide is NULL (required)",
                       !g->valid ? "valid" : !g->position ? "position" : "normal");
    if (!indirect || !out)
        return lx_fail(LX_ERR_INVALID, "denoise: the %s buffer is NULL",
                       !indirect ? (combine ? "indirect" : "input") : "output");
    int w = g->width, h = g->height;
    size_t n = (size_t)w * h;
    int threads = lx_thread_count(d.threads);
    if (mode == LX_DENOISE_OFF) {
#pragma omp parallel for schedule(static) num_threads(threads)
        for (int y = 0; y < h; y++)
            for (size_t p = (size_t)y * w; p < (size_t)(y + 1) * w; p++)
                passthrough(direct, indirect, out, p);
        if (d.progress && !d.progress(d.progress_user, 1.0f))
            return lx_fail(LX_ERR_CANCELLED, "denoise cancelled");
        return LX_OK;
    }
    st = check_texels(g, direct, indirect,
                      "direct colour is NaN, infinite or beyond 1e18",
                      combine ? "indirect colour is NaN, infinite or beyond 1e18"
                              : "colour is NaN, infinite or beyond 1e18",
                      mode == LX_DENOISE_ALL);
    if (st != LX_OK)
        return st;
    char what[96];
    snprintf(what, sizeof what, "denoise: a %dx%d lightmap", w, h);
    if ((st = lx_check_memory((uint64_t)n * BYTES_PER_TEXEL, what)) != LX_OK)
        return st;

    filter f = {.w = w,
                .h = h,
                .threads = threads,
                .valid = g->valid,
                .albedo = g->albedo,
                .chart = g->chart,
                .cos_cut = cosf(d.normal_cutoff * (LX_PI / 180.0f)),
                .sigma_n = d.normal_sigma,
                .sigma_p = d.position_sigma,
                .r_cut = 1.0f + 3.0f * d.position_sigma,
                .r_cut2 = (1.0f + 3.0f * d.position_sigma) * (1.0f + 3.0f * d.position_sigma),
                .sigma_l = d.luminance_sigma,
                .inv_sa2 = 1.0f / (d.albedo_sigma * d.albedo_sigma),
                .use_luminance = !d.ignore_luminance,
                .progress = d.progress,
                .user = d.progress_user};
    atomic_init(&f.rows, 0);
    atomic_init(&f.stop, false);
    lx_dn_guides dg = {.w = w,
                       .h = h,
                       .albedo = g->albedo,
                       .cos_cut = f.cos_cut,
                       .sigma_n = f.sigma_n,
                       .sigma_p = f.sigma_p,
                       .r_cut2 = f.r_cut2,
                       .sigma_l = f.sigma_l,
                       .inv_sa2 = f.inv_sa2,
                       .use_luminance = f.use_luminance};
    lx_dn_planes pa = {0}, pb = {0};
    float *lum = NULL, *scratch = NULL;
    f.g = malloc(n * sizeof(guide));
    f.a = malloc(n * 4 * sizeof(float));
    scratch = malloc(LX_DN_ROW_SCRATCH(w) * (size_t)threads * sizeof(float));
    if (!f.g || !f.a || !scratch) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for the scratch", what);
        goto done;
    }
    /* progress: the guides and the variance count as one pass */
    float units = (float)d.iterations + 1.0f;

    init_guides(&f, g);
    if (!g->texel_size)
        measure_sizes(&f);
    /* progress: the surfaces are the first half of the first unit (they
     * run on one thread), the variance the second */
    stage_begin(&f, 0.0f, 0.5f / units);
    build_surfaces(&f);

    /* the signal: RGB and its variance */
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < h; y++)
        for (size_t p = (size_t)y * w; p < (size_t)(y + 1) * w; p++) {
            float *a = f.a + 4 * p;
            if (!g->valid[p]) {
                a[0] = a[1] = a[2] = a[3] = 0.0f;
                continue;
            }
            for (int c = 0; c < 3; c++)
                a[c] = indirect[3 * p + c] +
                       (mode == LX_DENOISE_ALL && direct ? direct[3 * p + c] : 0.0f);
            a[3] = g->variance ? g->variance[p] : 0.0f;
        }
    stage_begin(&f, 0.5f / units, 0.5f / units);
    if (!g->variance && !stopped(&f))
        estimate_variance(&f);

    if (!stopped(&f) && !to_planes(&f, &dg, &pa, &pb, &lum)) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for the scratch", what);
        goto done;
    }
    lx_dn_planes *src = &pa, *dst = &pb;
    for (int it = 0; it < d.iterations && !stopped(&f); it++) {
        stage_begin(&f, (float)(it + 1) / units, 1.0f / units);
        atrous_pass(&f, &dg, src, dst, lum, scratch, 1 << it);
        lx_dn_planes *t = src;
        src = dst;
        dst = t;
    }
    if (stopped(&f) || (d.progress && !d.progress(d.progress_user, 1.0f))) {
        st = lx_fail(LX_ERR_CANCELLED, "denoise cancelled");
        goto done;
    }

#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < h; y++)
        for (size_t p = (size_t)y * w; p < (size_t)(y + 1) * w; p++) {
            if (!g->valid[p]) {
                passthrough(direct, indirect, out, p);
                continue;
            }
            float r[3] = {src->r[p], src->g[p], src->b[p]};
            for (int c = 0; c < 3; c++)
                out[3 * p + c] =
                    mode == LX_DENOISE_INDIRECT && direct ? direct[3 * p + c] + r[c] : r[c];
        }

done:
    free(f.g);
    free(f.a);
    free(dg.px); /* the planes' blocks start at their first plane */
    free(dg.surface);
    free(pa.r);
    free(pb.r);
    free(scratch);
    return st;
}

lx_status lx_denoise(const lx_denoise_guides *guides, const float *in, float *out,
                     const lx_denoise_desc *desc)
{
    if (!in)
        return lx_fail_null(__func__, "in");
    return run(LX_DENOISE_ALL, guides, NULL, in, out, desc, false);
}

lx_status lx_denoise_combine(lx_denoise_mode mode, const lx_denoise_guides *guides,
                             const float *direct, const float *indirect, float *out,
                             const lx_denoise_desc *desc)
{
    if (!indirect)
        return lx_fail_null(__func__, "indirect");
    return run(mode, guides, direct, indirect, out, desc, true);
}
