/* Tests of images reduced on load (lx_image_load_desc.keep_pixels): the
 * sizes the halvings give, each reduced pixel the area mean of the file's
 * pixels under it - colour averaged in linear light (the sRGB curve of
 * IEC 61966-2-1 written out here), alpha and raw data as codes / 255 -,
 * odd sides by exact area weights (measured on a grid fine enough to
 * split every source and output pixel), floats (PFM) alike, and an image
 * below the size kept loaded to the same floats as without the option. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "luxel/core.h"
#include "helpers.h"
#include "gltf_writer.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* IEC 61966-2-1 decoding, independent of the library's */
static double srgb_decode(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static uint8_t code_at(int x, int y, int c)
{
    return (uint8_t)((x * 37 + y * 91 + c * 53 + (x * y) % 7 * 11) & 255);
}

static uint8_t *pattern(int w, int h, int channels)
{
    uint8_t *p = malloc((size_t)w * h * channels);
    assert_non_null(p);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < channels; c++)
                p[((size_t)y * w + x) * channels + c] = code_at(x, y, c);
    return p;
}

/* The value the load gives source pixel (x, y) channel c. */
static double loaded(const uint8_t *p, int w, int channels, int x, int y, int c, bool raw)
{
    double v = p[((size_t)y * w + x) * channels + c] / 255.0;
    bool alpha = (channels == 2 || channels == 4) && c == channels - 1;
    return raw || alpha ? v : srgb_decode(v);
}

/* The area mean over output pixel (ox, oy) of a W x H result: the source
 * sampled on a grid of W x H cells per source pixel, so every cell lies in
 * one source pixel and one output pixel. */
static double area_mean(const uint8_t *p, int w, int h, int channels, int W, int H, int ox, int oy,
                        int c, bool raw)
{
    double sum = 0.0;
    int n = 0;
    for (int gy = oy * h; gy < (oy + 1) * h; gy++)
        for (int gx = ox * w; gx < (ox + 1) * w; gx++) {
            /* cell (gx, gy) of a (w W) x (h H) grid lies in source pixel (gx / W, gy / H) */
            sum += loaded(p, w, channels, gx / W, gy / H, c, raw);
            n++;
        }
    return sum / n;
}

static void check_reduced(int w, int h, int channels, bool raw, uint64_t keep, int want_w,
                          int want_h)
{
    const char *dir = lx_test_dir("image_reduce");
    char path[1200];
    snprintf(path, sizeof path, "%s/p%dx%dx%d.png", dir, w, h, channels);
    uint8_t *p = pattern(w, h, channels);
    lx_test_write_png(path, w, h, channels, p);
    lx_image_load_desc d = {.raw_8bit = raw, .keep_pixels = keep};
    lx_image img;
    assert_int_equal(lx_image_load(path, &d, &img), LX_OK);
    assert_int_equal(img.width, want_w);
    assert_int_equal(img.height, want_h);
    assert_int_equal(img.channels, channels);
    double worst = 0.0;
    for (int y = 0; y < want_h; y++)
        for (int x = 0; x < want_w; x++)
            for (int c = 0; c < channels; c++) {
                double want = area_mean(p, w, h, channels, want_w, want_h, x, y, c, raw);
                double got = img.data[((size_t)y * want_w + x) * channels + c];
                worst = fmax(worst, fabs(got - want));
            }
    /* float results of double sums; the library's sRGB table is float */
    if (worst > 2e-6)
        fail_msg("%dx%d -> %dx%d: worst error %g", w, h, want_w, want_h, worst);
    lx_image_free(&img);
    free(p);
}

static void test_sizes(void **state)
{
    (void)state;
    /* 64x32: 32x16 (512) and 16x8 (128) hold 100 pixels, 8x4 (32) not */
    check_reduced(64, 32, 3, false, 100, 16, 8);
    /* fewer than 4 x keep_pixels: as stored; 0: as stored */
    check_reduced(16, 16, 3, false, 65, 16, 16);
    check_reduced(16, 16, 3, false, 0, 16, 16);
    /* exactly 4 x keep_pixels: halved once */
    check_reduced(16, 16, 4, false, 64, 8, 8);
}

static void test_linear_mean(void **state)
{
    (void)state;
    /* sRGB colour averaged in linear light, alpha as codes; raw data as codes */
    check_reduced(32, 32, 4, false, 16, 4, 4);
    check_reduced(32, 32, 3, true, 64, 8, 8);
    check_reduced(16, 8, 2, false, 8, 4, 2);
    check_reduced(8, 8, 1, false, 1, 1, 1);
}

static void test_odd_sides(void **state)
{
    (void)state;
    /* 5x3 -> 3x2 (one halving, sides rounded up): fractional weights */
    check_reduced(5, 3, 3, false, 6, 3, 2);
    /* 33x17 -> 17x9 -> 9x5 */
    check_reduced(33, 17, 4, false, 45, 9, 5);
    /* a strip: 64x1 -> 16x1 */
    check_reduced(64, 1, 3, false, 16, 16, 1);
}

/* Below the size kept, the same floats as a plain load. */
static void test_unreduced_same(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("image_reduce_same");
    char path[1200];
    snprintf(path, sizeof path, "%s/same.png", dir);
    uint8_t *p = pattern(24, 20, 4);
    lx_test_write_png(path, 24, 20, 4, p);
    free(p);
    lx_image a, b;
    lx_image_load_desc plain = {.channels = 4}, kept = {.channels = 4, .keep_pixels = 24 * 20};
    assert_int_equal(lx_image_load(path, &plain, &a), LX_OK);
    assert_int_equal(lx_image_load(path, &kept, &b), LX_OK);
    assert_int_equal(a.width, b.width);
    assert_int_equal(a.height, b.height);
    assert_memory_equal(a.data, b.data, sizeof(float) * 24 * 20 * 4);
    lx_image_free(&a);
    lx_image_free(&b);
}

/* Float files (PFM, decoded whole and reduced after): the plain mean. */
static void test_float_file(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("image_reduce_pfm");
    char path[1200];
    snprintf(path, sizeof path, "%s/f.pfm", dir);
    lx_image src;
    assert_int_equal(lx_image_alloc(&src, 8, 6, 3), LX_OK);
    for (int i = 0; i < 8 * 6 * 3; i++)
        src.data[i] = (float)(i % 13) * 0.25f + (float)(i / 24);
    assert_int_equal(lx_image_write(path, &src, NULL), LX_OK);
    lx_image_load_desc d = {.keep_pixels = 12};
    lx_image img;
    assert_int_equal(lx_image_load(path, &d, &img), LX_OK);
    assert_int_equal(img.width, 4);
    assert_int_equal(img.height, 3);
    for (int y = 0; y < 3; y++)
        for (int x = 0; x < 4; x++)
            for (int c = 0; c < 3; c++) {
                double sum = 0.0;
                for (int j = 0; j < 2; j++)
                    for (int i = 0; i < 2; i++)
                        sum += src.data[((size_t)(2 * y + j) * 8 + 2 * x + i) * 3 + c];
                assert_float_equal(img.data[((size_t)y * 4 + x) * 3 + c], sum / 4.0, 1e-6);
            }
    lx_image_free(&img);
    lx_image_free(&src);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sizes),
        cmocka_unit_test(test_linear_mean),
        cmocka_unit_test(test_odd_sides),
        cmocka_unit_test(test_unreduced_same),
        cmocka_unit_test(test_float_file),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
