/* Shared machinery of the IBL filters: exact texel solid-angle tables (the
 * solid angle of a face rectangle seen from the cube centre, as in
 * cubemap.c), argument checks, the parallel loop with progress and
 * cancellation, and the bilinear samplers (a fast path inside a face, and
 * padded copies whose border holds the texels across each edge). */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

double *lx_ibl_solid_angles(int n)
{
    int h = (n + 1) / 2;
    double *q = malloc(sizeof(double) * (size_t)h * (size_t)h);
    /* the corner function on two neighbouring grid lines: grid point i is
     * at (2i - n) / n */
    double *lo = malloc(sizeof(double) * (size_t)(h + 1));
    double *hi = malloc(sizeof(double) * (size_t)(h + 1));
    if (!q || !lo || !hi) {
        free(q);
        free(lo);
        free(hi);
        lx_fail(LX_ERR_NOMEM, "out of memory for the solid angles of a %d x %d face", n, n);
        return NULL;
    }
    for (int j = 0; j <= h; j++) {
        double b = (double)(2 * j - n) / (double)n;
        for (int i = 0; i <= h; i++)
            hi[i] = lx_ibl_corner((double)(2 * i - n) / (double)n, b);
        if (j > 0)
            for (int i = 0; i < h; i++)
                q[(size_t)(j - 1) * h + i] = lo[i] - lo[i + 1] - hi[i] + hi[i + 1];
        double *t = lo;
        lo = hi;
        hi = t;
    }
    free(lo);
    free(hi);
    return q;
}

lx_status lx_ibl_check_cubemap(const lx_cubemap *c, const char *what, bool scan)
{
    if (!c)
        return lx_fail(LX_ERR_INVALID, "%s is missing (NULL)", what);
    if (c->size < 1 || c->size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "%s: face size %d is outside 1..%d", what, c->size,
                       LX_MAX_CUBE_SIZE);
    if (!c->data)
        return lx_fail(LX_ERR_INVALID, "%s: no texel data", what);
    if (!scan)
        return LX_OK;
    size_t count = (size_t)6 * (size_t)c->size * (size_t)c->size * 3;
    size_t bad = 0;
    for (size_t i = 0; i < count; i++)
        bad += !isfinite(c->data[i]);
    if (bad)
        return lx_fail(LX_ERR_INVALID, "%s: %zu of %zu values are NaN or infinite", what, bad,
                       count);
    return LX_OK;
}

lx_status lx_ibl_check_threads(int threads)
{
    if (threads < 0 || threads > 1024)
        return lx_fail(LX_ERR_INVALID, "thread count %d is outside 0..1024", threads);
    return LX_OK;
}

void lx_ibl_warn_upsampling(const char *name, int size, double source_size)
{
    if (!((double)size > 4.0 * source_size))
        return;
    char bytes[32];
    lx_format_bytes(lx_ibl_cube_bytes(size), bytes, sizeof bytes);
    lx_log(LX_LOG_WARN,
           "%s upsample it %.0fx: the %s cube map holds no more detail than %.0f x %.0f faces "
           "would",
           name, (double)size / source_size, bytes, source_size, source_size);
}

/* ---- the parallel loop ------------------------------------------------------ */

lx_ibl_desc lx_ibl_desc_defaults(const lx_ibl_desc *desc)
{
    lx_ibl_desc d = {0};
    if (desc)
        d = *desc;
    return d;
}

lx_ibl_run lx_ibl_run_make(int threads, lx_progress_fn progress, void *user)
{
    lx_ibl_run r = {lx_thread_count(threads), progress, user, 0.0f, 1.0f};
    return r;
}

lx_ibl_run lx_ibl_run_part(const lx_ibl_run *run, double from, double to)
{
    lx_ibl_run r = *run;
    r.base = run->base + (float)(from * run->span);
    r.span = (float)((to - from) * run->span);
    return r;
}

lx_status lx_ibl_for(const lx_ibl_run *run, int count, const double *cost, lx_ibl_item_fn fn,
                     void *ctx, const char *what)
{
    double total = 0.0;
    if (run->progress) {
        for (int i = 0; i < count; i++)
            total += cost ? cost[i] : 1.0;
    }
    total = total > 0.0 ? total : 1.0;
    double done = 0.0, reported = 0.0;
    volatile int stop = 0, nomem = 0;
    /* whichever thread finishes an item reports, unless another one is
     * reporting: one at a time, never a smaller fraction than before */
    omp_lock_t lock;
    omp_init_lock(&lock);
#pragma omp parallel for schedule(dynamic, 1) num_threads(run->threads > 0 ? run->threads : 1)
    for (int i = 0; i < count; i++) {
        if (stop)
            continue;
        if (!fn(ctx, i)) {
            nomem = 1;
            stop = 1;
            continue;
        }
        if (!run->progress)
            continue;
        double now;
#pragma omp atomic capture
        now = done += cost ? cost[i] : 1.0;
        if (!omp_test_lock(&lock))
            continue;
        reported = now > reported ? now : reported;
        double f = reported / total;
        if (!stop && !run->progress(run->user, run->base + run->span * (float)(f < 1.0 ? f : 1.0)))
            stop = 1;
        omp_unset_lock(&lock);
    }
    omp_destroy_lock(&lock);
    if (nomem)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    if (!stop && run->progress && !run->progress(run->user, run->base + run->span))
        stop = 1;
    if (stop)
        return lx_fail(LX_ERR_CANCELLED, "%s cancelled", what);
    return LX_OK;
}

/* ---- sampling ------------------------------------------------------------------ */

void lx_ibl_sample(const lx_cubemap *c, lx_vec3 d, float out[3])
{
    int face;
    float s, t;
    lx_ibl_face_st(d, &face, &s, &t);
    int n = c->size;
    float fx = s * (float)n - 0.5f, fy = t * (float)n - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    int x0 = (int)x0f, y0 = (int)y0f;
    if (x0 < 0 || y0 < 0 || x0 + 1 >= n || y0 + 1 >= n) {
        lx_cubemap_sample(c, d, out);
        return;
    }
    float wx = fx - x0f, wy = fy - y0f;
    const float *a = lx_cubemap_texel(c, face, x0, y0);
    const float *e = a + 3 * (size_t)n;
    for (int k = 0; k < 3; k++) {
        float top = a[k] + (a[k + 3] - a[k]) * wx;
        float bottom = e[k] + (e[k + 3] - e[k]) * wx;
        out[k] = top + (bottom - top) * wy;
    }
}

lx_status lx_ibl_pad(const lx_cubemap *c, lx_ibl_padded *out)
{
    int n = c->size, w = n + 2;
    out->size = n;
    out->data = malloc(sizeof(float) * 3 * 6 * (size_t)w * (size_t)w);
    if (!out->data)
        return lx_fail(LX_ERR_NOMEM, "out of memory for a %d x %d cube map", n, n);
    for (int face = 0; face < 6; face++)
        for (int y = -1; y <= n; y++)
            for (int x = -1; x <= n; x++) {
                int f, tx, ty;
                lx_ibl_texel_across(n, face, x, y, &f, &tx, &ty);
                const float *src = lx_cubemap_texel(c, f, tx, ty);
                float *dst =
                    out->data + (((size_t)face * w + (size_t)(y + 1)) * w + (size_t)(x + 1)) * 3;
                dst[0] = src[0], dst[1] = src[1], dst[2] = src[2];
            }
    return LX_OK;
}

void lx_ibl_padded_free(lx_ibl_padded *p)
{
    free(p->data);
    p->data = NULL;
    p->size = 0;
}
