/* Colour temperature against independent values: the cubic-spline
 * approximation of the Planckian locus by Kim et al. (2002), a different
 * method from the library's Krystek approximation, plus the published CIE
 * illuminant A chromaticity (a black body at 2856 K). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "luxel/light.h"

#include <math.h>

/* Krystek's and Kim's approximations differ by up to 6.0e-4 in x (2856 K)
 * and 3.1e-4 in y (2700 K): */
#define LOCUS_X_TOL 1.5e-3
#define LOCUS_Y_TOL 1e-3

/* Kim, Kim, Lee, Kim, Kim: "Design of advanced color temperature control
 * system for HDTV applications", 2002 (1667 K .. 25000 K). */
static void kim_xy(double t, double *x, double *y)
{
    if (t <= 4000.0)
        *x = -0.2661239e9 / (t * t * t) - 0.2343589e6 / (t * t) + 0.8776956e3 / t + 0.179910;
    else
        *x = -3.0258469e9 / (t * t * t) + 2.1070379e6 / (t * t) + 0.2226347e3 / t + 0.240390;
    double u = *x;
    if (t <= 2222.0)
        *y = -1.1063814 * u * u * u - 1.34811020 * u * u + 2.18555832 * u - 0.20219683;
    else if (t <= 4000.0)
        *y = -0.9549476 * u * u * u - 1.37418593 * u * u + 2.09137015 * u - 0.16748867;
    else
        *y = 3.0817580 * u * u * u - 5.87338670 * u * u + 3.75112997 * u - 0.37001483;
}

static void locus_matches_independent_spline(void **state)
{
    (void)state;
    const float temps[] = {2000.0f, 2856.0f, 4000.0f, 6500.0f, 10000.0f};
    for (int i = 0; i < 5; i++) {
        float x, y;
        assert_int_equal(lx_temperature_to_xy(temps[i], &x, &y), LX_OK);
        double kx, ky;
        kim_xy(temps[i], &kx, &ky);
        assert_true(fabs(x - kx) < LOCUS_X_TOL);
        assert_true(fabs(y - ky) < LOCUS_Y_TOL);
    }
}

static void illuminant_a(void **state)
{
    (void)state;
    float x, y;
    assert_int_equal(lx_temperature_to_xy(2856.0f, &x, &y), LX_OK);
    /* Krystek's approximation: measured 9.8e-5 (x) and 3.2e-4 (y) off */
    assert_true(fabs(x - 0.44757) < 4e-4);
    assert_true(fabs(y - 0.40745) < 1e-3);
}

/* The RGB colour maps back to the locus chromaticity through the inverse
 * (RGB -> XYZ) sRGB matrix, and its largest channel is 1. */
static void rgb_round_trips_to_xy(void **state)
{
    (void)state;
    const float temps[] = {2000.0f, 2700.0f, 4000.0f, 6500.0f, 10000.0f};
    for (int i = 0; i < 5; i++) {
        lx_vec3 c;
        assert_int_equal(lx_temperature_to_rgb(temps[i], &c), LX_OK);
        assert_true(lx_max_component(c) == 1.0f); /* divided by itself */
        assert_true(c.x >= 0 && c.y >= 0 && c.z >= 0);
        double X = 0.4124564 * c.x + 0.3575761 * c.y + 0.1804375 * c.z;
        double Y = 0.2126729 * c.x + 0.7151522 * c.y + 0.0721750 * c.z;
        double Z = 0.0193339 * c.x + 0.1191920 * c.y + 0.9503041 * c.z;
        double kx, ky;
        kim_xy(temps[i], &kx, &ky);
        assert_true(fabs(X / (X + Y + Z) - kx) < LOCUS_X_TOL);
        assert_true(fabs(Y / (X + Y + Z) - ky) < LOCUS_Y_TOL);
        /* and exactly the chromaticity it came from, but for float
         * rounding: measured 5.6e-8 */
        float x, y;
        assert_int_equal(lx_temperature_to_xy(temps[i], &x, &y), LX_OK);
        assert_true(fabs(X / (X + Y + Z) - x) < 2e-7);
        assert_true(fabs(Y / (X + Y + Z) - y) < 2e-7);
    }
    /* warm light is red-heavy, cool light blue-heavy, 6500 K nearly white */
    lx_vec3 warm, cool, d65;
    lx_temperature_to_rgb(2700.0f, &warm);
    lx_temperature_to_rgb(10000.0f, &cool);
    lx_temperature_to_rgb(6500.0f, &d65);
    assert_true(warm.x == 1.0f && warm.z < warm.y);
    assert_true(cool.z == 1.0f && cool.x < cool.y);
    assert_true(d65.x > 0.9f && d65.y > 0.9f && d65.z > 0.9f);
}

static void out_of_range(void **state)
{
    (void)state;
    lx_vec3 c;
    float x, y;
    assert_int_equal(lx_temperature_to_rgb(500.0f, &c), LX_ERR_INVALID);
    assert_int_equal(lx_temperature_to_xy(NAN, &x, &y), LX_ERR_INVALID);
    assert_int_equal(lx_temperature_to_xy(1e6f, &x, &y), LX_ERR_INVALID);
}

static void srgb_colours(void **state)
{
    (void)state;
    /* IEC 61966-2-1: ((V + 0.055) / 1.055)^2.4 above the knee at 0.04045,
     * V / 12.92 below it; 0.5 encoded is 0.21404 linear. Floats: measured
     * 1.5e-8 relative, 0 at 1 and at the knee */
    lx_vec3 l = lx_srgb_color_to_linear(lx_v3(0.5f, 1.0f, 0.04045f));
    double half = pow((0.5 + 0.055) / 1.055, 2.4);
    assert_true(fabs(l.x - half) < 2e-7 * half);
    assert_true(fabs(half - 0.214041) < 1e-6); /* the published value, to its 6 digits */
    assert_true(l.y == 1.0f);
    assert_true(fabs(l.z - 0.04045 / 12.92) < 2e-7 * (0.04045 / 12.92));
}

/* Camera exposure: EV100 = log2(N^2/t * 100/S); "sunny 16" (f/16, 1/100 s,
 * ISO 100) is log2(25600) = 14.64; f/1.4 at 1 s, ISO 100 is log2(1.96). */
static void camera_ev100(void **state)
{
    (void)state;
    float ev;
    /* floats: an ulp at 14.6 is 9.5e-7 (measured 1.4e-7 off), at 0.97
     * 6e-8 (measured 2.8e-8) */
    assert_int_equal(lx_ev100_from_camera(16.0f, 0.01f, 100.0f, &ev), LX_OK);
    assert_true(fabs(ev - log2(25600.0)) < 1e-6);
    assert_int_equal(lx_ev100_from_camera(1.4f, 1.0f, 100.0f, &ev), LX_OK);
    assert_true(fabs(ev - log2(1.96)) < 2e-7);
    /* doubling ISO lowers EV100 by one stop (measured exactly) */
    float ev200;
    assert_int_equal(lx_ev100_from_camera(1.4f, 1.0f, 200.0f, &ev200), LX_OK);
    assert_true(fabs(ev - ev200 - 1.0) < 2e-7);
    double exposure = 1.0 / (1.2 * pow(2.0, ev));
    assert_true(fabs(lx_exposure_from_ev100(ev) - exposure) < 2e-7 * exposure);
    assert_int_equal(lx_ev100_from_camera(0.0f, 1.0f, 100.0f, &ev), LX_ERR_INVALID);
    assert_int_equal(lx_ev100_from_camera(2.0f, NAN, 100.0f, &ev), LX_ERR_INVALID);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(locus_matches_independent_spline),
        cmocka_unit_test(illuminant_a),
        cmocka_unit_test(rgb_round_trips_to_xy),
        cmocka_unit_test(out_of_range),
        cmocka_unit_test(srgb_colours),
        cmocka_unit_test(camera_ev100),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
