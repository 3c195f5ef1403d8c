/* lx_normal_map against values from outside it:
 * - a brute-force reference written here in double (its own wrap
 *   addressing, the three filters' 3x3 kernels as published: central
 *   [-1 0 1]/2, Sobel [1 2 1]^T[-1 0 1]/8, Scharr [3 10 3]^T[-1 0 1]/32),
 *   on every wrap mode and odd sizes down to 1x1, borders included;
 * - closed forms: a plane (the slope exactly, the border slopes of each
 *   wrap mode), a sinusoid at a non-power-of-two size (central differences
 *   of sin(kx) are k cos(kx) times sin(k)/k; the Sobel and Scharr
 *   smoothing across multiplies by (2 + 2 cos k)/4 and (10 + 6 cos k)/16),
 *   a step (exactly the two texels either side of the edge tilt, by
 *   atan(S/2): no offset), a cone (normals point away from the apex with
 *   the cone's slope, to the central-difference error c/r^2);
 * - 16-bit PNG output decodes to within 0.05 degrees (8-bit: ~0.3);
 * - determinism over thread counts, green down, bad input. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"
#include "luxel/maps.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* ---- the reference -------------------------------------------------------- */

static int ref_wrap(lx_wrap mode, int i, int n)
{
    if (mode == LX_WRAP_CLAMP)
        return i < 0 ? 0 : i >= n ? n - 1 : i;
    if (mode == LX_WRAP_MIRROR) {
        /* reflect with the edge texel repeated: ... 1 0 | 0 1 ... n-1 | n-1 n-2 ... */
        for (;;) {
            if (i < 0)
                i = -1 - i;
            else if (i >= n)
                i = 2 * n - 1 - i;
            else
                return i;
        }
    }
    return ((i % n) + n) % n;
}

/* Height at column x, row r (rows down the image) with wrap. */
static double H(const lx_image *h, lx_wrap mode, int x, int r)
{
    x = ref_wrap(mode, x, h->width);
    r = ref_wrap(mode, r, h->height);
    return h->data[(size_t)r * h->width + x];
}

static void ref_normal(const lx_image *h, double s, lx_normal_filter f, lx_wrap mode, bool down,
                       int x, int r, double n[3])
{
    /* weights across the derivative: the row (column) above, here, below */
    double w[3] = {0, 1, 0};
    if (f == LX_NORMAL_SOBEL)
        w[0] = 1, w[1] = 2, w[2] = 1;
    if (f == LX_NORMAL_SCHARR)
        w[0] = 3, w[1] = 10, w[2] = 3;
    double sum = w[0] + w[1] + w[2];
    double dx = 0, dy = 0;
    for (int k = -1; k <= 1; k++) {
        dx += w[k + 1] * (H(h, mode, x + 1, r + k) - H(h, mode, x - 1, r + k));
        dy += w[k + 1] * (H(h, mode, x + k, r - 1) - H(h, mode, x + k, r + 1)); /* up */
    }
    dx /= 2 * sum;
    dy /= 2 * sum;
    double v[3] = {-s * dx, (down ? 1 : -1) * s * dy, 1};
    double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        n[k] = v[k] / len;
}

static lx_image make_height(int w, int h)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, w, h, 1), LX_OK);
    return img;
}

static lx_image normals_of(const lx_image *h, const lx_normalmap_desc *d)
{
    lx_image out;
    lx_status s = lx_normal_map(h, d, &out);
    if (s != LX_OK)
        fail_msg("lx_normal_map: %s", lx_last_error());
    assert_int_equal(out.width, h->width);
    assert_int_equal(out.height, h->height);
    assert_int_equal(out.channels, 3);
    return out;
}

static double max_error_vs_reference(const lx_image *h, const lx_normalmap_desc *d)
{
    lx_image n = normals_of(h, d);
    lx_normalmap_desc f = lx_normalmap_desc_defaults(d);
    double worst = 0;
    for (int r = 0; r < h->height; r++)
        for (int x = 0; x < h->width; x++) {
            double want[3];
            ref_normal(h, f.strength, f.filter, f.wrap, f.green_down, x, r, want);
            for (int k = 0; k < 3; k++) {
                double e = fabs(n.data[((size_t)r * h->width + x) * 3 + k] - want[k]);
                worst = e > worst ? e : worst;
            }
        }
    lx_image_free(&n);
    return worst;
}

/* Random heights; every size from 1x1 up, every filter, wrap, green. The
 * float results agree with the double reference to float rounding
 * (measured: 2.2e-7). */
static void matches_brute_force(void **state)
{
    (void)state;
    static const int sizes[][2] = {{1, 1}, {1, 4}, {4, 1}, {2, 3}, {3, 2}, {7, 5}, {33, 70}};
    uint32_t seed = 12345;
    double worst = 0;
    for (size_t z = 0; z < sizeof sizes / sizeof sizes[0]; z++) {
        lx_image h = make_height(sizes[z][0], sizes[z][1]);
        for (int i = 0; i < h.width * h.height; i++) {
            seed = seed * 1664525u + 1013904223u;
            h.data[i] = (float)(seed >> 8) / 16777216.0f;
        }
        for (int f = 0; f < 3; f++)
            for (int w = 0; w < 3; w++)
                for (int down = 0; down < 2; down++) {
                    lx_normalmap_desc d = {.strength = 5.0f,
                                           .filter = (lx_normal_filter)f,
                                           .wrap = (lx_wrap)w,
                                           .green_down = down};
                    double e = max_error_vs_reference(&h, &d);
                    worst = fmax(worst, e);
                    if (e > 5e-7)
                        fail_msg("%dx%d %s %s green %s: error %g", h.width, h.height,
                                 lx_normal_filter_name(d.filter), lx_wrap_name(d.wrap),
                                 down ? "down" : "up", e);
                }
        lx_image_free(&h);
    }
    print_message("largest component error against the reference: %.3g\n", worst);
}

/* ---- closed forms ----------------------------------------------------------- */

static void assert_normal(const lx_image *n, int x, int r, double nx, double ny, double nz,
                          double tol)
{
    double len = sqrt(nx * nx + ny * ny + nz * nz);
    const float *p = n->data + ((size_t)r * n->width + x) * 3;
    double want[3] = {nx / len, ny / len, nz / len};
    for (int k = 0; k < 3; k++)
        if (fabs(p[k] - want[k]) > tol)
            fail_msg("texel (%d, %d): (%g, %g, %g), want (%g, %g, %g)", x, r, p[0], p[1], p[2],
                     want[0], want[1], want[2]);
}

/* h = a x + b y, y up the image (y = H - 1 - row): every filter gives the
 * normal (-S a, -S b, 1) inside; at the left and right columns the slope
 * along x is a/2 for clamp and mirror (the edge texel repeated) and
 * a (2 - W)/2 for repeat (the far edge wraps around). */
static void plane(void **state)
{
    (void)state;
    int W = 20, Hh = 13;
    double a = 1.0 / 64, b = -3.0 / 256, S = 6;
    lx_image h = make_height(W, Hh);
    for (int r = 0; r < Hh; r++)
        for (int x = 0; x < W; x++)
            h.data[r * W + x] = (float)(0.5 + a * x + b * (Hh - 1 - r));
    for (int f = 0; f < 3; f++)
        for (int w = 0; w < 3; w++) {
            lx_normalmap_desc d = {
                .strength = (float)S, .filter = (lx_normal_filter)f, .wrap = (lx_wrap)w};
            lx_image n = normals_of(&h, &d);
            for (int r = 1; r < Hh - 1; r++)
                for (int x = 1; x < W - 1; x++)
                    assert_normal(&n, x, r, -S * a, -S * b, 1, 2e-7);
            if (f == LX_NORMAL_CENTRAL) {
                double edge = w == LX_WRAP_REPEAT ? a * (2 - W) / 2 : a / 2;
                double edge_y = w == LX_WRAP_REPEAT ? b * (2 - Hh) / 2 : b / 2;
                for (int r = 1; r < Hh - 1; r++) {
                    assert_normal(&n, 0, r, -S * edge, -S * b, 1, 2e-7);
                    assert_normal(&n, W - 1, r, -S * edge, -S * b, 1, 2e-7);
                }
                for (int x = 1; x < W - 1; x++) {
                    assert_normal(&n, x, 0, -S * a, -S * edge_y, 1, 2e-7);
                    assert_normal(&n, x, Hh - 1, -S * a, -S * edge_y, 1, 2e-7);
                }
            }
            lx_image_free(&n);
        }
    lx_image_free(&h);
}

/* h = 0.5 + A sin(kx x) sin(ky r), kx = 2 pi 3 / 90, ky = 2 pi 2 / 54 (rows
 * r down the image), repeat: periodic, so every texel, borders included,
 * has the closed form. With y = -r up: dh/dx = A kx cos(kx x) sin(ky r)
 * and dh/dy = -A ky sin(kx x) cos(ky r); central differences multiply each
 * by sin(k)/k of its direction, and Sobel/Scharr multiply each by the
 * smoothing factor of the other direction. */
static void sinusoid(void **state)
{
    (void)state;
    int W = 90, Hh = 54;
    double A = 0.3, kx = 2 * M_PI * 3 / W, ky = 2 * M_PI * 2 / Hh, S = 10;
    lx_image h = make_height(W, Hh);
    for (int r = 0; r < Hh; r++)
        for (int x = 0; x < W; x++)
            h.data[r * W + x] = (float)(0.5 + A * sin(kx * x) * sin(ky * r));
    for (int f = 0; f < 3; f++) {
        double sx = 1, sy = 1; /* smoothing across: of x-variation (in dy), of y (in dx) */
        if (f == LX_NORMAL_SOBEL)
            sx = (2 + 2 * cos(kx)) / 4, sy = (2 + 2 * cos(ky)) / 4;
        if (f == LX_NORMAL_SCHARR)
            sx = (10 + 6 * cos(kx)) / 16, sy = (10 + 6 * cos(ky)) / 16;
        lx_normalmap_desc d = {.strength = (float)S, .filter = (lx_normal_filter)f};
        lx_image n = normals_of(&h, &d);
        for (int r = 0; r < Hh; r++)
            for (int x = 0; x < W; x++) {
                double dx = A * kx * cos(kx * x) * sin(ky * r) * (sin(kx) / kx) * sy;
                double dy = -A * ky * sin(kx * x) * cos(ky * r) * (sin(ky) / ky) * sx;
                assert_normal(&n, x, r, -S * dx, -S * dy, 1, 1e-6);
            }
        lx_image_free(&n);
    }
    lx_image_free(&h);
}

/* A step from 0 to 1 between columns 15 and 16 of a 31-wide image, clamp:
 * central differences tilt exactly columns 15 and 16, by (h[x+1] - h[x-1])
 * / 2 = 1/2, i.e. n = normalize(-S/2, 0, 1), pointing toward the low side
 * (-x); every other texel is flat. The tilted pair straddles the edge:
 * texel x of the map is height texel x, no shift. */
static void step(void **state)
{
    (void)state;
    int W = 31, Hh = 9, edge = 16;
    double S = 4;
    lx_image h = make_height(W, Hh);
    for (int r = 0; r < Hh; r++)
        for (int x = 0; x < W; x++)
            h.data[r * W + x] = x >= edge ? 1.0f : 0.0f;
    for (int f = 0; f < 3; f++) {
        lx_normalmap_desc d = {
            .strength = (float)S, .filter = (lx_normal_filter)f, .wrap = LX_WRAP_CLAMP};
        lx_image n = normals_of(&h, &d);
        for (int r = 0; r < Hh; r++)
            for (int x = 0; x < W; x++) {
                bool tilted = x == edge - 1 || x == edge;
                assert_normal(&n, x, r, tilted ? -S / 2 : 0, 0, 1, 2e-7);
            }
        lx_image_free(&n);
    }
    lx_image_free(&h);
}

/* A cone of c value units per texel (S c texels of height per texel)
 * centred on texel (32, 32) of 65x65: away from the apex and the rim the
 * normal's horizontal part points away from the centre (x right, y up)
 * with |n_xy| / n_z = S c, to the central-difference error of c r: its
 * third derivative is at most c/r^2, so the slope errs by under c/(6 r^2)
 * per component, and the ratio by under S c/(2 r^2) (measured: half
 * of it). Green down flips the y part. */
static void cone(void **state)
{
    (void)state;
    int N = 65, cx = 32, cy = 32;
    double R = 30, c = 1.0 / 40, S = 8;
    lx_image h = make_height(N, N);
    for (int r = 0; r < N; r++)
        for (int x = 0; x < N; x++) {
            double d = hypot(x - cx, r - cy);
            h.data[r * N + x] = (float)(d < R ? c * (R - d) : 0.0);
        }
    for (int down = 0; down < 2; down++) {
        lx_normalmap_desc d = {.strength = (float)S, .green_down = down};
        lx_image n = normals_of(&h, &d);
        int checked = 0;
        double used = 0; /* the largest error as a share of its bound */
        for (int r = 0; r < N; r++)
            for (int x = 0; x < N; x++) {
                double ex = x - cx, ey = cy - r; /* y up */
                double dist = hypot(ex, ey);
                if (dist < 4 || dist > R - 2)
                    continue;
                const float *p = n.data + ((size_t)r * N + x) * 3;
                double ny = down ? -p[1] : p[1];
                double ratio = hypot(p[0], ny) / p[2];
                double tol = S * c / (2 * dist * dist) + 1e-6;
                if (fabs(ratio - S * c) > tol)
                    fail_msg("(%d, %d): slope %g, want %g +- %g", x, r, ratio, S * c, tol);
                used = fmax(used, fabs(ratio - S * c) / tol);
                /* outward: the horizontal part along (ex, ey) */
                double along = (p[0] * ex + ny * ey) / (dist * hypot(p[0], ny));
                assert_true(along > 0.999);
                checked++;
            }
        assert_true(checked > 2000);
        if (!down)
            print_message("cone: largest slope error %.2f of its bound\n", used);
        lx_image_free(&n);
    }
    lx_image_free(&h);
}

/* ---- precision of the encoded files --------------------------------------------- */

static double angle_degrees(const float *a, const double *b)
{
    double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double la = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
    double c = dot / la;
    c = c > 1 ? 1 : c;
    return acos(c) * 180 / M_PI;
}

/* Worst angle between the sinusoid's normals (the double reference) and
 * those written as a `bits`-bit PNG with linear codes, read back and
 * decoded. */
static double png_angle_error(int bits)
{
    int W = 96, Hh = 80;
    lx_image h = make_height(W, Hh);
    for (int r = 0; r < Hh; r++)
        for (int x = 0; x < W; x++)
            h.data[r * W + x] =
                (float)(0.5 + 0.4 * sin(2 * M_PI * 5 * x / W) * cos(2 * M_PI * 3 * r / Hh));
    lx_normalmap_desc d = {.strength = 4};
    lx_image n = normals_of(&h, &d), enc, back, dec;
    assert_int_equal(lx_normal_encode(&n, &enc), LX_OK);
    char path[4096];
    snprintf(path, sizeof path, "%s/n%d.png", lx_test_dir("normalmap_bits"), bits);
    lx_image_write_desc wd = {.linear = true, .bits = bits};
    assert_int_equal(lx_image_write(path, &enc, &wd), LX_OK);
    lx_image_load_desc ld = {.raw_8bit = true};
    assert_int_equal(lx_image_load(path, &ld, &back), LX_OK);
    assert_int_equal(lx_normal_decode(&back, path, &dec), LX_OK);
    double worst = 0;
    for (int r = 0; r < Hh; r++)
        for (int x = 0; x < W; x++) {
            double want[3];
            ref_normal(&h, 4, LX_NORMAL_CENTRAL, LX_WRAP_REPEAT, false, x, r, want);
            worst = fmax(worst, angle_degrees(dec.data + ((size_t)r * W + x) * 3, want));
        }
    lx_image_free(&h);
    lx_image_free(&n);
    lx_image_free(&enc);
    lx_image_free(&back);
    lx_image_free(&dec);
    return worst;
}

/* One code step is 2/65535 of a component (8 bits: 2/255); rounding to
 * the nearest errs by half a step per component, about 0.0025 degrees
 * (8 bits: 0.3-0.4). Measured: 16 bits 0.0014, 8 bits 0.34. */
static void sixteen_bit_precision(void **state)
{
    (void)state;
    double e16 = png_angle_error(16), e8 = png_angle_error(8);
    print_message("angle error: 16-bit %.4f deg, 8-bit %.3f deg\n", e16, e8);
    assert_true(e16 < 0.005);
    assert_true(e8 > 0.1 && e8 < 0.5);
}

/* rgb = n/2 + 1/2 exactly (float halving is exact; the sum rounds once) */
static void encoding(void **state)
{
    (void)state;
    lx_image n;
    assert_int_equal(lx_image_alloc(&n, 2, 1, 3), LX_OK);
    float v[6] = {0, 0, 1, -0.6f, 0.8f, 0};
    memcpy(n.data, v, sizeof v);
    lx_image e, d;
    assert_int_equal(lx_normal_encode(&n, &e), LX_OK);
    for (int i = 0; i < 6; i++)
        assert_float_equal(e.data[i], (v[i] + 1) / 2, 1e-7);
    assert_int_equal(lx_normal_decode(&e, "x.png", &d), LX_OK);
    for (int i = 0; i < 6; i++)
        assert_float_equal(d.data[i], v[i], 1e-6);
    lx_image_free(&d);
    /* (0.5, 0.5, 0.5) is no direction: the pixel is named */
    e.data[3] = e.data[4] = e.data[5] = 0.5f;
    assert_int_equal(lx_normal_decode(&e, "x.png", &d), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "x.png: pixel (1, 0)"));
    assert_null(d.data);
    lx_image grey;
    assert_int_equal(lx_image_alloc(&grey, 2, 2, 1), LX_OK);
    assert_int_equal(lx_normal_decode(&grey, "g.png", &d), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "g.png"));
    lx_image_free(&grey);
    lx_image_free(&e);
    lx_image_free(&n);
}

/* ---- threads, errors ----------------------------------------------------------- */

static void same_bits_any_threads(void **state)
{
    (void)state;
    int W = 301, Hh = 257;
    lx_image h = make_height(W, Hh);
    for (int i = 0; i < W * Hh; i++)
        h.data[i] = (float)(0.5 + 0.5 * sin(i * 0.37) * cos(i * 0.011));
    for (int f = 0; f < 3; f++) {
        lx_normalmap_desc d1 = {.filter = (lx_normal_filter)f, .threads = 1};
        lx_normalmap_desc d2 = {.filter = (lx_normal_filter)f, .threads = 2};
        lx_normalmap_desc d3 = {.filter = (lx_normal_filter)f, .threads = 3};
        lx_image a = normals_of(&h, &d1), b = normals_of(&h, &d2), c = normals_of(&h, &d3);
        assert_memory_equal(a.data, b.data, sizeof(float) * 3 * W * Hh);
        assert_memory_equal(a.data, c.data, sizeof(float) * 3 * W * Hh);
        lx_image_free(&a);
        lx_image_free(&b);
        lx_image_free(&c);
    }
    lx_image_free(&h);
}

static bool stop_at_once(void *user, float f)
{
    (void)f;
    (*(int *)user)++;
    return false;
}

static void bad_input(void **state)
{
    (void)state;
    lx_image h = make_height(8, 8), out;
    lx_normalmap_desc d = {.strength = -1};
    assert_int_equal(lx_normal_map(&h, &d, &out), LX_ERR_INVALID);
    assert_null(out.data);
    d.strength = NAN;
    assert_int_equal(lx_normal_map(&h, &d, &out), LX_ERR_INVALID);
    h.data[8 * 3 + 5] = NAN;
    assert_int_equal(lx_normal_map(&h, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "texel (5, 3) is NaN"));
    assert_null(out.data);
    h.data[8 * 3 + 5] = 0;
    int calls = 0;
    lx_normalmap_desc c = {.progress = stop_at_once, .progress_user = &calls};
    assert_int_equal(lx_normal_map(&h, &c, &out), LX_ERR_CANCELLED);
    assert_true(calls >= 1);
    assert_null(out.data);
    lx_image two;
    assert_int_equal(lx_image_alloc(&two, 4, 4, 2), LX_OK);
    assert_int_equal(lx_normal_map(&two, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "2 channels"));
    lx_image_free(&two);
    lx_image_free(&h);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(matches_brute_force), cmocka_unit_test(plane),
        cmocka_unit_test(sinusoid),            cmocka_unit_test(step),
        cmocka_unit_test(cone),                cmocka_unit_test(sixteen_bit_precision),
        cmocka_unit_test(encoding),            cmocka_unit_test(same_bits_any_threads),
        cmocka_unit_test(bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
