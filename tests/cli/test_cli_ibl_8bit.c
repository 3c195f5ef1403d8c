/* `luxel ibl` 8-bit outputs, read back: a constant environment of 1 nit
 * has irradiance pi lux everywhere (the integral of L cos over the
 * hemisphere), so every texel of irradiance_*.png must hold the sRGB code
 * of curve(pi x 1 / (1.2 x 2^EV100)), the curves written here from their
 * published formulas in double (Hable's filmic, the default; Hill's ACES
 * fit, whose matrices keep grey grey; clamp). The DFG table is data: its
 * PNG holds round(255 v) of the values the same run writes as PFM, with no
 * sRGB transfer. --exposure with a float format is a usage error.
 *
 * The CLI is the `luxel` next to this test's executable. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"
#include "texture_oracle.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char dir[PATH_MAX];

static int run_ibl(const char *const *args)
{
    const char *argv[32] = {"ibl", "const:1", "-q"};
    int n = 3;
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
    return img;
}

static int setup(void **state)
{
    (void)state;
    snprintf(dir, sizeof dir, "%s", lx_test_dir("test_cli_ibl_8bit"));
    return 0;
}

static double hable(double x)
{
    const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

static double filmic(double v)
{
    return fmin(hable(2.0 * v) / hable(11.2), 1.0);
}

static double aces(double v)
{
    double f = (v * (v + 0.0245786) - 0.000090537) / (v * (0.983729 * v + 0.4329510) + 0.238081);
    return fmin(fmax(f, 0.0), 1.0);
}

static double clamp_curve(double v)
{
    return fmin(v, 1.0);
}

/* Every texel of the six irradiance faces holds code(curve(v)). */
static void check_faces(const char *sub, double v, double (*curve)(double))
{
    double s = lx_test_srgb_encode(curve(v)) * 255.0;
    int want = (int)floor(s + 0.5);
    /* float against double: a code either side only right at a half-way
     * point */
    bool tie = fabs(s - floor(s) - 0.5) < 1e-3;
    static const char *faces[] = {"px", "nx", "py", "ny", "pz", "nz"};
    for (int f = 0; f < 6; f++) {
        char name[64];
        snprintf(name, sizeof name, "irradiance_%s.png", faces[f]);
        lx_image img = load(sub, name, true);
        for (size_t i = 0; i < (size_t)img.width * img.height * img.channels; i++) {
            int got = (int)lrint(img.data[i] * 255.0);
            if (got != want && !(tie && abs(got - want) <= 1))
                fail_msg("%s/%s: value %zu: code %d, want %d (curve(%.6g) = %.6g)", sub, name, i,
                         got, want, v, curve(v));
        }
        lx_image_free(&img);
    }
}

static void curves_and_exposure(void **state)
{
    (void)state;
    const double pi = 3.14159265358979323846;
    char out[PATH_MAX + 16];
    snprintf(out, sizeof out, "%s/filmic", dir);
    const char *a1[] = {"--irradiance", "--format", "png", "--exposure", "0", "-o", out, NULL};
    assert_int_equal(run_ibl(a1), 0);
    check_faces("filmic", pi / 1.2, filmic);

    snprintf(out, sizeof out, "%s/aces", dir);
    const char *a2[] = {"--irradiance", "--format", "png", "--exposure", "1",
                        "--tonemap",    "aces",     "-o",  out,          NULL};
    assert_int_equal(run_ibl(a2), 0);
    check_faces("aces", pi / 2.4, aces);

    snprintf(out, sizeof out, "%s/clamp", dir);
    const char *a3[] = {"--irradiance", "--format", "png", "--exposure", "2",
                        "--tonemap",    "clamp",    "-o",  out,          NULL};
    assert_int_equal(run_ibl(a3), 0);
    check_faces("clamp", pi / 4.8, clamp_curve);

    /* without --exposure the values go in as they are: pi, through filmic */
    snprintf(out, sizeof out, "%s/plain", dir);
    const char *a4[] = {"--irradiance", "--format", "png", "-o", out, NULL};
    assert_int_equal(run_ibl(a4), 0);
    check_faces("plain", pi, filmic);
}

static void dfg_png_is_linear(void **state)
{
    (void)state;
    char out[PATH_MAX + 16];
    snprintf(out, sizeof out, "%s/lut_png", dir);
    const char *a1[] = {"--lut", "--format", "png", "--samples", "64", "-o", out, NULL};
    assert_int_equal(run_ibl(a1), 0);
    snprintf(out, sizeof out, "%s/lut_pfm", dir);
    const char *a2[] = {"--lut", "--format", "pfm", "--samples", "64", "-o", out, NULL};
    assert_int_equal(run_ibl(a2), 0);
    lx_image png = load("lut_png", "dfg_lut.png", true);
    lx_image pfm = load("lut_pfm", "dfg_lut.pfm", false);
    assert_int_equal(png.width, pfm.width);
    assert_int_equal(png.height, pfm.height);
    int differs_from_srgb = 0;
    for (size_t p = 0; p < (size_t)png.width * png.height; p++)
        for (int c = 0; c < 3; c++) {
            double v = pfm.data[p * pfm.channels + c];
            int want = (int)floor(fmin(fmax(v, 0.0), 1.0) * 255.0 + 0.5);
            int got = (int)lrint(png.data[p * png.channels + c] * 255.0);
            if (got != want)
                fail_msg("dfg_lut.png: texel %zu channel %d: code %d, want %d (value %.6g)", p, c,
                         got, want, v);
            differs_from_srgb += want != (int)floor(lx_test_srgb_encode(v) * 255.0 + 0.5);
        }
    assert_true(differs_from_srgb > 0); /* the check can tell the two apart */
    lx_image_free(&png);
    lx_image_free(&pfm);
}

static void exposure_needs_8bit(void **state)
{
    (void)state;
    char out[PATH_MAX + 16];
    snprintf(out, sizeof out, "%s/float", dir);
    const char *a1[] = {"--irradiance", "--format", "exr", "--exposure", "0", "-o", out, NULL};
    assert_int_equal(run_ibl(a1), 2);
    const char *a2[] = {"--irradiance", "--format", "png", "--tonemap", "gamma", "-o", out, NULL};
    assert_int_equal(run_ibl(a2), 2);
    assert_int_equal(access(out, F_OK), -1);
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(curves_and_exposure),
        cmocka_unit_test(dfg_png_is_linear),
        cmocka_unit_test(exposure_needs_8bit),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
