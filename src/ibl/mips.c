/* Cube map mip levels and resampling down: each texel of the smaller map
 * is the mean of the source texels it covers, weighted by their exact
 * solid angles (so the level keeps the source's radiant flux through
 * every texel), sums in double. When the sizes divide, a texel covers a
 * whole block of source texels; otherwise (an odd size halved, or any
 * ratio) the texels along a block's border are weighted by the covered
 * fraction of their side too. One pass from the source to any smaller
 * size gives what halving repeatedly gives when the sizes divide (the
 * solid angles of the children add up to the parent's), without the
 * levels between. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int lx_ibl_halved_size(int size, int limit)
{
    limit = limit < 1 ? 1 : limit;
    while (size > limit)
        size = size / 2 > 0 ? size / 2 : 1;
    return size;
}

/* Source texels under destination texel X along one axis (m destination
 * texels over n source ones), with the length each one has inside it in
 * units of 1 / (n m): integers, so exact. */
typedef struct lx_span {
    int first, count;
    const double *w;
} lx_span;

typedef struct down_job {
    const lx_cubemap *src;
    lx_cubemap *dst;
    const double *omega;
    const lx_span *spans;
} down_job;

static bool down_row(void *ctx, int r)
{
    const down_job *j = ctx;
    int n = j->src->size, m = j->dst->size;
    int face = r / m, Y = r % m;
    const lx_span *sy = &j->spans[Y];
    for (int X = 0; X < m; X++) {
        const lx_span *sx = &j->spans[X];
        double sum[3] = {0, 0, 0}, wsum = 0.0;
        for (int jj = 0; jj < sy->count; jj++) {
            int y = sy->first + jj;
            const float *row = lx_cubemap_texel(j->src, face, 0, y);
            for (int i = 0; i < sx->count; i++) {
                int x = sx->first + i;
                double w = sx->w[i] * sy->w[jj] * lx_ibl_omega(j->omega, n, x, y);
                const float *p = row + 3 * (size_t)x;
                sum[0] += w * p[0];
                sum[1] += w * p[1];
                sum[2] += w * p[2];
                wsum += w;
            }
        }
        float *o = lx_cubemap_texel(j->dst, face, X, Y);
        for (int k = 0; k < 3; k++)
            o[k] = (float)(sum[k] / wsum);
    }
    return true;
}

lx_status lx_ibl_downsample(const lx_cubemap *src, int size, const lx_ibl_run *run, lx_cubemap *dst)
{
    int n = src->size, m = size;
    lx_status st = lx_cubemap_alloc(dst, m);
    if (st != LX_OK)
        return st;
    double *omega = lx_ibl_solid_angles(n);
    lx_span *spans = malloc(sizeof(lx_span) * (size_t)m);
    /* every destination texel covers at most n / m + 2 source texels */
    double *weights = malloc(sizeof(double) * ((size_t)n + 2 * (size_t)m));
    if (!omega || !spans || !weights) {
        free(omega);
        free(spans);
        free(weights);
        lx_cubemap_free(dst);
        return lx_fail(LX_ERR_NOMEM, "out of memory downsampling a %d x %d cube map", n, n);
    }
    double *w = weights;
    for (int X = 0; X < m; X++) {
        /* destination X covers [X n, (X+1) n), source i covers [i m, (i+1) m) */
        long lo = (long)X * n, hi = (long)(X + 1) * n;
        int first = (int)(lo / m), last = (int)((hi - 1) / m);
        spans[X] = (lx_span){first, last - first + 1, w};
        for (int k = 0; k < spans[X].count; k++) {
            long a = (long)(first + k) * m, b = a + m;
            *w++ = (double)((b < hi ? b : hi) - (a > lo ? a : lo));
        }
    }
    down_job job = {src, dst, omega, spans};
    /* rows of the destination, each costing the source rows it reads */
    st = lx_ibl_for(run, 6 * m, NULL, down_row, &job, "downsampling");
    free(weights);
    free(spans);
    free(omega);
    if (st != LX_OK)
        lx_cubemap_free(dst);
    return st;
}

lx_status lx_cubemap_downsample(const lx_cubemap *src, int size, const lx_ibl_desc *in,
                                lx_cubemap *dst)
{
    if (dst)
        memset(dst, 0, sizeof *dst);
    if (!dst)
        return lx_fail(LX_ERR_INVALID, "downsample: no output cube map (NULL)");
    lx_ibl_desc d = lx_ibl_desc_defaults(in);
    lx_status st = lx_ibl_check_cubemap(src, "downsample: source cube map", true);
    if (st == LX_OK)
        st = lx_ibl_check_threads(d.threads);
    if (st != LX_OK)
        return st;
    if (size == 0)
        size = src->size / 2 > 0 ? src->size / 2 : 1;
    if (size < 1 || size > src->size)
        return lx_fail(LX_ERR_INVALID, "downsample: face size %d is outside 1..%d (the source's)",
                       size, src->size);
    lx_ibl_run run = lx_ibl_run_make(d.threads, d.progress, d.progress_user);
    return lx_ibl_downsample(src, size, &run, dst);
}

/* ---- the chain ------------------------------------------------------------- */

int lx_ibl_chain_sizes(int size, int min_size, int sizes[LX_MAX_CUBE_MIPS + 1])
{
    min_size = min_size < 1 ? 1 : min_size;
    int count = 1;
    sizes[0] = size;
    while (sizes[count - 1] / 2 >= min_size && count <= LX_MAX_CUBE_MIPS) {
        sizes[count] = sizes[count - 1] / 2;
        count++;
    }
    return count;
}

uint64_t lx_ibl_chain_bytes(int size, int min_size)
{
    int sizes[LX_MAX_CUBE_MIPS + 1];
    int count = lx_ibl_chain_sizes(size, min_size, sizes);
    uint64_t bytes = 0;
    for (int i = 1; i < count; i++)
        bytes += lx_ibl_cube_bytes(sizes[i]);
    return bytes;
}

lx_status lx_ibl_chain_build(const lx_cubemap *src, int min_size, const lx_ibl_run *run,
                             lx_ibl_chain *out)
{
    memset(out, 0, sizeof *out);
    int sizes[LX_MAX_CUBE_MIPS + 1];
    int count = lx_ibl_chain_sizes(src->size, min_size, sizes);
    out->level[0] = *src;
    out->count = 1;
    /* progress by texels made: level i is a quarter of level i - 1 */
    double total = 0.0, done = 0.0;
    for (int i = 1; i < count; i++)
        total += (double)sizes[i] * sizes[i];
    for (int i = 1; i < count; i++) {
        double part = (double)sizes[i] * sizes[i];
        lx_ibl_run r = lx_ibl_run_part(run, done / total, (done + part) / total);
        lx_status st = lx_ibl_downsample(&out->level[i - 1], sizes[i], &r, &out->level[i]);
        if (st != LX_OK) {
            lx_ibl_chain_free(out);
            return st;
        }
        out->count++;
        done += part;
    }
    return LX_OK;
}

void lx_ibl_chain_free(lx_ibl_chain *chain)
{
    for (int i = 1; i < chain->count; i++)
        lx_cubemap_free(&chain->level[i]);
    memset(chain, 0, sizeof *chain);
}
