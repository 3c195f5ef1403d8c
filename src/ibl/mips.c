/* Cube map mip levels: each texel of the half-size map is the mean of the
 * source texels it covers, weighted by their exact solid angles (so the
 * level keeps the source's radiant flux through every texel), sums in
 * double. Even sizes cover exactly 2x2 texels; an odd size n gives n / 2
 * texels per side, each covering a fractional 2.x texels, weighted by the
 * covered fraction of each source texel. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <stdlib.h>
#include <string.h>

/* Source texels under destination texel X along one axis, with the length
 * each one has inside it in units of 1 / dst (integers, so exact). */
typedef struct lx_span {
    int first, count;
    double w[4];
} lx_span;

static void make_span(int n, int m, int X, lx_span *s)
{
    /* destination X covers [X n, (X+1) n), source i covers [i m, (i+1) m) */
    long lo = (long)X * n, hi = (long)(X + 1) * n;
    int first = (int)(lo / m), last = (int)((hi - 1) / m);
    s->first = first;
    s->count = last - first + 1;
    for (int k = 0; k < s->count; k++) {
        long a = (long)(first + k) * m, b = a + m;
        long o = (b < hi ? b : hi) - (a > lo ? a : lo);
        s->w[k] = (double)o;
    }
}

lx_status lx_ibl_downsample(const lx_cubemap *src, lx_cubemap *dst, int threads)
{
    int n = src->size, m = n / 2 > 0 ? n / 2 : 1;
    lx_status st = lx_cubemap_alloc(dst, m);
    if (st != LX_OK)
        return st;
    double *omega = lx_ibl_solid_angles(n);
    lx_span *spans = malloc(sizeof(lx_span) * (size_t)m);
    if (!omega || !spans) {
        free(omega);
        free(spans);
        lx_cubemap_free(dst);
        return lx_fail(LX_ERR_NOMEM, "out of memory downsampling a %d x %d cube map", n, n);
    }
    for (int X = 0; X < m; X++)
        make_span(n, m, X, &spans[X]);
    int rows = 6 * m;
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(threads))
    for (int r = 0; r < rows; r++) {
        int face = r / m, Y = r % m;
        const lx_span *sy = &spans[Y];
        for (int X = 0; X < m; X++) {
            const lx_span *sx = &spans[X];
            double sum[3] = {0, 0, 0}, wsum = 0.0;
            for (int j = 0; j < sy->count; j++)
                for (int i = 0; i < sx->count; i++) {
                    int x = sx->first + i, y = sy->first + j;
                    double w = sx->w[i] * sy->w[j] * lx_ibl_omega(omega, n, x, y);
                    const float *p = lx_cubemap_texel(src, face, x, y);
                    sum[0] += w * p[0];
                    sum[1] += w * p[1];
                    sum[2] += w * p[2];
                    wsum += w;
                }
            float *o = lx_cubemap_texel(dst, face, X, Y);
            for (int k = 0; k < 3; k++)
                o[k] = (float)(sum[k] / wsum);
        }
    }
    free(spans);
    free(omega);
    return LX_OK;
}

lx_status lx_cubemap_downsample(const lx_cubemap *src, lx_cubemap *dst)
{
    if (dst)
        memset(dst, 0, sizeof *dst);
    if (!dst)
        return lx_fail(LX_ERR_INVALID, "downsample: no output cube map (NULL)");
    lx_status st = lx_ibl_check_cubemap(src, "downsample: source cube map", true);
    if (st != LX_OK)
        return st;
    return lx_ibl_downsample(src, dst, 0);
}
