/* Beam and field angles (lx_ies_spread_angle, lx_ies_beam_field) against
 * closed forms: cos^n distributions (50% at acos(0.5^(1/n)) from the axis,
 * 10% at acos(0.1^(1/n))), linear ramps (exact: the profile is linear
 * between its angles), an asymmetric plane and the plane between two
 * others, a batwing, the step where the measured range ends, a beam
 * around the zenith (the plane's walk passes 180 degrees), planes that
 * never fall or are dark, a type B floodlight, and bad input. Files are
 * written here as LM-63-2002 text. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"

#define PI_D 3.14159265358979323846
#define RAD (PI_D / 180.0)
/* Where the profile is exactly linear between its angles the answer is
 * exact but for float candela: measured up to 2.3e-6 deg (the C90 plane,
 * interpolated halfway between two), 0 in most cases */
#define EXACT_TOL 1e-5

/* An LM-63-2002 file: vertical angles v[0..nv), horizontal h[0..nh), and
 * fn(v, h) candela, one plane after another. */
static char *ies_text(int type, const double *v, int nv, const double *h, int nh,
                      double (*fn)(double v, double h))
{
    size_t cap = 64 + (size_t)(nv + nh + nv * nh) * 24;
    char *t = malloc(cap);
    assert_non_null(t);
    int n = snprintf(t, cap,
                     "IESNA:LM-63-2002\n[TEST] spread\nTILT=NONE\n1 -1 1 %d %d %d 2 0 0 0\n1 1 0\n",
                     nv, nh, type);
    for (int i = 0; i < nv; i++)
        n += snprintf(t + n, cap - n, "%.6f ", v[i]);
    n += snprintf(t + n, cap - n, "\n");
    for (int j = 0; j < nh; j++)
        n += snprintf(t + n, cap - n, "%.6f ", h[j]);
    n += snprintf(t + n, cap - n, "\n");
    for (int j = 0; j < nh; j++) {
        for (int i = 0; i < nv; i++)
            n += snprintf(t + n, cap - n, "%.9g ", fn(v[i], h[j]));
        n += snprintf(t + n, cap - n, "\n");
    }
    assert_true((size_t)n < cap);
    return t;
}

static lx_ies_profile *profile(int type, const double *v, int nv, const double *h, int nh,
                               double (*fn)(double v, double h))
{
    char *t = ies_text(type, v, nv, h, nh, fn);
    lx_ies_profile *p = lx_test_parse_ies(t);
    free(t);
    return p;
}

/* Vertical angles from a to b in steps of `step` degrees. */
static int grid(double a, double b, double step, double *out)
{
    int n = (int)lround((b - a) / step) + 1;
    for (int i = 0; i < n; i++)
        out[i] = a + (b - a) * i / (n - 1);
    return n;
}

static double spread(const lx_ies_profile *p, float h, double fraction)
{
    double a = -2.0;
    assert_int_equal(lx_ies_spread_angle(p, h, fraction, &a), LX_OK);
    return a;
}

static void assert_angle(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol))
        fail_msg("%s: got %.9g deg, want %.9g (error %.3g > %g)", what, got, want, fabs(got - want),
                 tol);
}

/* ---- cos^n --------------------------------------------------------------- */

static int cos_power;
static double cos_fn(double v, double h)
{
    (void)h;
    double c = cos(v * RAD);
    return c > 0.0 ? 1000.0 * pow(c, cos_power) : 0.0;
}

/* How far the 0.5-degree chords of cos^n move its crossing of fraction:
 * a chord sags below the curve by at most step^2 / 8 max|f''| over the
 * interval, which shifts the crossing by that over |f'| (radians), for
 * each of the two sides. */
static double chord_shift(int n, double fraction, double step_deg)
{
    double t = acos(pow(fraction, 1.0 / n)), h = step_deg * RAD;
    double f1 = n * pow(cos(t), n - 1) * sin(t), f2 = 0.0;
    for (int i = -1; i <= 1; i++) { /* |f''| over the interval around t */
        double u = t + i * h, c = cos(u), s = sin(u);
        double d2 = n * (n - 1) * pow(c, n - 2) * s * s - n * pow(c, n);
        f2 = fmax(f2, fabs(d2));
    }
    return 2.0 * h * h / 8.0 * f2 / f1 / RAD;
}

static void test_cos_power(void **state)
{
    (void)state;
    static double v[181];
    const double h[1] = {0};
    int nv = grid(0, 90, 0.5, v);
    const int powers[] = {1, 2, 8, 30};
    double worst = 0.0;
    for (int k = 0; k < 4; k++) {
        cos_power = powers[k];
        lx_ies_profile *p = profile(1, v, nv, h, 1, cos_fn);
        double beam = 2.0 * acos(pow(0.5, 1.0 / cos_power)) / RAD;
        double field = 2.0 * acos(pow(0.1, 1.0 / cos_power)) / RAD;
        double b, f;
        assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
        /* twice the chords' largest shift: the errors measured are 0 to
         * 0.46 of that (1.1e-4 of 2.4e-4 deg for the cosine's field, 9.0e-3
         * of 2.1e-2 for cos^30's) */
        double sb = 2.0 * chord_shift(cos_power, 0.5, 0.5);
        double sf = 2.0 * chord_shift(cos_power, 0.1, 0.5);
        char what[64];
        snprintf(what, sizeof what, "cos^%d beam", cos_power);
        assert_angle(b, beam, sb, what);
        snprintf(what, sizeof what, "cos^%d field", cos_power);
        assert_angle(f, field, sf, what);
        worst = fmax(worst, fmax(fabs(b - beam), fabs(f - field)));
        /* rotationally symmetric: every plane the same */
        assert_angle(spread(p, 90.0f, 0.5), b, 0.0, "cos^n in C90");
        assert_angle(spread(p, 33.0f, 0.1), f, 0.0, "cos^n in C33");
        lx_ies_free(p);
    }
    print_message("cos^n: largest error %.3g deg\n", worst);
}

/* ---- linear ramps: exact ------------------------------------------------- */

/* 1000 cd at the nadir falling linearly to 0 at 60 deg (C0) and at 40 deg
 * (C180): C0-C180 crosses 50% at 30 and 20, 10% at 54 and 36; the C90
 * plane, halfway between the two, is their mean, 1000 (1 - v / 48) up to
 * 40 deg (50% at 24) and 500 (1 - v / 60) past it (10% at 48). */
static double ramp_fn(double v, double h)
{
    double zero = h < 90.0 ? 60.0 : 40.0;
    return v < zero ? 1000.0 * (1.0 - v / zero) : 0.0;
}

static void test_linear_ramps(void **state)
{
    (void)state;
    double v[10];
    const double h[2] = {0, 180};
    int nv = grid(0, 90, 10, v);
    lx_ies_profile *p = profile(1, v, nv, h, 2, ramp_fn);
    double b, f;
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
    assert_angle(b, 30 + 20, EXACT_TOL, "ramp beam C0-C180");
    assert_angle(f, 54 + 36, EXACT_TOL, "ramp field C0-C180");
    assert_int_equal(lx_ies_beam_field(p, 180.0f, &b, &f), LX_OK); /* the same plane */
    assert_angle(b, 50, EXACT_TOL, "ramp beam C180-C0");
    assert_int_equal(lx_ies_beam_field(p, 90.0f, &b, &f), LX_OK);
    assert_angle(b, 2 * 24, EXACT_TOL, "ramp beam C90-C270");
    assert_angle(f, 2 * 48, EXACT_TOL, "ramp field C90-C270");
    /* any fraction: 25% at 45 (C0) and 30 (C180) */
    assert_angle(spread(p, 0.0f, 0.25), 75, EXACT_TOL, "ramp at 25%");
    lx_ies_free(p);
}

/* ---- a batwing: the beam of one wing ------------------------------------- */

/* 1000 cd at 20 deg from the nadir, falling 50 cd a degree either side:
 * two wings (at +-20 in every plane), dark at the nadir. The walk starts
 * at the wing first in the plane (the maxima tie): 50% at 10 and 30. */
static double batwing_fn(double v, double h)
{
    (void)h;
    double f = 1000.0 - 50.0 * fabs(v - 20.0);
    return f > 0.0 ? f : 0.0;
}

static void test_batwing(void **state)
{
    (void)state;
    double v[91];
    const double h[1] = {0};
    int nv = grid(0, 90, 1, v);
    lx_ies_profile *p = profile(1, v, nv, h, 1, batwing_fn);
    double b, f;
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
    assert_angle(b, 20, EXACT_TOL, "batwing beam");
    assert_angle(f, 36, EXACT_TOL, "batwing field"); /* 10% at 2 and 38 */
    lx_ies_free(p);
}

/* ---- steps, the zenith, never, dark --------------------------------------- */

static double flat_fn(double v, double h)
{
    (void)v, (void)h;
    return 100.0;
}

static double zero_fn(double v, double h)
{
    (void)v, (void)h;
    return 0.0;
}

/* An uplight: dark to 120 deg, rising linearly to 1000 cd at the zenith.
 * 50% at 150 deg either side: the walk from the zenith passes 180. */
static double up_fn(double v, double h)
{
    (void)h;
    return v > 120.0 ? 1000.0 * (v - 120.0) / 60.0 : 0.0;
}

static void test_steps_zenith_never_dark(void **state)
{
    (void)state;
    double v[19];
    const double h[1] = {0};
    /* measured 0..90 only: a step to dark at 90 on both sides */
    int nv = grid(0, 90, 10, v);
    lx_ies_profile *p = profile(1, v, nv, h, 1, flat_fn);
    double b, f;
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
    assert_angle(b, 180, 0.0, "a hemisphere's beam");
    assert_angle(f, 180, 0.0, "a hemisphere's field");
    lx_ies_free(p);
    /* the whole sphere: it never falls */
    nv = grid(0, 180, 10, v);
    p = profile(1, v, nv, h, 1, flat_fn);
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
    assert_true(b == -1.0 && f == -1.0);
    lx_ies_free(p);
    /* dark */
    p = profile(1, v, nv, h, 1, zero_fn);
    assert_int_equal(lx_ies_beam_field(p, 90.0f, &b, &f), LX_OK);
    assert_true(b == -1.0 && f == -1.0);
    lx_ies_free(p);
    /* the uplight: 60 deg around the zenith, 10% at 126 deg: 108 */
    p = profile(1, v, nv, h, 1, up_fn);
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
    assert_angle(b, 60, EXACT_TOL, "uplight beam");
    assert_angle(f, 108, EXACT_TOL, "uplight field");
    lx_ies_free(p);
    /* measured 90..180 only: dark below, a step at 90 */
    nv = grid(90, 180, 10, v);
    p = profile(1, v, nv, h, 1, up_fn);
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
    assert_angle(b, 60, EXACT_TOL, "uplight 90-180 beam");
    lx_ies_free(p);
}

/* ---- type B: the floodlight -------------------------------------------------- */

/* Flat to 20 deg, zero from 40 in V; flat to 10, zero from 20 in H (the
 * trapezoids of test_ies_types.c): C0-C180 holds V, 50% at 30; C90-C270
 * holds H, 50% at 15; 10% at 38 and 19. */
static double trap(double a, double flat, double zero)
{
    a = fabs(a);
    return a <= flat ? 1.0 : (a >= zero ? 0.0 : (zero - a) / (zero - flat));
}

static double flood_fn(double v, double h)
{
    return 1000.0 * trap(v, 20, 40) * trap(h, 10, 20);
}

static void test_type_b_flood(void **state)
{
    (void)state;
    const double v[] = {-90, -40, -20, 0, 20, 40, 90};
    const double h[] = {0, 10, 20, 90};
    lx_ies_profile *p = profile(2, v, 7, h, 4, flood_fn);
    double b, f;
    /* resampled to a type C grid (docs/ies.md): measured 0 */
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &b, &f), LX_OK);
    assert_angle(b, 60, EXACT_TOL, "flood beam C0-C180");
    assert_angle(f, 76, EXACT_TOL, "flood field C0-C180");
    assert_int_equal(lx_ies_beam_field(p, 90.0f, &b, &f), LX_OK);
    assert_angle(b, 30, EXACT_TOL, "flood beam C90-C270");
    assert_angle(f, 38, EXACT_TOL, "flood field C90-C270");
    lx_ies_free(p);
}

/* ---- bad input ------------------------------------------------------------------ */

static void test_bad_input(void **state)
{
    (void)state;
    double v[10];
    const double h[1] = {0};
    int nv = grid(0, 90, 10, v);
    lx_ies_profile *p = profile(1, v, nv, h, 1, flat_fn);
    double a = 7.0, b = 7.0;
    assert_int_equal(lx_ies_spread_angle(NULL, 0.0f, 0.5, &a), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "NULL profile"));
    assert_int_equal(lx_ies_spread_angle(p, 0.0f, 0.5, NULL), LX_ERR_INVALID);
    assert_int_equal(lx_ies_spread_angle(p, NAN, 0.5, &a), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "not finite"));
    const double bad[] = {0.0, 1.0, -0.5, 2.0, NAN};
    for (int i = 0; i < 5; i++) {
        assert_int_equal(lx_ies_spread_angle(p, 0.0f, bad[i], &a), LX_ERR_INVALID);
        assert_non_null(strstr(lx_last_error(), "is not between 0 and 1"));
    }
    assert_true(a == 7.0);
    assert_int_equal(lx_ies_beam_field(p, 0.0f, &a, NULL), LX_ERR_INVALID);
    assert_int_equal(lx_ies_beam_field(p, INFINITY, &a, &b), LX_ERR_INVALID);
    assert_true(a == 7.0 && b == 7.0);
    lx_ies_free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cos_power),    cmocka_unit_test(test_linear_ramps),
        cmocka_unit_test(test_batwing),      cmocka_unit_test(test_steps_zenith_never_dark),
        cmocka_unit_test(test_type_b_flood), cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
