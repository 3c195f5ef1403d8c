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

#include "cube_reference.h"
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
                const float *t = lx_test_cube_texel(&c, f, x, y);
                assert_true(t[0] == (float)(100 * f + 10 * y + x));
                assert_true(t[1] == 1.0f && t[2] == 2.0f);
            }
    lx_cubemap_free(&c);
    lx_image_free(&img);
}

/* Flux of a small sun kept by the equirect -> cube conversion, at several
 * elevations up to near the zenith, where an equirect's columns crowd: the
 * equirect's flux is summed here with each pixel's exact solid angle
 * (2 pi / W)(cos t0 - cos t1), the cube's with each texel's exact solid
 * angle (cube_reference.h). */
static void small_sun_keeps_its_flux(void **state)
{
    (void)state;
    const int w = 1024, h = 512, size = 256;
    const double pi = 3.14159265358979323846, radius = 0.5 * pi / 180.0;
    const double elevations[4] = {10.0, 45.0, 80.0, 87.0};
    /* measured: 0.83% at 10 deg (the sun's edge on the 2 x 2 grid per
     * texel), 0.060% at 45, 0.023% at 80 and 0.0081% at 87; bounds about 3x
     * each */
    const double bounds[4] = {0.02, 2e-3, 7e-4, 2.5e-4};
    for (int e = 0; e < 4; e++) {
        double el = elevations[e] * pi / 180.0;
        double sun[3] = {cos(el) * sin(0.3), sin(el), -cos(el) * cos(0.3)};
        lx_image img;
        assert_int_equal(lx_image_alloc(&img, w, h, 3), LX_OK);
        double want = 0.0;
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double phi = 2.0 * pi * ((x + 0.5) / w - 0.5), theta = pi * (y + 0.5) / h;
                double d[3] = {sin(theta) * sin(phi), cos(theta), -sin(theta) * cos(phi)};
                if (d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2] < cos(radius))
                    continue;
                float *p = img.data + ((size_t)y * w + x) * 3;
                p[0] = p[1] = p[2] = 1e6f;
                want += 1e6 * (2.0 * pi / w) * (cos(pi * y / h) - cos(pi * (y + 1) / h));
            }
        lx_env_load_desc d = {.size = size};
        lx_cubemap c;
        assert_int_equal(lx_env_from_image(&img, "sun", &d, &c), LX_OK);
        double got = 0.0;
        for (int f = 0; f < 6; f++)
            for (int y = 0; y < size; y++)
                for (int x = 0; x < size; x++)
                    got +=
                        lx_test_cube_texel(&c, f, x, y)[0] * lx_test_texel_solid_angle(size, x, y);
        if (!(fabs(got / want - 1.0) <= bounds[e]))
            fail_msg("sun at %g deg: cube flux %.6g, equirect flux %.6g", elevations[e], got, want);
        lx_cubemap_free(&c);
        lx_image_free(&img);
    }
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
        cmocka_unit_test(small_sun_keeps_its_flux),
        cmocka_unit_test(bad_images),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
