/* Tests of images and their files: the sRGB curve against IEC 61966-2-1, PFM bytes against
 * the format's definition, round trips through every format, bad files failing cleanly. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include "luxel/core.h"
#include "core/internal.h"

#include <OpenEXR/openexr.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* ---- helpers ------------------------------------------------------------- */

static int count_files(const char *dir, bool remove_them)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        n++;
        char p[1400];
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (remove_them)
            remove(p);
    }
    closedir(d);
    return n;
}

/* A fresh, empty folder $LX_TEST_TMP/image/<name> (mkdir -p; $LX_TEST_TMP defaults to /tmp) */
static const char *test_dir(const char *name)
{
    static char dir[1024];
    const char *root = getenv("LX_TEST_TMP");
    snprintf(dir, sizeof dir, "%s/image/%s", root && root[0] ? root : "/tmp", name);
    for (char *p = dir + 1; *p; p++) {
        if (*p == '/') {
            *p = '\0';
            mkdir(dir, 0777);
            *p = '/';
        }
    }
    mkdir(dir, 0777);
    count_files(dir, true);
    return dir;
}

static char *path_in(const char *dir, const char *file)
{
    static char buf[4][1300];
    static int next;
    char *p = buf[next++ % 4];
    snprintf(p, sizeof buf[0], "%s/%s", dir, file);
    return p;
}

static unsigned char *read_all(const char *path, size_t *size)
{
    char *buf;
    assert_int_equal(lx_read_file(path, (size_t)1 << 30, &buf, size), LX_OK);
    return (unsigned char *)buf;
}

static void assert_error_mentions(const char *needle)
{
    if (!strstr(lx_last_error(), needle))
        fail_msg("error \"%s\" does not mention \"%s\"", lx_last_error(), needle);
}

static lx_image make(int w, int h, int c)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, w, h, c), LX_OK);
    return img;
}

/* Deterministic test values in [lo, hi). */
static void fill(lx_image *img, float lo, float hi, uint32_t seed)
{
    size_t n = (size_t)img->width * img->height * img->channels;
    for (size_t i = 0; i < n; i++)
        img->data[i] = lo + (hi - lo) * lx_random(seed, (uint32_t)i, 0, 0);
}

/* Loading bytes as name fails with want and a message naming the file. */
static void load_fails(const void *bytes, size_t size, const char *name, lx_status want,
                       const char *mentions)
{
    lx_image img = {.width = 99};
    assert_int_equal(lx_image_load_memory(bytes, size, name, NULL, &img), want);
    assert_true(img.data == NULL && img.width == 0);
    assert_error_mentions(name);
    assert_error_mentions(mentions);
}

static lx_image load_ok(const char *path, const lx_image_load_desc *desc)
{
    lx_image img;
    if (lx_image_load(path, desc, &img) != LX_OK)
        fail_msg("%s", lx_last_error());
    return img;
}

/* The sRGB formulas of IEC 61966-2-1, written out independently of the library. */
static double ref_linear_to_srgb(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static double ref_srgb_to_linear(double c)
{
    return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

static float le_float(const unsigned char *b)
{
    uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
    float f;
    memcpy(&f, &u, 4);
    return f;
}

static void put_float(unsigned char *b, float f, bool big_endian)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    for (int i = 0; i < 4; i++)
        b[big_endian ? 3 - i : i] = (unsigned char)(u >> (8 * i));
}

/* ---- sRGB, formats, allocation --------------------------------------------- */

static void test_srgb_curve(void **state)
{
    (void)state;
    /* 0 -> 0 and 1 -> 1 both ways: k = 0 and 255 in the loop below */
    assert_true(lx_linear_to_srgb(0.0f) == 0.0f && lx_srgb_to_linear(0.0f) == 0.0f);
    /* the segments meet at linear 0.0031308 = encoded 0.04045 (the
     * published, rounded pair: 12.92 x 0.0031308 = 0.0404499); measured
     * 8.9e-8 and 4.9e-9 off, bounds 3e-7 and 1.5e-8 */
    assert_float_equal(lx_linear_to_srgb(0.0031308f), 0.04045f, 3e-7f);
    assert_float_equal(lx_srgb_to_linear(0.04045f), 0.0031308f, 1.5e-8f);
    /* slope 12.92: measured one float ulp (9.3e-10), bound three */
    assert_float_equal(lx_linear_to_srgb(0.001f), 0.01292f, 3e-9f);
    /* the published 0.214041 (six digits): measured 1.5e-7, bound 5e-7 */
    assert_float_equal(lx_srgb_to_linear(0.5f), 0.214041f, 5e-7f);
    /* both ways at every 8-bit code: measured 5.0e-8 and 4.5e-8 (float
     * rounding in [0, 1]), bounds 1.5e-7 */
    for (int k = 0; k <= 255; k++) {
        double c = k / 255.0;
        assert_float_equal(lx_srgb_to_linear((float)c), ref_srgb_to_linear(c), 1.5e-7);
        assert_float_equal(lx_linear_to_srgb((float)ref_srgb_to_linear(c)), c, 1.5e-7);
    }
}

static void test_format_names(void **state)
{
    (void)state;
    const char *paths[] = {"a/b/sky.EXR", "x.hdr",  "x.Pfm",   "x.png", "x.jpg", "x.JPEG",
                           "x.tga",       "x.pngx", "d.png/f", ".png",  "noext"};
    const lx_image_format want[] = {LX_IMAGE_EXR, LX_IMAGE_HDR, LX_IMAGE_PFM, LX_IMAGE_PNG,
                                    LX_IMAGE_JPG, LX_IMAGE_JPG, LX_IMAGE_TGA};
    for (size_t i = 0; i < sizeof paths / sizeof paths[0]; i++)
        assert_int_equal(lx_image_format_from_path(paths[i]), i < 7 ? want[i] : LX_IMAGE_AUTO);
    assert_string_equal(lx_image_format_extension(LX_IMAGE_EXR), "exr");
    assert_string_equal(lx_image_format_extension(LX_IMAGE_JPG), "jpg");
    assert_null(lx_image_format_extension(LX_IMAGE_AUTO));
}

static void test_alloc(void **state)
{
    (void)state;
    lx_image img = make(3, 2, 4);
    for (int i = 0; i < 24; i++)
        assert_true(img.data[i] == 0.0f);
    lx_image_free(&img);
    assert_null(img.data);
    lx_image_free(&img); /* freeing twice, a zeroed image or NULL is harmless */
    lx_image_free(NULL);
    int bad[][3] = {{0, 2, 3}, {2, -1, 3}, {2, 2, 5}, {2, 2, 0}};
    for (int i = 0; i < 4; i++) {
        assert_int_equal(lx_image_alloc(&img, bad[i][0], bad[i][1], bad[i][2]), LX_ERR_INVALID);
        assert_null(img.data);
    }
    /* 100000^2 RGBA floats = 149 GiB; fails up front, saying how much */
    if (lx_memory_available(NULL) < 160000000000ull) {
        assert_int_equal(lx_image_alloc(&img, 100000, 100000, 4), LX_ERR_NOMEM);
        assert_null(img.data);
        assert_error_mentions("100000x100000");
        assert_error_mentions("149.0 GiB");
    }
}

/* ---- PFM ------------------------------------------------------------------- */

static void test_pfm_round_trip(void **state)
{
    (void)state;
    const char *dir = test_dir("pfm_round_trip");
    for (int c = 1; c <= 3; c += 2) {
        lx_image img = make(7, 5, c);
        fill(&img, -100.0f, 1000.0f, 1);
        memcpy(img.data, (const float[]){1e-40f, -0.0f, 3.0e38f}, 3 * sizeof(float));
        const char *p = path_in(dir, c == 1 ? "grey.pfm" : "rgb.pfm");
        assert_int_equal(lx_image_write(p, &img, NULL), LX_OK);
        lx_image back = load_ok(p, NULL);
        assert_true(back.width == 7 && back.height == 5 && back.channels == c);
        assert_memory_equal(back.data, img.data, sizeof(float) * 7 * 5 * (size_t)c);
        lx_image_free(&img);
        lx_image_free(&back);
    }
    assert_int_equal(count_files(dir, false), 2);
}

/* The file as the PFM definition describes it: "PF\n" (colour), "W H\n",
 * "-1.0\n" (negative scale = little endian), then rows bottom to top. */
static void test_pfm_byte_layout(void **state)
{
    (void)state;
    const char *dir = test_dir("pfm_layout");
    lx_image img = make(2, 3, 4);
    for (int i = 0; i < 2 * 3 * 4; i++)
        img.data[i] = (float)i + 0.25f;
    const char *p = path_in(dir, "layout.pfm");
    lx_image_write_desc wd = {.exposure = 2.0f};
    assert_int_equal(lx_image_write(p, &img, &wd), LX_OK);
    size_t size, hl = strlen("PF\n2 3\n-1.0\n");
    unsigned char *b = read_all(p, &size);
    assert_int_equal(size, hl + 2 * 3 * 3 * 4);
    assert_memory_equal(b, "PF\n2 3\n-1.0\n", hl);
    /* the file's first row is the image's bottom row (y = 2); alpha is
     * dropped and the exposure applied */
    const unsigned char *px = b + hl;
    for (int y = 2; y >= 0; y--)
        for (int x = 0; x < 2; x++)
            for (int c = 0; c < 3; c++, px += 4)
                assert_true(le_float(px) == 2.0f * img.data[(y * 2 + x) * 4 + c]);
    free(b);
    lx_image_free(&img);

    img = make(1, 2, 1); /* grey: "Pf", bottom value first */
    img.data[0] = 1.5f;
    img.data[1] = -2.0f;
    assert_int_equal(lx_image_write(p, &img, NULL), LX_OK);
    b = read_all(p, &size);
    assert_true(size == 20 && memcmp(b, "Pf\n1 2\n-1.0\n", 12) == 0);
    assert_true(le_float(b + 12) == -2.0f && le_float(b + 16) == 1.5f);
    free(b);
    lx_image_free(&img);
}

static void test_pfm_read(void **state)
{
    (void)state;
    /* positive scale = big endian; its magnitude does not scale values */
    unsigned char buf[64] = "Pf\n2  1\n\t2.5\n";
    size_t hl = strlen((char *)buf);
    put_float(buf + hl, 0.5f, true);
    put_float(buf + hl + 4, -7.0f, true);
    lx_image img;
    assert_int_equal(lx_image_load_memory(buf, hl + 8, "be.pfm", NULL, &img), LX_OK);
    assert_true(img.width == 2 && img.height == 1 && img.channels == 1);
    assert_true(img.data[0] == 0.5f && img.data[1] == -7.0f);
    lx_image_free(&img);

    /* NaN and infinity are refused on load, naming the pixel */
    const float bad[2] = {NAN, INFINITY};
    for (int k = 0; k < 2; k++) {
        memcpy(buf, "PF\n2 1\n-1.0\n", 13);
        float v[6] = {1, 2, 3, 4, bad[k], 6};
        for (int i = 0; i < 6; i++)
            put_float(buf + 12 + 4 * i, v[i], false);
        load_fails(buf, 12 + 24, "nan.pfm", LX_ERR_FORMAT,
                   "nan.pfm: pixel (1, 0) channel 1 is not finite");
    }
}

static void test_pfm_bad(void **state)
{
    (void)state;
    struct {
        const char *bytes, *mentions;
    } cases[] = {
        {"PF\n", "width"},
        {"PF\n4", "height"},
        {"PF\n4 4", "scale"},
        {"PF\n4 4\n-1.0", "line break"},
        {"PF\n0 4\n-1.0\n", "width 0"},
        {"PF\n-4 4\n-1.0\n", "width"},
        {"PF\n4 x\n-1.0\n", "height"},
        {"PF\n99999999999 4\n-1.0\n", "out of range"},
        {"PF\n2147483647 2147483647\n-1.0\n", "overflow"},
        {"PF\n2147483647 1\n-1.0\n", "expected 25769803764 bytes of pixels, found 0"},
        {"PF\n4 4\n0\n", "scale"},
        {"PF\n4 4\nnan\n", "scale"},
        {"PF\n4 4\n-1.0x\n", "scale"},
        {"PF\n4 4\n-1.0\n\x01\x02", "truncated: expected 192 bytes of pixels, found 2"},
        {"PF\n256 256\n-1.0\n", "expected 786432 bytes of pixels, found 0"},
        {"PF\n1 1\n-1.000000000000000000000000000000000000000000000000000000000000000000",
         "too long"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        load_fails(cases[i].bytes, strlen(cases[i].bytes), "bad.pfm", LX_ERR_FORMAT,
                   cases[i].mentions);
    /* the loader names the file on disk */
    const char *p = path_in(test_dir("pfm_bad"), "x.pfm");
    FILE *fp = fopen(p, "wb");
    assert_true(fp && fwrite("PF\n16 16\n-1.0\n\0\0\0\0", 1, 18, fp) == 18 && fclose(fp) == 0);
    lx_image img;
    assert_int_equal(lx_image_load(p, NULL, &img), LX_ERR_FORMAT);
    assert_error_mentions(p);
    assert_error_mentions("truncated: expected 3072 bytes of pixels, found 4");
}

/* ---- EXR ------------------------------------------------------------------- */

static void test_exr_float_round_trip(void **state)
{
    (void)state;
    const char *dir = test_dir("exr_float");
    for (int c = 1; c <= 4; c++) {
        /* 37 rows: an odd count for any chunking (float files are uncompressed,
         * one scanline a chunk; half files ZIP, 16) */
        lx_image img = make(53, 37, c);
        fill(&img, -5.0f, 50000.0f, (uint32_t)c);
        memcpy(img.data, (const float[]){1e-42f, 3.0e38f}, 2 * sizeof(float)); /* tiny, huge */
        const char *p = path_in(dir, (const char *[]){"1.exr", "2.exr", "3.exr", "4.exr"}[c - 1]);
        assert_int_equal(lx_image_write(p, &img, NULL), LX_OK);
        lx_image back = load_ok(p, NULL);
        assert_true(back.width == 53 && back.height == 37 && back.channels == c);
        assert_memory_equal(back.data, img.data, sizeof(float) * 53 * 37 * (size_t)c);
        lx_image_free(&img);
        lx_image_free(&back);
    }
}

/* binary16 keeps 11 significant bits: a normal value comes back within
 * 2^-11 relative, a subnormal within 2^-25 absolute. */
static void test_exr_half_round_trip(void **state)
{
    (void)state;
    const char *dir = test_dir("exr_half");
    lx_image img = make(19, 17, 4);
    fill(&img, -60000.0f, 60000.0f, 7);
    float specials[] = {65504.0f, -65504.0f, 6.1035156e-5f, 5.9604645e-8f, 1e-9f,
                        0.1f,     1.0f,      0.333f,        2049.0f};
    memcpy(img.data, specials, sizeof specials);
    const char *p = path_in(dir, "h.exr");
    lx_image_write_desc wd = {.half = true};
    assert_int_equal(lx_image_write(p, &img, &wd), LX_OK);
    lx_image back = load_ok(p, NULL);
    assert_int_equal(back.channels, 4);
    for (size_t i = 0; i < 19 * 17 * 4; i++) {
        double v = img.data[i], got = back.data[i];
        double tol = fabs(v) >= 6.1035156e-5 ? fabs(v) * 0x1p-11 : 0x1p-25;
        if (fabs(got - v) > tol)
            fail_msg("value %zu: wrote %.9g, read %.9g", i, v, got);
    }
    assert_true(back.data[0] == 65504.0f && back.data[1] == -65504.0f);
    /* 2049 lies halfway between halves 2048 and 2050: ties go to even */
    assert_true(back.data[8] == 2048.0f);
    lx_image_free(&back);

    /* beyond the half range: refused, naming the pixel, nothing written */
    img.data[(3 * 19 + 2) * 4 + 1] = 70000.0f;
    p = path_in(dir, "big.exr");
    assert_int_equal(lx_image_write(p, &img, &wd), LX_ERR_INVALID);
    assert_error_mentions("big.exr: pixel (2, 3) channel 1");
    assert_error_mentions("half");
    img.data[(3 * 19 + 2) * 4 + 1] = 40000.0f; /* fits, but not after exposure */
    wd.exposure = 2.0f;
    assert_int_equal(lx_image_write(p, &img, &wd), LX_ERR_INVALID);
    assert_int_equal(count_files(dir, false), 1); /* h.exr */
    lx_image_free(&img);
}

static void test_exr_truncated_and_corrupted(void **state)
{
    (void)state;
    const char *dir = test_dir("exr_bad");
    lx_image img = make(40, 40, 3);
    fill(&img, 0.0f, 1.0f, 3);
    const char *p = path_in(dir, "good.exr");
    assert_int_equal(lx_image_write(p, &img, NULL), LX_OK);
    lx_image_free(&img);
    size_t size;
    unsigned char *b = read_all(p, &size);
    /* every truncation fails with a message naming the file */
    for (size_t len = 1; len < size; len += (len < 400 ? 1 : 37)) {
        lx_image out;
        lx_status s = lx_image_load_memory(b, len, "cut.exr", NULL, &out);
        if (s != LX_ERR_FORMAT && s != LX_ERR_IO)
            fail_msg("cut to %zu of %zu bytes: %s (%s)", len, size, lx_status_name(s),
                     lx_last_error());
        assert_null(out.data);
        assert_error_mentions("cut.exr");
    }
    lx_image out;
    /* flipped bytes must never crash; a failure names the file */
    unsigned char *c = malloc(size);
    for (size_t i = 0; i < size; i++) {
        memcpy(c, b, size);
        c[i] ^= (unsigned char)(1u + (i * 37u) % 255u);
        if (lx_image_load_memory(c, size, "flip.exr", NULL, &out) == LX_OK)
            lx_image_free(&out);
        else
            assert_error_mentions("flip.exr");
    }
    free(c);
    free(b);
}

/* ---- HDR ------------------------------------------------------------------- */

static void test_hdr_round_trip(void **state)
{
    (void)state;
    const char *p = path_in(test_dir("hdr"), "x.hdr");
    lx_image img = make(41, 9, 3);
    fill(&img, 0.0f, 5000.0f, 11);
    memcpy(img.data, (const float[]){1e-20f, 1, 1, 0, 0, 0}, 6 * sizeof(float));
    assert_int_equal(lx_image_write(p, &img, NULL), LX_OK);
    lx_image back = load_ok(p, NULL);
    assert_true(back.channels == 3 && back.width == 41 && back.height == 9);
    /* RGBE: 8-bit mantissas share the pixel's exponent, so each value is within 1/256 of
     * the pixel's power-of-two scale 2^e (stb truncates: up to 1/128 of the largest) */
    for (int i = 0; i < 41 * 9; i++) {
        const float *v = img.data + i * 3, *g = back.data + i * 3;
        int e;
        frexp(fmaxf(v[0], fmaxf(v[1], v[2])), &e);
        for (int c = 0; c < 3; c++)
            if (fabs((double)g[c] - v[c]) > ldexp(1.0, e - 8))
                fail_msg("pixel %d channel %d: wrote %g, read %g", i, c, v[c], g[c]);
    }
    assert_true(back.data[3] == 0.0f && back.data[5] == 0.0f);
    lx_image_free(&back);
    lx_image_free(&img);
}

/* ---- 8-bit formats ----------------------------------------------------------- */

static int ref_srgb8(double linear)
{
    if (linear <= 0.0)
        return 0;
    return linear >= 1.0 ? 255 : (int)floor(255.0 * ref_linear_to_srgb(linear) + 0.5);
}

static int code8(float v)
{
    return (int)lroundf(v * 255.0f);
}

/* Writes values (w x 1, c channels) as PNG with exposure, checks the 8-bit codes in the
 * file, and that decoding gives each code's linear value. */
static void check_png(const char *p, const float *values, int w, int c, float exposure,
                      const int *codes)
{
    lx_image img = make(w, 1, c);
    memcpy(img.data, values, sizeof(float) * (size_t)(w * c));
    lx_image_write_desc wd = {.exposure = exposure};
    assert_int_equal(lx_image_write(p, &img, &wd), LX_OK);
    lx_image_load_desc rd = {.raw_8bit = true};
    lx_image raw = load_ok(p, &rd), lin = load_ok(p, NULL);
    assert_int_equal(raw.channels, c);
    for (int i = 0; i < w * c; i++) {
        bool alpha = c == 4 && i % 4 == 3; /* alpha stays linear and unexposed */
        int want = codes ? codes[i] : ref_srgb8(values[i] * exposure);
        assert_int_equal(code8(raw.data[i]), want);
        /* measured 3.1e-8 (float rounding in [0, 1]), bound 1.5e-7 */
        assert_float_equal(lin.data[i], alpha ? want / 255.0 : ref_srgb_to_linear(want / 255.0),
                           1.5e-7);
    }
    lx_image_free(&raw);
    lx_image_free(&lin);
    lx_image_free(&img);
}

static void test_png_code_values(void **state)
{
    (void)state;
    const char *dir = test_dir("png");
    /* known codes; code 128 starts at linear 0.214041 (0.214 encodes to 127.49) */
    check_png(path_in(dir, "known.png"), (const float[]){0.5f, 0.2142f, 0.0f, 1.0f}, 4, 1, 1.0f,
              (const int[]){188, 128, 0, 255});
    const float values[] = {2.0f, -1.0f, 0.0031308f, 0.001f, 0.18f, 0.9f, 0.05f, 0.7f};
    check_png(path_in(dir, "grey.png"), values, 8, 1, 1.0f, NULL);
    check_png(path_in(dir, "rgba.png"), (const float[]){0.25f, 0.1071f, 1.0f, 0.5f}, 1, 4, 2.0f,
              (const int[]){188, 128, 255, 128});
}

/* Hand-built PNGs (ISO/IEC 15948 chunks around a zlib stream): the 16-bit path
 * stb_image_write cannot produce, and a bad stream. */
static void put_be32(unsigned char *b, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        b[i] = (unsigned char)(v >> (24 - 8 * i));
}

static size_t put_chunk(unsigned char *out, const char *type, const void *data, uint32_t n)
{
    put_be32(out, n);
    memcpy(out + 4, type, 4);
    memcpy(out + 8, data, n);
    uint32_t crc = ~0u; /* CRC-32 of type and data */
    for (uint32_t i = 4; i < n + 8; i++)
        for (int k = 0, byte = out[i]; k < 8; k++, byte >>= 1)
            crc = (crc >> 1) ^ (0xedb88320u & (0u - ((crc ^ (uint32_t)byte) & 1u)));
    put_be32(out + 8 + n, ~crc);
    return 12 + n;
}

static void test_png_built(void **state)
{
    (void)state;
    /* 3x1 grey, 16 bits: 0, 32768, 65535 */
    unsigned char png[256] = "\x89PNG\r\n\x1a\n", ihdr[13] = {0, 0, 0, 3, 0, 0, 0, 1, 16};
    size_t n = 8 + put_chunk(png + 8, "IHDR", ihdr, 13);
    const unsigned char raw[7] = {0, 0x00, 0x00, 0x80, 0x00, 0xff, 0xff}; /* filter 0 */
    unsigned char z[18] = {0x78, 0x01, 1, 7, 0, 0xf8, 0xff};
    memcpy(z + 7, raw, 7);
    uint32_t a = 1, b = 0;
    for (int i = 0; i < 7; i++) {
        a = (a + raw[i]) % 65521;
        b = (b + a) % 65521;
    }
    put_be32(z + 14, b << 16 | a); /* Adler-32 */
    n += put_chunk(png + n, "IDAT", z, sizeof z);
    n += put_chunk(png + n, "IEND", "", 0);

    for (int raw8 = 0; raw8 < 2; raw8++) {
        lx_image img;
        lx_image_load_desc rd = {.raw_8bit = raw8};
        assert_int_equal(lx_image_load_memory(png, n, "w.png", &rd, &img), LX_OK);
        assert_true(img.width == 3 && img.channels == 1 && img.data[0] == 0.0f);
        double mid = 32768.0 / 65535.0;
        /* measured 4.5e-9 and exactly 1; bounds one float ulp at 0.5 and 1 */
        assert_float_equal(img.data[1], raw8 ? mid : ref_srgb_to_linear(mid), 6e-8);
        assert_float_equal(img.data[2], 1.0f, 1.2e-7f);
        lx_image_free(&img);
    }
    /* fuzz: 2x1 grey whose fixed-Huffman block (03 3e 00) copies 3 bytes from distance code
     * 30, which stb 2.27 reads as distance 0, copying bytes it never wrote */
    ihdr[3] = 2;
    ihdr[8] = 8;
    n = 8 + put_chunk(png + 8, "IHDR", ihdr, 13);
    n += put_chunk(png + n, "IDAT", (const unsigned char[]){0x78, 1, 0x03, 0x3e, 0, 0, 0, 0, 0}, 9);
    n += put_chunk(png + n, "IEND", "", 0);
    load_fails(png, n, "dist.png", LX_ERR_FORMAT, "dist.png: corrupt PNG: the compressed image");
}

/* ---- the writers' threads -------------------------------------------------- */

static bool same_file(const char *a, const char *b)
{
    size_t na, nb;
    unsigned char *da = read_all(a, &na), *db = read_all(b, &nb);
    bool same = na == nb && memcmp(da, db, na) == 0;
    free(da);
    free(db);
    return same;
}

/* A file read straight through OpenEXRCore (not luxel's reader): its
 * compression, channels and pixels, every channel decoded to float planes,
 * in file (alphabetical) order. */
static float *exr_core_read(const char *path, int *w, int *h, int *channels,
                            exr_compression_t *compression)
{
    exr_context_t ctx;
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    assert_int_equal(exr_start_read(&ctx, path, &init), EXR_ERR_SUCCESS);
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *list;
    int32_t lines;
    assert_int_equal(exr_get_data_window(ctx, 0, &dw), EXR_ERR_SUCCESS);
    assert_int_equal(exr_get_channels(ctx, 0, &list), EXR_ERR_SUCCESS);
    assert_int_equal(exr_get_compression(ctx, 0, compression), EXR_ERR_SUCCESS);
    assert_int_equal(exr_get_scanlines_per_chunk(ctx, 0, &lines), EXR_ERR_SUCCESS);
    *w = dw.max.x - dw.min.x + 1, *h = dw.max.y - dw.min.y + 1, *channels = list->num_channels;
    size_t plane = (size_t)*w * (size_t)*h;
    float *planes = calloc(plane * (size_t)*channels, sizeof(float));
    assert_non_null(planes);
    exr_decode_pipeline_t dec = EXR_DECODE_PIPELINE_INITIALIZER;
    for (int y = 0; y < *h; y += lines) {
        exr_chunk_info_t ci;
        assert_int_equal(exr_read_scanline_chunk_info(ctx, 0, dw.min.y + y, &ci), EXR_ERR_SUCCESS);
        assert_int_equal(y == 0 ? exr_decoding_initialize(ctx, 0, &ci, &dec)
                                : exr_decoding_update(ctx, 0, &ci, &dec),
                         EXR_ERR_SUCCESS);
        for (int c = 0; c < dec.channel_count; c++) {
            exr_coding_channel_info_t *ch = &dec.channels[c];
            ch->user_data_type = EXR_PIXEL_FLOAT;
            ch->user_bytes_per_element = 4;
            ch->user_pixel_stride = 4;
            ch->user_line_stride = *w * 4;
            ch->decode_to_ptr = (uint8_t *)(planes + (size_t)c * plane + (size_t)y * *w);
        }
        if (y == 0)
            assert_int_equal(exr_decoding_choose_default_routines(ctx, 0, &dec), EXR_ERR_SUCCESS);
        assert_int_equal(exr_decoding_run(ctx, 0, &dec), EXR_ERR_SUCCESS);
    }
    exr_decoding_destroy(ctx, &dec);
    exr_finish(&ctx);
    return planes;
}

/* EXR files are the same bytes on 1, 2, 3 and all threads; 32-bit floats
 * are stored uncompressed and come back exactly, halves go through ZIP
 * (16-scanline chunks, the last partial) and come back rounded to the
 * nearest half, through luxel's reader and through OpenEXRCore directly. */
static void test_exr_threads(void **state)
{
    (void)state;
    const char *dir = test_dir("exr_threads");
    for (int half = 0; half < 2; half++)
        for (int c = 1; c <= 4; c++) {
            lx_image img = make(301, 77, c);
            fill(&img, -3.0f, 3000.0f, (uint32_t)(10 * half + c));
            const int threads[] = {1, 2, 3, 0};
            char name[4][64];
            for (int t = 0; t < 4; t++) {
                snprintf(name[t], sizeof name[t], "%d_%d_%d.exr", half, c, threads[t]);
                lx_image_write_desc wd = {.half = half, .threads = threads[t]};
                assert_int_equal(lx_image_write(path_in(dir, name[t]), &img, &wd), LX_OK);
            }
            for (int t = 1; t < 4; t++)
                if (!same_file(path_in(dir, name[0]), path_in(dir, name[t])))
                    fail_msg("%s and %s differ", name[0], name[t]);
            lx_image ours = load_ok(path_in(dir, name[0]), NULL);
            int w, h, nc;
            exr_compression_t comp;
            float *core = exr_core_read(path_in(dir, name[0]), &w, &h, &nc, &comp);
            assert_true(w == 301 && h == 77 && nc == c && ours.channels == c);
            assert_int_equal(comp, half ? EXR_COMPRESSION_ZIP : EXR_COMPRESSION_NONE);
            /* file order is alphabetical: A, B, G, R or A, Y */
            static const int rgba_plane[4][4] = {
                {0}, {1, 0}, {2, 1, 0}, {3, 2, 1, 0}}; /* luxel channel -> plane */
            for (size_t i = 0; i < (size_t)w * h; i++)
                for (int k = 0; k < c; k++) {
                    float v = img.data[i * c + k], a = ours.data[i * c + k];
                    float b = core[(size_t)rgba_plane[c - 1][k] * w * h + i];
                    /* binary16: 11 significant bits, subnormals below 2^-14 */
                    double tol = !half                     ? 0.0
                                 : fabs(v) >= 6.1035156e-5 ? fabs(v) * 0x1p-11
                                                           : 0x1p-25;
                    if (a != b || fabs((double)a - v) > tol)
                        fail_msg("%s pixel %zu channel %d: wrote %.9g, luxel read %.9g, "
                                 "OpenEXRCore read %.9g",
                                 name[0], i, k, v, a, b);
                }
            free(core);
            lx_image_free(&ours);
            lx_image_free(&img);
        }
}

/* The nearest code to 255 x srgb(v), or -1 when v lies within 1e-9 of a
 * midpoint between two codes (where float rounding may go either way). */
static int ref_srgb8_clear(double v)
{
    if (v <= 0.0)
        return 0;
    if (v >= 1.0)
        return 255;
    double x = 255.0 * ref_linear_to_srgb(v);
    double frac = x - floor(x);
    if (fabs(frac - 0.5) < 1e-9)
        return -1;
    return (int)floor(x + 0.5);
}

/* PNG files large enough for many deflate strips are the same bytes on 1,
 * 2, 3 and all threads, and stb decodes each to exactly the 8-bit codes
 * the IEC 61966-2-1 formula gives (ties left out), alpha unexposed. */
static void test_png_threads(void **state)
{
    (void)state;
    const char *dir = test_dir("png_threads");
    const int sizes[2][3] = {{700, 400, 3}, {333, 517, 4}}; /* 820 KiB and 672 KiB */
    for (int s = 0; s < 2; s++) {
        int w = sizes[s][0], h = sizes[s][1], c = sizes[s][2];
        lx_image img = make(w, h, c);
        /* smooth gradients (what previews are) with noise on top */
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++)
                for (int k = 0; k < c; k++)
                    img.data[((size_t)y * w + x) * c + k] =
                        0.4f * (float)(x + k * 37) / (float)w + 0.3f * (float)y / (float)h +
                        0.05f * lx_random(7, (uint32_t)(y * w + x), (uint32_t)k, 0);
        const float exposure = 1.3f;
        const int threads[] = {1, 2, 3, 0};
        char name[4][64];
        for (int t = 0; t < 4; t++) {
            snprintf(name[t], sizeof name[t], "%d_%d.png", s, threads[t]);
            lx_image_write_desc wd = {.exposure = exposure, .threads = threads[t]};
            assert_int_equal(lx_image_write(path_in(dir, name[t]), &img, &wd), LX_OK);
        }
        for (int t = 1; t < 4; t++)
            if (!same_file(path_in(dir, name[0]), path_in(dir, name[t])))
                fail_msg("%s and %s differ", name[0], name[t]);
        lx_image_load_desc rd = {.raw_8bit = true};
        lx_image raw = load_ok(path_in(dir, name[0]), &rd);
        assert_true(raw.width == w && raw.height == h && raw.channels == c);
        size_t checked = 0;
        for (size_t i = 0; i < (size_t)w * h * c; i++) {
            bool alpha = c == 4 && i % 4 == 3;
            double v = img.data[i];
            /* alpha: linear 8-bit, ties (within float rounding) left out */
            double a = 255.0 * fmin(fmax(v, 0.0), 1.0);
            int want = alpha ? (fabs(a - floor(a) - 0.5) < 1e-4 ? -1 : (int)floor(a + 0.5))
                             : ref_srgb8_clear((double)(float)(img.data[i] * exposure));
            if (want < 0)
                continue;
            if (code8(raw.data[i]) != want)
                fail_msg("%s value %zu (%.9g): code %d, want %d", name[0], i, v, code8(raw.data[i]),
                         want);
            checked++;
        }
        assert_true(checked > (size_t)w * h * c * 99 / 100);
        lx_image_free(&raw);
        lx_image_free(&img);
    }
}

/* Every 256th float from 0 to 1 (about 4 million values) encodes to the
 * nearest sRGB code, as the formula in double says (ties left out). */
static void test_srgb8_encoder_exhaustive(void **state)
{
    (void)state;
    const char *dir = test_dir("srgb8");
    const uint32_t top = 0x3f800000u, step = 256;
    const int w = 4096, h = (int)((top / step + 1 + w - 1) / w);
    lx_image img = make(w, h, 1);
    size_t n = 0;
    for (uint32_t bits = 0; bits <= top; bits += step) {
        memcpy(&img.data[n++], &bits, sizeof bits);
    }
    while (n < (size_t)w * h)
        img.data[n++] = 1.0f;
    assert_int_equal(lx_image_write(path_in(dir, "all.png"), &img, NULL), LX_OK);
    lx_image_load_desc rd = {.raw_8bit = true};
    lx_image raw = load_ok(path_in(dir, "all.png"), &rd);
    for (size_t i = 0; i < n; i++) {
        int want = ref_srgb8_clear(img.data[i]);
        if (want >= 0 && code8(raw.data[i]) != want)
            fail_msg("%.9g (bits %08x): code %d, want %d", img.data[i], (unsigned)(i * step),
                     code8(raw.data[i]), want);
    }
    lx_image_free(&raw);
    lx_image_free(&img);
}

/* With bad values in several rows (checked on several threads), the first
 * in memory order is the one named. */
static void test_write_names_first_bad_value(void **state)
{
    (void)state;
    const char *dir = test_dir("first_bad");
    lx_image img = make(64, 200, 3);
    fill(&img, 0.0f, 1.0f, 3);
    img.data[(150 * 64 + 3) * 3 + 1] = NAN;
    img.data[(40 * 64 + 60) * 3 + 2] = INFINITY;
    img.data[(40 * 64 + 61) * 3 + 0] = NAN;
    for (int threads = 1; threads <= 3; threads++) {
        lx_image_write_desc wd = {.threads = threads};
        assert_int_equal(lx_image_write(path_in(dir, "b.exr"), &img, &wd), LX_ERR_INVALID);
        assert_error_mentions("pixel (60, 40) channel 2");
    }
    assert_int_equal(count_files(dir, false), 0);
    lx_image_free(&img);
}

static void test_8bit_formats_round_trip(void **state)
{
    (void)state;
    const char *dir = test_dir("ldr");
    const char *names[] = {"x.png", "x.tga", "x.jpg"};
    for (int f = 0; f < 3; f++) {
        for (int c = 1; c <= 4; c++) {
            if (f == 2 && (c == 2 || c == 4))
                continue; /* JPEG has no alpha */
            lx_image img = make(16, 8, c);
            /* flat colour: JPEG keeps it nearly exactly */
            for (int i = 0; i < 16 * 8 * c; i++)
                img.data[i] = (i % c == 0) ? 0.2f : (i % c == 1) ? 0.5f : 0.8f;
            const char *p = path_in(dir, names[f]);
            assert_int_equal(lx_image_write(p, &img, NULL), LX_OK);
            lx_image back = load_ok(p, NULL);
            assert_true(back.width == 16 && back.height == 8 && (f == 2 || back.channels == c));
            lx_image_load_desc rd = {.channels = c};
            lx_image conv = load_ok(p, &rd);
            /* set by the formats: 8-bit sRGB codes (half a step is up to
             * 0.0043 in linear at 0.8; measured 0.0029) and JPEG's
             * quantisation (measured 0.0051) */
            for (int i = 0; i < 16 * 8 * c; i++) {
                double tol = (f == 2 ? 0.008 : 0.004) * (1 + img.data[i]) + 0.002;
                if (fabs(conv.data[i] - img.data[i]) > tol)
                    fail_msg("%s, %d channels, value %d: %g, wrote %g", names[f], c, i,
                             conv.data[i], img.data[i]);
            }
            lx_image_free(&conv);
            lx_image_free(&back);
            lx_image_free(&img);
        }
    }
}

static void test_8bit_and_hdr_bad(void **state)
{
    (void)state;
    const char *dir = test_dir("ldr_bad");
    lx_image img = make(32, 32, 3);
    fill(&img, 0.0f, 1.0f, 5);
    const char *names[] = {"t.png", "t.jpg", "t.tga", "t.hdr"};
    for (int f = 0; f < 4; f++) {
        const char *p = path_in(dir, names[f]);
        assert_int_equal(lx_image_write(p, &img, NULL), LX_OK);
        size_t size;
        unsigned char *b = read_all(p, &size);
        /* cut short: never crashes; fails naming the file, except that stb
         * fills a cut JPEG or TGA with grey */
        for (size_t len = 0; len < size; len += 1 + len / 8) {
            lx_image out;
            if (lx_image_load_memory(b, len, names[f], NULL, &out) == LX_OK) {
                assert_true(f == 1 || f == 2);
                lx_image_free(&out);
            } else {
                assert_error_mentions(names[f]);
            }
        }
        free(b);
    }
    lx_image_free(&img);
    load_fails("GIF89a......", 12, "fake.png", LX_ERR_FORMAT, "fake.png: not a PNG file");
    load_fails("GIF89a......................", 28, "fake.tga", LX_ERR_FORMAT, "not a TGA");
    load_fails("hello", 5, "notes.txt", LX_ERR_UNSUPPORTED, "unknown image format");
    load_fails("", 0, "empty.png", LX_ERR_FORMAT, "empty.png: empty file");
    lx_image out;
    assert_int_equal(lx_image_load(path_in(dir, "missing.png"), NULL, &out), LX_ERR_IO);
    assert_error_mentions("missing.png");
}

/* ---- channels, NaN, writing errors ------------------------------------------ */

/* Loads path asking for `channels` and compares with want. */
static void check_load(const char *path, int channels, const float *want)
{
    lx_image_load_desc d = {.channels = channels};
    lx_image out = load_ok(path, &d);
    assert_int_equal(out.channels, channels);
    for (int i = 0; i < out.width * out.height * channels; i++) /* measured 6.0e-8 */
        assert_float_equal(out.data[i], want[i], 2e-7);
    lx_image_free(&out);
}

static void test_channel_conversion(void **state)
{
    (void)state;
    const char *dir = test_dir("channels");
    const char *p[3] = {path_in(dir, "rgb.pfm"), path_in(dir, "rgba.exr"),
                        path_in(dir, "grey.exr")};
    float v[3][6] = {{1.0f, 0.0f, 0.0f, 0.25f, 0.5f, 2.0f}, {0.1f, 0.2f, 0.3f, 0.4f}, {0.7f}};
    int w[3] = {2, 1, 1}, c[3] = {3, 4, 1};
    for (int i = 0; i < 3; i++) {
        lx_image img = make(w[i], 1, c[i]);
        memcpy(img.data, v[i], sizeof(float) * (size_t)(w[i] * c[i]));
        assert_int_equal(lx_image_write(p[i], &img, NULL), LX_OK);
        lx_image_free(&img);
    }
    /* alpha 1 added; grey is Rec.709 luminance */
    check_load(p[0], 4, (const float[]){1, 0, 0, 1, 0.25f, 0.5f, 2, 1});
    check_load(p[0], 1, (const float[]){0.2126f, 0.2126f * 0.25f + 0.7152f * 0.5f + 0.0722f * 2});
    /* alpha dropped or kept beside grey */
    check_load(p[1], 3, v[1]);
    check_load(p[1], 2, (const float[]){0.2126f * 0.1f + 0.7152f * 0.2f + 0.0722f * 0.3f, 0.4f});
    check_load(p[2], 3, (const float[]){0.7f, 0.7f, 0.7f}); /* replicated */
    lx_image out;
    lx_image_load_desc d = {.channels = 5};
    assert_int_equal(lx_image_load(p[2], &d, &out), LX_ERR_INVALID);
}

static void test_write_nan_leaves_nothing(void **state)
{
    (void)state;
    const char *dir = test_dir("nan");
    lx_image img = make(4, 3, 3);
    fill(&img, 0.0f, 1.0f, 9);
    float *bad = &img.data[(2 * 4 + 1) * 3 + 2];
    *bad = NAN;
    const char *names[] = {"n.exr", "n.hdr", "n.pfm", "n.png", "n.jpg", "n.tga"};
    for (int i = 0; i < 6; i++) {
        assert_int_equal(lx_image_write(path_in(dir, names[i]), &img, NULL), LX_ERR_INVALID);
        assert_error_mentions(names[i]);
        assert_error_mentions("pixel (1, 2) channel 2");
    }
    *bad = -INFINITY;
    assert_int_equal(lx_image_write(path_in(dir, "i.exr"), &img, NULL), LX_ERR_INVALID);
    assert_error_mentions("infinite");
    *bad = 3e38f; /* finite, but not after the exposure */
    lx_image_write_desc wd = {.exposure = 10.0f};
    assert_int_equal(lx_image_write(path_in(dir, "o.pfm"), &img, &wd), LX_ERR_INVALID);
    assert_error_mentions("exposure");
    assert_int_equal(count_files(dir, false), 0); /* no output, no temporary file */
    lx_image_free(&img);
}

static void test_write_errors(void **state)
{
    (void)state;
    const char *dir = test_dir("write_errors");
    lx_image img = make(2, 2, 3);
    assert_int_equal(lx_image_write(path_in(dir, "x.bmp"), &img, NULL), LX_ERR_INVALID);
    assert_error_mentions("x.bmp");
    lx_image_write_desc wd = {.format = LX_IMAGE_PFM};
    assert_int_equal(lx_image_write(path_in(dir, "x.bmp"), &img, &wd), LX_OK);
    wd.exposure = -1.0f;
    assert_int_equal(lx_image_write(path_in(dir, "y.pfm"), &img, &wd), LX_ERR_INVALID);
    assert_int_equal(lx_image_write(path_in(dir, "no/such/dir/x.exr"), &img, NULL), LX_ERR_IO);
    assert_error_mentions("no/such/dir/x.exr");
    lx_image bad[2] = {{2, 2, 3, NULL}, {2, 2, 5, img.data}};
    for (int i = 0; i < 2; i++)
        assert_int_equal(lx_image_write(path_in(dir, "z.exr"), &bad[i], NULL), LX_ERR_INVALID);
    /* overwriting replaces the file whole */
    img.data[0] = 5.0f;
    wd.exposure = 0.0f; /* means 1 */
    const char *p = path_in(dir, "x.bmp");
    assert_int_equal(lx_image_write(p, &img, &wd), LX_OK);
    size_t size;
    unsigned char *b = read_all(p, &size);
    assert_true(size == 12 + 48 && le_float(b + 12 + 24) == 5.0f); /* bottom row first */
    free(b);
    assert_int_equal(count_files(dir, false), 1); /* x.bmp only */
    lx_image_free(&img);
}

/* ---- found by fuzz/fuzz_image.c ------------------------------------------- */

/* A half-float EXR with a channel luxel does not read ("0" beside B, G, R, made by renaming
 * the "A" of an RGBA file): OpenEXRCore 3.1 crashed decoding it with that channel skipped. */
static void test_fuzz_exr_half_extra_channel(void **state)
{
    (void)state;
    const char *p = path_in(test_dir("fuzz_exr"), "rgba.exr");
    lx_image img = make(11, 3, 4);
    fill(&img, 0.0f, 100.0f, 13);
    lx_image_write_desc wd = {.half = true};
    assert_int_equal(lx_image_write(p, &img, &wd), LX_OK);
    size_t size;
    unsigned char *b = read_all(p, &size);
    /* the channel list: "channels\0chlist\0", its size, the first name */
    size_t at = 8;
    while (at + 22 < size && memcmp(b + at, "channels\0chlist\0", 16) != 0)
        at++;
    assert_true(b[at + 20] == 'A' && b[at + 21] == 0);
    b[at + 20] = '0';
    lx_image back;
    assert_int_equal(lx_image_load_memory(b, size, "extra.exr", NULL, &back), LX_OK);
    assert_int_equal(back.channels, 3);
    for (int i = 0; i < 11 * 3; i++)
        for (int c = 0; c < 3; c++)
            /* half floats: half an ulp of the format (2^-11 relative) */
            assert_float_equal(back.data[i * 3 + c], img.data[i * 4 + c],
                               img.data[i * 4 + c] * 0x1p-11 + 0x1p-25);
    lx_image_free(&back);
    free(b);
    lx_image_free(&img);
}

/* Inputs stb_image 2.27 mishandles, now refused before stb sees them: Radiance RLE with a
 * zero-length run (stb loops forever) or cut inside the runs (reads zeros); JPEGs with a
 * Huffman table of over 256 codes (writes past it), no scan or an AC scan before the DC one
 * (uses uninitialised memory), tiny JPEG and TGA files claiming huge images. */
static void test_fuzz_stb_guards(void **state)
{
    (void)state;
    unsigned char buf[128] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 8\n";
    size_t hl = strlen((char *)buf);
    memcpy(buf + hl, (const unsigned char[]){2, 2, 0, 8, 0x80 + 8, 1, 0, 7}, 8);
    load_fails(buf, hl + 8, "zero.hdr", LX_ERR_FORMAT, "scanline 0: bad run length 0");
    buf[hl + 6] = 0x80 + 8; /* the next channel starts a run, then the file ends */
    load_fails(buf, hl + 8, "cut.hdr", LX_ERR_FORMAT, "cut.hdr: truncated");
    unsigned char jpg[64] = {0xff, 0xd8, 0xff, 0xc4, 0x00, 0x13, 0x00}; /* SOI, DHT */
    memset(jpg + 7, 0xff, 16);                                          /* 16 x 255 codes */
    load_fails(jpg, sizeof jpg, "huff.jpg", LX_ERR_FORMAT, "table at byte 6 has 4080 codes");
    /* SOI, quantization table 0, a 1x1 grey frame, a scan without Huffman tables, EOI */
    unsigned char jpg2[128] = {0xff, 0xd8, 0xff, 0xdb, 0, 67, 0};
    const unsigned char frame[] = {0xff, 0xc0, 0, 11, 8, 0, 1, 0, 1, 1, 1, 0x11, 0};
    const unsigned char scan[] = {0xff, 0xda, 0, 8, 1, 1, 0, 0, 63, 0, 0xff, 0xd9};
    memcpy(jpg2 + 71, frame, 13);
    memcpy(jpg2 + 84, scan, 12);
    load_fails(jpg2, 96, "nodht.jpg", LX_ERR_FORMAT, "scan of component 1 uses an undefined");
    /* progressive: an AC table (one 1-bit code), then an AC scan before any DC scan */
    const unsigned char ac[] = {0xff, 0xc4, 0, 20, 0x10, 1, [21] = 0, 0xff, 0xda,
                                0,    8,    1, 1,  0,    1, 63,       0};
    jpg2[72] = 0xc2;
    memcpy(jpg2 + 84, ac, sizeof ac);
    load_fails(jpg2, 84 + sizeof ac, "ac.jpg", LX_ERR_FORMAT, "1 before its first DC scan");
    memcpy(jpg2 + 84, scan + 10, 2); /* EOI: no scan at all */
    load_fails(jpg2, 86, "noscan.jpg", LX_ERR_FORMAT, "component 1 has no DC scan data");
    memset(jpg2 + 76, 0xff, 4); /* 65535x65535 */
    load_fails(jpg2, 86, "huge.jpg", LX_ERR_FORMAT, "65535x65535 JPEG needs more than 86");
    const unsigned char tga[20] = {0, 0, 10, [12] = 0x03, 0x19, 0x6d, 0x6f, 32};
    load_fails(tga, sizeof tga, "big.tga", LX_ERR_FORMAT, "needs at least 7134595 bytes");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_srgb_curve),
        cmocka_unit_test(test_format_names),
        cmocka_unit_test(test_alloc),
        cmocka_unit_test(test_pfm_round_trip),
        cmocka_unit_test(test_pfm_byte_layout),
        cmocka_unit_test(test_pfm_read),
        cmocka_unit_test(test_pfm_bad),
        cmocka_unit_test(test_exr_float_round_trip),
        cmocka_unit_test(test_exr_half_round_trip),
        cmocka_unit_test(test_exr_truncated_and_corrupted),
        cmocka_unit_test(test_hdr_round_trip),
        cmocka_unit_test(test_png_code_values),
        cmocka_unit_test(test_png_built),
        cmocka_unit_test(test_exr_threads),
        cmocka_unit_test(test_png_threads),
        cmocka_unit_test(test_srgb8_encoder_exhaustive),
        cmocka_unit_test(test_write_names_first_bad_value),
        cmocka_unit_test(test_8bit_formats_round_trip),
        cmocka_unit_test(test_8bit_and_hdr_bad),
        cmocka_unit_test(test_channel_conversion),
        cmocka_unit_test(test_write_nan_leaves_nothing),
        cmocka_unit_test(test_write_errors),
        cmocka_unit_test(test_fuzz_exr_half_extra_channel),
        cmocka_unit_test(test_fuzz_stb_guards),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
