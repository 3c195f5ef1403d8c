/* Blending a detail normal map into a base one: Colin Barre-Brisebois and
 * Stephen Hill, "Blending in Detail" (2012). Reoriented normal mapping
 * (RNM) rotates the detail normal by the shortest-arc rotation that takes
 * +z to the base normal; UDN adds the detail's slopes to the base keeping
 * the base's z; Whiteout also multiplies the z's. The formulas are the
 * article's for unit vectors (its encoded-texture forms unpacked). */
#include "luxel/maps.h"
#include "core/internal.h"

#include <math.h>
#include <string.h>

static const char *const blend_names[] = {"rnm", "udn", "whiteout"};

const char *lx_normal_blend_name(lx_normal_blend_method method)
{
    return (unsigned)method < 3 ? blend_names[method] : NULL;
}

bool lx_normal_blend_parse(const char *name, lx_normal_blend_method *out)
{
    for (int k = 0; name && k < 3; k++)
        if (strcmp(name, blend_names[k]) == 0) {
            *out = (lx_normal_blend_method)k;
            return true;
        }
    return false;
}

static lx_vec3 unit(double x, double y, double z)
{
    double len = sqrt(x * x + y * y + z * z);
    if (!(len > 0.0))
        return lx_v3(0.0f, 0.0f, 1.0f);
    return lx_v3((float)(x / len), (float)(y / len), (float)(z / len));
}

lx_vec3 lx_normal_blend(lx_normal_blend_method method, lx_vec3 b, lx_vec3 d)
{
    switch (method) {
    case LX_BLEND_UDN:
        return unit((double)b.x + d.x, (double)b.y + d.y, b.z);
    case LX_BLEND_WHITEOUT:
        return unit((double)b.x + d.x, (double)b.y + d.y, (double)b.z * d.z);
    case LX_BLEND_RNM:
    default: {
        double tx = b.x, ty = b.y, tz = (double)b.z + 1.0;
        if (!(tz > 1e-12))
            return d; /* base straight down: no rotation from +z defined */
        double ux = -(double)d.x, uy = -(double)d.y, uz = d.z;
        double k = (tx * ux + ty * uy + tz * uz) / tz;
        /* unit for unit inputs; normalized against rounding */
        return unit(tx * k - ux, ty * k - uy, tz * k - uz);
    }
    }
}

lx_status lx_normal_blend_image(lx_normal_blend_method method, const lx_image *base,
                                const lx_image *detail, int threads, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_normal_blend_image: out must not be NULL");
    memset(out, 0, sizeof *out);
    if (!lx_normal_blend_name(method))
        return lx_fail(LX_ERR_INVALID, "normal blend: unknown method %d", (int)method);
    if (!base || !detail || !base->data || !detail->data || base->channels < 3 ||
        detail->channels < 3)
        return lx_fail(LX_ERR_INVALID, "normal blend: base and detail need 3 channels");
    if (base->width != detail->width || base->height != detail->height)
        return lx_fail(LX_ERR_INVALID,
                       "normal blend: the base is %dx%d and the detail %dx%d (sizes must match)",
                       base->width, base->height, detail->width, detail->height);
    if (threads < 0)
        return lx_fail(LX_ERR_INVALID, "normal blend: thread count %d is negative", threads);
    lx_status s = lx_image_alloc(out, base->width, base->height, 3);
    if (s != LX_OK)
        return s;
    int cb = base->channels, cd = detail->channels;
    long n = (long)base->width * (long)base->height;
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(threads))
    for (long i = 0; i < n; i++) {
        const float *pb = base->data + (size_t)i * (size_t)cb;
        const float *pd = detail->data + (size_t)i * (size_t)cd;
        lx_vec3 r = lx_normal_blend(method, lx_v3(pb[0], pb[1], pb[2]), lx_v3(pd[0], pd[1], pd[2]));
        out->data[3 * i] = r.x;
        out->data[3 * i + 1] = r.y;
        out->data[3 * i + 2] = r.z;
    }
    return LX_OK;
}
