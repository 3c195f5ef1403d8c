/* Height fields: loading and texel addressing outside the image (the wrap
 * modes the texture-space tools share; Lengyel's listings in FGED vol. 2
 * ch. 7 use `& (size - 1)`, which only works for powers of two). */
#include "luxel/maps.h"
#include "core/internal.h"

#include <string.h>

int lx_wrap_index(lx_wrap wrap, int i, int n)
{
    if (i >= 0 && i < n)
        return i;
    switch (wrap) {
    case LX_WRAP_CLAMP:
        return i < 0 ? 0 : n - 1;
    case LX_WRAP_MIRROR: {
        /* period 2n: 0..n-1 forward, then n-1..0 back */
        long long p = 2LL * n, m = ((long long)i % p + p) % p;
        return (int)(m < n ? m : p - 1 - m);
    }
    case LX_WRAP_REPEAT:
    default: {
        int m = i % n;
        return m < 0 ? m + n : m;
    }
    }
}

static const char *const wrap_names[] = {"repeat", "clamp", "mirror"};

const char *lx_wrap_name(lx_wrap wrap)
{
    return (unsigned)wrap < 3 ? wrap_names[wrap] : NULL;
}

bool lx_wrap_parse(const char *name, lx_wrap *out)
{
    for (int k = 0; name && k < 3; k++)
        if (strcmp(name, wrap_names[k]) == 0) {
            *out = (lx_wrap)k;
            return true;
        }
    return false;
}

lx_status lx_height_load(const char *path, lx_image *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    lx_image img;
    lx_image_load_desc d = {.raw_8bit = true};
    lx_status s = lx_image_load(path, &d, &img);
    if (s != LX_OK)
        return s;
    if (img.width < 1 || img.height < 1) {
        lx_image_free(&img);
        return lx_fail(LX_ERR_FORMAT, "%s: the image has no texels", path);
    }
    if (img.channels == 1) {
        *out = img;
        return LX_OK;
    }
    s = lx_image_alloc(out, img.width, img.height, 1);
    if (s != LX_OK) {
        lx_image_free(&img);
        lx_error_prefix(path);
        return s;
    }
    size_t n = (size_t)img.width * (size_t)img.height;
    for (size_t i = 0; i < n; i++)
        out->data[i] = img.data[i * (size_t)img.channels];
    lx_image_free(&img);
    return LX_OK;
}
