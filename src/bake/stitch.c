/* Seam stitching: where a surface continues across a UV seam (the same
 * edge in two charts, lx_uv_seams), the lightmap texels that bilinear
 * lookups read on the two sides are made to agree, so a rendered surface
 * shows no line there. The least-squares approach of Sloan's "Stitching
 * lightmaps" (as Unity and lightmapper.h use it): sample each seam at two
 * points a texel on both sides, and find texel values x minimizing
 *     sum over samples (bilerp_A(x) - bilerp_B(x))^2 + lambda |x - x0|^2
 * over the texels the samples touch (x0 the baked values), by conjugate
 * gradients on the normal equations (lambda I + A^T A) x = lambda x0.
 * Each channel is solved on its own, in a fixed order, so the bytes do
 * not depend on the thread count. The samples are made once with the
 * texel map; solving runs where lx_baker_apply has padded the map, so the
 * padding texels the lookups also read take part. A texel the solution
 * takes below zero (a dark texel beside a bright seam) is set to zero:
 * light cannot be negative, and luxel render refuses negative texels. */
#include "bake_internal.h"
#include "core/internal.h"
#include "luxel/unwrap.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The pull toward the baked values against the seam samples' pull toward
 * each other: small, so seams close to within a few percent of their
 * jump while texels move no more than the seam asks. */
#define STITCH_LAMBDA 0.05
/* samples per texel of seam length */
#define STITCH_DENSITY 2.0
#define STITCH_MAX_ITERATIONS 200
#define STITCH_TOLERANCE 1e-24 /* squared residual relative to the start's: to double precision */
#define NO_VAR UINT32_MAX

struct lx_seam_stitch {
    uint32_t sample_count, var_count;
    uint32_t *var_pixel;  /* var -> pixel */
    uint32_t *tap_var;    /* 8 per sample: side A's four texels, then B's */
    float *tap_weight;    /* 8 per sample: A's bilinear weights, B's negated */
};

/* Bilinear footprint of page UV (u, v) with clamp-to-edge addressing. */
static void footprint(double u, double v, int w, int h, uint32_t pixel[4], float weight[4])
{
    double x = u * w - 0.5, y = v * h - 0.5;
    double fx0 = floor(x), fy0 = floor(y);
    double fx = x - fx0, fy = y - fy0;
    int x0 = (int)fx0, y0 = (int)fy0;
    int xs[2] = {x0, x0 + 1}, ys[2] = {y0, y0 + 1};
    for (int k = 0; k < 2; k++) {
        xs[k] = xs[k] < 0 ? 0 : xs[k] >= w ? w - 1 : xs[k];
        ys[k] = ys[k] < 0 ? 0 : ys[k] >= h ? h - 1 : ys[k];
    }
    for (int j = 0; j < 2; j++)
        for (int i = 0; i < 2; i++) {
            pixel[2 * j + i] = (uint32_t)ys[j] * (uint32_t)w + (uint32_t)xs[i];
            weight[2 * j + i] = (float)((i ? fx : 1.0 - fx) * (j ? fy : 1.0 - fy));
        }
}

typedef struct builder {
    lx_seam_stitch *s;
    uint32_t cap;
    uint32_t *pixel_var; /* per pixel of the map, NO_VAR until touched */
    int w, h;
} builder;

static bool add_sample(builder *b, const uint32_t pixel[8], const float weight[8])
{
    lx_seam_stitch *s = b->s;
    if (s->sample_count == b->cap) {
        uint32_t cap = b->cap ? 2 * b->cap : 256;
        uint32_t *tv = realloc(s->tap_var, sizeof(uint32_t) * 8 * (size_t)cap);
        if (tv)
            s->tap_var = tv;
        float *tw = realloc(s->tap_weight, sizeof(float) * 8 * (size_t)cap);
        if (tw)
            s->tap_weight = tw;
        uint32_t *vp = realloc(s->var_pixel, sizeof(uint32_t) * 8 * (size_t)cap);
        if (vp)
            s->var_pixel = vp;
        if (!tv || !tw || !vp)
            return false;
        b->cap = cap;
    }
    uint32_t base = 8 * s->sample_count++;
    for (int k = 0; k < 8; k++) {
        uint32_t p = pixel[k];
        if (b->pixel_var[p] == NO_VAR) {
            b->pixel_var[p] = s->var_count;
            s->var_pixel[s->var_count++] = p;
        }
        s->tap_var[base + (uint32_t)k] = b->pixel_var[p];
        s->tap_weight[base + (uint32_t)k] = weight[k];
    }
    return true;
}

/* Samples along one seam, its UVs taken into the page by so. */
static bool add_seam(builder *b, const lx_uv_seam *seam, const double so[4])
{
    double a[2][2], c[2][2];
    for (int k = 0; k < 2; k++) {
        a[k][0] = seam->a[k].x * so[0] + so[2], a[k][1] = seam->a[k].y * so[1] + so[3];
        c[k][0] = seam->b[k].x * so[0] + so[2], c[k][1] = seam->b[k].y * so[1] + so[3];
    }
    double la = hypot((a[1][0] - a[0][0]) * b->w, (a[1][1] - a[0][1]) * b->h);
    double lb = hypot((c[1][0] - c[0][0]) * b->w, (c[1][1] - c[0][1]) * b->h);
    int n = (int)ceil(STITCH_DENSITY * fmax(la, lb));
    n = n < 2 ? 2 : n;
    for (int i = 0; i < n; i++) {
        double t = (i + 0.5) / n;
        uint32_t pixel[8];
        float weight[8];
        footprint(a[0][0] + t * (a[1][0] - a[0][0]), a[0][1] + t * (a[1][1] - a[0][1]), b->w, b->h,
                  pixel, weight);
        footprint(c[0][0] + t * (c[1][0] - c[0][0]), c[0][1] + t * (c[1][1] - c[0][1]), b->w, b->h,
                  pixel + 4, weight + 4);
        for (int k = 4; k < 8; k++)
            weight[k] = -weight[k];
        if (!add_sample(b, pixel, weight))
            return false;
    }
    return true;
}

void lx_seam_stitch_free(lx_seam_stitch *s)
{
    if (!s)
        return;
    free(s->var_pixel);
    free(s->tap_var);
    free(s->tap_weight);
    free(s);
}

lx_status lx_seam_stitch_build(const lx_stitch_mesh *meshes, uint32_t count, int width,
                               int height, const char *what, lx_seam_stitch **out)
{
    *out = NULL;
    builder b = {.s = calloc(1, sizeof(lx_seam_stitch)), .w = width, .h = height};
    b.pixel_var = malloc(sizeof(uint32_t) * (size_t)width * (size_t)height);
    if (!b.s || !b.pixel_var) {
        free(b.s);
        free(b.pixel_var);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory for seam stitching", what);
    }
    memset(b.pixel_var, 0xff, sizeof(uint32_t) * (size_t)width * (size_t)height);
    lx_status st = LX_OK;
    for (uint32_t m = 0; m < count && st == LX_OK; m++) {
        lx_uv_seam *seams;
        uint32_t n;
        st = lx_uv_seams(meshes[m].mesh, meshes[m].uv_set, &seams, &n);
        for (uint32_t k = 0; k < n && st == LX_OK; k++)
            if (!add_seam(&b, &seams[k], meshes[m].scale_offset))
                st = lx_fail(LX_ERR_NOMEM, "%s: out of memory for seam stitching", what);
        free(seams);
    }
    free(b.pixel_var);
    if (st != LX_OK || b.s->sample_count == 0) {
        lx_seam_stitch_free(b.s);
        return st;
    }
    *out = b.s;
    return LX_OK;
}

uint32_t lx_seam_stitch_samples(const lx_seam_stitch *s)
{
    return s ? s->sample_count : 0;
}

/* y = (lambda I + A^T A) x over the stitch's variables; r: a row each. */
static void apply_normal(const lx_seam_stitch *s, const double *x, double *y, double *r)
{
    for (uint32_t v = 0; v < s->var_count; v++)
        y[v] = STITCH_LAMBDA * x[v];
    for (uint32_t i = 0; i < s->sample_count; i++) {
        const uint32_t *tv = &s->tap_var[8 * i];
        const float *tw = &s->tap_weight[8 * i];
        double sum = 0.0;
        for (int k = 0; k < 8; k++)
            sum += tw[k] * x[tv[k]];
        r[i] = sum;
    }
    for (uint32_t i = 0; i < s->sample_count; i++) {
        const uint32_t *tv = &s->tap_var[8 * i];
        const float *tw = &s->tap_weight[8 * i];
        for (int k = 0; k < 8; k++)
            y[tv[k]] += tw[k] * r[i];
    }
}

static double dot(const double *a, const double *b, uint32_t n)
{
    double s = 0.0;
    for (uint32_t i = 0; i < n; i++)
        s += a[i] * b[i];
    return s;
}

lx_status lx_seam_stitch_apply(const lx_seam_stitch *s, float *data, int channels,
                               const char *what)
{
    if (!s || s->var_count == 0)
        return LX_OK;
    uint32_t n = s->var_count;
    double *x = malloc(sizeof(double) * n), *x0 = malloc(sizeof(double) * n);
    double *res = malloc(sizeof(double) * n), *p = malloc(sizeof(double) * n);
    double *ap = malloc(sizeof(double) * n);
    double *rows = malloc(sizeof(double) * s->sample_count);
    if (!x || !x0 || !res || !p || !ap || !rows) {
        free(x), free(x0), free(res), free(p), free(ap), free(rows);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory stitching seams", what);
    }
    for (int c = 0; c < channels; c++) {
        for (uint32_t v = 0; v < n; v++)
            x[v] = x0[v] = data[(size_t)s->var_pixel[v] * (size_t)channels + (size_t)c];
        /* r = lambda x0 - M x, from x = x0: r = -A^T A x0 */
        apply_normal(s, x, ap, rows);
        for (uint32_t v = 0; v < n; v++)
            res[v] = STITCH_LAMBDA * x0[v] - ap[v];
        memcpy(p, res, sizeof(double) * n);
        double rr = dot(res, res, n), start = rr;
        for (int it = 0; it < STITCH_MAX_ITERATIONS && rr > STITCH_TOLERANCE * start; it++) {
            apply_normal(s, p, ap, rows);
            double pap = dot(p, ap, n);
            if (!(pap > 0.0))
                break;
            double alpha = rr / pap;
            for (uint32_t v = 0; v < n; v++) {
                x[v] += alpha * p[v];
                res[v] -= alpha * ap[v];
            }
            double next = dot(res, res, n);
            double beta = next / rr;
            rr = next;
            for (uint32_t v = 0; v < n; v++)
                p[v] = res[v] + beta * p[v];
        }
        /* light is never negative: where a dark texel beside a bright
         * one would overshoot below zero, it keeps zero (the nearest
         * value a lightmap can hold; the least squares has no bound) */
        for (uint32_t v = 0; v < n; v++)
            data[(size_t)s->var_pixel[v] * (size_t)channels + (size_t)c] =
                (float)(x[v] > 0.0 ? x[v] : 0.0);
    }
    free(x), free(x0), free(res), free(p), free(ap), free(rows);
    return LX_OK;
}
