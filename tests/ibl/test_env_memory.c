/* lx_env_from_image: environments already in memory. A grey equirect of a
 * constant value gives that value in every channel of every texel; an RGBA
 * cross gives its faces exactly (alpha ignored), each face's texels read
 * straight from where the horizontal-cross layout puts that face (docs/ibl.md:
 * -X +Z +X -Z in the middle row, +Y above +Z, -Y below it); bad shapes,
 * NaN texels and six faces fail with the name in the message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <string.h>

static void grey_equirect_is_constant(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 16, 8, 1), LX_OK);
    for (int i = 0; i < 16 * 8; i++)
        img.data[i] = 42.0f;
    lx_env_load_desc d = {.size = 4};
    lx_cubemap c;
    assert_int_equal(lx_env_from_image(&img, "grey", &d, &c), LX_OK);
    assert_int_equal(c.size, 4);
    for (int i = 0; i < 6 * 4 * 4 * 3; i++)
        assert_true(fabsf(c.data[i] - 42.0f) <= 42.0f * 1e-6f);
    lx_cubemap_free(&c);
    lx_image_free(&img);
}

static void rgba_cross_gives_its_faces(void **state)
{
    (void)state;
    const int n = 3;
    /* (column, row) of each face in a horizontal cross, in GL face order */
    const int at[6][2] = {{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}};
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 4 * n, 3 * n, 4), LX_OK);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                float *p = img.data + ((size_t)(at[f][1] * n + y) * (4 * n) + at[f][0] * n + x) * 4;
                p[0] = (float)(100 * f + 10 * y + x);
                p[1] = 1.0f;
                p[2] = 2.0f;
                p[3] = -5.0f; /* alpha: ignored, even negative */
            }
    lx_cubemap c;
    assert_int_equal(lx_env_from_image(&img, "cross", NULL, &c), LX_OK);
    assert_int_equal(c.size, n);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                const float *t = lx_cubemap_texel(&c, f, x, y);
                assert_true(t[0] == (float)(100 * f + 10 * y + x));
                assert_true(t[1] == 1.0f && t[2] == 2.0f);
            }
    lx_cubemap_free(&c);
    lx_image_free(&img);
}

static void expect_error(const lx_image *img, const lx_env_load_desc *d, const char *needle)
{
    lx_cubemap c = {.size = 99};
    lx_status st = lx_env_from_image(img, "mem.hdr", d, &c);
    if (st == LX_OK)
        fail_msg("accepted; wanted an error with '%s'", needle);
    if (!strstr(lx_last_error(), "mem.hdr") || !strstr(lx_last_error(), needle))
        fail_msg("message '%s' lacks 'mem.hdr' or '%s'", lx_last_error(), needle);
    assert_null(c.data);
    assert_int_equal(c.size, 0);
}

static void bad_images(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 30, 10, 3), LX_OK);
    expect_error(&img, NULL, "cannot tell the layout of a 30x10 image");
    lx_env_load_desc eq = {.layout = LX_ENV_EQUIRECT};
    expect_error(&img, &eq, "twice as wide");
    lx_env_load_desc faces = {.layout = LX_ENV_FACES};
    expect_error(&img, &faces, "six faces come from files");
    lx_image_free(&img);
    assert_int_equal(lx_image_alloc(&img, 8, 4, 3), LX_OK);
    img.data[7] = NAN;
    img.data[20] = -1.0f;
    expect_error(&img, NULL, "NaN");
    lx_image_free(&img);
    /* grey: one value per pixel is all that is read */
    assert_int_equal(lx_image_alloc(&img, 8, 4, 1), LX_OK);
    img.data[31] = INFINITY;
    expect_error(&img, NULL, "1 texel is NaN or infinite (the first at pixel (7, 3))");
    lx_image_free(&img);
    lx_cubemap c;
    assert_int_equal(lx_env_from_image(NULL, "none", NULL, &c), LX_ERR_INVALID);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(grey_equirect_is_constant),
        cmocka_unit_test(rgba_cross_gives_its_faces),
        cmocka_unit_test(bad_images),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
