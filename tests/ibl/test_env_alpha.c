/* Alpha in environments in memory (lx_env_from_image, ibl.h: "1 to
 * 4 channels; grey is grey, alpha ignored"): a grey + alpha image whose
 * alpha is negative or NaN is read like the same grey image without alpha,
 * as an RGBA image's alpha already is. A constant grey equirect L gives L
 * in every channel of every texel (a box filter of a constant). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <string.h>

static void grey_alpha_ignores_alpha(void **state)
{
    (void)state;
    const float alphas[2] = {-1.0f, NAN};
    for (int a = 0; a < 2; a++) {
        lx_image img;
        assert_int_equal(lx_image_alloc(&img, 16, 8, 2), LX_OK);
        for (int i = 0; i < 16 * 8; i++) {
            img.data[2 * i] = 3.0f;
            img.data[2 * i + 1] = alphas[a];
        }
        lx_env_load_desc d = {.size = 4};
        lx_cubemap c;
        lx_status st = lx_env_from_image(&img, "grey_alpha", &d, &c);
        if (st != LX_OK)
            fail_msg("alpha %g: %s", (double)alphas[a], lx_last_error());
        /* measured exactly 3; bound one float ulp of 3 */
        for (int i = 0; i < 6 * 4 * 4 * 3; i++)
            assert_true(fabsf(c.data[i] - 3.0f) <= 2.4e-7f);
        lx_cubemap_free(&c);
        lx_image_free(&img);
    }
}

/* The grey value itself is still checked. */
static void grey_alpha_rejects_bad_grey(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 16, 8, 2), LX_OK);
    for (int i = 0; i < 16 * 8; i++) {
        img.data[2 * i] = 1.0f;
        img.data[2 * i + 1] = 1.0f;
    }
    img.data[2 * 5] = -2.0f;
    lx_cubemap c;
    assert_int_equal(lx_env_from_image(&img, "grey_alpha", NULL, &c), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "1 texel is negative"));
    assert_null(c.data);
    lx_image_free(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(grey_alpha_ignores_alpha),
        cmocka_unit_test(grey_alpha_rejects_bad_grey),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
