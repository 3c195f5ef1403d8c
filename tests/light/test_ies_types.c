/* Tests of IES photometric types B (2) and A (3) in the IES reader
 * (src/light/ies.c), which resamples them onto a type C grid when loading.
 * Expected values come from closed forms, never from the reader itself:
 *
 * - the axis convention of docs/ies.md, worked out here on its own: a type
 *   C direction (gamma, C) has components x = sin g cos C (toward C0),
 *   y = sin g sin C (toward C90), z = cos g (the nadir, the A/B beam axis);
 *   type B reads H = asin y, V = atan2(x, z); type A V = asin x,
 *   H = atan2(y, z). Tables linear in V and H are interpolated exactly by
 *   the file's bilinear interpolation, so the reader's value at a direction
 *   must be the linear function of the angles computed here;
 * - 100 cos V cos H is 100 z = 100 cos(gamma) in both types (a Lambertian
 *   emitter facing the beam axis): flux 100 pi;
 * - a uniform file covers the half space z >= 0 (2 pi I); one measured on
 *   one side of the beam axis only, a quarter of the sphere (pi I);
 * - a floodlight table a(V) b(H) of trapezoids (flat to 20 / 10 degrees,
 *   zero at 40 / 20) has flux I0 * int a dV * int b cos H dH in type B
 *   (H is the latitude there, dOmega = cos H dH dV) and
 *   I0 * int b dH * int a cos V dV in type A;
 * - a half-range file (0..90) equals the file with the mirrored half
 *   written out;
 * - malformed angles fail with LX_ERR_FORMAT naming the file and the line.
 */
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
#include "luxel/light.h"

#define PI_D 3.14159265358979323846
#define RAD (PI_D / 180.0)

/* Parsing fails with LX_ERR_FORMAT and a message holding every needle. */
static void parse_fails(const char *text, const char *n1, const char *n2)
{
    lx_ies_profile *p = (lx_ies_profile *)1;
    lx_status st = lx_ies_parse(text, strlen(text), "x.ies", &p);
    if (st != LX_ERR_FORMAT)
        fail_msg("status %s, want LX_ERR_FORMAT (message: %s)", lx_status_name(st),
                 lx_last_error());
    assert_null(p);
    const char *msg = lx_last_error();
    if (strncmp(msg, "x.ies: ", 7) != 0)
        fail_msg("message '%s' does not start with the file name", msg);
    if (n1 && !strstr(msg, n1))
        fail_msg("message '%s' does not contain '%s'", msg, n1);
    if (n2 && !strstr(msg, n2))
        fail_msg("message '%s' does not contain '%s'", msg, n2);
}

static void assert_cd(const lx_ies_profile *p, double g, double c, double want, double tol)
{
    double got = lx_ies_candela(p, (float)g, (float)c);
    if (!(fabs(got - want) <= tol))
        fail_msg("candela at (%g, %g): got %.7g, want %.7g (+-%g)", g, c, got, want, tol);
}

/* ---- the axis convention, on its own ---------------------------------------- */

/* The file angles (degrees) of type C direction (g, c) for type 2 (B) or 3
 * (A), from the closed forms above. */
static void ab_angles(int type, double g, double c, double *v, double *h)
{
    double x = sin(g * RAD) * cos(c * RAD), y = sin(g * RAD) * sin(c * RAD), z = cos(g * RAD);
    if (type == 2) {
        *h = asin(y) / RAD;
        *v = atan2(x, z) / RAD;
    } else {
        *v = asin(x) / RAD;
        *h = atan2(y, z) / RAD;
    }
}

/* ---- writing A/B files ----------------------------------------------------------- */

typedef double (*table_fn)(double v, double h);

/* An LM-63-2002 file of photometric type `type` whose candela values are
 * f(V, H) at the given angles; free() the result. */
static char *ab_file(int type, const double *va, int nv, const double *ha, int nh, table_fn f)
{
    size_t cap = 256 + (size_t)(nv + nh) * 16 + (size_t)nv * (size_t)nh * 16;
    char *t = malloc(cap);
    assert_non_null(t);
    size_t n = (size_t)snprintf(t, cap, "IESNA:LM-63-2002\n[TEST] type %c\nTILT=NONE\n",
                                type == 2 ? 'B' : 'A');
    n += (size_t)snprintf(t + n, cap - n, "1 -1 1 %d %d %d 2 0 0 0\n1 1 100\n", nv, nh, type);
    for (int i = 0; i < nv; i++)
        n += (size_t)snprintf(t + n, cap - n, "%.9g%s", va[i], i + 1 < nv ? " " : "\n");
    for (int j = 0; j < nh; j++)
        n += (size_t)snprintf(t + n, cap - n, "%.9g%s", ha[j], j + 1 < nh ? " " : "\n");
    for (int j = 0; j < nh; j++)
        for (int i = 0; i < nv; i++)
            n += (size_t)snprintf(t + n, cap - n, "%.9g%s", f(va[i], ha[j]),
                                  i + 1 < nv ? " " : "\n");
    assert_true(n < cap);
    return t;
}

/* lo, lo + step, ..., hi into a (at most 512); returns the count. */
static int steps(double *a, double lo, double hi, double step)
{
    int n = (int)lround((hi - lo) / step) + 1;
    assert_true(n <= 512);
    for (int i = 0; i < n; i++)
        a[i] = lo + i * step;
    return n;
}

static lx_ies_profile *ab_profile(int type, double vlo, double vhi, double hlo, double hhi,
                                  double step, table_fn f)
{
    double va[512], ha[512];
    int nv = steps(va, vlo, vhi, step), nh = steps(ha, hlo, hhi, step);
    char *text = ab_file(type, va, nv, ha, nh, f);
    lx_ies_profile *p = lx_test_parse_ies(text);
    free(text);
    return p;
}

static double linear_fn(double v, double h)
{
    return 200.0 + v + 0.5 * h;
}

static double cosine_fn(double v, double h)
{
    return 100.0 * cos(v * RAD) * cos(h * RAD);
}

static double uniform_fn(double v, double h)
{
    return 40.0;
}

/* trapezoids: 1 to 20 (V) / 10 (H) degrees, 0 from 40 / 20 */
static double trap(double a, double flat, double zero)
{
    a = fabs(a);
    return a <= flat ? 1.0 : (a >= zero ? 0.0 : (zero - a) / (zero - flat));
}

static double flood_fn(double v, double h)
{
    return 1000.0 * trap(v, 20, 40) * trap(h, 10, 20);
}

/* an uneven table, to compare half-range files with their mirror images;
 * 50 at V = +-90 and at H = +-90, as the poles of both types must be (every
 * angle on the other axis names the same direction there) */
static double uneven_fn(double v, double h)
{
    double s = sin(h * RAD);
    return 50.0 + (30.0 + 20.0 * s * s + 0.1 * fabs(v)) * cos(v * RAD) * cos(h * RAD);
}

/* ---- the axis convention: types B and A --------------------------------------------- */

/* Directions across the half space, on and off the resampling grid, away
 * from the A/B pole (where the file's own angles change fastest). */
static const double dirs[][2] = {
    {0, 0},      {0, 123},       {30, 0},      {30, 90},      {30, 180}, {30, 270},
    {60, 45},    {45, 135},      {37.3, 61.7}, {52.9, 222.2}, {75, 300}, {80, 10},
    {88.6, 135}, {12.25, 333.3}, {89.5, 0},    {20, 359.6},
};

static void check_linear(int type)
{
    lx_ies_profile *p = ab_profile(type, -90, 90, -90, 90, 10, linear_fn);
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    assert_int_equal(info.photometric_type, type);
    assert_int_equal(info.symmetry, LX_IES_FULL);
    for (size_t k = 0; k < sizeof dirs / sizeof dirs[0]; k++) {
        double v, h;
        ab_angles(type, dirs[k][0], dirs[k][1], &v, &h);
        /* resampled to type C on a grid: measured 2.2e-3 */
        assert_cd(p, dirs[k][0], dirs[k][1], linear_fn(v, h), 8e-3);
    }
    /* the principal planes read the same in both types: C0 is vertical
     * angle = gamma, C90 horizontal angle = gamma */
    /* exactly on the grid: measured 0; a float's rounding at 230 is 1e-5 */
    assert_cd(p, 30, 0, 230, 5e-5);
    assert_cd(p, 30, 180, 170, 5e-5);
    assert_cd(p, 30, 90, 215, 5e-5);
    assert_cd(p, 30, 270, 185, 5e-5);
    /* behind the beam axis nothing was measured: dark */
    assert_cd(p, 90.5, 0, 0, 0);
    assert_cd(p, 120, 45, 0, 0);
    assert_cd(p, 180, 0, 0, 0);
    lx_test_assert_rel(lx_ies_peak_candela(p), 200 + 90 + 45, 0);
    lx_ies_free(p);
}

static void test_type_b_axes(void **state)
{
    check_linear(2);
    /* off the principal planes the types differ: at (60, 45), worked by
     * hand, x = y = sin 60 cos 45 = 0.612372, z = 0.5; B: H = asin x =
     * 37.761 deg, V = atan(x / z) = 50.768 deg */
    lx_ies_profile *p = ab_profile(2, -90, 90, -90, 90, 10, linear_fn);
    assert_cd(p, 60, 45, 200 + 50.768 + 0.5 * 37.761, 2e-3); /* measured 6.1e-4 */
    lx_ies_free(p);
}

static void test_type_a_axes(void **state)
{
    check_linear(3);
    /* A swaps them: V = 37.761, H = 50.768 */
    lx_ies_profile *p = ab_profile(3, -90, 90, -90, 90, 10, linear_fn);
    assert_cd(p, 60, 45, 200 + 37.761 + 0.5 * 50.768, 2e-3); /* measured 4.8e-4 */
    lx_ies_free(p);
}

/* ---- a Lambertian emitter facing the beam axis ------------------------------------- */

static void test_cosine(void **state)
{
    for (int type = 2; type <= 3; type++) {
        lx_ies_profile *p = ab_profile(type, -90, 90, -90, 90, 1, cosine_fn);
        for (size_t k = 0; k < sizeof dirs / sizeof dirs[0]; k++)
            assert_cd(p, dirs[k][0], dirs[k][1], 100 * cos(dirs[k][0] * RAD),
                      0.02); /* sampled each degree, resampled: measured 8.9e-3 */
        lx_test_assert_rel(lx_ies_total_lumens(p), 100 * PI_D, 3e-4); /* measured 7.4e-5 */
        lx_ies_free(p);
    }
}

/* ---- total lumens -------------------------------------------------------------------- */

static void test_lumens_uniform(void **state)
{
    for (int type = 2; type <= 3; type++) {
        /* the whole measured half space: 2 pi I */
        lx_ies_profile *p = ab_profile(type, -90, 90, -90, 90, 15, uniform_fn);
        /* the midpoint rule's (pi/1800)^2 / 24: measured 1.3e-7 */
        lx_test_assert_rel(lx_ies_total_lumens(p), 2 * PI_D * 40, 5e-7);
        assert_cd(p, 89.9f, 90, 40, 1e-5); /* measured 0 */
        assert_cd(p, 90.2f, 90, 0, 0);
        lx_ies_free(p);
        /* symmetric halves mirrored: the same half space */
        p = ab_profile(type, 0, 90, 0, 90, 15, uniform_fn);
        lx_test_assert_rel(lx_ies_total_lumens(p), 2 * PI_D * 40, 5e-7);
        lx_ies_free(p);
        /* measured on one side of the axis only (V <= 0 or H <= 0): a
         * quarter of the sphere, pi I, dark on the other side. The type C
         * grid (1 degree here) interpolates across the edge of the measured
         * range: half a step on each of the two edge half-planes adds
         * 40 x 2 x 0.5 deg = 0.70 lm to the 125.7, 0.56% */
        p = ab_profile(type, -90, 0, -90, 90, 15, uniform_fn);
        /* measured 5.1e-5 beyond that half step */
        lx_test_assert_rel(lx_ies_total_lumens(p), PI_D * 40 + 40 * 2 * 0.5 * RAD, 2e-4);
        assert_cd(p, 30, 180, 40, 1e-5); /* x < 0; measured 0 */
        assert_cd(p, 30, 0, 0, 0);       /* x > 0 */
        lx_ies_free(p);
        p = ab_profile(type, -90, 90, -90, 0, 15, uniform_fn);
        lx_test_assert_rel(lx_ies_total_lumens(p), PI_D * 40 + 40 * 2 * 0.5 * RAD, 2e-4);
        assert_cd(p, 30, 270, 40, 1e-5); /* y < 0 */
        assert_cd(p, 30, 90, 0, 0);      /* y > 0 */
        lx_ies_free(p);
    }
}

/* The floodlight: beam angles by plane and flux in closed form. */
static void test_flood(void **state)
{
    const double va[] = {-90, -40, -20, 0, 20, 40, 90};
    const double ha[] = {0, 10, 20, 90};
    /* int a dV = 60 deg, int b dH = 30 deg; a trapezoid flat to f, zero
     * from z: int cos = 2 (sin f + int_f^z (z - t) / (z - f) cos t dt)
     * = 2 (cos f - cos z) / (z - f), integrating the ramp by parts */
    double a10 = 10 * RAD, a20 = 20 * RAD, a40 = 40 * RAD;
    double b_cos = 2 * (cos(a10) - cos(a20)) / (a20 - a10);
    double a_cos = 2 * (cos(a20) - cos(a40)) / (a40 - a20);
    for (int type = 2; type <= 3; type++) {
        char *text = ab_file(type, va, 7, ha, 4, flood_fn);
        lx_ies_profile *p = lx_test_parse_ies(text);
        free(text);
        lx_ies_info info;
        lx_ies_get_info(p, &info);
        assert_int_equal(info.symmetry, LX_IES_BILATERAL); /* horizontal 0..90 */
        double want = type == 2 ? 1000 * (60 * RAD) * b_cos : 1000 * (30 * RAD) * a_cos;
        lx_test_assert_rel(lx_ies_total_lumens(p), want, 1e-3); /* measured 2.7e-4 */
        /* the C0 plane is V = gamma: 50% at 30 deg; C90 is H = gamma: 50% at
         * 15 (on the grid: measured 0; a float's rounding at 1000 is 6e-5) */
        assert_cd(p, 30, 0, 500, 2e-4);
        assert_cd(p, 30, 180, 500, 2e-4);
        assert_cd(p, 15, 90, 500, 2e-4);
        assert_cd(p, 15, 270, 500, 2e-4);
        assert_cd(p, 10, 0, 1000, 2e-4);
        assert_cd(p, 25, 90, 0, 2e-4);
        lx_ies_free(p);
    }
}

/* ---- symmetric half ranges ---------------------------------------------------------------- */

static void assert_same(const lx_ies_profile *a, const lx_ies_profile *b)
{
    for (double g = 0; g <= 180; g += 3.7)
        for (double c = -10; c <= 370; c += 4.3) {
            double x = lx_ies_candela(a, (float)g, (float)c);
            double y = lx_ies_candela(b, (float)g, (float)c);
            if (!(fabs(x - y) <= 4e-7 * (1 + fabs(y)))) /* measured 1.1e-7 */
                fail_msg("at (%g, %g): half-range file %.7g, mirrored file %.7g", g, c, x, y);
        }
    lx_test_assert_rel(lx_ies_total_lumens(a), lx_ies_total_lumens(b), 3e-10); /* 8e-11 */
    lx_test_assert_rel(lx_ies_peak_candela(a), lx_ies_peak_candela(b), 0);
}

static void test_symmetric_halves(void **state)
{
    static const struct {
        double v0, h0;
        lx_ies_symmetry sym;
    } cases[] = {
        {-90, 0, LX_IES_BILATERAL},    /* horizontal 0..90: mirrored about the C0-C180 plane */
        {0, -90, LX_IES_BILATERAL_90}, /* vertical 0..90: about the C90-C270 plane */
        {0, 0, LX_IES_QUADRANT},
    };
    for (int type = 2; type <= 3; type++)
        for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
            lx_ies_profile *half =
                ab_profile(type, cases[k].v0, 90, cases[k].h0, 90, 2.5, uneven_fn);
            lx_ies_profile *full = ab_profile(type, -90, 90, -90, 90, 2.5, uneven_fn);
            lx_ies_info info;
            lx_ies_get_info(half, &info);
            assert_int_equal(info.symmetry, cases[k].sym);
            assert_same(half, full);
            /* and the value itself, at a direction away from the grid */
            double v, h;
            ab_angles(type, 41.3, 227.9, &v, &h);
            assert_cd(half, 41.3, 227.9, uneven_fn(v, h), 0.05); /* measured 0.014 */
            lx_ies_free(half);
            lx_ies_free(full);
        }
}

/* ---- the header as read -------------------------------------------------------------------- */

static void test_info(void **state)
{
    lx_ies_profile *p = lx_test_parse_ies("IESNA:LM-63-1995\n[TEST] b\nTILT=NONE\n"
                                          "1 -1 2 3 2 2 1 0 0 0\n1 1 50\n"
                                          "-90 0 90\n0 90\n"
                                          "1 5 2\n3 4 3\n");
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    assert_int_equal(info.photometric_type, 2);
    assert_int_equal(info.vertical_count, 3);
    assert_int_equal(info.horizontal_count, 2);
    lx_test_assert_rel(info.vertical_angles[0], -90, 0);
    lx_test_assert_rel(info.vertical_angles[2], 90, 0);
    lx_test_assert_rel(info.horizontal_angles[1], 90, 0);
    assert_int_equal(info.symmetry, LX_IES_BILATERAL);
    /* the largest value times the multiplier 2 */
    lx_test_assert_rel(lx_ies_peak_candela(p), 10, 0);
    /* the beam axis and the principal planes: V = 0, H = 0 is 5 x 2; C0 at
     * 45 deg is V = 45 (between 5 and 2: 3.5 x 2); C90 at 90 is H = 90 (4 x 2) */
    /* on the grid or halfway: measured 0 (a float's rounding at 10 is 6e-7) */
    assert_cd(p, 0, 0, 10, 3e-6);
    assert_cd(p, 45, 0, 7, 3e-6);
    assert_cd(p, 45, 180, 6, 3e-6); /* V = -45: between 1 and 5 */
    /* C90 at 45 deg is H = 45, V = 0: between 5 and 4, 4.5 x 2; mirrored */
    assert_cd(p, 45, 90, 9, 3e-6);
    assert_cd(p, 45, 270, 9, 3e-6);
    lx_ies_free(p);
    /* type A */
    p = lx_test_parse_ies("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 2 3 2 0 0 0\n1 1 0\n0 90\n-90 90\n"
                          "7 7\n7 7\n");
    lx_ies_get_info(p, &info);
    assert_int_equal(info.photometric_type, 3);
    assert_int_equal(info.symmetry, LX_IES_BILATERAL_90);
    assert_cd(p, 60, 300, 7, 3e-6);                                 /* measured 0 */
    lx_test_assert_rel(lx_ies_total_lumens(p), 2 * PI_D * 7, 5e-7); /* 1.3e-7 */
    lx_ies_free(p);
}

/* ---- malformed angles ------------------------------------------------------------------------ */

#define HEAD "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n" /* lines 1-3 */

static void test_bad_angles(void **state)
{
    /* vertical above 90 or below -90 */
    parse_fails(HEAD "1 -1 1 3 2 2 2 0 0 0\n1 1 0\n-90 0 95\n-90 90\n1 2 3 4 5 6\n",
                "line 6: vertical angles 3 is 95, outside -90..90", "photometric type B");
    parse_fails(HEAD "1 -1 1 3 2 2 2 0 0 0\n1 1 0\n-90.5\n0 90\n-90 90\n1 2 3 4 5 6\n",
                "line 6: vertical angles 1 is -90.5, outside -90..90", "type B");
    parse_fails(HEAD "1 -1 1 2 3 3 2 0 0 0\n1 1 0\n0 90\n-100 0 90\n1 2 3 4 5 6\n",
                "line 7: horizontal angles 1 is -100, outside -90..90", "photometric type A");
    parse_fails(HEAD "1 -1 1 2 2 2 2 0 0 0\n1 1 0\n0 90\n0 180\n1 2 3 4\n",
                "line 7: horizontal angles 2 is 180", "outside -90..90");
    /* out of order */
    parse_fails(HEAD "1 -1 1 3 2 2 2 0 0 0\n1 1 0\n-10 -20 90\n0 90\n1 2 3 4 5 6\n", "line 6",
                "vertical angles out of order: -20 follows -10");
    /* a range that misses the beam axis */
    parse_fails(HEAD "1 -1 1 2 2 2 2 0 0 0\n1 1 0\n10 90\n-90 90\n1 2 3 4\n",
                "line 6: vertical angles 10..90 do not reach the beam axis", "type B");
    parse_fails(HEAD "1 -1 1 2 2 3 2 0 0 0\n1 1 0\n-90 90\n-90 -30\n1 2 3 4\n",
                "line 7: horizontal angles -90..-30", "type A");
    /* one angle is not a range */
    parse_fails(HEAD "1 -1 1 2 1 2 2 0 0 0\n1 1 0\n-90 90\n0\n1 2\n",
                "line 7: photometric type B needs at least 2 horizontal angles", NULL);
    parse_fails(HEAD "1 -1 1 1 2 3 2 0 0 0\n1 1 0\n0\n0 90\n1 2\n",
                "line 6: photometric type A needs at least 2 vertical angles", NULL);
    /* type C keeps its own ranges, without the note */
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n-90 90\n0\n1 2\n",
                "line 6: vertical angles 1 is -90, outside 0..180", NULL);
    /* truncated candela values of a type B file */
    parse_fails(HEAD "1 -1 1 2 2 2 2 0 0 0\n1 1 0\n-90 90\n-90 90\n1 2 3\n",
                "line 8: expected 4 candela values, found 3", NULL);
}

/* A type B file read from disk, CRLF line ends. */
static void test_load_file(void **state)
{
    char path[512];
    snprintf(path, sizeof path, "%s/flood.ies", lx_test_dir("ies_types_load"));
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs("IESNA:LM-63-2002\r\n[TEST] x\r\nTILT=NONE\r\n1 -1 1 3 3 2 2 0 0 0\r\n1 1 0\r\n"
          "-90 0 90\r\n-90 0 90\r\n0 0 0\r\n0 100 0\r\n0 0 0\r\n",
          fp);
    fclose(fp);
    lx_ies_profile *p = NULL;
    assert_int_equal(lx_ies_load(path, &p), LX_OK);
    /* a pyramid: 100 (1 - |V|/90) at H = 0 */
    /* measured 0; a float's rounding at 100 is 6e-6 */
    assert_cd(p, 0, 0, 100, 2e-5);
    assert_cd(p, 45, 0, 50, 2e-5);
    assert_cd(p, 45, 90, 50, 2e-5); /* H = 45 at V = 0 */
    lx_ies_free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_type_b_axes), cmocka_unit_test(test_type_a_axes),
        cmocka_unit_test(test_cosine),      cmocka_unit_test(test_lumens_uniform),
        cmocka_unit_test(test_flood),       cmocka_unit_test(test_symmetric_halves),
        cmocka_unit_test(test_info),        cmocka_unit_test(test_bad_angles),
        cmocka_unit_test(test_load_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
