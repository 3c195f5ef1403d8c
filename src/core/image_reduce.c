/* Images reduced on load (lx_image_load_desc.keep_pixels): halved in both
 * sides while the half still holds the pixels asked for, every pixel of
 * the result the exact area average of the source pixels under it (a box
 * filter; for even sides the plain 2^s x 2^s block mean, otherwise
 * fractional weights at the blocks' edges, so texel centres keep their
 * UVs). The average is taken of the values the load returns - linear
 * light for colour after the sRGB decoding, raw codes for raw_8bit data,
 * alpha as stored - a row at a time, so only the reduced image and a row's
 * accumulators are made: the caller's decoded source is read once and
 * never converted whole. Sums are in double, in a fixed order: the result
 * does not depend on threads or runs. */
#include "image_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

void lx_img_reduced_size(int width, int height, uint64_t keep_pixels, int *out_w, int *out_h,
                         int *halvings)
{
    int w = width, h = height, s = 0;
    while (keep_pixels > 0 && (w > 1 || h > 1)) {
        int hw = (w + 1) / 2, hh = (h + 1) / 2;
        if ((uint64_t)hw * (uint64_t)hh < keep_pixels)
            break;
        w = hw;
        h = hh;
        s++;
    }
    *out_w = w;
    *out_h = h;
    if (halvings)
        *halvings = s;
}

/* Output pixel i of n over a source of `size` covers [i size / n, (i + 1)
 * size / n): its first source pixel, its last and the weights (the covered
 * length) of those two; the pixels between weigh 1. */
typedef struct span {
    int first, last;
    double w_first, w_last;
} span;

static void spans(int size, int n, span *out)
{
    for (int i = 0; i < n; i++) {
        double a = (double)i * size / n, b = (double)(i + 1) * size / n;
        int first = (int)floor(a), last = (int)ceil(b) - 1;
        last = last < first ? first : last > size - 1 ? size - 1 : last;
        out[i].first = first;
        out[i].last = last;
        out[i].w_first = (first == last ? b : (double)(first + 1)) - a;
        out[i].w_last = first == last ? 0.0 : b - (double)last;
    }
}

lx_status lx_img_reduce(int width, int height, int channels, lx_img_row_fn row, void *ctx,
                        lx_image *out)
{
    int w = out->width, h = out->height, c = channels;
    span *sx = malloc(sizeof *sx * (size_t)w), *sy = malloc(sizeof *sy * (size_t)h);
    float *line = malloc(sizeof(float) * (size_t)width * (size_t)c);
    double *acc = malloc(sizeof(double) * (size_t)w * (size_t)c);
    if (!sx || !sy || !line || !acc) {
        free(sx);
        free(sy);
        free(line);
        free(acc);
        return lx_fail(LX_ERR_NOMEM, "out of memory reducing an image %dx%d to %dx%d", width,
                       height, w, h);
    }
    spans(width, w, sx);
    spans(height, h, sy);
    /* every output pixel covers the same area of source pixels */
    double area = ((double)width / w) * ((double)height / h);
    for (int y = 0; y < h; y++) {
        memset(acc, 0, sizeof(double) * (size_t)w * (size_t)c);
        for (int r = sy[y].first; r <= sy[y].last; r++) {
            double wy = r == sy[y].first ? sy[y].w_first : r == sy[y].last ? sy[y].w_last : 1.0;
            if (wy == 0.0)
                continue;
            row(ctx, r, line);
            for (int x = 0; x < w; x++) {
                double *a = acc + (size_t)x * (size_t)c;
                for (int col = sx[x].first; col <= sx[x].last; col++) {
                    double wx = col == sx[x].first  ? sx[x].w_first
                                : col == sx[x].last ? sx[x].w_last
                                                    : 1.0;
                    const float *p = line + (size_t)col * (size_t)c;
                    for (int k = 0; k < c; k++)
                        a[k] += wy * wx * (double)p[k];
                }
            }
        }
        float *o = out->data + (size_t)y * (size_t)w * (size_t)c;
        for (size_t k = 0; k < (size_t)w * (size_t)c; k++)
            o[k] = (float)(acc[k] / area);
    }
    free(sx);
    free(sy);
    free(line);
    free(acc);
    return LX_OK;
}
