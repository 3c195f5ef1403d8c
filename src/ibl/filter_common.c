/* Shared machinery of the IBL filters: exact texel solid-angle tables (the
 * solid angle of a face rectangle seen from the cube centre, as in
 * cubemap.c), argument checks, progress and cancellation of the tiled
 * OpenMP loops, and a bilinear sampler with a fast path inside a face. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

double *lx_ibl_solid_angles(int n)
{
    int h = (n + 1) / 2;
    double *q = malloc(sizeof(double) * (size_t)h * (size_t)h);
    /* F on two neighbouring grid lines: grid point i is at (2i - n) / n */
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
        for (int i = 0; i <= h; i++) {
            double a = (double)(2 * i - n) / (double)n;
            hi[i] = atan2(a * b, sqrt(a * a + b * b + 1.0));
        }
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

void lx_ibl_progress_init(lx_ibl_progress *p, lx_progress_fn fn, void *user, double total,
                          float base, float span)
{
    p->fn = fn;
    p->user = user;
    p->total = total > 0.0 ? total : 1.0;
    p->done = 0.0;
    p->base = base;
    p->span = span;
    p->cancelled = 0;
}

void lx_ibl_progress_add(lx_ibl_progress *p, double work)
{
    if (!p->fn)
        return;
    double done;
#pragma omp atomic capture
    done = p->done += work;
    if (omp_get_thread_num() != 0 || p->cancelled)
        return;
    double f = done / p->total;
    if (f > 1.0)
        f = 1.0;
    if (!p->fn(p->user, p->base + p->span * (float)f))
        p->cancelled = 1;
}

bool lx_ibl_progress_end(lx_ibl_progress *p)
{
    if (p->cancelled)
        return false;
    if (p->fn && !p->fn(p->user, p->base + p->span))
        p->cancelled = 1;
    return !p->cancelled;
}

lx_status lx_ibl_chain_build(const lx_cubemap *src, int min_size, int threads, lx_ibl_chain *out)
{
    memset(out, 0, sizeof *out);
    out->level[0] = *src;
    out->count = 1;
    if (min_size < 1)
        min_size = 1;
    while (out->level[out->count - 1].size / 2 >= min_size && out->count <= LX_MAX_CUBE_MIPS) {
        lx_status st =
            lx_ibl_downsample(&out->level[out->count - 1], &out->level[out->count], threads);
        if (st != LX_OK) {
            lx_ibl_chain_free(out);
            return st;
        }
        out->count++;
    }
    return LX_OK;
}

void lx_ibl_chain_free(lx_ibl_chain *chain)
{
    for (int i = 1; i < chain->count; i++)
        lx_cubemap_free(&chain->level[i]);
    memset(chain, 0, sizeof *chain);
}

void lx_ibl_sample(const lx_cubemap *c, lx_vec3 d, float out[3])
{
    /* lx_cube_face_coords, inlined */
    float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
    float sc, tc, ma;
    int face;
    if (ax >= ay && ax >= az) {
        ma = ax;
        face = d.x >= 0.0f ? LX_FACE_PX : LX_FACE_NX;
        sc = d.x >= 0.0f ? -d.z : d.z;
        tc = -d.y;
    } else if (ay >= az) {
        ma = ay;
        face = d.y >= 0.0f ? LX_FACE_PY : LX_FACE_NY;
        sc = d.x;
        tc = d.y >= 0.0f ? d.z : -d.z;
    } else {
        ma = az;
        face = d.z >= 0.0f ? LX_FACE_PZ : LX_FACE_NZ;
        sc = d.z >= 0.0f ? d.x : -d.x;
        tc = -d.y;
    }
    float s = lx_saturate(0.5f * (sc / ma + 1.0f));
    float t = lx_saturate(0.5f * (tc / ma + 1.0f));
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
                const float *src;
                if (x >= 0 && x < n && y >= 0 && y < n) {
                    src = lx_cubemap_texel(c, face, x, y);
                } else {
                    /* the texel whose centre is nearest the extrapolated
                     * direction, as lx_cubemap_sample takes it */
                    float sc = 2.0f * ((float)x + 0.5f) / (float)n - 1.0f;
                    float tc = 2.0f * ((float)y + 0.5f) / (float)n - 1.0f;
                    int f;
                    float s, t;
                    lx_cube_face_coords(lx_ibl_face_vector(face, sc, tc), &f, &s, &t);
                    int nx = (int)(s * (float)n), ny = (int)(t * (float)n);
                    nx = nx < 0 ? 0 : nx >= n ? n - 1 : nx;
                    ny = ny < 0 ? 0 : ny >= n ? n - 1 : ny;
                    src = lx_cubemap_texel(c, f, nx, ny);
                }
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
