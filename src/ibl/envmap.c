/* Environments into cube maps: loading (layout detection from the name
 * and the shape, validation of sizes and values, the memory a load needs
 * checked before it is taken), the asked face size (env_resample.c) and
 * intensity, and constant environments. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static bool image_ok(const lx_image *img)
{
    return img && img->data && img->width > 0 && img->height > 0 && img->channels >= 1 &&
           img->channels <= 4;
}

/* ---- validation ---------------------------------------------------------- */

/* Fails naming `name` when any of the count RGB texels (stride floats
 * apart, the first three used) is NaN, infinite or negative: the message
 * gives how many of each and the first one's position (x, y) in an image
 * `width` texels wide (or, when face >= 0, on that face). */
static lx_status check_values(const float *data, size_t count, int stride, int width, int face,
                              const char *name)
{
    size_t nonfinite = 0, negative = 0, first = 0;
    bool found = false;
    int colours = stride < 3 ? 1 : 3; /* grey (alpha ignored), or RGB without alpha */
    for (size_t i = 0; i < count; i++) {
        const float *p = data + i * (size_t)stride;
        bool bad_nf = false, bad_neg = false;
        for (int k = 0; k < colours; k++) {
            if (!isfinite(p[k]))
                bad_nf = true;
            else if (p[k] < 0.0f)
                bad_neg = true;
        }
        if (bad_nf)
            nonfinite++;
        else if (bad_neg)
            negative++;
        if ((bad_nf || bad_neg) && !found) {
            found = true;
            first = i;
        }
    }
    if (!found)
        return LX_OK;
    char what[160] = "", where[48] = "";
    if (nonfinite)
        snprintf(what, sizeof what, "%zu texel%s NaN or infinite", nonfinite,
                 nonfinite == 1 ? " is" : "s are");
    if (negative) {
        size_t n = strlen(what);
        snprintf(what + n, sizeof what - n, "%s%zu texel%s negative", n ? " and " : "", negative,
                 negative == 1 ? " is" : "s are");
    }
    if (face >= 0) {
        size_t per_face = (size_t)width * (size_t)width;
        size_t f = first / per_face, r = first % per_face;
        snprintf(where, sizeof where, "face %s texel (%zu, %zu)", lx_cube_face_name((int)f),
                 r % (size_t)width, r / (size_t)width);
    } else {
        snprintf(where, sizeof where, "pixel (%zu, %zu)", first % (size_t)width,
                 first / (size_t)width);
    }
    return lx_fail(LX_ERR_FORMAT,
                   "%s: %s (the first at %s); an environment needs finite radiance >= 0", name,
                   what, where);
}

static lx_status check_image_values(const lx_image *img, const char *name)
{
    return check_values(img->data, (size_t)img->width * (size_t)img->height, img->channels,
                        img->width, -1, name);
}

static lx_status check_cube_values(const lx_cubemap *c, const char *name)
{
    return check_values(c->data, 6 * (size_t)c->size * (size_t)c->size, 3, c->size, 0, name);
}

/* ---- loading ------------------------------------------------------------- */

/* The offset of "px" in a path whose file name ends in "_px.<ext>", or -1. */
static long px_suffix(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot - base < 4 || dot[1] == '\0')
        return -1;
    if (dot[-3] != '_' || dot[-2] != 'p' || dot[-1] != 'x')
        return -1;
    return (long)(dot - 2 - path);
}

static lx_status load_rgb(const char *path, lx_image *img)
{
    lx_image_load_desc ld = {.channels = 3, .keep_nonfinite = true};
    return lx_image_load(path, &ld, img);
}

/* Fails with LX_ERR_NOMEM when bytes are more than the machine has; the
 * message starts with the printf-formatted description of what needs
 * them. */
static lx_status check_bytes(uint64_t bytes, const char *fmt, ...) LX_PRINTF(2, 3);
static lx_status check_bytes(uint64_t bytes, const char *fmt, ...)
{
    char what[640];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    return lx_check_memory(bytes, what);
}

static lx_status load_faces(const char *path, lx_cubemap *out)
{
    long at = px_suffix(path);
    if (at < 0)
        return lx_fail(LX_ERR_INVALID,
                       "%s: six faces are named <name>_px.<ext>, <name>_nx.<ext>, ... and the "
                       "path must name the _px file",
                       path);
    char *name = lx_strdup(path);
    if (!name)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    lx_status st = LX_OK;
    int size = 0;
    for (int f = 0; f < 6 && st == LX_OK; f++) {
        memcpy(name + at, lx_cube_face_name(f), 2);
        lx_image img;
        st = load_rgb(name, &img);
        if (st != LX_OK)
            break;
        if (img.width != img.height) {
            st = lx_fail(LX_ERR_FORMAT, "%s: a cube face must be square, not %dx%d", name,
                         img.width, img.height);
        } else if (f > 0 && img.width != size) {
            st = lx_fail(LX_ERR_FORMAT,
                         "%s: the faces differ in size: this one is %dx%d, the _px face %dx%d",
                         name, img.width, img.height, size, size);
        } else if (img.width > LX_MAX_CUBE_SIZE) {
            st = lx_fail(LX_ERR_INVALID, "%s: face size %d is more than %d", name, img.width,
                         LX_MAX_CUBE_SIZE);
        } else {
            st = check_image_values(&img, name);
        }
        if (st == LX_OK && f == 0) {
            size = img.width;
            /* the cube map besides the face being read */
            st = check_bytes(lx_ibl_cube_bytes(size) + 12ull * size * size, "%s: six %d x %d faces",
                             path, size, size);
            if (st == LX_OK && (st = lx_cubemap_alloc(out, size)) != LX_OK)
                lx_error_prefix(path);
        }
        if (st == LX_OK)
            memcpy(lx_cubemap_texel(out, f, 0, 0), img.data,
                   (size_t)size * (size_t)size * 3 * sizeof(float));
        lx_image_free(&img);
    }
    free(name);
    if (st != LX_OK)
        lx_cubemap_free(out);
    return st;
}

/* An equirect or a cross image (layout AUTO, EQUIRECT or a cross) as a
 * cube map of face size `size` (0 = the image's own); name is for
 * messages. An equirect goes straight to that size, a cross is copied
 * (and resampled by finish). */
static lx_status image_layout(const lx_image *img, const char *path, lx_env_layout layout, int size,
                              const lx_ibl_run *run, lx_cubemap *out)
{
    lx_status st = LX_OK;
    int cross_size;
    bool vertical;
    bool is_cross = lx_ibl_cross_shape(img->width, img->height, &cross_size, &vertical);
    uint64_t image_bytes = 4ull * img->width * img->height * img->channels;
    if (layout == LX_ENV_AUTO) {
        if (img->width == 2 * img->height)
            layout = LX_ENV_EQUIRECT;
        else if (is_cross)
            layout = LX_ENV_CROSS;
        else {
            st = lx_fail(LX_ERR_FORMAT,
                         "%s: cannot tell the layout of a %dx%d image: an equirect is 2:1, a "
                         "cross 4:3 or 3:4, six faces are named <name>_px.<ext> ...",
                         path, img->width, img->height);
            goto done;
        }
    }
    if (layout == LX_ENV_EQUIRECT) {
        if (img->width != 2 * img->height) {
            st = lx_fail(LX_ERR_FORMAT,
                         "%s: an equirect must be exactly twice as wide as it is tall, not %dx%d",
                         path, img->width, img->height);
            goto done;
        }
        st = check_image_values(img, path);
        if (st != LX_OK)
            goto done;
        if (size == 0)
            size = img->width / 4 > 0 ? img->width / 4 : 1;
        if (size > LX_MAX_CUBE_SIZE) {
            st = lx_fail(LX_ERR_INVALID,
                         "%s: a %dx%d equirect makes %d x %d faces, more than %d; ask for a "
                         "smaller size",
                         path, img->width, img->height, size, size, LX_MAX_CUBE_SIZE);
            goto done;
        }
        st = check_bytes(image_bytes + lx_ibl_cube_bytes(size),
                         "%s: a %d x %d equirect resampled to %d x %d faces", path, img->width,
                         img->height, size, size);
        if (st != LX_OK)
            goto done;
        char name[512];
        snprintf(name, sizeof name, "%s: %d x %d faces from a %d x %d equirect", path, size, size,
                 img->width, img->height);
        lx_ibl_warn_upsampling(name, size, img->width / 4.0);
        st = lx_ibl_cube_from_equirect(img, size, run, out);
    } else {
        if (!is_cross) {
            st = lx_fail(LX_ERR_FORMAT,
                         "%s: a cross must be 4:3 (horizontal) or 3:4 (vertical) with square "
                         "faces, not %dx%d",
                         path, img->width, img->height);
            goto done;
        }
        if (cross_size > LX_MAX_CUBE_SIZE) {
            st = lx_fail(LX_ERR_INVALID, "%s: face size %d is more than %d", path, cross_size,
                         LX_MAX_CUBE_SIZE);
            goto done;
        }
        st = check_bytes(image_bytes + lx_ibl_cube_bytes(cross_size),
                         "%s: a %d x %d cross of %d x %d faces", path, img->width, img->height,
                         cross_size, cross_size);
        if (st != LX_OK)
            goto done;
        lx_ibl_run part = lx_ibl_run_part(run, 0.0, 0.1);
        st = lx_ibl_cube_from_cross(img, &part, out);
        if (st == LX_OK)
            st = check_cube_values(out, path);
    }
    if (st != LX_OK && strncmp(lx_last_error(), path, strlen(path)) != 0)
        lx_error_prefix(path);
done:
    if (st != LX_OK)
        lx_cubemap_free(out);
    return st;
}

lx_env_load_desc lx_env_load_desc_defaults(const lx_env_load_desc *desc)
{
    lx_env_load_desc d = {0};
    if (desc)
        d = *desc;
    if (d.intensity == 0.0f)
        d.intensity = 1.0f;
    return d;
}

/* Checks desc (NULL: defaults) into *d. */
static lx_status check_desc(const char *name, const lx_env_load_desc *desc, lx_env_load_desc *d)
{
    *d = lx_env_load_desc_defaults(desc);
    if (!isfinite(d->intensity) || d->intensity < 0.0f)
        return lx_fail(LX_ERR_INVALID, "%s: intensity %g must be a finite number > 0", name,
                       (double)d->intensity);
    if (d->size < 0 || d->size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "%s: cube size %d is outside 1..%d", name, d->size,
                       LX_MAX_CUBE_SIZE);
    if (d->layout == LX_ENV_KTX)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: KTX is an output layout; luxel does not read it",
                       name);
    if (d->layout < LX_ENV_AUTO || d->layout > LX_ENV_CROSS_VERTICAL)
        return lx_fail(LX_ERR_INVALID, "%s: unknown layout %d", name, (int)d->layout);
    lx_status st = lx_ibl_check_threads(d->threads);
    if (st != LX_OK)
        lx_error_prefix(name);
    /* the cube map asked for, before any file is read */
    if (st == LX_OK && d->size)
        st = check_bytes(lx_ibl_cube_bytes(d->size), "%s: a %d x %d environment", name, d->size,
                         d->size);
    return st;
}

/* The asked size and intensity applied to a loaded cube map. */
static lx_status finish(const char *name, const lx_env_load_desc *d, const lx_ibl_run *run,
                        lx_cubemap *out)
{
    lx_status st;
    if (d->size != 0 && d->size != out->size) {
        st = check_bytes(lx_ibl_cube_bytes(out->size) + lx_ibl_cube_bytes(d->size),
                         "%s: %d x %d faces resampled to %d x %d", name, out->size, out->size,
                         d->size, d->size);
        char what[512];
        snprintf(what, sizeof what, "%s: %d x %d faces from %d x %d ones", name, d->size, d->size,
                 out->size, out->size);
        if (st == LX_OK)
            lx_ibl_warn_upsampling(what, d->size, out->size);
        lx_cubemap resized;
        lx_ibl_run part = lx_ibl_run_part(run, 0.1, 1.0);
        if (st == LX_OK)
            st = lx_ibl_cube_resample(out, d->size, &part, &resized);
        lx_cubemap_free(out);
        if (st != LX_OK) {
            if (strncmp(lx_last_error(), name, strlen(name)) != 0)
                lx_error_prefix(name);
            return st;
        }
        *out = resized;
    }
    float intensity = d->intensity;
    if (intensity != 1.0f) {
        size_t n = 6 * (size_t)out->size * (size_t)out->size * 3, overflow = 0;
        for (size_t i = 0; i < n; i++) {
            out->data[i] *= intensity;
            overflow += !isfinite(out->data[i]);
        }
        if (overflow) {
            lx_cubemap_free(out);
            return lx_fail(LX_ERR_INVALID, "%s: intensity %g makes %zu values overflow to infinity",
                           name, (double)intensity, overflow);
        }
    }
    if (run->progress && !run->progress(run->user, 1.0f)) {
        lx_cubemap_free(out);
        return lx_fail(LX_ERR_CANCELLED, "%s: loading cancelled", name);
    }
    return LX_OK;
}

lx_status lx_env_load(const char *path, const lx_env_load_desc *desc, lx_cubemap *out)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!path || !out)
        return lx_fail(LX_ERR_INVALID, "lx_env_load: path and out must not be NULL");
    lx_env_load_desc d;
    lx_status st = check_desc(path, desc, &d);
    if (st != LX_OK)
        return st;
    lx_ibl_run run = lx_ibl_run_make(d.threads, d.progress, d.progress_user);
    lx_ibl_run first = lx_ibl_run_part(&run, 0.0, 0.999);
    if (d.layout == LX_ENV_FACES || (d.layout == LX_ENV_AUTO && px_suffix(path) >= 0)) {
        st = load_faces(path, out);
    } else {
        lx_image img;
        if ((st = load_rgb(path, &img)) != LX_OK)
            return st;
        st = image_layout(&img, path, d.layout, d.size, &first, out);
        lx_image_free(&img);
    }
    return st == LX_OK ? finish(path, &d, &first, out) : st;
}

lx_status lx_env_from_image(const lx_image *img, const char *name, const lx_env_load_desc *desc,
                            lx_cubemap *out)
{
    if (!img)
        return lx_fail_null(__func__, "img");
    if (out)
        memset(out, 0, sizeof *out);
    name = name ? name : "environment";
    if (!out || !image_ok(img))
        return lx_fail(LX_ERR_INVALID, "%s: no image, or an image without pixels", name);
    lx_env_load_desc d;
    lx_status st = check_desc(name, desc, &d);
    if (st != LX_OK)
        return st;
    if (d.layout == LX_ENV_FACES)
        return lx_fail(LX_ERR_INVALID, "%s: six faces come from files (lx_env_load)", name);
    lx_ibl_run run = lx_ibl_run_make(d.threads, d.progress, d.progress_user);
    lx_ibl_run first = lx_ibl_run_part(&run, 0.0, 0.999);
    st = image_layout(img, name, d.layout, d.size, &first, out);
    return st == LX_OK ? finish(name, &d, &first, out) : st;
}

lx_status lx_env_constant(lx_vec3 radiance, int size, lx_cubemap *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    if (!lx_vec3_finite(radiance) || radiance.x < 0.0f || radiance.y < 0.0f || radiance.z < 0.0f)
        return lx_fail(LX_ERR_INVALID,
                       "constant environment (%g, %g, %g): radiance must be finite and >= 0",
                       (double)radiance.x, (double)radiance.y, (double)radiance.z);
    lx_status st = lx_cubemap_alloc(out, size);
    if (st != LX_OK)
        return st;
    size_t n = 6 * (size_t)size * (size_t)size;
    for (size_t i = 0; i < n; i++) {
        out->data[3 * i] = radiance.x;
        out->data[3 * i + 1] = radiance.y;
        out->data[3 * i + 2] = radiance.z;
    }
    return LX_OK;
}
