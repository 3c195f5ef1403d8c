/* luxel light2d keeps the albedo's alpha: a sprite sheet lit with an RGBA
 * albedo comes out RGBA with the same alpha codes (an 8-bit code decodes
 * to code/255 and encodes back to itself), so transparent pixels stay
 * transparent instead of coming out opaque and lit; the RGB is the same
 * as with the albedo's colours alone (an RGB copy of it). A PFM output,
 * which holds no alpha, is RGB with one warning saying so.
 *
 * The CLI is the `luxel` next to this test's executable. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define W 48
#define H 32

static char dir[PATH_MAX];
static char log_text[8192];

static const char *in_dir(const char *name)
{
    static char p[8][PATH_MAX + 64];
    static int next;
    char *b = p[next++ & 7];
    snprintf(b, sizeof p[0], "%s/%s", dir, name);
    return b;
}

/* Runs luxel with args (NULL-terminated); its stderr in log_text. */
static int run_luxel(const char *const *args)
{
    const char *log = in_dir("cli.log");
    int status = lx_test_run_luxel(args, in_dir("out.log"), log);
    lx_test_read_text(log, log_text, sizeof log_text);
    return status;
}

static lx_image load_raw(const char *path)
{
    lx_image_load_desc d = {.raw_8bit = true};
    lx_image img;
    if (lx_image_load(path, &d, &img) != LX_OK)
        fail_msg("%s", lx_last_error());
    return img;
}

static void albedo_alpha_carries_over(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_light2d_alpha"));
    /* a sprite: a block caster on the left, opaque coloured ground below,
     * transparent sky above with a soft edge of partial alpha */
    uint8_t rgba[W * H * 4], rgb[W * H * 3];
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            uint8_t *p = &rgba[4 * (y * W + x)];
            bool block = x >= 8 && x < 14 && y >= 10;
            p[0] = (uint8_t)(40 + 4 * x);
            p[1] = (uint8_t)(200 - 5 * y);
            p[2] = block ? 30 : 120;
            p[3] = block || y >= 24 ? 255 : y >= 16 ? (uint8_t)(30 * (y - 16)) : 0;
            memcpy(&rgb[3 * (y * W + x)], p, 3);
        }
    lx_test_write_png(in_dir("sprite.png"), W, H, 4, rgba);
    lx_test_write_png(in_dir("colours.png"), W, H, 3, rgb);
    FILE *fp = fopen(in_dir("lights.json"), "w");
    assert_non_null(fp);
    fputs("{\"ambient\": [0.1, 0.1, 0.1], \"lights\": [{\"type\": \"point\", \"position\": "
          "[30, 20], \"intensity\": 1.5, \"radius\": 40}]}",
          fp);
    fclose(fp);

    const char *lit[] = {"light2d", "--casters", in_dir("sprite.png"), "--albedo",
                         in_dir("sprite.png"), "--lights", in_dir("lights.json"), "-q",
                         "-o", in_dir("lit.png"), NULL};
    assert_int_equal(run_luxel(lit), 0);
    const char *plain[] = {"light2d", "--casters", in_dir("sprite.png"), "--albedo",
                           in_dir("colours.png"), "--lights", in_dir("lights.json"), "-q",
                           "-o", in_dir("plain.png"), NULL};
    assert_int_equal(run_luxel(plain), 0);
    lx_image a = load_raw(in_dir("lit.png")), b = load_raw(in_dir("plain.png"));
    assert_int_equal(a.channels, 4);
    assert_int_equal(b.channels, 3);
    int transparent = 0;
    for (int i = 0; i < W * H; i++) {
        int code = (int)(a.data[4 * i + 3] * 255.0f + 0.5f);
        assert_int_equal(code, rgba[4 * i + 3]);
        transparent += code == 0;
        for (int c = 0; c < 3; c++)
            assert_float_equal(a.data[4 * i + c], b.data[3 * i + c], 1e-6);
    }
    assert_true(transparent >= W * 10); /* the sky rows above the soft edge */
    lx_image_free(&a);
    lx_image_free(&b);

    /* PFM holds no alpha: RGB, and a warning naming the albedo */
    const char *pfm[] = {"light2d", "--casters", in_dir("sprite.png"), "--albedo",
                         in_dir("sprite.png"), "--lights", in_dir("lights.json"),
                         "-o", in_dir("lit.pfm"), NULL};
    assert_int_equal(run_luxel(pfm), 0);
    if (!strstr(log_text, "holds no alpha") || !strstr(log_text, "sprite.png"))
        fail_msg("no warning about the alpha left out: %s", log_text);
    lx_image f;
    if (lx_image_load(in_dir("lit.pfm"), NULL, &f) != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_int_equal(f.channels, 3);
    lx_image_free(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(albedo_alpha_carries_over),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
