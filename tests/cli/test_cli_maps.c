/* `luxel normalmap` and `luxel parallaxmap` end to end, on height images
 * written here:
 * - alignment: a 16-bit height with a step between columns 19 and 20 and
 *   one between rows 8 and 9 (clamp) tilts exactly those columns and rows
 *   of the map, by the closed form normalize(-S/2, 0, 1), toward the low
 *   side; the map has the height's (odd) size: no texel offset;
 * - codes: a flat texel is (128, 128, 255) in 8 bits, rgb = n/2 + 1/2
 *   rounded to nearest; --green down negates y; float formats hold the
 *   encoded values unrounded; the same bytes on 1 and 2 threads;
 * - parallax: a flat height comes back as itself (n.z = 1), code for code;
 * - blend: RNM with a flat detail gives the base;
 * - failures: a missing, empty, garbage or zero-size file, a PNG of an
 *   unsupported bit depth, a normal map with too few channels, sizes that
 *   do not match, values PNG cannot hold: one line "luxel: error: " naming
 *   the file, exit 1, and no output (not even its folder); usage errors
 *   exit 2.
 * The CLI is the `luxel` next to this test's executable. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

static char dir[PATH_MAX];
static char err_text[8192];

/* Runs luxel with args (NULL-terminated); stderr into err_text. */
static int run(const char *const *args)
{
    char log[PATH_MAX + 16], out[PATH_MAX + 16];
    snprintf(log, sizeof log, "%s/stderr.txt", dir);
    snprintf(out, sizeof out, "%s/stdout.txt", dir);
    int status = lx_test_run_luxel(args, out, log);
    lx_test_read_text(log, err_text, sizeof err_text);
    return status;
}

static const char *path(const char *name)
{
    static char p[64][PATH_MAX + 64];
    static int next;
    char *b = p[next++ & 63];
    snprintf(b, sizeof p[0], "%s/%s", dir, name);
    return b;
}

static bool exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

static void write_png(const char *name, const lx_image *img, int bits)
{
    lx_image_write_desc d = {.linear = true, .bits = bits};
    if (lx_image_write(path(name), img, &d) != LX_OK)
        fail_msg("%s", lx_last_error());
}

static lx_image load_raw(const char *name)
{
    lx_image_load_desc d = {.raw_8bit = true};
    lx_image img;
    if (lx_image_load(path(name), &d, &img) != LX_OK)
        fail_msg("%s", lx_last_error());
    return img;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_maps"));
    return 0;
}

/* 37 x 23, two steps: h = 0.25 (x >= 20) + 0.5 (row <= 8). */
#define SW 37
#define SH 23
static void write_steps(void)
{
    lx_image h;
    assert_int_equal(lx_image_alloc(&h, SW, SH, 1), LX_OK);
    for (int r = 0; r < SH; r++)
        for (int x = 0; x < SW; x++)
            h.data[r * SW + x] = 0.25f * (x >= 20) + 0.5f * (r <= 8);
    write_png("steps.png", &h, 16);
    lx_image_free(&h);
}

/* The steps' height at (x, row) as a 16-bit code / 65535. */
static double q(int x, int r)
{
    return floor((0.25 * (x >= 20) + 0.5 * (r <= 8)) * 65535 + 0.5) / 65535;
}

static void step_alignment(void **state)
{
    (void)state;
    write_steps();
    const char *args[] = {"normalmap", path("steps.png"), "-o", path("n16.png"), "--bits", "16",
                          "--wrap",    "clamp",          "--strength", "8", "-q", NULL};
    assert_int_equal(run(args), 0);
    lx_image n = load_raw("n16.png");
    assert_int_equal(n.width, SW);
    assert_int_equal(n.height, SH);
    assert_int_equal(n.channels, 3);
    /* dh/dx at columns 19, 20: (0.25 - 0) / 2 in values, S = 8 -> -1 in
     * x; dh/dy (up) at rows 8, 9: (0.5 - 0) / 2 -> -2 in y; the normal is
     * normalize(-S dx, -S dy, 1) */
    double worst = 0;
    for (int r = 0; r < SH; r++)
        for (int x = 0; x < SW; x++) {
            /* the step's two sides as the 16-bit file holds them */
            double gx = (x == 19 || x == 20) ? -8 * (q(20, r) - q(19, r)) / 2 : 0;
            double gy = (r == 8 || r == 9) ? -8 * (q(x, 8) - q(x, 9)) / 2 : 0;
            double len = sqrt(gx * gx + gy * gy + 1);
            double want[3] = {gx / len, gy / len, 1 / len};
            for (int k = 0; k < 3; k++) {
                double got = 2 * n.data[(r * SW + x) * 3 + k] - 1;
                worst = fmax(worst, fabs(got - want[k]));
            }
        }
    /* half a 16-bit code step in the decoded unit: 1/65535 */
    if (worst > 1.0 / 65535 + 1e-7)
        fail_msg("largest error %g", worst);
    lx_image_free(&n);
}

static void codes_and_formats(void **state)
{
    (void)state;
    write_steps();
    const char *a8[] = {"normalmap", path("steps.png"), "-o", path("n8.png"), "-q", NULL};
    assert_int_equal(run(a8), 0);
    lx_image n = load_raw("n8.png");
    /* flat texel (5, 20): (0, 0, 1) -> codes (128, 128, 255) */
    const float *p = n.data + (20 * SW + 5) * 3;
    assert_int_equal((int)lrint(p[0] * 255), 128);
    assert_int_equal((int)lrint(p[1] * 255), 128);
    assert_int_equal((int)lrint(p[2] * 255), 255);
    /* column 20, row 15 (strength 24): n = normalize(-3, 0, 1): codes
     * round((n + 1) / 2 * 255) */
    double l = sqrt(10.0);
    p = n.data + (15 * SW + 20) * 3;
    assert_int_equal((int)lrint(p[0] * 255), (int)floor((-3 / l + 1) / 2 * 255 + 0.5));
    assert_int_equal((int)lrint(p[2] * 255), (int)floor((1 / l + 1) / 2 * 255 + 0.5));
    lx_image_free(&n);

    /* --invert reads the steps as a depth map: heights negated, so the
     * slope's x and y flip and z stays (closed form at column 20, row 15:
     * normalize(+3, 0, 1)); in float, every texel mirrors the plain map */
    const char *inv[] = {"normalmap", path("steps.png"), "-o", path("inv.exr"), "--invert",
                         "-q", NULL};
    const char *plain[] = {"normalmap", path("steps.png"), "-o", path("plain.exr"), "-q", NULL};
    assert_int_equal(run(inv), 0);
    assert_int_equal(run(plain), 0);
    lx_image ni = load_raw("inv.exr"), np = load_raw("plain.exr");
    assert_float_equal(ni.data[(15 * SW + 20) * 3], (3 / l + 1) / 2, 1e-6);
    for (int i = 0; i < SW * SH; i++) {
        assert_float_equal(2 * ni.data[3 * i] - 1, -(2 * np.data[3 * i] - 1), 1e-6);
        assert_float_equal(2 * ni.data[3 * i + 1] - 1, -(2 * np.data[3 * i + 1] - 1), 1e-6);
        assert_float_equal(ni.data[3 * i + 2], np.data[3 * i + 2], 1e-6);
    }
    lx_image_free(&ni);
    lx_image_free(&np);

    /* green down: y negated (row 8 tilts toward +y up, so down it is < 0.5) */
    const char *up[] = {"normalmap", path("steps.png"), "-o", path("up.exr"), "-q", NULL};
    const char *down[] = {"normalmap", path("steps.png"), "-o",   path("down.pfm"),
                          "--green",   "down",            "-q", NULL};
    assert_int_equal(run(up), 0);
    assert_int_equal(run(down), 0);
    lx_image u = load_raw("up.exr"), d = load_raw("down.pfm");
    for (int i = 0; i < SW * SH; i++) {
        assert_float_equal(u.data[3 * i], d.data[3 * i], 1e-7);
        assert_float_equal(2 * u.data[3 * i + 1] - 1, -(2 * d.data[3 * i + 1] - 1), 1e-6);
    }
    double gy = -24 * 0.25, len = sqrt(gy * gy + 1);
    assert_float_equal(u.data[(8 * SW + 3) * 3 + 1], (gy / len + 1) / 2, 1e-6);
    assert_true(u.data[(8 * SW + 3) * 3 + 1] < 0.5f);
    lx_image_free(&u);
    lx_image_free(&d);

    /* the same bytes on one and two threads */
    const char *t1[] = {"normalmap", path("steps.png"), "-o", path("t1.png"), "--filter", "sobel",
                        "--threads", "1", "-q", NULL};
    const char *t2[] = {"normalmap", path("steps.png"), "-o", path("t2.png"), "--filter", "sobel",
                        "--threads", "2", "-q", NULL};
    assert_int_equal(run(t1), 0);
    assert_int_equal(run(t2), 0);
    lx_image x1 = load_raw("t1.png"), x2 = load_raw("t2.png");
    assert_memory_equal(x1.data, x2.data, sizeof(float) * 3 * SW * SH);
    lx_image_free(&x1);
    lx_image_free(&x2);
}

static void parallax_and_blend(void **state)
{
    (void)state;
    lx_image h;
    assert_int_equal(lx_image_alloc(&h, 9, 7, 1), LX_OK);
    for (int i = 0; i < 63; i++)
        h.data[i] = 40000.0f / 65535.0f;
    write_png("flat.png", &h, 16);
    const char *pa[] = {"parallaxmap", path("flat.png"), "-o", path("p.png"), "--bits", "16",
                        "-q", NULL};
    assert_int_equal(run(pa), 0);
    lx_image p = load_raw("p.png");
    assert_int_equal(p.channels, 1);
    assert_int_equal(p.width, 9);
    assert_int_equal(p.height, 7);
    for (int i = 0; i < 63; i++)
        assert_int_equal((int)lrint(p.data[i] * 65535), 40000);
    lx_image_free(&p);
    const char *flat[] = {"normalmap", path("flat.png"), "-o", path("flatn.png"), "-q", NULL};
    assert_int_equal(run(flat), 0);

    write_steps();
    const char *base[] = {"normalmap", path("steps.png"), "-o", path("base.png"), "--bits", "16",
                          "-q", NULL};
    assert_int_equal(run(base), 0);
    /* a flat detail of another size: refused */
    const char *bad[] = {"normalmap", "--blend", path("base.png"), path("flatn.png"), "-o",
                         path("out/b.png"), NULL};
    assert_int_equal(run(bad), 1);
    assert_non_null(strstr(err_text, "flatn.png: 9x7, but the base"));
    assert_false(exists(path("out")));
    /* a flat detail of the base's size: RNM gives the base */
    lx_image f;
    assert_int_equal(lx_image_alloc(&f, SW, SH, 3), LX_OK);
    for (int i = 0; i < SW * SH; i++)
        f.data[3 * i] = f.data[3 * i + 1] = 0.5f, f.data[3 * i + 2] = 1.0f;
    write_png("detail.png", &f, 16);
    lx_image_free(&f);
    const char *bl[] = {"normalmap", "--blend", path("base.png"), path("detail.png"), "-o",
                        path("blend.png"), "--bits", "16", "-q", NULL};
    assert_int_equal(run(bl), 0);
    lx_image b = load_raw("base.png"), r = load_raw("blend.png");
    for (int i = 0; i < SW * SH * 3; i++)
        assert_true(fabs(b.data[i] - r.data[i]) <= 1.5 / 65535);
    lx_image_free(&b);
    lx_image_free(&r);
    lx_image_free(&h);
}

/* ---- failures ------------------------------------------------------------------ */

/* One line, "luxel: error: ", naming `name`; the output folder absent. */
static void expect_failure(const char *const *args, int status, const char *name)
{
    int rc = run(args);
    if (rc != status)
        fail_msg("exit %d, want %d: %s", rc, status, err_text);
    if (strncmp(err_text, "luxel: error: ", 14) != 0 || strchr(err_text, '\n') !=
                                                               err_text + strlen(err_text) - 1)
        fail_msg("not one error line: '%s'", err_text);
    if (name && !strstr(err_text, name))
        fail_msg("'%s' does not name %s", err_text, name);
    assert_false(exists(path("out")));
}

static void write_bytes(const char *name, const unsigned char *b, size_t n)
{
    FILE *f = fopen(path(name), "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(b, 1, n, f), n);
    fclose(f);
}

/* A PNG signature and IHDR (CRC correct) of the given size and depth,
 * grey, and nothing more. */
static void write_header_only_png(const char *name, uint32_t w, uint32_t h, int depth)
{
    unsigned char b[33] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13,
                           'I', 'H', 'D', 'R'};
    uint32_t v[2] = {w, h};
    for (int k = 0; k < 2; k++)
        for (int i = 0; i < 4; i++)
            b[16 + 4 * k + i] = (unsigned char)(v[k] >> (24 - 8 * i));
    b[24] = (unsigned char)depth;
    uLong crc = crc32(0L, b + 12, 17);
    for (int i = 0; i < 4; i++)
        b[29 + i] = (unsigned char)(crc >> (24 - 8 * i));
    write_bytes(name, b, sizeof b);
}

static void bad_inputs(void **state)
{
    (void)state;
    char out[PATH_MAX + 64];
    snprintf(out, sizeof out, "%s", path("out/x.png"));
    write_bytes("empty.png", (const unsigned char *)"", 0);
    write_bytes("garbage.png", (const unsigned char *)"this is no image", 16);
    write_header_only_png("zero.png", 0, 16, 8);
    write_header_only_png("depth3.png", 4, 4, 3);
    const char *files[] = {"missing.png", "empty.png", "garbage.png", "zero.png", "depth3.png"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; i++) {
        const char *in = path(files[i]);
        const char *nm[] = {"normalmap", in, "-o", out, NULL};
        expect_failure(nm, 1, files[i]);
        if (i == 3)
            assert_non_null(strstr(err_text, "no pixels (0x16)"));
        if (i == 4)
            assert_non_null(strstr(err_text, "unsupported bit depth 3"));
        const char *px[] = {"parallaxmap", in, "-o", out, NULL};
        expect_failure(px, 1, files[i]);
        const char *bl[] = {"normalmap", "--blend", in, in, "-o", out, NULL};
        expect_failure(bl, 1, files[i]);
    }
    /* a grey image is no normal map */
    write_steps();
    const char *grey[] = {"normalmap", "--blend", path("steps.png"), path("steps.png"), "-o",
                          out, NULL};
    expect_failure(grey, 1, "steps.png: 1 channel;");
    /* float heights outside [0,1] cannot go to a png parallax map */
    lx_image h;
    assert_int_equal(lx_image_alloc(&h, 4, 4, 1), LX_OK);
    for (int i = 0; i < 16; i++)
        h.data[i] = 3.0f;
    assert_int_equal(lx_image_write(path("tall.pfm"), &h, NULL), LX_OK);
    lx_image_free(&h);
    const char *tall[] = {"parallaxmap", path("tall.pfm"), "-o", out, NULL};
    expect_failure(tall, 1, "x.png: value 3");
}

static void usage_errors(void **state)
{
    (void)state;
    write_steps();
    char in[PATH_MAX + 64], out[PATH_MAX + 64];
    snprintf(in, sizeof in, "%s", path("steps.png"));
    snprintf(out, sizeof out, "%s", path("out/x.png"));
    const char *cases[][12] = {
        {"normalmap", in, "-o", out, "--bits", "12", NULL},
        {"normalmap", in, "-o", path("out/x.exr"), "--bits", "16", NULL},
        {"normalmap", in, NULL},
        {"normalmap", in, "-o", out, "--method", "udn", NULL},
        {"normalmap", in, "-o", out, "--filter", "prewitt", NULL},
        {"normalmap", in, "-o", out, "--strength", "-2", NULL},
        {"normalmap", in, "-o", out, "--green", "sideways", NULL},
        {"normalmap", "--blend", in, "-o", out, NULL},
        {"normalmap", "--blend", in, in, "--strength", "3", "-o", out, NULL},
        {"normalmap", in, "-o", path("out/x.jpg"), NULL},
        {"normalmap", in, "-o", out, "--format", "exr", NULL},
        {"parallaxmap", in, "-o", out, "--wrap", "tile", NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        expect_failure(cases[i], 2, NULL);
    const char *help[] = {"normalmap", "--help", NULL};
    assert_int_equal(run(help), 0);
    const char *phelp[] = {"parallaxmap", "-h", NULL};
    assert_int_equal(run(phelp), 0);
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(step_alignment), cmocka_unit_test(codes_and_formats),
        cmocka_unit_test(parallax_and_blend), cmocka_unit_test(bad_inputs),
        cmocka_unit_test(usage_errors),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
