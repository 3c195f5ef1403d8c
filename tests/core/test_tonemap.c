/* Tone curves against their published formulas, evaluated here in double:
 * Hill's ACES fit (a rational function between two 3x3 matrices whose rows
 * sum to 1, so grey stays grey) and Hable's filmic curve (white point 11.2
 * maps to 1, black to 0). Every curve is monotonic and bounded by [0,1],
 * and an 8-bit PNG written through a curve holds the sRGB code of the
 * curve's value. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"
#include "luxel/core.h"

#include <math.h>
#include <stdio.h>

static double aces_fit(double v)
{
    return (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.4329510) + 0.238081);
}

static double hable(double x)
{
    const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

static double srgb_code(double linear)
{
    double c = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
    return floor(c * 255.0 + 0.5);
}

static void test_clamp(void **state)
{
    (void)state;
    assert_true(lx_tonemap_grey(LX_TONEMAP_CLAMP, 0.25f) == 0.25f);
    assert_true(lx_tonemap_grey(LX_TONEMAP_CLAMP, 7.0f) == 1.0f);
    assert_true(lx_tonemap_grey(LX_TONEMAP_CLAMP, -1.0f) == 0.0f);
}

/* float constants and arithmetic against double: a few ulps of 1 */
#define CURVE_TOL 2e-6

static void test_aces_grey(void **state)
{
    (void)state;
    const float grey[] = {0.0f, 0.01f, 0.18f, 0.5f, 1.0f, 4.0f, 16.0f};
    for (size_t i = 0; i < sizeof grey / sizeof grey[0]; i++) {
        double want = fmin(fmax(aces_fit(grey[i]), 0.0), 1.0);
        assert_true(fabs(lx_tonemap_grey(LX_TONEMAP_ACES, grey[i]) - want) < CURVE_TOL);
        float rgb[3] = {grey[i], grey[i], grey[i]};
        lx_tonemap_rgb(LX_TONEMAP_ACES, rgb);
        /* the third output row sums to 0.99999, not 1: 1e-5 of the value */
        for (int k = 0; k < 3; k++)
            assert_true(fabs(rgb[k] - want) < 1.2e-5 * want + CURVE_TOL);
    }
}

static void test_filmic(void **state)
{
    (void)state;
    assert_true(fabs(lx_tonemap_grey(LX_TONEMAP_FILMIC, 0.0f)) < CURVE_TOL);
    assert_true(fabs(lx_tonemap_grey(LX_TONEMAP_FILMIC, 5.6f) - 1.0) < CURVE_TOL);
    double want = hable(2.0 * 0.18) / hable(11.2);
    assert_true(fabs(lx_tonemap_grey(LX_TONEMAP_FILMIC, 0.18f) - want) < CURVE_TOL);
}

static void test_monotonic_bounded(void **state)
{
    (void)state;
    for (int c = LX_TONEMAP_CLAMP; c <= LX_TONEMAP_FILMIC; c++) {
        float last = -1.0f;
        for (int i = 0; i <= 4000; i++) {
            float v = lx_tonemap_grey((lx_tonemap)c, i * 0.01f);
            assert_true(v >= 0.0f && v <= 1.0f);
            assert_true(v >= last);
            last = v;
        }
        float rgb[3] = {1e6f, -3.0f, 0.5f};
        lx_tonemap_rgb((lx_tonemap)c, rgb);
        for (int k = 0; k < 3; k++)
            assert_true(rgb[k] >= 0.0f && rgb[k] <= 1.0f);
    }
}

static void test_names(void **state)
{
    (void)state;
    lx_tonemap t;
    for (int c = LX_TONEMAP_CLAMP; c <= LX_TONEMAP_FILMIC; c++) {
        assert_true(lx_tonemap_parse(lx_tonemap_name((lx_tonemap)c), &t));
        assert_int_equal(t, c);
    }
    assert_false(lx_tonemap_parse("reinhard", &t));
    assert_null(lx_tonemap_name((lx_tonemap)7));
}

static void test_png_through_curve(void **state)
{
    (void)state;
    float pixels[2 * 3] = {0.18f, 0.18f, 0.18f, 3.0f, 0.5f, 0.05f};
    lx_image img = {.width = 2, .height = 1, .channels = 3, .data = pixels};
    char path[512];
    snprintf(path, sizeof path, "%s/aces.png", lx_test_dir("tonemap"));
    lx_image_write_desc desc = {.tonemap = LX_TONEMAP_ACES, .exposure = 2.0f};
    assert_int_equal(lx_image_write(path, &img, &desc), LX_OK);
    lx_image back;
    lx_image_load_desc raw = {.raw_8bit = true};
    assert_int_equal(lx_image_load(path, &raw, &back), LX_OK);
    float rgb[3] = {3.0f * 2.0f, 0.5f * 2.0f, 0.05f * 2.0f};
    lx_tonemap_rgb(LX_TONEMAP_ACES, rgb); /* checked against the formula above */
    double want[6] = {srgb_code(fmin(aces_fit(0.36), 1.0)), 0, 0, srgb_code(rgb[0]),
                      srgb_code(rgb[1]), srgb_code(rgb[2])};
    want[1] = want[2] = want[0];
    for (int k = 0; k < 6; k++)
        assert_true(fabs(back.data[k] * 255.0 - want[k]) < 1.01);
    lx_image_free(&back);

    desc.tonemap = (lx_tonemap)9;
    assert_int_equal(lx_image_write(path, &img, &desc), LX_ERR_INVALID);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clamp),
        cmocka_unit_test(test_aces_grey),
        cmocka_unit_test(test_filmic),
        cmocka_unit_test(test_monotonic_bounded),
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_png_through_curve),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
