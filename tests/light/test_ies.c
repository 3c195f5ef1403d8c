/* Tests of the IES LM-63 reader (src/light/ies.c): hand-written files of
 * every LM-63 version (1986, 1991, 1995, 2002) and every horizontal
 * symmetry, candela values at given and in-between angles against bilinear
 * values worked out by hand, total lumens against closed forms (isotropic
 * 4 pi I, cosine pi I0, hemisphere 2 pi I, a linear ramp 200 pi - 400), the
 * multiplier and ballast factors, and every malformed case with its status
 * and the line its message names. Photometric types A and B:
 * test_ies_types.c. */
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
/* lx_ies_total_lumens integrates with the midpoint rule on 0.1 x 0.5 deg
 * cells (docs/ies.md): a constant distribution comes out (pi/1800)^2 / 24
 * = 1.3e-7 low, which every case without a slope measures */
#define LUMENS_TOL 5e-7

/* Parsing fails with `want` and a message holding every needle. */
static void parse_fails(const char *text, lx_status want, const char *n1, const char *n2)
{
    lx_ies_profile *p = (lx_ies_profile *)1;
    lx_status st = lx_ies_parse(text, strlen(text), "x.ies", &p);
    if (st != want)
        fail_msg("status %s, want %s (message: %s)", lx_status_name(st), lx_status_name(want),
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

static void assert_cd(const lx_ies_profile *p, float v, float h, double want)
{
    double got = lx_ies_candela(p, v, h);
    /* bilinear in float: measured 0 but at one point 2.6e-8 relative */
    if (!(fabs(got - want) <= 2e-7 * (fabs(want) + 1.0)))
        fail_msg("candela at (%g, %g): got %.7g, want %.7g", v, h, got, want);
}

/* ---- versions -------------------------------------------------------------- */

/* 1986: no IESNA line, free label lines; rotationally symmetric 100 cd. */
static const char *ies_1986 = "ACME LIGHTING 1986\n"
                              "BARE LAMP, ISOTROPIC\n"
                              "TILT=NONE\n"
                              "1 1000 1 3 1 1 1 0 0 0\n"
                              "1 1 60\n"
                              "0 90 180\n"
                              "0\n"
                              "100 100 100\n";

static void test_version_1986(void **state)
{
    lx_ies_profile *p = lx_test_parse_ies(ies_1986);
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    assert_string_equal(info.version, "LM-63-1986");
    assert_int_equal(info.keyword_count, 2);
    const char *value;
    assert_string_equal(lx_ies_keyword(p, 0, &value), "");
    assert_string_equal(value, "ACME LIGHTING 1986");
    assert_null(lx_ies_keyword(p, 2, &value));
    assert_false(info.tilt_included);
    assert_int_equal(info.lamp_count, 1);
    lx_test_assert_rel(info.lumens_per_lamp, 1000, 0);
    assert_int_equal(info.photometric_type, 1);
    assert_int_equal(info.units, 1);
    lx_test_assert_rel(info.input_watts, 60, 0);
    assert_int_equal(info.symmetry, LX_IES_ROTATIONAL);
    assert_cd(p, 0, 0, 100);
    assert_cd(p, 37, 123, 100);
    assert_cd(p, 180, 300, 100);
    lx_test_assert_rel(lx_ies_peak_candela(p), 100, 0);
    lx_test_assert_rel(lx_ies_total_lumens(p), 4 * PI_D * 100, LUMENS_TOL);
    lx_ies_free(p);
}

/* 1991: "IESNA91", keywords, TILT=INCLUDE with its four lines; quadrant
 * symmetry. c(v, h): h=0: 100 80 40 0, h=45: 90 70 30 0, h=90: 60 50 20 0
 * at v = 0 30 60 90. */
static const char *ies_1991 = "IESNA91\n"
                              "[TEST] 1991-17\n"
                              "[MANUFAC] Acme\n"
                              "TILT=INCLUDE\n"
                              "1\n"
                              "7\n"
                              "0 15 30 45\n"
                              "60 75 90\n"
                              "1.0 .95 .94 .90 .88 .87 .94\n"
                              "2 500 1.0 4 3 1 2 0.5 0.6 0.1\n"
                              "1.0 1.0 100\n"
                              "0 30 60 90\n"
                              "0 45 90\n"
                              "100 80 40 0\n"
                              "90 70 30 0\n"
                              "60 50 20 0\n";

static void test_version_1991_quadrant(void **state)
{
    lx_ies_profile *p = lx_test_parse_ies(ies_1991);
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    assert_string_equal(info.version, "LM-63-1991");
    assert_true(info.tilt_included);
    assert_int_equal(info.keyword_count, 2);
    const char *value;
    assert_string_equal(lx_ies_keyword(p, 1, &value), "MANUFAC");
    assert_string_equal(value, "Acme");
    assert_int_equal(info.lamp_count, 2);
    assert_int_equal(info.units, 2);
    lx_test_assert_rel(info.width, 0.5, 0);
    lx_test_assert_rel(info.length, 0.6, 0);
    lx_test_assert_rel(info.height, 0.1, 0);
    assert_int_equal(info.vertical_count, 4);
    assert_int_equal(info.horizontal_count, 3);
    lx_test_assert_rel(info.horizontal_angles[2], 90, 0);
    assert_int_equal(info.symmetry, LX_IES_QUADRANT);
    /* given angles */
    assert_cd(p, 0, 0, 100);
    assert_cd(p, 30, 45, 70);
    assert_cd(p, 60, 90, 20);
    /* in between: bilinear */
    assert_cd(p, 15, 0, 90);
    assert_cd(p, 15, 22.5f, 85);   /* lerp(90, 80) */
    assert_cd(p, 45, 67.5f, 42.5); /* h45: 50, h90: 35 */
    /* v 40 is 1/3 from 30 to 60: h0 80 -> 40 gives 200/3, h45 70 -> 30 gives
     * 170/3; h 10 is 2/9 of the way from plane 0 to plane 45 */
    assert_cd(p, 40, 10, 200 / 3.0 * (7 / 9.0) + 170 / 3.0 * (2 / 9.0));
    /* mirrored into the other quadrants */
    assert_cd(p, 15, 337.5f, 85);
    assert_cd(p, 15, 157.5f, 85);
    assert_cd(p, 15, 202.5f, 85);
    assert_cd(p, 30, 270, 50);
    assert_cd(p, 30, -90, 50);
    /* above the last vertical angle: dark */
    assert_cd(p, 95, 0, 0);
    assert_cd(p, 180, 0, 0);
    lx_test_assert_rel(lx_ies_peak_candela(p), 100, 0);
    lx_ies_free(p);
}

/* 1995: bilateral 0-180, absolute photometry, values wrapped and separated
 * by commas. h0: 10 20, h90: 30 40, h180: 50 60 at v = 0 90. */
static const char *ies_1995 = "IESNA:LM-63-1995\n"
                              "[TEST] ABC-1995\n"
                              "[LUMINAIRE] wall washer\n"
                              "[MORE] second line\n"
                              "TILT=NONE\n"
                              "1 -1 1 2 3 1 2 0 0 0\n"
                              "1 1 40\n"
                              "0,90\n"
                              "0,90,180\n"
                              "10,20, 30\n"
                              "40 50\n"
                              "60\n";

static void test_version_1995_bilateral(void **state)
{
    lx_ies_profile *p = lx_test_parse_ies(ies_1995);
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    assert_string_equal(info.version, "LM-63-1995");
    assert_int_equal(info.keyword_count, 3);
    lx_test_assert_rel(info.lumens_per_lamp, -1, 0);
    assert_int_equal(info.symmetry, LX_IES_BILATERAL);
    assert_cd(p, 0, 90, 30);
    assert_cd(p, 45, 0, 15);
    assert_cd(p, 45, 90, 35);
    assert_cd(p, 45, 270, 35); /* mirror of 90 */
    assert_cd(p, 45, 225, 45); /* mirror of 135: lerp(35, 55) */
    assert_cd(p, 45, 315, 25); /* mirror of 45: lerp(15, 35) */
    assert_cd(p, 90, 180, 60);
    assert_cd(p, 120, 180, 0);
    lx_ies_free(p);
}

/* 2002: full 0-360 with TILT=INCLUDE, the tilt block wrapped. Planes at 0,
 * 90, 180, 270 hold 10, 20, 30, 40 cd at every vertical angle 0..180; past
 * 270 the last plane blends into plane 0. */
static const char *ies_2002 = "IESNA:LM-63-2002\n"
                              "[TEST] XYZ-2002\n"
                              "[TESTLAB] Lab\n"
                              "[ISSUEDATE] 2002-02-02\n"
                              "[MANUFAC] Acme\n"
                              "TILT=INCLUDE\n"
                              "3\n"
                              "2\n"
                              "0\n"
                              "90\n"
                              "1 0.5\n"
                              "1 1000 1 3 4 1 2 0 0 0\n"
                              "1 1 10\n"
                              "0 90 180\n"
                              "0 90 180 270\n"
                              "10 10 10 20 20 20\n"
                              "30 30 30 40 40 40\n";

static void test_version_2002_full(void **state)
{
    lx_ies_profile *p = lx_test_parse_ies(ies_2002);
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    assert_string_equal(info.version, "LM-63-2002");
    assert_true(info.tilt_included);
    assert_int_equal(info.keyword_count, 4);
    assert_int_equal(info.symmetry, LX_IES_FULL);
    assert_cd(p, 30, 0, 10);
    assert_cd(p, 30, 45, 15);
    assert_cd(p, 30, 270, 40);
    assert_cd(p, 30, 315, 25); /* between 270 (40) and 360 = 0 (10) */
    assert_cd(p, 30, -45, 25);
    assert_cd(p, 30, 405, 15);
    /* past the zenith: the opposite plane */
    assert_cd(p, 200, 0, 30);
    /* the azimuthal mean of the piecewise-linear ring is 25: 4 pi 25 */
    lx_test_assert_rel(lx_ies_total_lumens(p), 4 * PI_D * 25, LUMENS_TOL);
    lx_ies_free(p);
}

/* 0-360 written out with the duplicate 360 plane. */
static void test_full_360(void **state)
{
    lx_ies_profile *p =
        lx_test_parse_ies("IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 2 4 1 2 0 0 0\n1 1 0\n"
                          "0 90\n0 120 240 360\n10 10 40 40 70 70 10 10\n");
    assert_cd(p, 0, 300, 40);
    assert_cd(p, 45, 60, 25);
    assert_cd(p, 0, 360, 10);
    lx_ies_free(p);
}

/* 90-270: mirrored about the 90-270 plane, I(h) = I(180 - h). */
static void test_bilateral_90_270(void **state)
{
    lx_ies_profile *p =
        lx_test_parse_ies("IESNA:LM-63-1995\nTILT=NONE\n1 1000 1 2 3 1 2 0 0 0\n1 1 0\n"
                          "0 90\n90 180 270\n10 20\n30 40\n50 60\n");
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    assert_int_equal(info.symmetry, LX_IES_BILATERAL_90);
    assert_string_equal(lx_ies_symmetry_name(info.symmetry), "bilateral 90-270");
    assert_cd(p, 0, 0, 30);   /* = 180 */
    assert_cd(p, 0, 45, 20);  /* = 135 */
    assert_cd(p, 0, 315, 40); /* = 225 */
    assert_cd(p, 90, 90, 20);
    assert_cd(p, 45, 270, 55);
    lx_ies_free(p);
}

/* Vertical 90-180 (uplight): a linear ramp 0 at 90 to 100 at 180, dark
 * below. Flux 2 pi * 100 (2/pi) * integral_0^{pi/2} u cos u du
 * = 400 (pi/2 - 1) = 200 pi - 400. */
static void test_vertical_90_180(void **state)
{
    lx_ies_profile *p =
        lx_test_parse_ies("IESNA:LM-63-1995\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 0\n"
                          "90 135 180\n0\n0 50 100\n");
    assert_cd(p, 45, 0, 0);
    assert_cd(p, 89, 0, 0);
    assert_cd(p, 90, 0, 0);
    assert_cd(p, 157.5f, 77, 75);
    lx_test_assert_rel(lx_ies_total_lumens(p), 200 * PI_D - 400, 2e-6); /* measured 5.7e-7 */
    lx_ies_free(p);
}

/* ---- total lumens --------------------------------------------------------- */

static void test_lumens_cosine(void **state)
{
    /* I(theta) = 1000 cos(theta) on 0..90 in 1 degree steps: pi * 1000 */
    char *text = malloc(8192);
    int n = snprintf(text, 8192, "IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 91 1 1 2 0 0 0\n1 1 0\n");
    for (int i = 0; i <= 90; i++)
        n += snprintf(text + n, 8192 - n, "%d%s", i, i % 10 == 9 ? "\n" : " ");
    n += snprintf(text + n, 8192 - n, "\n0\n");
    for (int i = 0; i <= 90; i++)
        n += snprintf(text + n, 8192 - n, "%.6f%s", 1000 * cos(i * PI_D / 180),
                      i % 8 == 7 ? "\n" : " ");
    lx_ies_profile *p = lx_test_parse_ies(text);
    /* the file samples the cosine, bilinear in between: measured 2.5e-5 */
    lx_test_assert_rel(lx_ies_total_lumens(p), PI_D * 1000, 1e-4);
    assert_cd(p, 60, 0, 500);
    lx_ies_free(p);
    free(text);
}

static void test_lumens_hemisphere(void **state)
{
    /* constant 250 cd on 0..90, nothing above: 2 pi 250 */
    lx_ies_profile *p =
        lx_test_parse_ies("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 3 1 1 2 0 0 0\n1 1 0\n"
                          "0 45 90\n0\n250 250 250\n");
    lx_test_assert_rel(lx_ies_total_lumens(p), 2 * PI_D * 250, LUMENS_TOL);
    lx_ies_free(p);
    /* the same as a quadrant file with planes 0, 45, 90 */
    p = lx_test_parse_ies("IESNA:LM-63-2002\nTILT=NONE\n1 -1 1 2 3 1 2 0 0 0\n1 1 0\n"
                          "0 90\n0 45 90\n250 250 250 250 250 250\n");
    lx_test_assert_rel(lx_ies_total_lumens(p), 2 * PI_D * 250, LUMENS_TOL);
    lx_ies_free(p);
}

static void test_lumens_bilateral_varying(void **state)
{
    /* bilateral, constant in theta over 0..180: planes 0, 90, 180 at 10, 30,
     * 50; mirrored ring 10-30-50-30-10: mean 30, flux 4 pi 30 */
    lx_ies_profile *p =
        lx_test_parse_ies("IESNA:LM-63-1995\nTILT=NONE\n1 -1 1 2 3 1 2 0 0 0\n1 1 0\n"
                          "0 180\n0 90 180\n10 10 30 30 50 50\n");
    lx_test_assert_rel(lx_ies_total_lumens(p), 4 * PI_D * 30, LUMENS_TOL);
    lx_ies_free(p);
}

/* ---- scale factors ---------------------------------------------------------- */

static void test_multiplier_and_ballast(void **state)
{
    /* 100 cd x multiplier 2 x ballast 0.5 x ballast-lamp factor 0.9 = 90 */
    lx_ies_profile *p = lx_test_parse_ies("IESNA:LM-63-2002\nTILT=NONE\n1 1000 2 2 1 1 2 0 0 0\n"
                                          "0.5 0.9 0\n0 180\n0\n100 100\n");
    lx_ies_info info;
    lx_ies_get_info(p, &info);
    lx_test_assert_rel(info.multiplier, 2, 0);
    lx_test_assert_rel(info.ballast_factor, 0.5, 0);
    lx_test_assert_rel(info.ballast_lamp_factor, 0.9, 0);
    assert_cd(p, 30, 0, 90);
    lx_test_assert_rel(lx_ies_peak_candela(p), 90, 2e-7); /* a float: measured exactly */
    lx_test_assert_rel(lx_ies_total_lumens(p), 4 * PI_D * 90, LUMENS_TOL);
    lx_ies_free(p);
}

static void test_load_file(void **state)
{
    char path[512];
    snprintf(path, sizeof path, "%s/lamp.ies", lx_test_dir("ies_load"));
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(ies_1986, fp);
    fclose(fp);
    lx_ies_profile *p = NULL;
    assert_int_equal(lx_ies_load(path, &p), LX_OK);
    assert_cd(p, 10, 10, 100);
    lx_ies_free(p);
    /* CRLF line ends read the same */
    snprintf(path, sizeof path, "%s/crlf.ies", lx_test_dir("ies_load_crlf"));
    fp = fopen(path, "wb");
    fputs("IESNA:LM-63-1995\r\n[TEST] x\r\nTILT=NONE\r\n1 -1 1 2 1 1 2 0 0 0\r\n1 1 0\r\n"
          "0 180\r\n0\r\n5 5\r\n",
          fp);
    fclose(fp);
    assert_int_equal(lx_ies_load(path, &p), LX_OK);
    const char *value;
    assert_string_equal(lx_ies_keyword(p, 0, &value), "TEST");
    assert_string_equal(value, "x");
    lx_ies_free(p);
    snprintf(path, sizeof path, "%s/none.ies", lx_test_dir("ies_load_missing"));
    p = (lx_ies_profile *)1;
    assert_int_equal(lx_ies_load(path, &p), LX_ERR_IO);
    assert_null(p);
    assert_non_null(strstr(lx_last_error(), "none.ies"));
}

/* ---- malformed files --------------------------------------------------------- */

#define HEAD "IESNA:LM-63-2002\n[TEST] bad\nTILT=NONE\n" /* lines 1-3 */

static void test_truncated(void **state)
{
    /* 2 x 2 = 4 values wanted, 2 given; the file ends on line 8 */
    parse_fails(HEAD "1 -1 1 2 2 1 2 0 0 0\n1 1 0\n0 90\n0 90\n10 20\n", LX_ERR_FORMAT,
                "line 8: expected 4 candela values, found 2", NULL);
    parse_fails(HEAD "1 -1 1 2 2 1 2 0 0 0\n1 1 0\n0 90\n0\n", LX_ERR_FORMAT,
                "line 7: expected 2 horizontal angles, found 1", NULL);
    parse_fails(HEAD "1 -1 1 2 2 1 2\n", LX_ERR_FORMAT, "line 4", "width");
    parse_fails(HEAD, LX_ERR_FORMAT, "line 3", "number of lamps");
    parse_fails("IESNA:LM-63-2002\nTILT=INCLUDE\n1\n3\n0 45\n", LX_ERR_FORMAT,
                "line 5: expected 3 tilt angles, found 2", NULL);
}

static void test_not_numbers(void **state)
{
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 nan\n", LX_ERR_FORMAT, "line 8",
                "'nan' is not a finite number");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 inf\n0\n10 10\n", LX_ERR_FORMAT, "line 6",
                "not a finite number");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 1e999\n", LX_ERR_FORMAT, "line 8",
                "not a finite number");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 abc\n", LX_ERR_FORMAT, "line 8",
                "'abc' is not a number");
    parse_fails(HEAD "1 lots 1 2 1 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4: lumens per lamp", NULL);
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10 10 12\n", LX_ERR_FORMAT, "line 8",
                "unexpected '12'");
}

static void test_negative_values(void **state)
{
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n0\n10\n-5\n", LX_ERR_FORMAT,
                "line 9: candela value -5 is negative", NULL);
    parse_fails(HEAD "1 -1 -1 2 1 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4", "multiplier");
    parse_fails(HEAD "1 -2 1 2 1 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4", "lumens per lamp");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n-1 1 0\n", LX_ERR_FORMAT, "line 5", "ballast factor");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 -1 0\n", LX_ERR_FORMAT, "line 5",
                "ballast-lamp photometric factor");
}

static void test_angles_out_of_order(void **state)
{
    parse_fails(HEAD "1 -1 1 3 1 1 2 0 0 0\n1 1 0\n0\n60 45\n0\n1 2 3\n", LX_ERR_FORMAT, "line 7",
                "vertical angles out of order: 45 follows 60");
    parse_fails(HEAD "1 -1 1 2 3 1 2 0 0 0\n1 1 0\n0 90\n0 90 90\n1 2 3 4 5 6\n", LX_ERR_FORMAT,
                "line 7", "horizontal angles out of order");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 190\n0\n1 2\n", LX_ERR_FORMAT, "line 6",
                "outside 0..180");
    parse_fails("IESNA:LM-63-2002\nTILT=INCLUDE\n1\n2\n30 10\n1 1\n", LX_ERR_FORMAT, "line 5",
                "tilt angles out of order");
}

static void test_bad_symmetry(void **state)
{
    parse_fails(HEAD "1 -1 1 2 2 1 2 0 0 0\n1 1 0\n0 90\n0 120\n1 2 3 4\n", LX_ERR_FORMAT, "line 7",
                "horizontal angles 0..120 match no symmetry");
    parse_fails(HEAD "1 -1 1 2 2 1 2 0 0 0\n1 1 0\n0 90\n10 180\n1 2 3 4\n", LX_ERR_FORMAT,
                "line 7", "match no symmetry");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 90\n45\n1 2\n", LX_ERR_FORMAT, "line 7",
                "match no symmetry");
    parse_fails(HEAD "1 -1 1 2 1 1 2 0 0 0\n1 1 0\n0 60\n0\n1 2\n", LX_ERR_FORMAT, "line 6",
                "vertical angles 0..60");
    parse_fails(HEAD "1 -1 1 1 1 1 2 0 0 0\n1 1 0\n0\n0\n1\n", LX_ERR_FORMAT, "line 6",
                "vertical angles");
}

static void test_tilt(void **state)
{
    parse_fails("IESNA:LM-63-2002\n[TEST] t\nTILT=lamp.tlt\n1 -1 1 2 1 1 2 0 0 0\n",
                LX_ERR_UNSUPPORTED, "line 3: TILT=lamp.tlt", "not supported");
    parse_fails("IESNA:LM-63-2002\nTILT=\n", LX_ERR_FORMAT, "line 2", "TILT=");
    parse_fails("IESNA:LM-63-2002\nTILT=INCLUDE\n4\n", LX_ERR_FORMAT, "line 3",
                "lamp-to-luminaire geometry");
    parse_fails("IESNA:LM-63-2002\nTILT=INCLUDE\n1\n2\n0 90\n1 -0.5\n", LX_ERR_FORMAT, "line 6",
                "tilt multiplying factor -0.5 is negative");
}

static void test_bad_counts(void **state)
{
    parse_fails(HEAD "1 -1 1 0 1 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4",
                "number of vertical angles is 0");
    parse_fails(HEAD "1 -1 1 -3 1 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4",
                "number of vertical angles");
    parse_fails(HEAD "1 -1 1 2 1e9 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4",
                "number of horizontal angles");
    parse_fails(HEAD "1 -1 1 2.5 1 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4", "whole number");
    parse_fails(HEAD "1 -1 1 100000\n100000 1 2 0 0 0\n", LX_ERR_FORMAT, "line 5", "more than the");
    parse_fails(HEAD "0 -1 1 2 1 1 2 0 0 0\n", LX_ERR_FORMAT, "line 4", "number of lamps");
    parse_fails(HEAD "1 -1 1 2 1 4 2 0 0 0\n", LX_ERR_FORMAT, "line 4", "photometric type");
    parse_fails(HEAD "1 -1 1 2 1 1 3 0 0 0\n", LX_ERR_FORMAT, "line 4", "units type");
    parse_fails("IESNA:LM-63-2002\nTILT=INCLUDE\n1\n0\n", LX_ERR_FORMAT, "line 4",
                "number of tilt angles");
}

static void test_garbage(void **state)
{
    parse_fails("", LX_ERR_FORMAT, "no TILT= line", NULL);
    parse_fails("hello world\nthis is not\nan ies file\n", LX_ERR_FORMAT, "line 3",
                "no TILT= line");
    parse_fails("IESNA:LM-63-2002\nTILT=NONE\n\x01\x02\x03\n", LX_ERR_FORMAT, "line 3",
                "not a number");
    /* NUL bytes inside the numbers */
    static const char nul[] = "IESNA:LM-63-2002\nTILT=NONE\n1\0 -1 1 2 1 1 2 0 0 0\n";
    lx_ies_profile *p = (lx_ies_profile *)1;
    assert_int_equal(lx_ies_parse(nul, sizeof nul - 1, "x.ies", &p), LX_ERR_FORMAT);
    assert_null(p);
    assert_non_null(strstr(lx_last_error(), "line 3"));
    /* more than 16 MiB */
    size_t big = (16u << 20) + 1;
    char *text = malloc(big);
    assert_non_null(text);
    memset(text, ' ', big);
    assert_int_equal(lx_ies_parse(text, big, "x.ies", &p), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "more than"));
    free(text);
    /* NULL profile queries are harmless */
    assert_true(lx_ies_candela(NULL, 0, 0) == 0.0f);
    assert_true(lx_ies_total_lumens(NULL) == 0.0);
    lx_ies_free(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_version_1986),
        cmocka_unit_test(test_version_1991_quadrant),
        cmocka_unit_test(test_version_1995_bilateral),
        cmocka_unit_test(test_version_2002_full),
        cmocka_unit_test(test_full_360),
        cmocka_unit_test(test_bilateral_90_270),
        cmocka_unit_test(test_vertical_90_180),
        cmocka_unit_test(test_lumens_cosine),
        cmocka_unit_test(test_lumens_hemisphere),
        cmocka_unit_test(test_lumens_bilateral_varying),
        cmocka_unit_test(test_multiplier_and_ballast),
        cmocka_unit_test(test_load_file),
        cmocka_unit_test(test_truncated),
        cmocka_unit_test(test_not_numbers),
        cmocka_unit_test(test_negative_values),
        cmocka_unit_test(test_angles_out_of_order),
        cmocka_unit_test(test_bad_symmetry),
        cmocka_unit_test(test_tilt),
        cmocka_unit_test(test_bad_counts),
        cmocka_unit_test(test_garbage),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
