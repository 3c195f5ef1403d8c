/* lx_image_write_desc.linear: an 8-bit file of data (a lookup table) holds
 * the unorm code round(255 v) of each value, clamped to [0,1], with no sRGB
 * transfer; the default stays sRGB (0.5 -> code 188, IEC 61966-2-1). Codes
 * are read back with raw_8bit (code / 255), so the comparison is exact. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"
#include "luxel/core.h"

#include <math.h>
#include <stdio.h>

static const float values[] = {0.0f, 0.1f, 0.25f, 0.5f, 0.75f, 0.999f, 1.0f, 1.5f};
#define N ((int)(sizeof values / sizeof values[0]))

static lx_image write_and_load(const char *name, const lx_image_write_desc *desc, int channels)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, N, 1, channels), LX_OK);
    for (int i = 0; i < N; i++)
        for (int c = 0; c < channels; c++)
            img.data[i * channels + c] = values[(i + c) % N];
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", lx_test_dir("image_linear"), name);
    assert_int_equal(lx_image_write(path, &img, desc), LX_OK);
    lx_image_free(&img);
    lx_image_load_desc ld = {.raw_8bit = true};
    lx_image back;
    assert_int_equal(lx_image_load(path, &ld, &back), LX_OK);
    return back;
}

static void linear_codes(void **state)
{
    (void)state;
    for (int channels = 1; channels <= 3; channels += 2) {
        lx_image_write_desc d = {.linear = true};
        lx_image back = write_and_load("lut.png", &d, channels);
        for (int i = 0; i < N; i++)
            for (int c = 0; c < channels; c++) {
                double v = values[(i + c) % N];
                int want = (int)floor(fmin(v, 1.0) * 255.0 + 0.5);
                int got = (int)lrint(back.data[i * back.channels + c] * 255.0);
                assert_int_equal(got, want);
            }
        lx_image_free(&back);
    }
}

static void srgb_by_default(void **state)
{
    (void)state;
    lx_image back = write_and_load("srgb.png", NULL, 1);
    /* 0.5 linear: 1.055 * 0.5^(1/2.4) - 0.055 = 0.7354 -> code 188 */
    assert_int_equal((int)lrint(back.data[3] * 255.0), 188);
    lx_image_free(&back);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(linear_codes),
        cmocka_unit_test(srgb_by_default),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
