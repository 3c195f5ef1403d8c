/* Bilinear texture lookups with wrap-around addressing. */
#include "luxel/core.h"

#include <math.h>

static int wrap(int i, int n)
{
    int r = i % n;
    return r < 0 ? r + n : r;
}

void lx_image_sample_bilinear(const lx_image *img, float u, float v, float *out)
{
    int c = img->channels;
    /* texel centres sit at half-integers in pixel space */
    float x = u * (float)img->width - 0.5f, y = v * (float)img->height - 0.5f;
    if (!isfinite(x) || !isfinite(y)) {
        x = 0.0f;
        y = 0.0f;
    }
    float fx = floorf(x), fy = floorf(y);
    float tx = x - fx, ty = y - fy;
    /* fmodf keeps huge UVs from overflowing the int conversion */
    int x0 = wrap((int)fmodf(fx, (float)img->width), img->width);
    int y0 = wrap((int)fmodf(fy, (float)img->height), img->height);
    int x1 = wrap(x0 + 1, img->width), y1 = wrap(y0 + 1, img->height);
    const float *p00 = img->data + ((size_t)y0 * img->width + x0) * c;
    const float *p10 = img->data + ((size_t)y0 * img->width + x1) * c;
    const float *p01 = img->data + ((size_t)y1 * img->width + x0) * c;
    const float *p11 = img->data + ((size_t)y1 * img->width + x1) * c;
    for (int k = 0; k < c; k++) {
        float top = p00[k] + (p10[k] - p00[k]) * tx;
        float bottom = p01[k] + (p11[k] - p01[k]) * tx;
        out[k] = top + (bottom - top) * ty;
    }
}
