/* Tests of environments in and out (src/ibl/envmap.c, seams.c, ktx.c):
 * layout round trips (cross and faces exact, equirect -> cube -> equirect
 * within 1% for a smooth environment whose values come from its formula),
 * cross layouts checked for continuity with directions as texel values,
 * the seam fix checked against neighbours found here from the face table,
 * KTX files read back by a minimal parser written from the KTX 1.1
 * specification with half floats decoded by their definition, and every
 * bad environment input (message, status, nothing written). Input files
 * are written here: PFM by hand (so they can hold NaN), PNG with
 * stb_image_write, others with lx_image_write. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image_write.h>

#include "cube_reference.h"
#include "helpers.h"
#include "core/internal.h"
#include "luxel/ibl.h"

typedef struct v3d {
    double x, y, z;
} v3d;

/* The face table of luxel/ibl.h, not normalised. */
static v3d table_vec(int face, double sc, double tc)
{
    switch (face) {
    case 0:
        return (v3d){1, -tc, -sc};
    case 1:
        return (v3d){-1, -tc, sc};
    case 2:
        return (v3d){sc, 1, tc};
    case 3:
        return (v3d){sc, -1, -tc};
    case 4:
        return (v3d){sc, -tc, 1};
    default:
        return (v3d){-sc, -tc, -1};
    }
}

static double dot3(v3d a, v3d b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

/* Face coordinates of d on face f: d / (d.e) = e + sc U + tc V. */
static void coords_on(int f, v3d d, double *sc, double *tc)
{
    v3d e = table_vec(f, 0, 0), u = table_vec(f, 1, 0), v = table_vec(f, 0, 1);
    u = (v3d){u.x - e.x, u.y - e.y, u.z - e.z};
    v = (v3d){v.x - e.x, v.y - e.y, v.z - e.z};
    double de = dot3(d, e);
    *sc = dot3(d, u) / de;
    *tc = dot3(d, v) / de;
}

static void assert_error_mentions(const char *needle)
{
    if (!strstr(lx_last_error(), needle))
        fail_msg("error \"%s\" does not mention \"%s\"", lx_last_error(), needle);
}

static char *path_in(const char *dir, const char *file)
{
    static char buf[4][1300];
    static int next;
    char *p = buf[next++ % 4];
    snprintf(p, sizeof buf[0], "%s/%s", dir, file);
    return p;
}

/* A PFM written by hand after the format's definition: "PF", width,
 * height, -1 (little endian), rows bottom to top. rgb is top row first. */
static void write_pfm(const char *path, int w, int h, const float *rgb)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fprintf(fp, "PF\n%d %d\n-1.0\n", w, h);
    for (int y = h - 1; y >= 0; y--)
        for (int i = 0; i < w * 3; i++) {
            float v = rgb[(size_t)y * w * 3 + i];
            uint32_t b;
            memcpy(&b, &v, 4);
            unsigned char le[4] = {(unsigned char)b, (unsigned char)(b >> 8),
                                   (unsigned char)(b >> 16), (unsigned char)(b >> 24)};
            fwrite(le, 1, 4, fp);
        }
    fclose(fp);
}

static void write_image_pfm(const char *path, const lx_image *img)
{
    assert_int_equal(img->channels, 3);
    write_pfm(path, img->width, img->height, img->data);
}

static void fill_random(lx_cubemap *c, uint32_t seed)
{
    size_t n = 6 * (size_t)c->size * c->size * 3;
    for (size_t i = 0; i < n; i++)
        c->data[i] = lx_random(seed, (uint32_t)i, 0, 0) * 4.0f;
}

static void assert_cubes_equal(const lx_cubemap *a, const lx_cubemap *b)
{
    assert_int_equal(a->size, b->size);
    size_t n = 6 * (size_t)a->size * a->size * 3;
    for (size_t i = 0; i < n; i++)
        if (a->data[i] != b->data[i])
            fail_msg("value %zu: %.9g != %.9g", i, a->data[i], b->data[i]);
}

/* ---- cross layouts ------------------------------------------------------- */

/* Face cells of the crosses in face units (column, row), as docs/ibl.md
 * draws them. */
static const int cells_h[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
static const int cells_v[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {1, 3}};

static int cell_face(bool vertical, int col, int row)
{
    for (int f = 0; f < 6; f++) {
        const int *c = vertical ? cells_v[f] : cells_h[f];
        if (c[0] == col && c[1] == row)
            return f;
    }
    return -1;
}

static void test_cross_round_trip_exact(void **state)
{
    (void)state;
    for (int vertical = 0; vertical < 2; vertical++) {
        lx_cubemap c, back;
        assert_int_equal(lx_cubemap_alloc(&c, 7), LX_OK);
        fill_random(&c, 21 + vertical);
        lx_image cross;
        assert_int_equal(lx_cubemap_to_cross(&c, vertical, NULL, &cross), LX_OK);
        assert_int_equal(cross.width, vertical ? 21 : 28);
        assert_int_equal(cross.height, vertical ? 28 : 21);
        /* cells that hold no face are black */
        for (int y = 0; y < cross.height; y++)
            for (int x = 0; x < cross.width; x++)
                if (cell_face(vertical, x / 7, y / 7) < 0)
                    for (int k = 0; k < 3; k++)
                        assert_true(cross.data[((size_t)y * cross.width + x) * 3 + k] == 0.0f);
        assert_int_equal(lx_cubemap_from_cross(&cross, NULL, &back), LX_OK);
        assert_cubes_equal(&c, &back);
        lx_cubemap_free(&back);

        /* through files: PFM and 32-bit EXR keep every bit */
        const char *dir = lx_test_dir("ibl_env_io/cross");
        const char *names[2] = {"cross.pfm", "cross.exr"};
        for (int k = 0; k < 2; k++) {
            char *p = path_in(dir, names[k]);
            assert_int_equal(lx_image_write(p, &cross, NULL), LX_OK);
            assert_int_equal(lx_env_load(p, NULL, &back), LX_OK);
            assert_cubes_equal(&c, &back);
            lx_cubemap_free(&back);
            lx_env_load_desc d = {.layout = LX_ENV_CROSS};
            assert_int_equal(lx_env_load(p, &d, &back), LX_OK);
            assert_cubes_equal(&c, &back);
            lx_cubemap_free(&back);
        }
        lx_image_free(&cross);
        lx_cubemap_free(&c);
    }
}

/* With each texel's value its direction (+2), neighbouring cross pixels
 * must hold neighbouring directions: across every face boundary inside
 * the cross as much as inside a face. Checks the placement and the
 * turning of the faces. */
static void test_cross_layout_continuous(void **state)
{
    (void)state;
    const int n = 8;
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, n), LX_OK);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                v3d d = table_vec(f, 2.0 * (x + 0.5) / n - 1.0, 2.0 * (y + 0.5) / n - 1.0);
                double len = sqrt(dot3(d, d));
                float *t = lx_test_cube_texel(&c, f, x, y);
                t[0] = (float)(d.x / len + 2.0);
                t[1] = (float)(d.y / len + 2.0);
                t[2] = (float)(d.z / len + 2.0);
            }
    for (int vertical = 0; vertical < 2; vertical++) {
        lx_image img;
        assert_int_equal(lx_cubemap_to_cross(&c, vertical, NULL, &img), LX_OK);
        int pairs = 0, boundary_pairs = 0;
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++)
                for (int dir = 0; dir < 2; dir++) {
                    int x2 = x + (dir == 0), y2 = y + (dir == 1);
                    if (x2 >= img.width || y2 >= img.height)
                        continue;
                    int fa = cell_face(vertical, x / n, y / n),
                        fb = cell_face(vertical, x2 / n, y2 / n);
                    if (fa < 0 || fb < 0)
                        continue;
                    const float *a = img.data + ((size_t)y * img.width + x) * 3;
                    const float *b = img.data + ((size_t)y2 * img.width + x2) * 3;
                    double dist =
                        sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                             (a[2] - b[2]) * (a[2] - b[2]));
                    /* neighbouring texel centres are at most ~1.3 * 2/n apart */
                    if (dist > 3.0 / n)
                        fail_msg("%s cross: pixels (%d, %d) and (%d, %d) (faces %s, %s) hold "
                                 "directions %g apart",
                                 vertical ? "vertical" : "horizontal", x, y, x2, y2,
                                 lx_cube_face_name(fa), lx_cube_face_name(fb), dist);
                    pairs++;
                    boundary_pairs += fa != fb;
                }
        /* 5 face boundaries inside either cross */
        assert_int_equal(boundary_pairs, 5 * n);
        assert_true(pairs > 0);
        /* the middle of each cell looks along its face's axis: pixel n/2 of
         * a cell is a texel next to the face's centre (which one depends on
         * the face's turn), 1/n off the axis in each face coordinate, so at
         * most (1/n) / sqrt(1 + 2/n^2) from it in each component (0.123 at
         * n = 8, the measured value); the bound adds float rounding. A
         * wrong face is 0.88 off or more. */
        const double off = (1.0 / n) / sqrt(1.0 + 2.0 / ((double)n * n)) + 1e-6;
        const double axes[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        for (int f = 0; f < 6; f++) {
            const int *cell = vertical ? cells_v[f] : cells_h[f];
            const float *p =
                img.data + ((size_t)(cell[1] * n + n / 2) * img.width + cell[0] * n + n / 2) * 3;
            for (int k = 0; k < 3; k++)
                assert_true(fabs(p[k] - 2.0 - axes[f][k]) < off);
        }
        lx_image_free(&img);
    }
    lx_cubemap_free(&c);
}

/* ---- six faces ----------------------------------------------------------- */

static void write_faces(const char *dir, const char *stem, const lx_cubemap *c, const char *ext)
{
    for (int f = 0; f < 6; f++) {
        char name[256];
        snprintf(name, sizeof name, "%s_%s.%s", stem, lx_cube_face_name(f), ext);
        lx_image face = lx_cubemap_face_image(c, f);
        if (strcmp(ext, "pfm") == 0)
            write_image_pfm(path_in(dir, name), &face);
        else
            assert_int_equal(lx_image_write(path_in(dir, name), &face, NULL), LX_OK);
    }
}

static void test_faces_round_trip_exact(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/faces");
    lx_cubemap c, back;
    assert_int_equal(lx_cubemap_alloc(&c, 9), LX_OK);
    fill_random(&c, 5);
    write_faces(dir, "sky", &c, "pfm");
    write_faces(dir, "env", &c, "exr");
    assert_int_equal(lx_env_load(path_in(dir, "sky_px.pfm"), NULL, &back), LX_OK);
    assert_cubes_equal(&c, &back);
    lx_cubemap_free(&back);
    lx_env_load_desc d = {.layout = LX_ENV_FACES};
    assert_int_equal(lx_env_load(path_in(dir, "env_px.exr"), &d, &back), LX_OK);
    assert_cubes_equal(&c, &back);
    lx_cubemap_free(&back);
    /* --intensity scales every texel */
    d.intensity = 2.0f;
    assert_int_equal(lx_env_load(path_in(dir, "sky_px.pfm"), &d, &back), LX_OK);
    for (size_t i = 0; i < 6 * 81 * 3; i++)
        assert_true(back.data[i] == 2.0f * c.data[i]);
    lx_cubemap_free(&back);
    lx_cubemap_free(&c);
}

/* ---- equirect ------------------------------------------------------------ */

/* A smooth colourful environment (all values > 0). */
static void smooth_env(v3d d, double out[3])
{
    out[0] = 2.0 + 0.8 * d.y + 0.5 * d.x + 0.3 * d.x * d.z;
    out[1] = 1.5 + 0.6 * d.z - 0.4 * d.y * d.y;
    out[2] = 1.0 + 0.5 * d.y * d.x + 0.3 * d.z;
}

static v3d equirect_dir(double u, double v)
{
    const double pi = 3.14159265358979323846;
    double p = 2 * pi * (u - 0.5), t = pi * v;
    return (v3d){sin(t) * sin(p), cos(t), -sin(t) * cos(p)};
}

static void make_smooth_equirect(lx_image *img, int w)
{
    assert_int_equal(lx_image_alloc(img, w, w / 2, 3), LX_OK);
    for (int y = 0; y < w / 2; y++)
        for (int x = 0; x < w; x++) {
            double v[3];
            smooth_env(equirect_dir((x + 0.5) / w, (y + 0.5) / (w / 2)), v);
            for (int k = 0; k < 3; k++)
                img->data[((size_t)y * w + x) * 3 + k] = (float)v[k];
        }
}

static void test_equirect_round_trip(void **state)
{
    (void)state;
    const int w = 256, size = 48;
    lx_image eq, back;
    make_smooth_equirect(&eq, w);
    lx_cubemap c;
    assert_int_equal(lx_cubemap_from_equirect(&eq, size, NULL, &c), LX_OK);
    /* every cube texel against the formula at its centre */
    double worst = 0.0;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++) {
                v3d d = table_vec(f, 2.0 * (x + 0.5) / size - 1.0, 2.0 * (y + 0.5) / size - 1.0);
                double len = sqrt(dot3(d, d)), want[3];
                smooth_env((v3d){d.x / len, d.y / len, d.z / len}, want);
                for (int k = 0; k < 3; k++) {
                    double e = fabs(lx_test_cube_texel(&c, f, x, y)[k] - want[k]) / want[k];
                    worst = e > worst ? e : worst;
                }
            }
    print_message("equirect -> cube: largest relative error %.3g%%\n", 100 * worst);
    assert_true(worst < 7e-4); /* measured 2.3e-4 */
    /* and back to the equirect */
    assert_int_equal(lx_cubemap_to_equirect(&c, w, NULL, &back), LX_OK);
    assert_int_equal(back.width, w);
    assert_int_equal(back.height, w / 2);
    worst = 0.0;
    for (size_t i = 0; i < (size_t)w * (w / 2) * 3; i++) {
        double e = fabs(back.data[i] - eq.data[i]) / eq.data[i];
        worst = e > worst ? e : worst;
    }
    print_message("equirect -> cube -> equirect: largest relative error %.3g%%\n", 100 * worst);
    assert_true(worst < 3e-3); /* measured 1.0e-3 */
    lx_image_free(&back);

    /* lx_env_load of the same equirect as a file: auto layout, size w/4 */
    const char *dir = lx_test_dir("ibl_env_io/equirect");
    write_image_pfm(path_in(dir, "sky.pfm"), &eq);
    lx_cubemap loaded;
    assert_int_equal(lx_env_load(path_in(dir, "sky.pfm"), NULL, &loaded), LX_OK);
    assert_int_equal(loaded.size, w / 4);
    lx_cubemap_free(&loaded);
    lx_env_load_desc d = {.size = size, .layout = LX_ENV_EQUIRECT};
    assert_int_equal(lx_env_load(path_in(dir, "sky.pfm"), &d, &loaded), LX_OK);
    assert_cubes_equal(&c, &loaded);
    lx_cubemap_free(&loaded);
    lx_cubemap_free(&c);
    lx_image_free(&eq);
}

/* A constant environment stays constant through every layout and resize:
 * measured exactly; bounds one float ulp of each value (2^-23 v). */
static void test_constant_environment(void **state)
{
    (void)state;
    lx_cubemap c, r;
    assert_int_equal(lx_env_constant(lx_v3(1.0f, 0.5f, 2.0f), 6, &c), LX_OK);
    for (size_t i = 0; i < 6 * 36; i++) {
        assert_true(c.data[3 * i] == 1.0f);
        assert_true(c.data[3 * i + 1] == 0.5f);
        assert_true(c.data[3 * i + 2] == 2.0f);
    }
    lx_image eq;
    assert_int_equal(lx_cubemap_to_equirect(&c, 30, NULL, &eq), LX_OK);
    for (size_t i = 0; i < 30 * 15; i++)
        assert_true(fabsf(eq.data[3 * i] - 1.0f) <= 1.2e-7f &&
                    fabsf(eq.data[3 * i + 2] - 2.0f) <= 2.4e-7f);
    assert_int_equal(lx_cubemap_from_equirect(&eq, 5, NULL, &r), LX_OK);
    for (size_t i = 0; i < 6 * 25; i++)
        assert_true(fabsf(r.data[3 * i + 1] - 0.5f) <= 6e-8f);
    lx_cubemap_free(&r);
    lx_image_free(&eq);
    /* a cross loaded at another size */
    const char *dir = lx_test_dir("ibl_env_io/constant");
    lx_image cross;
    assert_int_equal(lx_cubemap_to_cross(&c, false, NULL, &cross), LX_OK);
    write_image_pfm(path_in(dir, "c.pfm"), &cross);
    lx_env_load_desc d = {.size = 4};
    assert_int_equal(lx_env_load(path_in(dir, "c.pfm"), &d, &r), LX_OK);
    assert_int_equal(r.size, 4);
    for (size_t i = 0; i < 6 * 16; i++)
        assert_true(fabsf(r.data[3 * i + 2] - 2.0f) <= 2.4e-7f);
    lx_cubemap_free(&r);
    lx_image_free(&cross);
    lx_cubemap_free(&c);
}

/* 8-bit files are sRGB decoded: code value 128 -> ((128/255 + 0.055) /
 * 1.055)^2.4 (IEC 61966-2-1). Measured: within 3.1e-8 (two float ulps
 * at 0.216), bound 1e-7. */
static void test_png_is_srgb_decoded(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/png");
    unsigned char px[8 * 4 * 3];
    for (size_t i = 0; i < sizeof px; i++)
        px[i] = 128;
    assert_true(stbi_write_png(path_in(dir, "sky.png"), 8, 4, 3, px, 8 * 3) != 0);
    lx_cubemap c;
    lx_env_load_desc d = {.size = 2};
    assert_int_equal(lx_env_load(path_in(dir, "sky.png"), &d, &c), LX_OK);
    double want = pow((128.0 / 255.0 + 0.055) / 1.055, 2.4);
    for (size_t i = 0; i < 6 * 4 * 3; i++)
        assert_true(fabs(c.data[i] - want) < 1e-7);
    lx_cubemap_free(&c);
}

/* ---- seams ----------------------------------------------------------------- */

/* The texel across the edge from texel (x, y) of face f in direction
 * (dx, dy) (one of them +-1, leading off the face), found from the face
 * table: the point in the middle of the shared edge segment, seen from
 * the other face, half a texel inwards. */
static void across(int n, int f, int x, int y, int dx, int dy, int *g, int *gx, int *gy)
{
    double sc = 2.0 * (x + 0.5) / n - 1.0, tc = 2.0 * (y + 0.5) / n - 1.0;
    if (dx)
        sc = dx;
    if (dy)
        tc = dy;
    v3d d = table_vec(f, sc, tc);
    /* the other face is the one whose axis has the other largest component */
    int best = -1;
    double best_dot = -1.0;
    for (int h = 0; h < 6; h++) {
        if (h == f)
            continue;
        double e = dot3(d, table_vec(h, 0, 0));
        if (e > best_dot + 1e-12) {
            best_dot = e;
            best = h;
        }
    }
    double s2, t2;
    coords_on(best, d, &s2, &t2);
    *g = best;
    *gx = (int)floor((s2 + 1.0) / 2.0 * n);
    *gy = (int)floor((t2 + 1.0) / 2.0 * n);
    *gx = *gx < 0 ? 0 : *gx >= n ? n - 1 : *gx;
    *gy = *gy < 0 ? 0 : *gy >= n ? n - 1 : *gy;
}

static void test_seams_agree(void **state)
{
    (void)state;
    const int sizes[] = {1, 2, 3, 4, 9, 16};
    for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; si++) {
        int n = sizes[si];
        lx_cubemap c, orig;
        assert_int_equal(lx_cubemap_alloc(&c, n), LX_OK);
        assert_int_equal(lx_cubemap_alloc(&orig, n), LX_OK);
        fill_random(&c, 100 + (uint32_t)n);
        memcpy(orig.data, c.data, 6 * (size_t)n * n * 3 * sizeof(float));
        lx_cubemap_fix_seams(&c);
        int checked = 0;
        for (int f = 0; f < 6; f++)
            for (int y = 0; y < n; y++)
                for (int x = 0; x < n; x++) {
                    const int offs[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
                    int nb = 0; /* edges this texel lies on */
                    int nf[2], nx[2], ny[2];
                    for (int o = 0; o < 4; o++) {
                        int x2 = x + offs[o][0], y2 = y + offs[o][1];
                        if (x2 >= 0 && x2 < n && y2 >= 0 && y2 < n)
                            continue;
                        int g, gx, gy;
                        across(n, f, x, y, offs[o][0], offs[o][1], &g, &gx, &gy);
                        const float *a = lx_test_cube_texel(&c, f, x, y);
                        const float *b = lx_test_cube_texel(&c, g, gx, gy);
                        for (int k = 0; k < 3; k++)
                            if (a[k] != b[k])
                                fail_msg("size %d: face %s (%d, %d) = %g but across the edge "
                                         "face %s (%d, %d) = %g",
                                         n, lx_cube_face_name(f), x, y, a[k], lx_cube_face_name(g),
                                         gx, gy, b[k]);
                        checked++;
                        if (nb < 2) {
                            nf[nb] = g;
                            nx[nb] = gx;
                            ny[nb] = gy;
                        }
                        nb++;
                    }
                    const float *now = lx_test_cube_texel(&c, f, x, y);
                    const float *was = lx_test_cube_texel(&orig, f, x, y);
                    for (int k = 0; k < 3; k++) {
                        double want = was[k];
                        if (n == 1) {
                            want = 0.0;
                            for (int h = 0; h < 6; h++)
                                want += lx_test_cube_texel(&orig, h, 0, 0)[k];
                            want /= 6.0;
                        } else if (nb == 1) {
                            want =
                                0.5 * (was[k] + lx_test_cube_texel(&orig, nf[0], nx[0], ny[0])[k]);
                        } else if (nb == 2) {
                            want = (was[k] + lx_test_cube_texel(&orig, nf[0], nx[0], ny[0])[k] +
                                    lx_test_cube_texel(&orig, nf[1], nx[1], ny[1])[k]) /
                                   3.0;
                        }
                        /* measured: within 9.8e-8 (1 + |want|), bound 3e-7 */
                        if (fabs(now[k] - want) > 3e-7 * (1.0 + fabs(want)))
                            fail_msg("size %d: face %s (%d, %d) on %d edges is %g, want %g", n,
                                     lx_cube_face_name(f), x, y, nb, now[k], want);
                    }
                }
        /* every face has 4 * n texel-edges on its border */
        assert_int_equal(checked, 6 * 4 * n);
        lx_cubemap_free(&c);
        lx_cubemap_free(&orig);
    }
}

/* ---- KTX ------------------------------------------------------------------- */

static uint32_t rd32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* IEEE 754 binary16 by its definition. */
static double half_value(uint16_t h)
{
    int e = (h >> 10) & 31, m = h & 1023;
    double v = e == 0 ? ldexp(m, -24) : e == 31 ? INFINITY : ldexp(1024 + m, e - 25);
    return (h & 0x8000) ? -v : v;
}

typedef struct ktx_info {
    uint32_t gl_type, type_size, format, internal, base, width, height, depth, arrays, faces,
        levels, kv_bytes;
    char writer[64];
    const unsigned char *level_data[LX_MAX_CUBE_MIPS]; /* first face of each level */
    uint32_t image_size[LX_MAX_CUBE_MIPS];
} ktx_info;

/* A minimal KTX 1.1 reader: checks the identifier, the endianness, the
 * key/value block and that the levels fill the file exactly. */
static void parse_ktx(const unsigned char *d, size_t size, ktx_info *k)
{
    static const unsigned char id[12] = {0xAB, 0x4B, 0x54, 0x58, 0x20, 0x31,
                                         0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A};
    memset(k, 0, sizeof *k);
    assert_true(size >= 64);
    assert_memory_equal(d, id, 12);
    assert_int_equal(rd32(d + 12), 0x04030201);
    uint32_t *fields[12] = {&k->gl_type, &k->type_size, &k->format, &k->internal,
                            &k->base,    &k->width,     &k->height, &k->depth,
                            &k->arrays,  &k->faces,     &k->levels, &k->kv_bytes};
    for (int i = 0; i < 12; i++)
        *fields[i] = rd32(d + 16 + 4 * i);
    size_t pos = 64, kv_end = 64 + (size_t)k->kv_bytes;
    assert_true(kv_end <= size);
    while (pos < kv_end) {
        uint32_t n = rd32(d + pos);
        pos += 4;
        assert_true(pos + n <= kv_end);
        const char *key = (const char *)d + pos;
        size_t klen = strnlen(key, n);
        assert_true(klen < n);
        if (strcmp(key, "KTXwriter") == 0)
            snprintf(k->writer, sizeof k->writer, "%.*s", (int)(n - klen - 1), key + klen + 1);
        pos += n;
        pos += 3 - ((n + 3) % 4); /* valuePadding */
    }
    assert_int_equal(pos, kv_end);
    uint32_t levels = k->levels ? k->levels : 1;
    assert_true(levels <= LX_MAX_CUBE_MIPS);
    for (uint32_t l = 0; l < levels; l++) {
        assert_true(pos + 4 <= size);
        k->image_size[l] = rd32(d + pos);
        pos += 4;
        k->level_data[l] = d + pos;
        for (uint32_t face = 0; face < k->faces; face++) {
            pos += k->image_size[l];
            pos += 3 - ((k->image_size[l] + 3) % 4); /* cubePadding */
        }
        assert_true(pos <= size);
    }
    assert_int_equal(pos, size);
}

static void make_chain(lx_cubemap *levels, int size, int count, uint32_t seed)
{
    for (int l = 0; l < count; l++) {
        int s = size >> l > 0 ? size >> l : 1;
        assert_int_equal(lx_cubemap_alloc(&levels[l], s), LX_OK);
        fill_random(&levels[l], seed + (uint32_t)l);
    }
}

static void test_ktx_float_structure(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/ktx32");
    lx_cubemap levels[4];
    make_chain(levels, 8, 4, 40);
    char *path = path_in(dir, "env.ktx");
    assert_int_equal(lx_ktx_write_cubemap(path, levels, 4, false), LX_OK);
    assert_int_equal(lx_test_count_files(dir), 1);
    char *buf;
    size_t size;
    assert_int_equal(lx_read_file(path, 1 << 24, &buf, &size), LX_OK);
    ktx_info k;
    parse_ktx((unsigned char *)buf, size, &k);
    assert_int_equal(k.gl_type, 0x1406);
    assert_int_equal(k.type_size, 4);
    assert_int_equal(k.format, 0x1908);
    assert_int_equal(k.internal, 0x8814);
    assert_int_equal(k.base, 0x1908);
    assert_int_equal(k.width, 8);
    assert_int_equal(k.height, 8);
    assert_int_equal(k.depth, 0);
    assert_int_equal(k.arrays, 0);
    assert_int_equal(k.faces, 6);
    assert_int_equal(k.levels, 4);
    assert_true(strncmp(k.writer, "luxel", 5) == 0);
    for (int l = 0; l < 4; l++) {
        int s = 8 >> l;
        assert_int_equal(k.image_size[l], s * s * 16);
        for (int face = 0; face < 6; face++)
            for (int y = 0; y < s; y++)
                for (int x = 0; x < s; x++) {
                    const unsigned char *p =
                        k.level_data[l] + (size_t)face * k.image_size[l] + ((size_t)y * s + x) * 16;
                    const float *want = lx_test_cube_texel(&levels[l], face, x, y);
                    for (int ch = 0; ch < 4; ch++) {
                        uint32_t bits = rd32(p + 4 * ch);
                        float v;
                        memcpy(&v, &bits, 4);
                        assert_true(v == (ch < 3 ? want[ch] : 1.0f));
                    }
                }
    }
    free(buf);
    for (int l = 0; l < 4; l++)
        lx_cubemap_free(&levels[l]);
}

static void test_ktx_half_rounding(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/ktx16");
    const int n = 16;
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, n), LX_OK);
    /* values with their binary16 encodings worked out by hand */
    const struct {
        double v;
        uint16_t h;
    } known[] = {
        {1.0, 0x3C00},
        {-2.0, 0xC000},
        {65504.0, 0x7BFF},                 /* largest half */
        {65500.0, 0x7BFF},                 /* spacing 32 up there: 2046.875 -> 2047 */
        {0x1p-24, 0x0001},                 /* smallest subnormal */
        {0x1p-25, 0x0000},                 /* half of it: tie, to even (0) */
        {0x3p-25, 0x0002},                 /* 1.5 units: tie, to even (2) */
        {0x5p-25, 0x0002},                 /* 2.5 units: tie, to even (2) */
        {0x1p-14, 0x0400},                 /* smallest normal */
        {0x1p-14 - 0x1p-25, 0x0400},       /* 1023.5 units: tie, to even (1024) */
        {1.0 + 0x1p-11, 0x3C00},           /* half an ulp above 1: to even */
        {1.0 + 0x3p-11, 0x3C02},           /* 1.5 ulp: to even */
        {1.0 + 0x1p-11 + 0x1p-20, 0x3C01}, /* just over half an ulp: up */
        {2049.0, 0x6800},                  /* spacing 2: tie between 2048 and 2050 */
        {2051.0, 0x6802},                  /* tie between 2050 and 2052 */
        {0.1f, 0x2E66},                    /* 1.6 * 2^-4: 614.4 -> 614 */
        {0.0, 0x0000},
    };
    size_t nk = sizeof known / sizeof known[0];
    size_t total = 6 * (size_t)n * n * 3;
    for (size_t i = 0; i < total; i++) {
        if (i < nk) {
            c.data[i] = (float)known[i].v;
            continue;
        }
        /* random magnitudes from 2^-27 to 2^15 */
        double m = 1.0 + lx_random(9, (uint32_t)i, 0, 0);
        int e = -27 + (int)(lx_random(9, (uint32_t)i, 1, 0) * 42.0f);
        double v = ldexp(m, e);
        c.data[i] = (float)(v > 65504.0 ? 65504.0 : v);
    }
    char *path = path_in(dir, "half.ktx");
    assert_int_equal(lx_ktx_write_cubemap(path, &c, 1, true), LX_OK);
    char *buf;
    size_t size;
    assert_int_equal(lx_read_file(path, 1 << 24, &buf, &size), LX_OK);
    ktx_info k;
    parse_ktx((unsigned char *)buf, size, &k);
    assert_int_equal(k.gl_type, 0x140B);
    assert_int_equal(k.type_size, 2);
    assert_int_equal(k.internal, 0x881A);
    assert_int_equal(k.levels, 1);
    assert_int_equal(k.image_size[0], n * n * 8);
    for (size_t i = 0; i < total; i++) {
        size_t texel = i / 3, ch = i % 3;
        const unsigned char *p = k.level_data[0] + texel * 8 + ch * 2; /* faces are contiguous */
        uint16_t h = (uint16_t)(p[0] | p[1] << 8);
        if (i < nk && h != known[i].h)
            fail_msg("%.17g encoded as 0x%04X, want 0x%04X", known[i].v, h, known[i].h);
        /* nearest: no neighbouring half is closer; on a tie the even one */
        double v = c.data[i], got = fabs(half_value(h) - v);
        for (int dir2 = -1; dir2 <= 1; dir2 += 2) {
            uint16_t mag = h & 0x7fff;
            if ((dir2 < 0 && mag == 0) || (dir2 > 0 && mag >= 0x7BFF))
                continue;
            uint16_t other = (uint16_t)((h & 0x8000) | (mag + dir2));
            double alt = fabs(half_value(other) - v);
            if (alt < got || (alt == got && (h & 1)))
                fail_msg("%.17g encoded as 0x%04X (%.17g), 0x%04X (%.17g) is %s", v, h,
                         half_value(h), other, half_value(other),
                         alt < got ? "closer" : "as close and even");
        }
        /* alpha is 1 */
        if (ch == 2)
            assert_int_equal(p[2] | p[3] << 8, 0x3C00);
    }
    free(buf);
    lx_cubemap_free(&c);
}

static void test_ktx_bad(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/ktx_bad");
    char *path = path_in(dir, "bad.ktx");
    lx_cubemap levels[4];
    make_chain(levels, 8, 4, 3);
    /* above the half range: rejected, not clamped, nothing written */
    lx_test_cube_texel(&levels[2], LX_FACE_NY, 1, 0)[1] = 70000.0f;
    assert_int_equal(lx_ktx_write_cubemap(path, levels, 4, true), LX_ERR_INVALID);
    assert_error_mentions("bad.ktx");
    assert_error_mentions("level 2 face ny texel (1, 0)");
    assert_error_mentions("65504");
    assert_int_equal(lx_test_count_files(dir), 0);
    /* fine as 32-bit floats */
    assert_int_equal(lx_ktx_write_cubemap(path, levels, 4, false), LX_OK);
    remove(path);
    lx_test_cube_texel(&levels[0], LX_FACE_PZ, 3, 3)[0] = NAN;
    assert_int_equal(lx_ktx_write_cubemap(path, levels, 4, false), LX_ERR_INVALID);
    assert_error_mentions("NaN");
    lx_test_cube_texel(&levels[0], LX_FACE_PZ, 3, 3)[0] = 1.0f;
    /* mip counts and sizes that make no sense */
    assert_int_equal(lx_ktx_write_cubemap(path, levels, 0, false), LX_ERR_INVALID);
    assert_int_equal(lx_ktx_write_cubemap(path, levels, 5, false), LX_ERR_INVALID);
    assert_error_mentions("only 4");
    assert_int_equal(lx_ktx_write_cubemap(path, levels + 1, 3, false), LX_OK); /* 4, 2, 1 */
    remove(path);
    lx_cubemap wrong[2] = {levels[0], levels[2]};
    assert_int_equal(lx_ktx_write_cubemap(path, wrong, 2, false), LX_ERR_INVALID);
    assert_error_mentions("level 1 is 2 texels wide, expected 4");
    /* a folder that does not exist */
    assert_int_equal(lx_ktx_write_cubemap(path_in(dir, "no/such.ktx"), levels, 1, false),
                     LX_ERR_IO);
    assert_int_equal(lx_test_count_files(dir), 0);
    for (int l = 0; l < 4; l++)
        lx_cubemap_free(&levels[l]);
}

/* ---- bad input ------------------------------------------------------------- */

static void expect_env_error(const char *path, const lx_env_load_desc *d, lx_status want,
                             const char *needle1, const char *needle2)
{
    lx_cubemap c = {.size = 99};
    lx_status st = lx_env_load(path, d, &c);
    if (st != want)
        fail_msg("%s: status %s, want %s (%s)", path, lx_status_name(st), lx_status_name(want),
                 lx_last_error());
    assert_null(c.data);
    assert_int_equal(c.size, 0);
    assert_error_mentions(needle1);
    if (needle2)
        assert_error_mentions(needle2);
}

static float *grey(int w, int h, float v)
{
    float *p = malloc((size_t)w * h * 3 * sizeof(float));
    assert_non_null(p);
    for (size_t i = 0; i < (size_t)w * h * 3; i++)
        p[i] = v;
    return p;
}

static void test_bad_shapes(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/bad_shapes");
    float *px = grey(30, 20, 1.0f);
    write_pfm(path_in(dir, "wide.pfm"), 30, 20, px);
    lx_env_load_desc eq = {.layout = LX_ENV_EQUIRECT}, cross = {.layout = LX_ENV_CROSS};
    expect_env_error(path_in(dir, "wide.pfm"), &eq, LX_ERR_FORMAT, "wide.pfm",
                     "twice as wide as it is tall, not 30x20");
    expect_env_error(path_in(dir, "wide.pfm"), NULL, LX_ERR_FORMAT, "wide.pfm",
                     "cannot tell the layout of a 30x20 image");
    expect_env_error(path_in(dir, "wide.pfm"), &cross, LX_ERR_FORMAT, "wide.pfm", "4:3");
    /* a 2:1 image is not a cross, a 4:3 one is not an equirect */
    write_pfm(path_in(dir, "eq.pfm"), 20, 10, px);
    expect_env_error(path_in(dir, "eq.pfm"), &cross, LX_ERR_FORMAT, "eq.pfm", "not 20x10");
    write_pfm(path_in(dir, "cross.pfm"), 16, 12, px);
    expect_env_error(path_in(dir, "cross.pfm"), &eq, LX_ERR_FORMAT, "cross.pfm", "not 16x12");
    /* 3:2 is no cross either */
    write_pfm(path_in(dir, "odd.pfm"), 6, 4, px);
    expect_env_error(path_in(dir, "odd.pfm"), &cross, LX_ERR_FORMAT, "odd.pfm", "not 6x4");

    /* faces: unequal, not square, missing, wrong name */
    lx_cubemap c;
    assert_int_equal(lx_env_constant(lx_v3(1, 1, 1), 4, &c), LX_OK);
    write_faces(dir, "f", &c, "pfm");
    write_pfm(path_in(dir, "f_nz.pfm"), 5, 5, px);
    expect_env_error(path_in(dir, "f_px.pfm"), NULL, LX_ERR_FORMAT, "f_nz.pfm",
                     "differ in size: this one is 5x5, the _px face 4x4");
    write_pfm(path_in(dir, "f_nz.pfm"), 4, 5, px);
    expect_env_error(path_in(dir, "f_px.pfm"), NULL, LX_ERR_FORMAT, "f_nz.pfm",
                     "must be square, not 4x5");
    remove(path_in(dir, "f_nz.pfm"));
    expect_env_error(path_in(dir, "f_px.pfm"), NULL, LX_ERR_IO, "f_nz.pfm", NULL);
    lx_env_load_desc faces = {.layout = LX_ENV_FACES};
    expect_env_error(path_in(dir, "wide.pfm"), &faces, LX_ERR_INVALID, "wide.pfm", "_px");
    lx_cubemap_free(&c);

    /* the other arguments */
    write_pfm(path_in(dir, "ok.pfm"), 8, 4, px);
    lx_env_load_desc bad = {.size = -1};
    expect_env_error(path_in(dir, "ok.pfm"), &bad, LX_ERR_INVALID, "ok.pfm", "size -1");
    bad.size = LX_MAX_CUBE_SIZE + 1;
    expect_env_error(path_in(dir, "ok.pfm"), &bad, LX_ERR_INVALID, "ok.pfm", "16385");
    lx_env_load_desc neg = {.intensity = -1.0f}, nan_i = {.intensity = NAN};
    expect_env_error(path_in(dir, "ok.pfm"), &neg, LX_ERR_INVALID, "ok.pfm", "intensity");
    expect_env_error(path_in(dir, "ok.pfm"), &nan_i, LX_ERR_INVALID, "ok.pfm", "intensity");
    lx_env_load_desc ktx = {.layout = LX_ENV_KTX};
    expect_env_error(path_in(dir, "ok.pfm"), &ktx, LX_ERR_UNSUPPORTED, "ok.pfm", "KTX");
    float *big = grey(8, 4, 3e38f);
    write_pfm(path_in(dir, "big.pfm"), 8, 4, big);
    lx_env_load_desc loud = {.intensity = 10.0f};
    expect_env_error(path_in(dir, "big.pfm"), &loud, LX_ERR_INVALID, "big.pfm", "overflow");
    free(big);
    free(px);

    /* the library calls themselves */
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 12, 9, 3), LX_OK);
    assert_int_equal(lx_cubemap_from_equirect(&img, 4, NULL, &c), LX_ERR_INVALID);
    assert_error_mentions("12x9");
    assert_null(c.data);
    lx_image_free(&img);
    assert_int_equal(lx_image_alloc(&img, 12, 6, 3), LX_OK);
    assert_int_equal(lx_cubemap_from_cross(&img, NULL, &c), LX_ERR_INVALID);
    assert_error_mentions("12x6");
    assert_int_equal(lx_cubemap_from_equirect(&img, 0, NULL, &c), LX_ERR_INVALID);
    assert_int_equal(lx_cubemap_from_equirect(&img, LX_MAX_CUBE_SIZE + 1, NULL, &c),
                     LX_ERR_INVALID);
    lx_image_free(&img);
    assert_int_equal(lx_env_constant(lx_v3(1, 1, 1), 3, &c), LX_OK);
    assert_int_equal(lx_cubemap_to_equirect(&c, 7, NULL, &img), LX_ERR_INVALID);
    assert_int_equal(lx_cubemap_to_equirect(&c, 0, NULL, &img), LX_ERR_INVALID);
    assert_null(img.data);
    lx_cubemap_free(&c);
    assert_int_equal(lx_env_constant(lx_v3(1, -1, 1), 3, &c), LX_ERR_INVALID);
    assert_int_equal(lx_env_constant(lx_v3(1, NAN, 1), 3, &c), LX_ERR_INVALID);
    assert_int_equal(lx_env_constant(lx_v3(1, 1, 1), 0, &c), LX_ERR_INVALID);
    assert_null(c.data);
}

static void test_bad_values(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/bad_values");
    /* an equirect with 3 NaN texels, 1 infinite and 2 negative */
    float *p = grey(16, 8, 1.0f);
    p[3 * (2 * 16 + 5) + 1] = NAN;
    p[3 * (3 * 16 + 0)] = NAN;
    p[3 * (3 * 16 + 0) + 2] = NAN; /* the same texel twice */
    p[3 * (7 * 16 + 15)] = NAN;
    p[3 * (4 * 16 + 4)] = INFINITY;
    p[3 * (1 * 16 + 9) + 2] = -0.5f;
    p[3 * (6 * 16 + 1)] = -2.0f;
    write_pfm(path_in(dir, "nan.pfm"), 16, 8, p);
    expect_env_error(path_in(dir, "nan.pfm"), NULL, LX_ERR_FORMAT, "nan.pfm",
                     "4 texels are NaN or infinite and 2 texels are negative");
    assert_error_mentions("first at pixel (9, 1)");
    free(p);
    /* a single negative texel in a cross face; NaN where no face is is unused */
    p = grey(16, 12, 1.0f);
    p[3 * (0 * 16 + 0)] = NAN;        /* cell (0, 0): no face */
    p[3 * (5 * 16 + 13) + 1] = -1.0f; /* -Z (cell (3, 1)) texel (1, 1) */
    write_pfm(path_in(dir, "cross.pfm"), 16, 12, p);
    expect_env_error(path_in(dir, "cross.pfm"), NULL, LX_ERR_FORMAT, "cross.pfm",
                     "1 texel is negative (the first at face nz texel (1, 1))");
    p[3 * (5 * 16 + 13) + 1] = 1.0f;
    write_pfm(path_in(dir, "cross.pfm"), 16, 12, p);
    lx_cubemap c;
    assert_int_equal(lx_env_load(path_in(dir, "cross.pfm"), NULL, &c), LX_OK);
    lx_cubemap_free(&c);
    free(p);
    /* a NaN in one of six faces names that file */
    assert_int_equal(lx_env_constant(lx_v3(1, 1, 1), 4, &c), LX_OK);
    lx_test_cube_texel(&c, LX_FACE_PY, 2, 3)[0] = NAN;
    write_faces(dir, "sky", &c, "pfm");
    expect_env_error(path_in(dir, "sky_px.pfm"), NULL, LX_ERR_FORMAT, "sky_py.pfm",
                     "1 texel is NaN or infinite (the first at pixel (2, 3))");
    lx_cubemap_free(&c);
}

static void test_bad_files(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("ibl_env_io/bad_files");
    expect_env_error(path_in(dir, "missing.hdr"), NULL, LX_ERR_IO, "missing.hdr", NULL);
    /* random bytes */
    FILE *fp = fopen(path_in(dir, "noise.hdr"), "wb");
    assert_non_null(fp);
    for (int i = 0; i < 500; i++)
        fputc((int)(lx_hash4(1, (uint32_t)i, 0, 0) & 0xff), fp);
    fclose(fp);
    lx_cubemap c;
    assert_int_not_equal(lx_env_load(path_in(dir, "noise.hdr"), NULL, &c), LX_OK);
    assert_error_mentions("noise.hdr");
    assert_null(c.data);
    /* a truncated PFM and a truncated Radiance HDR */
    float *p = grey(16, 8, 0.5f);
    write_pfm(path_in(dir, "full.pfm"), 16, 8, p);
    lx_image img = {16, 8, 3, p};
    assert_int_equal(lx_image_write(path_in(dir, "full.hdr"), &img, NULL), LX_OK);
    free(p);
    const char *names[2][2] = {{"full.pfm", "cut.pfm"}, {"full.hdr", "cut.hdr"}};
    for (int k = 0; k < 2; k++) {
        char *buf;
        size_t size;
        assert_int_equal(lx_read_file(path_in(dir, names[k][0]), 1 << 20, &buf, &size), LX_OK);
        fp = fopen(path_in(dir, names[k][1]), "wb");
        assert_non_null(fp);
        fwrite(buf, 1, size * 2 / 3, fp);
        fclose(fp);
        free(buf);
        assert_int_equal(lx_env_load(path_in(dir, names[k][1]), NULL, &c), LX_ERR_FORMAT);
        assert_error_mentions(names[k][1]);
        assert_null(c.data);
    }
    /* the whole files load */
    assert_int_equal(lx_env_load(path_in(dir, "full.hdr"), NULL, &c), LX_OK);
    assert_int_equal(c.size, 4);
    lx_cubemap_free(&c);
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cross_round_trip_exact),
        cmocka_unit_test(test_cross_layout_continuous),
        cmocka_unit_test(test_faces_round_trip_exact),
        cmocka_unit_test(test_equirect_round_trip),
        cmocka_unit_test(test_constant_environment),
        cmocka_unit_test(test_png_is_srgb_decoded),
        cmocka_unit_test(test_seams_agree),
        cmocka_unit_test(test_ktx_float_structure),
        cmocka_unit_test(test_ktx_half_rounding),
        cmocka_unit_test(test_ktx_bad),
        cmocka_unit_test(test_bad_shapes),
        cmocka_unit_test(test_bad_values),
        cmocka_unit_test(test_bad_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
