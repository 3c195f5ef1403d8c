/* Environments in and out of cube maps: loading (layout detection from the
 * name and the shape, validation of sizes and values), constant
 * environments, and the equirect and cross layouts.
 *
 * Resampling is the plain box filter over the target texel or pixel: its
 * mean is estimated from an n x n grid of bilinear samples at the centres
 * of equal sub-cells of the texel in face (or equirect) coordinates, n
 * chosen so the grid is finer than the source's texels. The cross layouts
 * are the common ones of cube map tools (AMD CubeMapGen, cmft): faces in
 * the OpenGL orientation, +Z in the middle, and in the vertical cross -Z
 * below -Y turned by 180 degrees, so neighbouring faces meet edge to edge. */
#include "luxel/ibl.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest equirect width lx_cubemap_to_equirect makes (a 4 x 16384 face). */
#define MAX_EQUIRECT_WIDTH (4 * LX_MAX_CUBE_SIZE)
/* Most samples per side of a texel or pixel. */
#define MAX_GRID 32

static int grid_for(double ratio)
{
    double n = ceil(ratio) + 1.0;
    return n < 2.0 ? 2 : n > MAX_GRID ? MAX_GRID : (int)n;
}

/* RGB of pixel (x, y): grey images give grey, alpha is ignored. */
static void pixel_rgb(const lx_image *img, int x, int y, float out[3])
{
    const float *p = img->data + ((size_t)y * (size_t)img->width + (size_t)x) * img->channels;
    if (img->channels >= 3) {
        out[0] = p[0];
        out[1] = p[1];
        out[2] = p[2];
    } else {
        out[0] = out[1] = out[2] = p[0];
    }
}

static float *pixel_at(const lx_image *img, int x, int y)
{
    return img->data + ((size_t)y * (size_t)img->width + (size_t)x) * img->channels;
}

/* Bilinear sample of an equirect: u wraps around, v stops at the poles. */
static void equirect_sample(const lx_image *img, float u, float v, float out[3])
{
    int w = img->width, h = img->height;
    float fx = u * (float)w - 0.5f, fy = v * (float)h - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float wx = fx - x0f, wy = fy - y0f;
    int x0 = (int)x0f % w;
    if (x0 < 0)
        x0 += w;
    int x1 = x0 + 1 == w ? 0 : x0 + 1;
    int y0 = (int)y0f, y1 = y0 + 1;
    y0 = y0 < 0 ? 0 : y0 >= h ? h - 1 : y0;
    y1 = y1 < 0 ? 0 : y1 >= h ? h - 1 : y1;
    float a[3], b[3], c[3], d[3];
    pixel_rgb(img, x0, y0, a);
    pixel_rgb(img, x1, y0, b);
    pixel_rgb(img, x0, y1, c);
    pixel_rgb(img, x1, y1, d);
    for (int k = 0; k < 3; k++) {
        float top = a[k] + (b[k] - a[k]) * wx;
        float bottom = c[k] + (d[k] - c[k]) * wx;
        out[k] = top + (bottom - top) * wy;
    }
}

static bool image_ok(const lx_image *img)
{
    return img && img->data && img->width > 0 && img->height > 0 && img->channels >= 1 &&
           img->channels <= 4;
}

/* Fills a cube map of size texels a side, each texel the mean of an n x n
 * grid of lookup(source, direction) over the texel, n from the ratio of the
 * source's resolution to the cube's (grid_for). */
typedef void (*direction_lookup)(const void *source, lx_vec3 dir, float rgb[3]);

static lx_status cube_by_grid(int size, double ratio, bool equirect_source, direction_lookup lookup,
                              const void *source, lx_cubemap *out)
{
    lx_status st = lx_cubemap_alloc(out, size);
    if (st != LX_OK)
        return st;
    int rows = 6 * size;
#pragma omp parallel for schedule(dynamic)
    for (int row = 0; row < rows; row++) {
        int face = row / size, y = row % size;
        for (int x = 0; x < size; x++) {
            /* An equirect's columns crowd together toward the poles, 1 /
             * sin(theta) more of them across a texel: the grid grows with
             * them so a small sun there is not missed between samples. */
            int n = grid_for(ratio);
            if (equirect_source) {
                lx_vec3 c = lx_cube_direction(face, ((float)x + 0.5f) / (float)size,
                                              ((float)y + 0.5f) / (float)size);
                double sin_theta = sqrt(fmax(0.0, 1.0 - (double)c.y * c.y));
                n = grid_for(ratio / fmax(sin_theta, 1.0 / MAX_GRID));
            }
            double sum[3] = {0, 0, 0};
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++) {
                    float s = ((float)x + ((float)i + 0.5f) / (float)n) / (float)size;
                    float t = ((float)y + ((float)j + 0.5f) / (float)n) / (float)size;
                    float rgb[3];
                    lookup(source, lx_cube_direction(face, s, t), rgb);
                    for (int k = 0; k < 3; k++)
                        sum[k] += rgb[k];
                }
            float *texel = lx_cubemap_texel(out, face, x, y);
            for (int k = 0; k < 3; k++)
                texel[k] = (float)(sum[k] / (double)(n * n));
        }
    }
    return LX_OK;
}

static void equirect_lookup(const void *source, lx_vec3 dir, float rgb[3])
{
    float u, v;
    lx_equirect_coords(dir, &u, &v);
    equirect_sample(source, u, v, rgb);
}

static void cube_lookup(const void *source, lx_vec3 dir, float rgb[3])
{
    lx_cubemap_sample(source, dir, rgb);
}

/* ---- equirect ------------------------------------------------------------ */

lx_status lx_cubemap_from_equirect(const lx_image *eq, int size, lx_cubemap *out)
{
    memset(out, 0, sizeof *out);
    if (!image_ok(eq))
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_from_equirect: invalid image");
    if (eq->width != 2 * eq->height)
        return lx_fail(LX_ERR_INVALID,
                       "equirect is %dx%d; an equirect must be exactly twice as wide as it is "
                       "tall",
                       eq->width, eq->height);
    return cube_by_grid(size, (double)eq->width / (4.0 * size), true, equirect_lookup, eq, out);
}

lx_status lx_cubemap_to_equirect(const lx_cubemap *c, int width, lx_image *out)
{
    memset(out, 0, sizeof *out);
    if (!c || !c->data || c->size < 1)
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_to_equirect: invalid cube map");
    if (width < 2 || width % 2 != 0 || width > MAX_EQUIRECT_WIDTH)
        return lx_fail(LX_ERR_INVALID, "equirect width %d must be even and in 2..%d", width,
                       MAX_EQUIRECT_WIDTH);
    int height = width / 2;
    lx_status st = lx_image_alloc(out, width, height, 3);
    if (st != LX_OK)
        return st;
    int n = grid_for(4.0 * c->size / (double)width);
#pragma omp parallel for schedule(dynamic)
    for (int y = 0; y < height; y++) {
        for (int x = 0; x < width; x++) {
            double sum[3] = {0, 0, 0};
            for (int j = 0; j < n; j++)
                for (int i = 0; i < n; i++) {
                    float u = ((float)x + ((float)i + 0.5f) / (float)n) / (float)width;
                    float v = ((float)y + ((float)j + 0.5f) / (float)n) / (float)height;
                    float rgb[3];
                    lx_cubemap_sample(c, lx_equirect_direction(u, v), rgb);
                    for (int k = 0; k < 3; k++)
                        sum[k] += rgb[k];
                }
            float *p = pixel_at(out, x, y);
            for (int k = 0; k < 3; k++)
                p[k] = (float)(sum[k] / (double)(n * n));
        }
    }
    return LX_OK;
}

/* ---- cross --------------------------------------------------------------- */

/* Where each face sits in a cross, in face-size units (column, row). */
static const int cross_h[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
static const int cross_v[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {1, 3}};

/* The cross pixel that holds face texel (x, y). */
static void cross_pixel(bool vertical, int size, int face, int x, int y, int *px, int *py)
{
    const int *cell = vertical ? cross_v[face] : cross_h[face];
    if (vertical && face == LX_FACE_NZ) {
        /* turned by 180 degrees so its top edge meets -Y's bottom edge */
        x = size - 1 - x;
        y = size - 1 - y;
    }
    *px = cell[0] * size + x;
    *py = cell[1] * size + y;
}

/* The face size of a cross and whether it is vertical; false if the image
 * has neither 4:3 nor 3:4 proportions with whole faces. */
static bool cross_shape(int w, int h, int *size, bool *vertical)
{
    if (w % 4 == 0 && h == w / 4 * 3) {
        *size = w / 4;
        *vertical = false;
        return true;
    }
    if (w % 3 == 0 && h == w / 3 * 4) {
        *size = w / 3;
        *vertical = true;
        return true;
    }
    return false;
}

lx_status lx_cubemap_from_cross(const lx_image *cross, lx_cubemap *out)
{
    memset(out, 0, sizeof *out);
    if (!image_ok(cross))
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_from_cross: invalid image");
    int size;
    bool vertical;
    if (!cross_shape(cross->width, cross->height, &size, &vertical))
        return lx_fail(LX_ERR_INVALID,
                       "cross is %dx%d; a cross must be 4:3 (horizontal) or 3:4 (vertical) "
                       "with square faces",
                       cross->width, cross->height);
    lx_status st = lx_cubemap_alloc(out, size);
    if (st != LX_OK)
        return st;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++) {
                int px, py;
                cross_pixel(vertical, size, f, x, y, &px, &py);
                pixel_rgb(cross, px, py, lx_cubemap_texel(out, f, x, y));
            }
    return LX_OK;
}

lx_status lx_cubemap_to_cross(const lx_cubemap *c, bool vertical, lx_image *out)
{
    memset(out, 0, sizeof *out);
    if (!c || !c->data || c->size < 1 || c->size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_to_cross: invalid cube map");
    int size = c->size;
    lx_status st = lx_image_alloc(out, (vertical ? 3 : 4) * size, (vertical ? 4 : 3) * size, 3);
    if (st != LX_OK)
        return st;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++) {
                int px, py;
                cross_pixel(vertical, size, f, x, y, &px, &py);
                memcpy(pixel_at(out, px, py), lx_cubemap_texel(c, f, x, y), 3 * sizeof(float));
            }
    return LX_OK;
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
            st = lx_cubemap_alloc(out, size);
            if (st != LX_OK)
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

/* A cube map of another size: each texel the box-filtered mean of c. */
static lx_status resample_cube(const lx_cubemap *c, int size, lx_cubemap *out)
{
    return cube_by_grid(size, (double)c->size / (double)size, false, cube_lookup, c, out);
}

/* An equirect or a cross image (layout AUTO, EQUIRECT or CROSS) as a cube
 * map; name is for messages. */
static lx_status image_layout(const lx_image *img, const char *path, lx_env_layout layout, int size,
                              lx_cubemap *out)
{
    lx_status st = LX_OK;
    int cross_size;
    bool vertical;
    bool is_cross = cross_shape(img->width, img->height, &cross_size, &vertical);
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
        st = lx_cubemap_from_equirect(img, size, out);
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
        st = lx_cubemap_from_cross(img, out);
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

/* Checks desc (NULL: defaults) into *d and the intensity multiplier. */
static lx_status check_desc(const char *name, const lx_env_load_desc *desc, lx_env_load_desc *d,
                            float *intensity)
{
    *d = desc ? *desc : (lx_env_load_desc){0};
    *intensity = d->intensity == 0.0f ? 1.0f : d->intensity;
    if (!isfinite(*intensity) || *intensity < 0.0f)
        return lx_fail(LX_ERR_INVALID, "%s: intensity %g must be a finite number > 0", name,
                       (double)d->intensity);
    if (d->size < 0 || d->size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "%s: cube size %d is outside 1..%d", name, d->size,
                       LX_MAX_CUBE_SIZE);
    if (d->layout == LX_ENV_KTX)
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: KTX is an output layout; luxel does not read it",
                       name);
    if (d->layout < LX_ENV_AUTO || d->layout > LX_ENV_KTX)
        return lx_fail(LX_ERR_INVALID, "%s: unknown layout %d", name, (int)d->layout);
    return LX_OK;
}

/* The asked size and intensity applied to a loaded cube map. */
static lx_status finish(const char *name, const lx_env_load_desc *d, float intensity,
                        lx_cubemap *out)
{
    lx_status st;
    if (d->size != 0 && d->size != out->size) {
        lx_cubemap resized;
        st = resample_cube(out, d->size, &resized);
        lx_cubemap_free(out);
        if (st != LX_OK) {
            lx_error_prefix(name);
            return st;
        }
        *out = resized;
    }
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
    return LX_OK;
}

lx_status lx_env_load(const char *path, const lx_env_load_desc *desc, lx_cubemap *out)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!path || !out)
        return lx_fail(LX_ERR_INVALID, "lx_env_load: path and out must not be NULL");
    lx_env_load_desc d;
    float intensity;
    lx_status st = check_desc(path, desc, &d, &intensity);
    if (st != LX_OK)
        return st;
    if (d.layout == LX_ENV_FACES || (d.layout == LX_ENV_AUTO && px_suffix(path) >= 0)) {
        st = load_faces(path, out);
    } else {
        lx_image img;
        if ((st = load_rgb(path, &img)) != LX_OK)
            return st;
        st = image_layout(&img, path, d.layout, d.size, out);
        lx_image_free(&img);
    }
    return st == LX_OK ? finish(path, &d, intensity, out) : st;
}

lx_status lx_env_from_image(const lx_image *img, const char *name, const lx_env_load_desc *desc,
                            lx_cubemap *out)
{
    if (out)
        memset(out, 0, sizeof *out);
    name = name ? name : "environment";
    if (!out || !image_ok(img))
        return lx_fail(LX_ERR_INVALID, "%s: no image, or an image without pixels", name);
    lx_env_load_desc d;
    float intensity;
    lx_status st = check_desc(name, desc, &d, &intensity);
    if (st != LX_OK)
        return st;
    if (d.layout == LX_ENV_FACES)
        return lx_fail(LX_ERR_INVALID, "%s: six faces come from files (lx_env_load)", name);
    st = image_layout(img, name, d.layout, d.size, out);
    return st == LX_OK ? finish(name, &d, intensity, out) : st;
}

lx_status lx_env_constant(lx_vec3 radiance, int size, lx_cubemap *out)
{
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
