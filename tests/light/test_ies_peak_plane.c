/* lx_ies_plane_peak and lx_ies_peak_plane on a profile written here: a
 * quadrant-symmetric file whose 1000 cd peak lies only in the C45 plane
 * (200 cd at the nadir everywhere, 100 cd at 30 deg in C0 and C90). The
 * plane maximum is the largest grid value on either half: C0-C180 and
 * C90-C270 reach 200 (the nadir), C45-C225 1000, and the plane through
 * 22.5 deg, halfway between C0 and C45, 550 at 30 deg (bilinear). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <string.h>

static const char *peak_ies = "IESNA:LM-63-2002\n[TEST] peak in C45\nTILT=NONE\n"
                              "1 1000 1 4 3 1 2 0 0 0\n1 1 10\n0 30 60 90\n0 45 90\n"
                              "200 100 0 0\n200 1000 0 0\n200 100 0 0\n";

static void plane_maxima(void **state)
{
    (void)state;
    lx_ies_profile *p = lx_test_parse_ies(peak_ies);
    float m = -1.0f;
    const struct {
        float h, want;
    } cases[] = {{0, 200}, {90, 200}, {180, 200}, {45, 1000}, {225, 1000}, {22.5f, 550}};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        assert_int_equal(lx_ies_plane_peak(p, cases[i].h, &m), LX_OK);
        lx_test_assert_rel(m, cases[i].want, 1e-6); /* grid values, exact in float */
    }
    float h = -1.0f;
    assert_int_equal(lx_ies_peak_plane(p, &h), LX_OK);
    assert_true(h == 45.0f);
    lx_ies_free(p);
}

static void rotational_and_bad_input(void **state)
{
    (void)state;
    lx_ies_profile *p = lx_test_parse_ies("IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n"
                                          "1 1 10\n0 45 90\n0\n500 250 0\n");
    float h = -1.0f, m = -1.0f;
    assert_int_equal(lx_ies_peak_plane(p, &h), LX_OK);
    assert_true(h == 0.0f);
    assert_int_equal(lx_ies_plane_peak(p, 137.0f, &m), LX_OK);
    assert_true(m == 500.0f);
    assert_int_equal(lx_ies_plane_peak(NULL, 0.0f, &m), LX_ERR_INVALID);
    assert_int_equal(lx_ies_plane_peak(p, NAN, &m), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "not finite"));
    assert_int_equal(lx_ies_plane_peak(p, 0.0f, NULL), LX_ERR_INVALID);
    assert_int_equal(lx_ies_peak_plane(p, NULL), LX_ERR_INVALID);
    lx_ies_free(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(plane_maxima),
        cmocka_unit_test(rotational_and_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
