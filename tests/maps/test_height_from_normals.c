/* lx_height_from_normals against values from outside it:
 * - a sinusoid at a prime size (97 x 61, Bluestein transforms) with
 *   wrap repeat, normals from its exact derivatives: each Fourier mode of
 *   frequency w comes back scaled by (w/2) cot(w/2), derived here by hand
 *   (a step's mean slope is i w e^(iwx) (1 + e^iw)/2; its divergence
 *   w sin w e^(iwx) over the Laplacian's 4 sin^2(w/2)); and within the
 *   documented (pi f)^2 / 3 of the field itself;
 * - a paraboloid with clamp and mirror (Neumann edges): the mean of two
 *   neighbours' exact slopes is exactly a quadratic's step, so the
 *   heights come back exactly (to float rounding);
 * - round trips through lx_normal_map: at 24 x 20 with repeat against a
 *   naive 2-D DFT written here (the central-difference slopes i sin w
 *   over the Laplacian: each mode times (sin^2 wx + sin^2 wy) /
 *   (4 sin^2(wx/2) + 4 sin^2(wy/2))), and a Gaussian bump at 150 x 110
 *   with clamp, within a tolerance a small factor above the error
 *   measured (0.46% of the bump's height);
 * - the lowest height is 0, green down, the same bits for any thread
 *   count, cancelling, and bad input. */
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

/* Unit normals (3 channels) from slopes gx, gy (y up the image) given by
 * fn at texel (x, r), r the row from the top. */
typedef void (*slope_fn)(double x, double r, const void *ctx, double *gx, double *gy);

static lx_image normals_from(int w, int h, slope_fn fn, const void *ctx)
{
    lx_image n;
    assert_int_equal(lx_image_alloc(&n, w, h, 3), LX_OK);
    for (int r = 0; r < h; r++)
        for (int x = 0; x < w; x++) {
            double gx, gy;
            fn(x, r, ctx, &gx, &gy);
            double len = sqrt(gx * gx + gy * gy + 1.0);
            float *t = n.data + ((size_t)r * w + x) * 3;
            t[0] = (float)(-gx / len);
            t[1] = (float)(-gy / len);
            t[2] = (float)(1.0 / len);
        }
    return n;
}

static double mean(const double *v, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; i++)
        s += v[i];
    return s / (double)n;
}

/* Largest |got - want| after removing each one's mean. */
static double max_error(const lx_image *got, const double *want)
{
    size_t n = (size_t)got->width * got->height;
    double *g = malloc(sizeof *g * n);
    for (size_t i = 0; i < n; i++)
        g[i] = got->data[i];
    double mg = mean(g, n), mw = mean(want, n), e = 0.0;
    for (size_t i = 0; i < n; i++)
        e = fmax(e, fabs((g[i] - mg) - (want[i] - mw)));
    free(g);
    return e;
}

static float min_of(const lx_image *img)
{
    float lo = INFINITY;
    for (size_t i = 0; i < (size_t)img->width * img->height; i++)
        lo = fminf(lo, img->data[i]);
    return lo;
}

/* ---- a sinusoid, repeat --------------------------------------------------- */

typedef struct wave {
    int w, h;
    double a, b; /* amplitudes in texels */
    int p, q;    /* periods across the width and the height */
} wave;

/* h = a sin(2 pi p x / W + 0.3) + b cos(2 pi q r / H) */
static void wave_slopes(double x, double r, const void *ctx, double *gx, double *gy)
{
    const wave *s = ctx;
    double wx = 2 * M_PI * s->p / s->w, wy = 2 * M_PI * s->q / s->h;
    *gx = s->a * wx * cos(wx * x + 0.3);
    *gy = s->b * wy * sin(wy * r); /* up the image: -dh/dr */
}

static void sinusoid_repeat(void **state)
{
    (void)state;
    wave s = {97, 61, 3.0, 2.0, 4, 3};
    lx_image n = normals_from(s.w, s.h, wave_slopes, &s);
    lx_image got;
    assert_int_equal(lx_height_from_normals(&n, NULL, &got), LX_OK);
    assert_int_equal(got.width, s.w);
    assert_int_equal(got.height, s.h);
    assert_int_equal(got.channels, 1);
    assert_true(min_of(&got) == 0.0f);
    double wx = 2 * M_PI * s.p / s.w, wy = 2 * M_PI * s.q / s.h;
    double fx = (wx / 2) / tan(wx / 2), fy = (wy / 2) / tan(wy / 2);
    size_t count = (size_t)s.w * s.h;
    double *exact = malloc(sizeof *exact * count), *field = malloc(sizeof *field * count);
    for (int r = 0; r < s.h; r++)
        for (int x = 0; x < s.w; x++) {
            double hx = s.a * sin(wx * x + 0.3), hy = s.b * cos(wy * r);
            exact[(size_t)r * s.w + x] = fx * hx + fy * hy;
            field[(size_t)r * s.w + x] = hx + hy;
        }
    /* float normals: slopes to ~1e-7 relative; measured 4.8e-7 texels */
    double e = max_error(&got, exact);
    if (e > 2e-6)
        fail_msg("sinusoid: error %g texels against the closed form", e);
    /* the field itself: (pi f)^2 / 3 of each amplitude, f = p / W */
    double bound = s.a * (1 - fx) + s.b * (1 - fy);
    double ef = max_error(&got, field);
    assert_true(ef < bound * 1.01 + 2e-6);
    assert_true(1 - fx < pow(M_PI * s.p / s.w, 2) / 3 * 1.01);
    free(exact);
    free(field);
    lx_image_free(&got);
    lx_image_free(&n);
}

/* ---- a paraboloid, clamp and mirror ---------------------------------------- */

typedef struct bowl {
    double c, cx, cy;
} bowl;

/* h = c ((x - cx)^2 + (r - cy)^2) */
static void bowl_slopes(double x, double r, const void *ctx, double *gx, double *gy)
{
    const bowl *b = ctx;
    *gx = 2 * b->c * (x - b->cx);
    *gy = -2 * b->c * (r - b->cy);
}

static void paraboloid_neumann(void **state)
{
    (void)state;
    int w = 75, h = 50;
    bowl b = {0.004, 30.3, 21.7};
    lx_image n = normals_from(w, h, bowl_slopes, &b);
    double *want = malloc(sizeof *want * (size_t)w * h);
    double hi = 0.0;
    for (int r = 0; r < h; r++)
        for (int x = 0; x < w; x++) {
            want[(size_t)r * w + x] = b.c * ((x - b.cx) * (x - b.cx) + (r - b.cy) * (r - b.cy));
            hi = fmax(hi, want[(size_t)r * w + x]);
        }
    lx_wrap modes[] = {LX_WRAP_CLAMP, LX_WRAP_MIRROR};
    for (int m = 0; m < 2; m++) {
        lx_height_from_normals_desc d = {.wrap = modes[m]};
        lx_image got;
        assert_int_equal(lx_height_from_normals(&n, &d, &got), LX_OK);
        assert_true(min_of(&got) == 0.0f);
        /* exact but for float slopes and heights (measured 4.7e-7 texels
         * of 10.6) */
        double e = max_error(&got, want);
        if (e > 2e-6)
            fail_msg("%s: error %g texels (heights up to %g)", lx_wrap_name(modes[m]), e, hi);
        lx_image_free(&got);
    }
    free(want);
    lx_image_free(&n);
}

/* ---- round trips through lx_normal_map --------------------------------------- */

/* A smooth tiling field: a few random low-frequency modes. */
static double tiling(int x, int r, int w, int h)
{
    return 0.6 * sin(2 * M_PI * (2.0 * x / w + 1.0 * r / h) + 0.4) +
           0.3 * cos(2 * M_PI * (5.0 * x / w - 3.0 * r / h)) +
           0.2 * sin(2 * M_PI * (7.0 * x / w) + 1.0) * cos(2 * M_PI * 4.0 * r / h);
}

static void round_trip_dft(void **state)
{
    (void)state;
    int w = 24, h = 20;
    float S = 3.0f;
    lx_image height;
    assert_int_equal(lx_image_alloc(&height, w, h, 1), LX_OK);
    for (int r = 0; r < h; r++)
        for (int x = 0; x < w; x++)
            height.data[r * w + x] = (float)(0.5 + 0.4 * tiling(x, r, w, h));
    lx_normalmap_desc nd = {.strength = S};
    lx_image n, got;
    assert_int_equal(lx_normal_map(&height, &nd, &n), LX_OK);
    assert_int_equal(lx_height_from_normals(&n, NULL, &got), LX_OK);
    /* the expected heights by a naive DFT: H(k, l) = sum h e^{-2 pi i (kx/W + lr/H)},
     * each mode times its transfer factor, then back */
    size_t count = (size_t)w * h;
    double *re = calloc(count, sizeof *re), *im = calloc(count, sizeof *im);
    for (int l = 0; l < h; l++)
        for (int k = 0; k < w; k++) {
            double sr = 0, si = 0;
            for (int r = 0; r < h; r++)
                for (int x = 0; x < w; x++) {
                    double a = -2 * M_PI * ((double)k * x / w + (double)l * r / h);
                    sr += S * height.data[r * w + x] * cos(a);
                    si += S * height.data[r * w + x] * sin(a);
                }
            double wx = 2 * M_PI * k / w, wy = 2 * M_PI * l / h;
            double den = 4 * pow(sin(wx / 2), 2) + 4 * pow(sin(wy / 2), 2);
            /* the central difference of mode w is i sin w (rows: the sign
             * of y up and of the step down cancel) */
            double f = den > 0 ? (pow(sin(wx), 2) + pow(sin(wy), 2)) / den : 0.0;
            re[l * w + k] = sr * f;
            im[l * w + k] = si * f;
        }
    double *want = malloc(sizeof *want * count);
    for (int r = 0; r < h; r++)
        for (int x = 0; x < w; x++) {
            double s = 0;
            for (int l = 0; l < h; l++)
                for (int k = 0; k < w; k++) {
                    double a = 2 * M_PI * ((double)k * x / w + (double)l * r / h);
                    s += re[l * w + k] * cos(a) - im[l * w + k] * sin(a);
                }
            want[r * w + x] = s / (double)count;
        }
    double e = max_error(&got, want);
    /* measured 1e-7 texels */
    if (e > 5e-7)
        fail_msg("round trip against the DFT: error %g texels", e);
    free(re);
    free(im);
    free(want);
    lx_image_free(&height);
    lx_image_free(&n);
    lx_image_free(&got);
}

static void round_trip_bump(void **state)
{
    (void)state;
    int w = 150, h = 110;
    float S = 10.0f;
    double sigma = 9.0;
    lx_image height;
    assert_int_equal(lx_image_alloc(&height, w, h, 1), LX_OK);
    double *want = malloc(sizeof *want * (size_t)w * h);
    for (int r = 0; r < h; r++)
        for (int x = 0; x < w; x++) {
            double d2 = (x - 70.2) * (x - 70.2) + (r - 52.6) * (r - 52.6);
            height.data[r * w + x] = (float)exp(-d2 / (2 * sigma * sigma));
            want[(size_t)r * w + x] = S * (double)height.data[r * w + x];
        }
    lx_normalmap_desc nd = {.strength = S, .wrap = LX_WRAP_CLAMP};
    lx_image n, got;
    assert_int_equal(lx_normal_map(&height, &nd, &n), LX_OK);
    lx_height_from_normals_desc d = {.wrap = LX_WRAP_CLAMP};
    assert_int_equal(lx_height_from_normals(&n, &d, &got), LX_OK);
    /* measured 0.046 texels of a 10-texel bump: the central differences'
     * cos^2(w/2) loss on its fine detail */
    double e = max_error(&got, want);
    if (e > 0.08)
        fail_msg("bump round trip: error %g texels of %g", e, (double)S);
    free(want);
    lx_image_free(&height);
    lx_image_free(&n);
    lx_image_free(&got);
}

/* ---- conventions, determinism, bad input ------------------------------------ */

static void green_down_and_flat(void **state)
{
    (void)state;
    wave s = {40, 33, 2.0, 1.5, 2, 1};
    lx_image n = normals_from(s.w, s.h, wave_slopes, &s);
    lx_image up, down;
    assert_int_equal(lx_height_from_normals(&n, NULL, &up), LX_OK);
    for (size_t i = 0; i < (size_t)s.w * s.h; i++)
        n.data[3 * i + 1] = -n.data[3 * i + 1];
    lx_height_from_normals_desc d = {.green_down = true};
    assert_int_equal(lx_height_from_normals(&n, &d, &down), LX_OK);
    assert_memory_equal(up.data, down.data, sizeof(float) * (size_t)s.w * s.h);
    lx_image_free(&up);
    lx_image_free(&down);
    /* flat: all zero; a 1x1 map too */
    for (size_t i = 0; i < (size_t)s.w * s.h; i++) {
        n.data[3 * i] = n.data[3 * i + 1] = 0.0f;
        n.data[3 * i + 2] = 1.0f;
    }
    lx_wrap modes[] = {LX_WRAP_REPEAT, LX_WRAP_CLAMP, LX_WRAP_MIRROR};
    for (int m = 0; m < 3; m++) {
        d.wrap = modes[m];
        assert_int_equal(lx_height_from_normals(&n, &d, &up), LX_OK);
        for (size_t i = 0; i < (size_t)s.w * s.h; i++)
            assert_true(fabsf(up.data[i]) < 1e-6f);
        lx_image_free(&up);
        n.width = n.height = 1;
        assert_int_equal(lx_height_from_normals(&n, &d, &up), LX_OK);
        assert_true(up.data[0] == 0.0f);
        lx_image_free(&up);
        n.width = s.w;
        n.height = s.h;
    }
    lx_image_free(&n);
}

static void same_bits_any_threads(void **state)
{
    (void)state;
    wave s = {130, 77, 4.0, 1.0, 5, 2};
    lx_image n = normals_from(s.w, s.h, wave_slopes, &s);
    lx_wrap modes[] = {LX_WRAP_REPEAT, LX_WRAP_CLAMP};
    for (int m = 0; m < 2; m++) {
        lx_image a, b;
        lx_height_from_normals_desc d = {.wrap = modes[m], .threads = 1};
        assert_int_equal(lx_height_from_normals(&n, &d, &a), LX_OK);
        d.threads = 3;
        assert_int_equal(lx_height_from_normals(&n, &d, &b), LX_OK);
        assert_memory_equal(a.data, b.data, sizeof(float) * (size_t)s.w * s.h);
        lx_image_free(&a);
        lx_image_free(&b);
    }
    lx_image_free(&n);
}

static int calls;
static bool stop_second(void *user, float f)
{
    (void)user;
    assert_true(f >= 0.0f && f <= 1.0f);
    return ++calls < 2;
}

static void cancel_and_bad_input(void **state)
{
    (void)state;
    wave s = {32, 16, 1.0, 1.0, 1, 1};
    lx_image n = normals_from(s.w, s.h, wave_slopes, &s);
    lx_image out;
    lx_height_from_normals_desc d = {.progress = stop_second};
    calls = 0;
    assert_int_equal(lx_height_from_normals(&n, &d, &out), LX_ERR_CANCELLED);
    assert_null(out.data);

    assert_int_equal(lx_height_from_normals(NULL, NULL, &out), LX_ERR_INVALID);
    assert_null(out.data);
    assert_int_equal(lx_height_from_normals(&n, NULL, NULL), LX_ERR_INVALID);
    d = (lx_height_from_normals_desc){.wrap = (lx_wrap)7};
    assert_int_equal(lx_height_from_normals(&n, &d, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "wrap"));
    d = (lx_height_from_normals_desc){.threads = -1};
    assert_int_equal(lx_height_from_normals(&n, &d, &out), LX_ERR_INVALID);
    lx_image two = n;
    two.channels = 2;
    assert_int_equal(lx_height_from_normals(&two, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "2 channels"));
    n.data[3 * (5 * 32 + 7) + 2] = NAN;
    assert_int_equal(lx_height_from_normals(&n, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "texel (7, 5)"));
    assert_null(out.data);
    n.data[3 * (5 * 32 + 7) + 0] = n.data[3 * (5 * 32 + 7) + 1] = n.data[3 * (5 * 32 + 7) + 2] = 0;
    assert_int_equal(lx_height_from_normals(&n, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "texel (7, 5)"));
    lx_image_free(&n);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sinusoid_repeat),     cmocka_unit_test(paraboloid_neumann),
        cmocka_unit_test(round_trip_dft),      cmocka_unit_test(round_trip_bump),
        cmocka_unit_test(green_down_and_flat), cmocka_unit_test(same_bits_any_threads),
        cmocka_unit_test(cancel_and_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
