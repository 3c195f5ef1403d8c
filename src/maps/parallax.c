/* Parallax maps (Lengyel, FGED vol. 2 sec. 7.7; seed 002): the offset
 * p = n.z h v.xy toward the viewer, with n.z h precomputed per texel, and
 * the iterated offset of the seed's ApplyParallaxOffset with bilinear
 * fetches and any wrap mode. */
#include "normal_internal.h"

#include <math.h>
#include <string.h>

typedef struct px_job {
    const lx_image *height;
    const lx_normalmap_desc *d;
    lx_image *out;
} px_job;

static bool parallax_rows(void *ctx, int y0, int y1, float *scratch)
{
    const px_job *j = ctx;
    int w = j->height->width;
    float *dx = scratch, *dy = scratch + w;
    float s = j->d->strength;
    bool ok = true;
    for (int y = y0; y < y1; y++) {
        lx_nm_slopes_row(j->height, j->d->filter, j->d->wrap, y, dx, dy);
        const float *h = j->height->data + (size_t)y * (size_t)w;
        float *o = j->out->data + (size_t)y * (size_t)w;
        for (int x = 0; x < w; x++) {
            float nx = s * dx[x], ny = s * dy[x];
            float nz = 1.0f / sqrtf(nx * nx + ny * ny + 1.0f);
            o[x] = nz * h[x];
            ok &= nz > 0.0f && isfinite(o[x]);
        }
    }
    return ok;
}

lx_status lx_parallax_map(const lx_image *height, const lx_normalmap_desc *desc, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_parallax_map: out must not be NULL");
    memset(out, 0, sizeof *out);
    lx_normalmap_desc d = lx_normalmap_desc_defaults(desc);
    lx_status s = lx_nm_check(height, &d, "parallax map");
    if (s != LX_OK)
        return s;
    s = lx_image_alloc(out, height->width, height->height, 1);
    if (s != LX_OK)
        return s;
    px_job job = {height, &d, out};
    bool bad = false;
    s = lx_nm_run_rows(height->height, 2 * (size_t)height->width, d.threads, d.progress,
                       d.progress_user, parallax_rows, &job, "parallax map", &bad);
    if (s == LX_ERR_INVALID && bad) {
        size_t n = (size_t)height->width * (size_t)height->height;
        s = lx_fail(LX_ERR_INVALID, "parallax map: slopes overflow a float at strength %g",
                    (double)d.strength);
        for (size_t i = 0; i < n; i++)
            if (!isfinite(height->data[i])) {
                s = lx_fail(LX_ERR_INVALID, "parallax map: height texel (%zu, %zu) is %s",
                            i % (size_t)height->width, i / (size_t)height->width,
                            isnan(height->data[i]) ? "NaN" : "infinite");
                break;
            }
    }
    if (s != LX_OK)
        lx_image_free(out);
    return s;
}

/* Channel 0 of img at uv, bilinear between texel centres, texels outside
 * addressed by wrap. */
static float sample(const lx_image *img, lx_wrap wrap, float u, float v)
{
    int w = img->width, h = img->height, c = img->channels;
    double fx = (double)u * w - 0.5, fy = (double)v * h - 0.5;
    double x0f = floor(fx), y0f = floor(fy);
    double ax = fx - x0f, ay = fy - y0f;
    /* far outside the image, bring the index near it first (the fraction
     * is kept): the wrap modes have periods w (or 2w) */
    double px = wrap == LX_WRAP_MIRROR ? 2.0 * w : w, py = wrap == LX_WRAP_MIRROR ? 2.0 * h : h;
    if (wrap != LX_WRAP_CLAMP) {
        x0f -= floor(x0f / px) * px;
        y0f -= floor(y0f / py) * py;
    } else {
        x0f = x0f < -1.0 ? -1.0 : x0f > w ? w : x0f;
        y0f = y0f < -1.0 ? -1.0 : y0f > h ? h : y0f;
    }
    int x0 = (int)x0f, y0 = (int)y0f;
    int xa = lx_wrap_index(wrap, x0, w), xb = lx_wrap_index(wrap, x0 + 1, w);
    int ya = lx_wrap_index(wrap, y0, h), yb = lx_wrap_index(wrap, y0 + 1, h);
    const float *d = img->data;
#define AT(x, y) ((double)d[((size_t)(y) * (size_t)w + (size_t)(x)) * (size_t)c])
    double top = AT(xa, ya) + ax * (AT(xb, ya) - AT(xa, ya));
    double bottom = AT(xa, yb) + ax * (AT(xb, yb) - AT(xa, yb));
#undef AT
    return (float)(top + ay * (bottom - top));
}

lx_vec2 lx_parallax_offset(const lx_image *parallax, lx_wrap wrap, lx_vec2 uv, lx_vec3 view,
                           const float scale[2], int iterations)
{
    if (!parallax || !parallax->data || parallax->width < 1 || parallax->height < 1 || !scale)
        return uv;
    if (!isfinite(uv.x) || !isfinite(uv.y) || !isfinite(view.x) || !isfinite(view.y) ||
        !isfinite(scale[0]) || !isfinite(scale[1]))
        return uv;
    if (iterations <= 0)
        iterations = LX_PARALLAX_ITERATIONS;
    /* the offset direction in UV: tangent y runs up the image, v down */
    float pu = view.x * scale[0], pv = -view.y * scale[1];
    for (int i = 0; i < iterations; i++) {
        float p = sample(parallax, wrap, uv.x, uv.y);
        uv.x += pu * p;
        uv.y += pv * p;
    }
    return uv;
}
