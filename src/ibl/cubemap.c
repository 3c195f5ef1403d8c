/* Cube map geometry and storage: the OpenGL cube face table (OpenGL 4.6
 * specification, section 8.13 "Cube Map Texture Selection"), exact texel
 * solid angles from the solid angle of a face rectangle seen from the cube
 * centre, F(a, b) = atan(a b / sqrt(a^2 + b^2 + 1)), and bilinear sampling
 * that takes its taps across face edges. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

const char *lx_cube_face_name(int face)
{
    static const char *names[6] = {"px", "nx", "py", "ny", "pz", "nz"};
    return face >= 0 && face < 6 ? names[face] : "?";
}

/* major axis, right (sc), down (tc): ibl.h's table */
const float lx_ibl_face_axes[6][3][3] = {
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},  /* +X (1, -tc, -sc) */
    {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},  /* -X (-1, -tc, sc) */
    {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},    /* +Y (sc, 1, tc) */
    {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},  /* -Y (sc, -1, -tc) */
    {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},   /* +Z (sc, -tc, 1) */
    {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}}, /* -Z (-sc, -tc, -1) */
};

lx_vec3 lx_cube_direction(int face, float s, float t)
{
    return lx_normalize(lx_ibl_face_vector(face, 2.0f * s - 1.0f, 2.0f * t - 1.0f));
}

void lx_cube_face_coords(lx_vec3 d, int *face, float *s, float *t)
{
    lx_ibl_face_st(d, face, s, t);
}

double lx_cube_texel_solid_angle(int size, int x, int y)
{
    double inv = 2.0 / size;
    double x0 = x * inv - 1.0, x1 = (x + 1) * inv - 1.0;
    double y0 = y * inv - 1.0, y1 = (y + 1) * inv - 1.0;
    return lx_ibl_corner(x0, y0) - lx_ibl_corner(x0, y1) - lx_ibl_corner(x1, y0) +
           lx_ibl_corner(x1, y1);
}

lx_vec3 lx_equirect_direction(float u, float v)
{
    float phi = 2.0f * (float)LX_PI * (u - 0.5f), theta = (float)LX_PI * v;
    float st = sinf(theta);
    return lx_v3(st * sinf(phi), cosf(theta), -st * cosf(phi));
}

void lx_equirect_coords(lx_vec3 d, float *u, float *v)
{
    d = lx_normalize(d);
    float phi = atan2f(d.x, -d.z);
    *u = phi / (2.0f * (float)LX_PI) + 0.5f;
    if (*u >= 1.0f)
        *u -= 1.0f;
    *v = acosf(lx_clampf(d.y, -1.0f, 1.0f)) / (float)LX_PI;
}

int lx_cube_mip_count(int size)
{
    int n = 1;
    while (size > 1) {
        size /= 2;
        n++;
    }
    return n;
}

lx_status lx_cubemap_alloc(lx_cubemap *c, int size)
{
    if (!c)
        return lx_fail_null(__func__, "c");
    memset(c, 0, sizeof *c);
    if (size < 1 || size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "cube map size %d is outside 1..%d", size, LX_MAX_CUBE_SIZE);
    uint64_t count = 6ull * (uint64_t)size * (uint64_t)size * 3ull;
    char what[64];
    snprintf(what, sizeof what, "a %d x %d cube map", size, size);
    lx_status st = lx_check_memory(count * sizeof(float), what);
    if (st != LX_OK)
        return st;
    c->data = calloc((size_t)count, sizeof(float));
    if (!c->data)
        return lx_fail(LX_ERR_NOMEM, "out of memory for a %d x %d cube map", size, size);
    c->size = size;
    return LX_OK;
}

void lx_cubemap_free(lx_cubemap *c)
{
    if (!c)
        return;
    free(c->data);
    c->data = NULL;
    c->size = 0;
}

lx_image lx_cubemap_face_image(const lx_cubemap *c, int face)
{
    lx_image img = {c->size, c->size, 3, lx_cubemap_texel(c, face, 0, 0)};
    return img;
}

void lx_cube_texel_at(lx_vec3 dir, int size, int *face, int *x, int *y)
{
    float s, t;
    lx_ibl_face_st(dir, face, &s, &t);
    int n = size, tx = (int)(s * (float)n), ty = (int)(t * (float)n);
    *x = tx < 0 ? 0 : tx >= n ? n - 1 : tx;
    *y = ty < 0 ? 0 : ty >= n ? n - 1 : ty;
}

void lx_ibl_texel_across(int size, int face, int x, int y, int *f, int *tx, int *ty)
{
    int n = size;
    if (x >= 0 && x < n && y >= 0 && y < n) {
        *f = face, *tx = x, *ty = y;
        return;
    }
    float sc = 2.0f * ((float)x + 0.5f) / (float)n - 1.0f;
    float tc = 2.0f * ((float)y + 0.5f) / (float)n - 1.0f;
    lx_cube_texel_at(lx_ibl_face_vector(face, sc, tc), n, f, tx, ty);
}

static const float *texel_across(const lx_cubemap *c, int face, int x, int y)
{
    int f, tx, ty;
    lx_ibl_texel_across(c->size, face, x, y, &f, &tx, &ty);
    return lx_cubemap_texel(c, f, tx, ty);
}

void lx_cubemap_sample(const lx_cubemap *c, lx_vec3 dir, float out[3])
{
    int face;
    float s, t;
    lx_cube_face_coords(dir, &face, &s, &t);
    float fx = s * (float)c->size - 0.5f, fy = t * (float)c->size - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float wx = fx - x0f, wy = fy - y0f;
    int x0 = (int)x0f, y0 = (int)y0f;
    const float *a = texel_across(c, face, x0, y0), *b = texel_across(c, face, x0 + 1, y0);
    const float *d = texel_across(c, face, x0, y0 + 1), *e = texel_across(c, face, x0 + 1, y0 + 1);
    for (int k = 0; k < 3; k++) {
        float top = a[k] + (b[k] - a[k]) * wx;
        float bottom = d[k] + (e[k] - d[k]) * wx;
        out[k] = top + (bottom - top) * wy;
    }
}
