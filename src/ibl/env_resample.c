/* Environments between layouts: equirect <-> cube map, cube map -> cube
 * map of another size, and the cross layouts.
 *
 * Resampling is the plain box filter over the target texel or pixel: its
 * mean is estimated from an n x n grid of bilinear samples at the centres
 * of equal sub-cells of the texel in face (or equirect) coordinates, n
 * chosen so the grid is finer than the source's texels; from an equirect,
 * n also grows toward the poles, where the equirect's columns crowd
 * together, 1 / sin(theta) more of them across a texel, so a small sun
 * there is not missed between samples. The equirect coordinates of a
 * sample come from a polynomial arctangent (below) accurate to 1.4e-7
 * radians, a thousandth of a pixel of the widest equirect, at a fraction
 * of the cost of atan2f and acosf. The cross layouts are the common ones
 * of cube map tools (AMD CubeMapGen, cmft): faces in the OpenGL
 * orientation, +Z in the middle, and in the vertical cross -Z below -Y
 * turned by 180 degrees, so neighbouring faces meet edge to edge. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Largest equirect width lx_cubemap_to_equirect makes (a 4 x 16384 face). */
#define MAX_EQUIRECT_WIDTH (4 * LX_MAX_CUBE_SIZE)
/* Most samples per side of a texel or pixel. */
#define MAX_GRID 32
#define PI_F 3.14159265358979323846f

/* Samples per side of a target texel covering `ratio` source texels per
 * side: more than ratio, so the grid is finer than the source; one where
 * the texel is at most half a source texel (an upsampling), as the
 * bilinear source is then nearly flat over it. */
static int grid_for(double ratio)
{
    if (ratio <= 0.5)
        return 1;
    double n = ceil(ratio) + 1.0;
    return n < 2.0 ? 2 : n > MAX_GRID ? MAX_GRID : (int)n;
}

/* atan2(y, x) in [-pi, pi] of four lanes: the octant reduced to
 * z = min / max in [0, 1] and atan(z) = z p(z^2), p of degree 7
 * interpolating atan(sqrt(w)) / sqrt(w) at the Chebyshev nodes of [0, 1]
 * (largest error 1.4e-7). */
static inline lx_v4f v4_atan2(lx_v4f y, lx_v4f x)
{
    lx_v4f ax = lx_v4_abs(x), ay = lx_v4_abs(y);
    lx_v4i steep = ay > ax;
    lx_v4f mx = lx_v4_select(steep, ay, ax), mn = lx_v4_select(steep, ax, ay);
    lx_v4f one = {1.0f, 1.0f, 1.0f, 1.0f};
    lx_v4f z = mn / lx_v4_select(mx == 0.0f, one, mx), w = z * z; /* 0 / 1 at the origin */
    lx_v4f p = -4.559791986e-03f * one;
    p = p * w + 2.378051860e-02f;
    p = p * w - 5.882975314e-02f;
    p = p * w + 9.868865458e-02f;
    p = p * w - 1.400329018e-01f;
    p = p * w + 1.996696183e-01f;
    p = p * w - 3.333181266e-01f;
    p = p * w + 9.999998820e-01f;
    lx_v4f a = p * z;
    a = lx_v4_select(steep, 0.5f * PI_F - a, a);
    a = lx_v4_select(x < 0.0f, PI_F - a, a);
    return lx_v4_select(y < 0.0f, -a, a);
}

/* An image's pixel as RGB: grey images give grey, alpha is ignored. */
static inline void pixel_rgb(const lx_image *img, int x, int y, float out[3])
{
    const float *p = img->data + ((size_t)y * (size_t)img->width + (size_t)x) * img->channels;
    if (img->channels >= 3) {
        out[0] = p[0], out[1] = p[1], out[2] = p[2];
    } else {
        out[0] = out[1] = out[2] = p[0];
    }
}

/* The bilinear taps of an equirect at four (u, v) in [0, 1) x [0, 1]:
 * columns x0, x1 (u wraps around), rows y0, y1 (v stops at the poles) and
 * the weights toward x1 and y1. */
static inline void v4_taps(const lx_image *img, lx_v4f u, lx_v4f v, int *x0, int *x1, int *y0,
                           int *y1, float *wx, float *wy)
{
    int w = img->width, h = img->height;
    lx_v4f fx = u * (float)w - 0.5f, fy = v * (float)h - 0.5f;
    /* floor: truncated, less one where that rounded up (negative) */
    lx_v4f tx = __builtin_convertvector(__builtin_convertvector(fx, lx_v4i), lx_v4f);
    lx_v4f ty = __builtin_convertvector(__builtin_convertvector(fy, lx_v4i), lx_v4f);
    lx_v4f one = {1.0f, 1.0f, 1.0f, 1.0f}, zero = {0, 0, 0, 0};
    tx -= lx_v4_select(tx > fx, one, zero);
    ty -= lx_v4_select(ty > fy, one, zero);
    lx_v4f ax = fx - tx, ay = fy - ty;
    lx_v4i ix = __builtin_convertvector(tx, lx_v4i), iy = __builtin_convertvector(ty, lx_v4i);
    /* fx in [-0.5, w - 0.5): ix in [-1, w - 1] */
    ix += (ix < 0) & w;
    ix -= (ix >= w) & w;
    lx_v4i jx = ix + 1;
    jx &= ~(jx == w);
    lx_v4i jy = iy + 1;
    iy &= ~(iy < 0);
    jy &= ~(jy < 0);
    iy -= (iy >= h) & (iy - (h - 1));
    jy -= (jy >= h) & (jy - (h - 1));
    memcpy(x0, &ix, sizeof ix), memcpy(x1, &jx, sizeof jx);
    memcpy(y0, &iy, sizeof iy), memcpy(y1, &jy, sizeof jy);
    memcpy(wx, &ax, sizeof ax), memcpy(wy, &ay, sizeof ay);
}

/* The bilinear read at those taps. */
static inline void equirect_read(const lx_image *img, int x0, int x1, int y0, int y1, float wx,
                                 float wy, float out[3])
{
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

/* The equirect coordinates (u, t) of four directions (any length but
 * zero): the inverse of lx_equirect_direction. */
static inline void v4_equirect_uv(lx_v4f x, lx_v4f y, lx_v4f z, lx_v4f *u, lx_v4f *t)
{
    lx_v4f r = lx_v4_sqrt(x * x + z * z);
    lx_v4f uu = v4_atan2(x, -z) * (0.5f / PI_F) + 0.5f;
    *u = lx_v4_select(uu >= 1.0f, uu - 1.0f, uu);
    *t = v4_atan2(r, y) * (1.0f / PI_F);
}

/* ---- to a cube map ---------------------------------------------------------- */

typedef struct grid_job {
    lx_cubemap *out;
    const lx_image *eq;     /* an equirect source, or */
    const lx_cubemap *cube; /* a cube map source */
    double ratio;           /* source resolution over the cube's */
} grid_job;

/* One row of a face: each texel the mean of an n x n grid of bilinear
 * samples of the source over it. */
static bool grid_row(void *ctx, int row)
{
    const grid_job *j = ctx;
    int size = j->out->size, face = row / size, y = row % size;
    const float(*axes)[3] = lx_ibl_face_axes[face];
    int n = grid_for(j->ratio), offs_n = 0;
    float offs[MAX_GRID];
    for (int x = 0; x < size; x++) {
        if (j->eq) {
            /* sin(theta) of the texel centre: its distance from the y axis
             * over its length */
            lx_vec3 c = lx_ibl_face_vector(face, 2.0f * ((float)x + 0.5f) / (float)size - 1.0f,
                                           2.0f * ((float)y + 0.5f) / (float)size - 1.0f);
            double r2 = (double)c.x * c.x + (double)c.z * c.z;
            double sin_theta = sqrt(r2 / (r2 + (double)c.y * c.y));
            n = grid_for(j->ratio / (sin_theta > 1.0 / MAX_GRID ? sin_theta : 1.0 / MAX_GRID));
        }
        /* the centres of the n sub-cells of a texel */
        if (n != offs_n) {
            for (int i = 0; i < n; i++)
                offs[i] = ((float)i + 0.5f) / (float)n;
            offs_n = n;
        }
        double sum[3] = {0, 0, 0};
        for (int jj = 0; jj < n; jj++) {
            float tc = 2.0f * (((float)y + offs[jj]) / (float)size) - 1.0f;
            /* the face vector major + sc right + tc down, tc fixed */
            float bx = axes[0][0] + tc * axes[2][0], by = axes[0][1] + tc * axes[2][1];
            float bz = axes[0][2] + tc * axes[2][2];
            float sc[MAX_GRID + 3];
            for (int i = 0; i < n; i++)
                sc[i] = 2.0f * (((float)x + offs[i]) / (float)size) - 1.0f;
            if (!j->eq) {
                for (int i = 0; i < n; i++) {
                    float rgb[3];
                    lx_ibl_sample(j->cube,
                                  lx_v3(bx + sc[i] * axes[1][0], by + sc[i] * axes[1][1],
                                        bz + sc[i] * axes[1][2]),
                                  rgb);
                    sum[0] += rgb[0], sum[1] += rgb[1], sum[2] += rgb[2];
                }
                continue;
            }
            /* the equirect coordinates and bilinear taps four at a time,
             * then the reads */
            int x0[MAX_GRID + 3], x1[MAX_GRID + 3], y0[MAX_GRID + 3], y1[MAX_GRID + 3];
            float wx[MAX_GRID + 3], wy[MAX_GRID + 3];
            for (int i = n; i < n + 3; i++)
                sc[i] = 0.0f;
            for (int i = 0; i < n; i += 4) {
                lx_v4f c = lx_v4_load(sc + i), u, w;
                v4_equirect_uv(bx + c * axes[1][0], by + c * axes[1][1], bz + c * axes[1][2], &u,
                               &w);
                v4_taps(j->eq, u, w, x0 + i, x1 + i, y0 + i, y1 + i, wx + i, wy + i);
            }
            for (int i = 0; i < n; i++) {
                float rgb[3];
                equirect_read(j->eq, x0[i], x1[i], y0[i], y1[i], wx[i], wy[i], rgb);
                sum[0] += rgb[0], sum[1] += rgb[1], sum[2] += rgb[2];
            }
        }
        float *texel = lx_cubemap_texel(j->out, face, x, y);
        for (int k = 0; k < 3; k++)
            texel[k] = (float)(sum[k] / (double)(n * n));
    }
    return true;
}

static lx_status run_grid(grid_job *j, int size, const lx_ibl_run *run, lx_cubemap *out)
{
    lx_status st = lx_cubemap_alloc(out, size);
    if (st != LX_OK)
        return st;
    j->out = out;
    st = lx_ibl_for(run, 6 * size, NULL, grid_row, j, "resampling the environment");
    if (st != LX_OK)
        lx_cubemap_free(out);
    return st;
}

lx_status lx_ibl_cube_from_equirect(const lx_image *eq, int size, const lx_ibl_run *run,
                                    lx_cubemap *out)
{
    grid_job j = {.eq = eq, .ratio = (double)eq->width / (4.0 * size)};
    return run_grid(&j, size, run, out);
}

lx_status lx_ibl_cube_resample(const lx_cubemap *c, int size, const lx_ibl_run *run,
                               lx_cubemap *out)
{
    grid_job j = {.cube = c, .ratio = (double)c->size / (double)size};
    return run_grid(&j, size, run, out);
}

static bool image_ok(const lx_image *img)
{
    return img && img->data && img->width > 0 && img->height > 0 && img->channels >= 1 &&
           img->channels <= 4;
}

/* The run of a public conversion's desc (NULL: all cores, no progress),
 * its thread count checked. */
static lx_status start(const lx_ibl_desc *in, lx_ibl_run *run)
{
    lx_ibl_desc d = lx_ibl_desc_defaults(in);
    *run = lx_ibl_run_make(d.threads, d.progress, d.progress_user);
    return lx_ibl_check_threads(d.threads);
}

lx_status lx_cubemap_from_equirect(const lx_image *eq, int size, const lx_ibl_desc *in,
                                   lx_cubemap *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    lx_ibl_run run;
    if (!image_ok(eq))
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_from_equirect: invalid image");
    if (eq->width != 2 * eq->height)
        return lx_fail(LX_ERR_INVALID,
                       "equirect is %dx%d; an equirect must be exactly twice as wide as it is "
                       "tall",
                       eq->width, eq->height);
    lx_status st = start(in, &run);
    if (st != LX_OK)
        return st;
    char name[96];
    snprintf(name, sizeof name, "%d x %d faces from a %d x %d equirect", size, size, eq->width,
             eq->height);
    lx_ibl_warn_upsampling(name, size, eq->width / 4.0);
    return lx_ibl_cube_from_equirect(eq, size, &run, out);
}

/* ---- to an equirect ----------------------------------------------------------- */

typedef struct eq_job {
    const lx_cubemap *c;
    lx_image *out;
    int n;
    const float *sin_phi, *cos_phi; /* per sub-column: n per pixel */
} eq_job;

static bool eq_row(void *ctx, int y)
{
    const eq_job *j = ctx;
    int width = j->out->width, height = j->out->height, n = j->n;
    float st[MAX_GRID], ct[MAX_GRID];
    for (int jj = 0; jj < n; jj++) {
        float v = ((float)y + ((float)jj + 0.5f) / (float)n) / (float)height;
        float theta = PI_F * v;
        st[jj] = sinf(theta), ct[jj] = cosf(theta);
    }
    for (int x = 0; x < width; x++) {
        double sum[3] = {0, 0, 0};
        for (int jj = 0; jj < n; jj++)
            for (int i = 0; i < n; i++) {
                size_t k = (size_t)x * n + i;
                /* lx_equirect_direction's arithmetic */
                lx_vec3 d = lx_v3(st[jj] * j->sin_phi[k], ct[jj], -st[jj] * j->cos_phi[k]);
                float rgb[3];
                lx_ibl_sample(j->c, d, rgb);
                sum[0] += rgb[0], sum[1] += rgb[1], sum[2] += rgb[2];
            }
        float *p = j->out->data + ((size_t)y * width + x) * 3;
        for (int k = 0; k < 3; k++)
            p[k] = (float)(sum[k] / (double)(n * n));
    }
    return true;
}

lx_status lx_ibl_cube_to_equirect(const lx_cubemap *c, int width, const lx_ibl_run *run,
                                  lx_image *out)
{
    int height = width / 2;
    lx_status st = lx_image_alloc(out, width, height, 3);
    if (st != LX_OK)
        return st;
    int n = grid_for(4.0 * c->size / (double)width);
    float *phi = malloc(sizeof(float) * 2 * (size_t)width * n);
    if (!phi) {
        lx_image_free(out);
        return lx_fail(LX_ERR_NOMEM, "out of memory for a %d x %d equirect", width, height);
    }
    for (int x = 0; x < width; x++)
        for (int i = 0; i < n; i++) {
            float u = ((float)x + ((float)i + 0.5f) / (float)n) / (float)width;
            float p = 2.0f * PI_F * (u - 0.5f);
            phi[(size_t)x * n + i] = sinf(p);
            phi[(size_t)width * n + (size_t)x * n + i] = cosf(p);
        }
    eq_job j = {c, out, n, phi, phi + (size_t)width * n};
    st = lx_ibl_for(run, height, NULL, eq_row, &j, "making the equirect");
    free(phi);
    if (st != LX_OK)
        lx_image_free(out);
    return st;
}

lx_status lx_cubemap_to_equirect(const lx_cubemap *c, int width, const lx_ibl_desc *in,
                                 lx_image *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    lx_ibl_run run;
    if (!c || !c->data || c->size < 1)
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_to_equirect: invalid cube map");
    if (width < 2 || width % 2 != 0 || width > MAX_EQUIRECT_WIDTH)
        return lx_fail(LX_ERR_INVALID, "equirect width %d must be even and in 2..%d", width,
                       MAX_EQUIRECT_WIDTH);
    lx_status st = start(in, &run);
    if (st != LX_OK)
        return st;
    char name[96];
    snprintf(name, sizeof name, "a %d x %d equirect from %d x %d faces", width, width / 2, c->size,
             c->size);
    if (width > 16.0 * c->size)
        lx_log(LX_LOG_WARN, "%s upsamples them %.0fx", name, width / (4.0 * c->size));
    return lx_ibl_cube_to_equirect(c, width, &run, out);
}

/* ---- cross ------------------------------------------------------------------------ */

/* Where each face sits in a cross, in face-size units (column, row). */
static const int cross_h[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
static const int cross_v[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {1, 3}};

bool lx_ibl_cross_shape(int w, int h, int *size, bool *vertical)
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

typedef struct cross_job {
    const lx_image *img;
    lx_cubemap *cube;
    bool vertical, to_cross;
} cross_job;

/* One face row: copied between the cube map and the cross. */
static bool cross_row(void *ctx, int row)
{
    const cross_job *j = ctx;
    int size = j->cube->size, f = row / size, y = row % size;
    const int *cell = j->vertical ? cross_v[f] : cross_h[f];
    /* the vertical cross's -Z is turned by 180 degrees so its top edge
     * meets -Y's bottom edge */
    bool turned = j->vertical && f == LX_FACE_NZ;
    int py = cell[1] * size + (turned ? size - 1 - y : y);
    for (int x = 0; x < size; x++) {
        int px = cell[0] * size + (turned ? size - 1 - x : x);
        float *t = lx_cubemap_texel(j->cube, f, x, y);
        if (j->to_cross)
            memcpy(j->img->data + ((size_t)py * j->img->width + px) * 3, t, 3 * sizeof(float));
        else
            pixel_rgb(j->img, px, py, t);
    }
    return true;
}

lx_status lx_ibl_cube_from_cross(const lx_image *cross, const lx_ibl_run *run, lx_cubemap *out)
{
    int size = 0;
    bool vertical = false;
    lx_ibl_cross_shape(cross->width, cross->height, &size, &vertical);
    lx_status st = lx_cubemap_alloc(out, size);
    if (st != LX_OK)
        return st;
    cross_job j = {cross, out, vertical, false};
    st = lx_ibl_for(run, 6 * size, NULL, cross_row, &j, "reading the cross");
    if (st != LX_OK)
        lx_cubemap_free(out);
    return st;
}

lx_status lx_cubemap_from_cross(const lx_image *cross, const lx_ibl_desc *in, lx_cubemap *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    lx_ibl_run run;
    if (!image_ok(cross))
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_from_cross: invalid image");
    int size;
    bool vertical;
    if (!lx_ibl_cross_shape(cross->width, cross->height, &size, &vertical))
        return lx_fail(LX_ERR_INVALID,
                       "cross is %dx%d; a cross must be 4:3 (horizontal) or 3:4 (vertical) "
                       "with square faces",
                       cross->width, cross->height);
    lx_status st = start(in, &run);
    if (st != LX_OK)
        return st;
    return lx_ibl_cube_from_cross(cross, &run, out);
}

lx_status lx_ibl_cube_to_cross(const lx_cubemap *c, bool vertical, const lx_ibl_run *run,
                               lx_image *out)
{
    int size = c->size;
    lx_status st = lx_image_alloc(out, (vertical ? 3 : 4) * size, (vertical ? 4 : 3) * size, 3);
    if (st != LX_OK)
        return st;
    cross_job j = {out, (lx_cubemap *)c, vertical, true};
    st = lx_ibl_for(run, 6 * size, NULL, cross_row, &j, "making the cross");
    if (st != LX_OK)
        lx_image_free(out);
    return st;
}

lx_status lx_cubemap_to_cross(const lx_cubemap *c, bool vertical, const lx_ibl_desc *in,
                              lx_image *out)
{
    if (!out)
        return lx_fail_null(__func__, "out");
    memset(out, 0, sizeof *out);
    lx_ibl_run run;
    if (!c || !c->data || c->size < 1 || c->size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "lx_cubemap_to_cross: invalid cube map");
    lx_status st = start(in, &run);
    if (st != LX_OK)
        return st;
    return lx_ibl_cube_to_cross(c, vertical, &run, out);
}
