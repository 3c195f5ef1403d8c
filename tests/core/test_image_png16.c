/* lx_image_write_desc.bits = 16: 16-bit PNGs of 1 to 4 channels. Read back
 * by stb_image's 16-bit loader (code independent of the writer), every
 * code comes back exactly: linear codes round(65535 v), sRGB codes of
 * values decoded from codes, alpha linear. The header is checked byte by
 * byte against the PNG specification (IHDR: bit depth 16, colour types 0,
 * 4, 2, 6), and the bytes do not depend on the thread count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "helpers.h"
#include "luxel/core.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* A reproducible code in [0, 65535] for sample i (a 32-bit mix). */
static int code_of(uint32_t i)
{
    uint32_t h = i * 2654435761u;
    h ^= h >> 15;
    h *= 2246822519u;
    h ^= h >> 13;
    return (int)(h & 0xffffu);
}

/* The sRGB decoding of code k / 65535 in double (IEC 61966-2-1). */
static double srgb_decode(int k)
{
    double c = k / 65535.0;
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static char *path_in(const char *tag, const char *name)
{
    static char path[4096];
    snprintf(path, sizeof path, "%s/%s", lx_test_dir(tag), name);
    return path;
}

static unsigned char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *b = malloc((size_t)n);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    *size = (size_t)n;
    return b;
}

/* Writes a w x h image of channels whose sample i is code_of(i) (as
 * sRGB-decoded values unless linear; alpha always linear), reads it back
 * raw and checks every code. */
static void round_trip(int w, int h, int channels, bool linear)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, w, h, channels), LX_OK);
    size_t n = (size_t)w * h * channels;
    bool has_alpha = channels == 2 || channels == 4;
    for (size_t i = 0; i < n; i++) {
        int k = code_of((uint32_t)i);
        bool alpha = has_alpha && (int)(i % channels) == channels - 1;
        img.data[i] = linear || alpha ? (float)(k / 65535.0) : (float)srgb_decode(k);
    }
    const char *path = path_in("png16", "rt.png");
    lx_image_write_desc d = {.bits = 16, .linear = linear};
    assert_int_equal(lx_image_write(path, &img, &d), LX_OK);

    size_t size;
    unsigned char *b = read_all(path, &size);
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const int colour_type[5] = {-1, 0, 4, 2, 6};
    assert_memory_equal(b, sig, 8);
    assert_memory_equal(b + 12, "IHDR", 4);
    assert_int_equal((b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19], w);
    assert_int_equal((b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23], h);
    assert_int_equal(b[24], 16);
    assert_int_equal(b[25], colour_type[channels]);
    free(b);

    lx_image_load_desc ld = {.raw_8bit = true};
    lx_image back;
    assert_int_equal(lx_image_load(path, &ld, &back), LX_OK);
    assert_int_equal(back.width, w);
    assert_int_equal(back.height, h);
    assert_int_equal(back.channels, channels);
    for (size_t i = 0; i < n; i++) {
        int got = (int)lrint(back.data[i] * 65535.0);
        if (got != code_of((uint32_t)i))
            fail_msg("%d channels, %s: sample %zu: code %d, want %d", channels,
                     linear ? "linear" : "sRGB", i, got, code_of((uint32_t)i));
    }
    lx_image_free(&back);
    lx_image_free(&img);
}

static void linear_codes_exact(void **state)
{
    (void)state;
    for (int c = 1; c <= 4; c++)
        round_trip(37, 23, c, true);
}

static void srgb_codes_exact(void **state)
{
    (void)state;
    for (int c = 1; c <= 4; c++)
        round_trip(37, 23, c, false);
}

/* Several deflate strips (128 KiB each): 300 x 200 RGBA is 480 KB of rows. */
static void large_image_exact(void **state)
{
    (void)state;
    round_trip(300, 200, 4, true);
}

/* Values round to the nearest code, and clamp to [0,1] as the 8-bit
 * writer does. */
static void rounding_and_clamp(void **state)
{
    (void)state;
    static const double v[] = {-0.5, 0.0, 0.4 / 65535, 0.6 / 65535, 0.5, 1.0 - 0.4 / 65535, 1.0,
                               7.0};
    static const int want[] = {0, 0, 0, 1, 32768, 65535, 65535, 65535};
    int n = (int)(sizeof v / sizeof v[0]);
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, n, 1, 1), LX_OK);
    for (int i = 0; i < n; i++)
        img.data[i] = (float)v[i];
    const char *path = path_in("png16_round", "r.png");
    lx_image_write_desc d = {.bits = 16, .linear = true};
    assert_int_equal(lx_image_write(path, &img, &d), LX_OK);
    lx_image_load_desc ld = {.raw_8bit = true};
    lx_image back;
    assert_int_equal(lx_image_load(path, &ld, &back), LX_OK);
    for (int i = 0; i < n; i++)
        assert_int_equal((int)lrint(back.data[i] * 65535.0), want[i]);
    lx_image_free(&back);
    lx_image_free(&img);
}

static void same_bytes_any_threads(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 257, 300, 3), LX_OK);
    for (size_t i = 0; i < (size_t)257 * 300 * 3; i++)
        img.data[i] = (float)(code_of((uint32_t)i) / 65535.0);
    char a[4096];
    snprintf(a, sizeof a, "%s", path_in("png16_threads", "a.png"));
    const char *dir = lx_test_dir("png16_threads2");
    char b[4096];
    snprintf(b, sizeof b, "%s/b.png", dir);
    lx_image_write_desc d1 = {.bits = 16, .threads = 1};
    lx_image_write_desc d2 = {.bits = 16, .threads = 2};
    assert_int_equal(lx_image_write(a, &img, &d1), LX_OK);
    assert_int_equal(lx_image_write(b, &img, &d2), LX_OK);
    size_t na, nb;
    unsigned char *ba = read_all(a, &na), *bb = read_all(b, &nb);
    assert_int_equal(na, nb);
    assert_memory_equal(ba, bb, na);
    free(ba);
    free(bb);
    lx_image_free(&img);
}

/* Bit depths other than 8 and 16, and 16 bits in formats without them,
 * fail with the file named and leave no file. */
static void bad_depths(void **state)
{
    (void)state;
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, 4, 4, 3), LX_OK);
    const char *dir = lx_test_dir("png16_bad");
    char path[4096];
    struct stat st;
    snprintf(path, sizeof path, "%s/x.png", dir);
    lx_image_write_desc d = {.bits = 12};
    assert_int_equal(lx_image_write(path, &img, &d), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "x.png"));
    assert_int_not_equal(stat(path, &st), 0);
    d.bits = 16;
    snprintf(path, sizeof path, "%s/x.jpg", dir);
    assert_int_equal(lx_image_write(path, &img, &d), LX_ERR_UNSUPPORTED);
    assert_non_null(strstr(lx_last_error(), "x.jpg"));
    assert_int_not_equal(stat(path, &st), 0);
    assert_int_equal(lx_test_count_files(dir), 0);
    lx_image_free(&img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(linear_codes_exact), cmocka_unit_test(srgb_codes_exact),
        cmocka_unit_test(large_image_exact),  cmocka_unit_test(rounding_and_clamp),
        cmocka_unit_test(same_bytes_any_threads), cmocka_unit_test(bad_depths),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
