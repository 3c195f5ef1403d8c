/* `luxel bake` end to end, reading its files back: a floor under a point
 * light and a sun (values from ~10 to ~1e4 lux) is baked by the CLI with
 * --format pfm, exr, exr --half and hdr, and by the library in this process
 * with the same settings; each file, read back with lx_image_load, must
 * hold the library's values within its format's precision:
 *
 * - PFM and 32-bit EXR: exactly (float in, float out);
 * - half EXR: round to nearest with 11 significant bits, so within 2^-11
 *   relative (2^-25 absolute below half's normal range, 2^-14); measured
 *   4.74e-4 = 0.97 x 2^-11;
 * - Radiance HDR: one shared exponent per pixel and 8-bit mantissas that
 *   stb_image_write truncates, so each channel is at most 2^-7 of the
 *   pixel's largest channel below the value, never above; measured
 *   7.59e-3 = 0.97 x 2^-7.
 * These bounds are the formats' own worst cases, not fitted tolerances.
 *
 * --exposure EV100 must set the preview PNG (and a --format png lightmap)
 * to the exposure 1 / (1.2 * 2^EV100) times E / pi, through the tone
 * curve (--tonemap clamp: clamped to [0, 1]; the default, Hable's filmic
 * curve, written here from its published formula) and sRGB-encoded to the
 * nearest 8-bit code, computed here in double from the library's values;
 * the manifest records the EV100 and the curve.
 *
 * The CLI is the `luxel` next to this test's executable (CMake puts both
 * in bin/); the scene is written here. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "texture_oracle.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define RES 32
#define EV100 7.5

static char dir[PATH_MAX];
static char scene_path[PATH_MAX];
static char lights_path[PATH_MAX];
static lx_image reference; /* the library's bake */

/* Runs the CLI with args (NULL-terminated, after "luxel bake"); its output
 * goes to DIR/cli.log. Returns the exit status. */
static int run_bake(const char *const *args)
{
    /* direct light only: the library bake it is compared with has no bounces */
    const char *argv[32] = {"bake",         scene_path, "--lights", lights_path, "--resolution",
                            "32",           "-q",       "--bounces", "0"};
    int n = 9;
    for (; *args && n < 31; args++)
        argv[n++] = *args;
    argv[n] = NULL;
    char log[PATH_MAX + 16];
    snprintf(log, sizeof log, "%s/cli.log", dir);
    return lx_test_run_luxel(argv, log, log);
}

static lx_image load(const char *sub, const char *file, bool raw)
{
    char path[PATH_MAX * 2];
    snprintf(path, sizeof path, "%s/%s/%s", dir, sub, file);
    lx_image_load_desc d = {.raw_8bit = raw};
    lx_image img;
    if (lx_image_load(path, &d, &img) != LX_OK)
        fail_msg("%s", lx_last_error());
    assert_int_equal(img.width, RES);
    assert_int_equal(img.height, RES);
    return img;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_readback"));

    /* a 4 m floor facing +Y, TEXCOORD_1 over the unit square */
    lx_test_quad q = {.o = {-2, 0, 2},
                      .e1 = {4, 0, 0},
                      .e2 = {0, 0, -4},
                      .uv = {{{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}}};
    snprintf(scene_path, sizeof scene_path, "%s/floor.gltf", dir);
    lx_test_write_quad_gltf(scene_path, &q, "{\"name\":\"grey\"}", NULL, 0, NULL);
    snprintf(lights_path, sizeof lights_path, "%s/lights.json", dir);
    FILE *fp = fopen(lights_path, "w");
    assert_non_null(fp);
    fputs("{\"ambient\": [0.05, 0.1, 0.2], \"lights\": ["
          "{\"type\": \"point\", \"position\": [0.5, 0.3, -0.25], \"intensity\": 900,"
          " \"unit\": \"cd\", \"color\": [1, 0.8, 0.6]},"
          "{\"type\": \"directional\", \"direction\": [0.3, -1, 0.2], \"intensity\": 2,"
          " \"unit\": \"lx\"}]}",
          fp);
    assert_int_equal(fclose(fp), 0);

    /* the library, as `luxel bake` drives it */
    lx_scene *scene;
    if (lx_scene_load(scene_path, NULL, &scene) != LX_OK ||
        lx_lights_json_apply(scene, lights_path) != LX_OK)
        fail_msg("%s", lx_last_error());
    lx_bake_desc desc = {.resolution = RES, .padding = LX_PADDING_RECOMMENDED};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    assert_int_equal(lx_baker_update(baker), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &reference), LX_OK);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
    double lo = INFINITY, hi = 0;
    for (int i = 0; i < RES * RES * 3; i++) {
        lo = fmin(lo, reference.data[i]);
        hi = fmax(hi, reference.data[i]);
    }
    if (getenv("LX_TEST_VERBOSE"))
        printf("values %g .. %g\n", lo, hi);
    /* the range the formats are tested over */
    assert_true(lo > 1 && lo < 20 && hi > 3000);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    lx_image_free(&reference);
    return 0;
}

static void bake_format(const char *sub, const char *format, bool half)
{
    char out[PATH_MAX + 8];
    snprintf(out, sizeof out, "%s/%s", dir, sub);
    const char *args[] = {"--format", format, "-o", out, half ? "--half" : NULL, NULL};
    int rc = run_bake(args);
    if (rc != 0)
        fail_msg("luxel bake --format %s%s: exit status %d (see %s/cli.log)", format,
                 half ? " --half" : "", rc, dir);
}

static void pfm_exact(void **state)
{
    (void)state;
    bake_format("pfm", "pfm", false);
    lx_image img = load("pfm", "quad.pfm", false);
    assert_int_equal(img.channels, 3);
    for (int i = 0; i < RES * RES * 3; i++)
        if (img.data[i] != reference.data[i])
            fail_msg("value %d: %.9g in the PFM, %.9g baked", i, img.data[i], reference.data[i]);
    lx_image_free(&img);
}

static void exr_float_exact(void **state)
{
    (void)state;
    bake_format("exr", "exr", false);
    lx_image img = load("exr", "quad.exr", false);
    assert_true(img.channels >= 3);
    for (int p = 0; p < RES * RES; p++)
        for (int c = 0; c < 3; c++)
            if (img.data[p * img.channels + c] != reference.data[p * 3 + c])
                fail_msg("texel %d channel %d: %.9g in the EXR, %.9g baked", p, c,
                         img.data[p * img.channels + c], reference.data[p * 3 + c]);
    lx_image_free(&img);
}

static void exr_half_within_half_precision(void **state)
{
    (void)state;
    bake_format("half", "exr", true);
    lx_image img = load("half", "quad.exr", false);
    double worst = 0;
    for (int p = 0; p < RES * RES; p++)
        for (int c = 0; c < 3; c++) {
            double a = img.data[p * img.channels + c], b = reference.data[p * 3 + c];
            double err = fabs(a - b);
            worst = fmax(worst, err / b);
            if (!(err <= ldexp(fabs(b), -11) + ldexp(1.0, -25)))
                fail_msg("texel %d channel %d: %.9g in the half EXR, %.9g baked", p, c, a, b);
        }
    if (getenv("LX_TEST_VERBOSE"))
        printf("half: worst %.3g relative (2^-11 = %.3g)\n", worst, ldexp(1.0, -11));
    /* some value must need the rounding, or this tested nothing */
    assert_true(worst > ldexp(1.0, -14));
    lx_image_free(&img);
}

static void hdr_within_rgbe_precision(void **state)
{
    (void)state;
    bake_format("hdr", "hdr", false);
    lx_image img = load("hdr", "quad.hdr", false);
    double worst = 0;
    for (int p = 0; p < RES * RES; p++) {
        const float *b = &reference.data[p * 3];
        double maxc = fmax(b[0], fmax(b[1], b[2]));
        for (int c = 0; c < 3; c++) {
            double a = img.data[p * img.channels + c];
            double below = b[c] - a;
            worst = fmax(worst, below / maxc);
            /* truncated mantissas: never above, at most one unit of
             * 2^(e-8) below, and maxc >= 2^(e-1) */
            if (!(below >= 0 && below <= ldexp(maxc, -7)))
                fail_msg("texel %d channel %d: %.9g in the HDR, %.9g baked (largest %.9g)", p, c, a,
                         b[c], maxc);
        }
    }
    if (getenv("LX_TEST_VERBOSE"))
        printf("hdr: worst %.3g of the largest channel (2^-7 = %.3g)\n", worst, ldexp(1.0, -7));
    assert_true(worst > ldexp(1.0, -10));
    lx_image_free(&img);
}

/* The 8-bit code of a linear value, nearest in sRGB; *tie when it lies
 * within 1e-4 of a code of half-way between two codes (float rounding in
 * the exposure product may tip it either way). */
static int srgb_code(double v, bool *tie)
{
    double s = lx_test_srgb_encode(v) * 255.0;
    double f = s - floor(s);
    *tie = fabs(f - 0.5) < 1e-4;
    return (int)floor(s + 0.5);
}

/* John Hable's filmic curve (A 0.15, B 0.5, C 0.1, D 0.2, E 0.02, F 0.3),
 * input doubled, divided by its value at the white point 11.2. */
static double hable(double x)
{
    const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

static double filmic(double v)
{
    double f = hable(2.0 * v) / hable(11.2);
    return f > 1.0 ? 1.0 : f;
}

static double clamp_curve(double v)
{
    return v > 1.0 ? 1.0 : v;
}

/* Every pixel of an 8-bit file against curve(exposure x E / pi). */
static void check_exposed(const char *sub, const char *file, double (*curve)(double))
{
    lx_image img = load(sub, file, true);
    const double exposure = 1.0 / (1.2 * pow(2.0, EV100)) / 3.14159265358979323846;
    int ties = 0, clipped = 0;
    for (int p = 0; p < RES * RES; p++)
        for (int c = 0; c < 3; c++) {
            bool tie;
            double v = reference.data[p * 3 + c] * exposure;
            int want = srgb_code(curve(v), &tie);
            int got = (int)lrint(img.data[p * img.channels + c] * 255.0);
            clipped += curve(v) >= 1.0;
            if (tie) {
                ties++;
                if (abs(got - want) <= 1)
                    continue;
            }
            if (got != want)
                fail_msg("%s: texel %d channel %d: code %d, want %d (exposed value %.6g)", file, p,
                         c, got, want, v);
        }
    if (getenv("LX_TEST_VERBOSE"))
        printf("%s/%s: %d clipped, %d near a tie\n", sub, file, clipped, ties);
    /* the exposure puts the values across the range, some above white */
    assert_true(clipped > 0 && clipped < RES * RES);
    assert_true(ties < 10);
    lx_image_free(&img);
}

static void exposure_sets_the_preview(void **state)
{
    (void)state;
    char out[PATH_MAX + 8], ev[32];
    snprintf(out, sizeof out, "%s/exposed", dir);
    snprintf(ev, sizeof ev, "%g", EV100);
    const char *args[] = {"--exposure", ev, "--tonemap", "clamp", "-o", out, NULL};
    assert_int_equal(run_bake(args), 0);
    check_exposed("exposed", "quad.png", clamp_curve);
    /* the manifest records the EV100 given */
    char path[PATH_MAX * 2];
    snprintf(path, sizeof path, "%s/manifest.json", out);
    FILE *fp = fopen(path, "r");
    assert_non_null(fp);
    char text[8192];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[n] = '\0';
    const char *k = strstr(text, "\"preview_ev100\":");
    assert_non_null(k);
    assert_true(fabs(strtod(k + strlen("\"preview_ev100\":"), NULL) - EV100) < 1e-12);

    snprintf(out, sizeof out, "%s/png", dir);
    const char *png_args[] = {"--exposure", ev, "--tonemap", "clamp", "--format", "png",
                              "-o",         out, NULL};
    assert_int_equal(run_bake(png_args), 0);
    check_exposed("png", "quad.png", clamp_curve);
}

/* Without --tonemap the preview goes through the filmic curve; the
 * exposure puts a few texels past its white point (2 x 5.6 = 11.2). */
static void filmic_by_default(void **state)
{
    (void)state;
    char out[PATH_MAX + 8], ev[32];
    snprintf(out, sizeof out, "%s/filmic", dir);
    snprintf(ev, sizeof ev, "%g", EV100 - 3.0);
    const char *args[] = {"--exposure", ev, "-o", out, NULL};
    assert_int_equal(run_bake(args), 0);
    lx_image img = load("filmic", "quad.png", true);
    const double exposure = 1.0 / (1.2 * pow(2.0, EV100 - 3.0)) / 3.14159265358979323846;
    int ties = 0, saturated = 0, mid = 0;
    for (int p = 0; p < RES * RES; p++)
        for (int c = 0; c < 3; c++) {
            bool tie;
            double v = filmic(reference.data[p * 3 + c] * exposure);
            int want = srgb_code(v, &tie);
            int got = (int)lrint(img.data[p * img.channels + c] * 255.0);
            saturated += v >= 1.0;
            mid += want > 20 && want < 235;
            /* float against double in the curve: a code either side of a
             * half-way point (tie band 1e-4 of a code) */
            if (tie && abs(got - want) <= 1) {
                ties++;
                continue;
            }
            if (got != want)
                fail_msg("filmic: texel %d channel %d: code %d, want %d (curve value %.6g)", p, c,
                         got, want, v);
        }
    assert_true(mid > RES * RES / 4); /* the curve is exercised, not just its ends */
    assert_true(ties < 10);
    (void)saturated;
    lx_image_free(&img);
    char path[PATH_MAX * 2];
    snprintf(path, sizeof path, "%s/manifest.json", out);
    FILE *fp = fopen(path, "r");
    assert_non_null(fp);
    char text[8192];
    size_t n = fread(text, 1, sizeof text - 1, fp);
    fclose(fp);
    text[n] = '\0';
    assert_non_null(strstr(text, "\"preview_tonemap\":\t\"filmic\""));
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pfm_exact),
        cmocka_unit_test(exr_float_exact),
        cmocka_unit_test(exr_half_within_half_precision),
        cmocka_unit_test(hdr_within_rgbe_precision),
        cmocka_unit_test(exposure_sets_the_preview),
        cmocka_unit_test(filmic_by_default),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
