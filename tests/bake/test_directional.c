/* Directional lightmaps against closed forms. The coefficients are the
 * projections L_lm = int L(w) Y_lm(w) dw with Y00 = 1 / (2 sqrt pi), Y1m
 * = sqrt(3 / (4 pi)) x (y, z, x), computed here in double:
 * - a directional light of illuminance E from unit direction l is a delta:
 *   L00 = E Y00, L1 = E Y1 l; its L1 irradiance for a normal n is then
 *   E (1/4 + (l . n) / 2) (pi Y00^2 = 1/4, 2 pi / 3 Y1^2 = 1/2), its
 *   dominant direction l with directionality 1;
 * - an unshadowed constant sky L: L00 = 4 pi L Y00, L1 = 0;
 * - a constant sky L seen over the hemisphere of +Y (sky shadows): L00 =
 *   2 pi L Y00, L1 = pi L Y1 (0, 1, 0) (int over the hemisphere of w is pi
 *   n), and the irradiance it gives a normal tilted by a is pi L (1 + cos
 *   a) / 2, exact for this field (L1 holds all of it);
 * - an ambient a (the same irradiance for every normal): L00 = 4 Y00 a;
 * and the data is the same for 1 and 2 threads, and refused when not
 * baked. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cube_reference.h"
#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_D 3.14159265358979323846
#define Y0_D (0.5 / sqrt(PI_D))
#define Y1_D (sqrt(3.0 / (4.0 * PI_D)))

static void constant_env(double x, double y, double z, float out[3])
{
    (void)x, (void)y, (void)z;
    out[0] = 2.0f, out[1] = 1.0f, out[2] = 0.5f;
}

typedef struct baked {
    lx_baker *baker;
    lx_image irradiance;
    lx_image sh[4];
    lx_image dominant;
} baked;

/* A 1 m floor (8x8 texels) lit by what the caller put in desc and scene. */
static void bake_floor(lx_scene *scene, lx_bake_desc desc, baked *out)
{
    uint32_t node = scene->node_count;
    lx_mesh floor = lx_test_plane("floor", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    desc.resolution = 8;
    if (!desc.directional)
        desc.directional = LX_DIRECTIONAL_SH;
    assert_int_equal(lx_baker_create(scene, &desc, &out->baker), LX_OK);
    assert_int_equal(lx_baker_bake(out->baker), LX_OK);
    uint32_t m = lx_test_map_of(out->baker, node);
    assert_int_equal(lx_baker_apply_alloc(out->baker, m, &out->irradiance), LX_OK);
    assert_int_equal(lx_baker_sh(out->baker, m, out->sh), LX_OK);
    assert_int_equal(lx_baker_dominant(out->baker, m, &out->dominant), LX_OK);
    assert_int_equal(out->dominant.channels, 4);
    for (int c = 0; c < 4; c++)
        assert_int_equal(out->sh[c].channels, 3);
}

static void baked_free(baked *b)
{
    lx_image_free(&b->irradiance);
    for (int c = 0; c < 4; c++)
        lx_image_free(&b->sh[c]);
    lx_image_free(&b->dominant);
    lx_baker_destroy(b->baker);
}

/* The L1 irradiance of texel p for unit normal n, channel ch. */
static double sh_irradiance(const baked *b, size_t p, int ch, const double n[3])
{
    return PI_D * Y0_D * b->sh[0].data[3 * p + ch] +
           2.0 * PI_D / 3.0 * Y1_D *
               (b->sh[1].data[3 * p + ch] * n[1] + b->sh[2].data[3 * p + ch] * n[2] +
                b->sh[3].data[3 * p + ch] * n[0]);
}

static void test_directional_light(void **state)
{
    (void)state;
    double l[3] = {0.3, 1.0, -0.5}; /* toward the light */
    double len = sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    for (int k = 0; k < 3; k++)
        l[k] /= len;
    const double e = 1000.0, color[3] = {1.0, 0.5, 0.25};
    lx_scene *scene = lx_test_new_scene("sun");
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_v3((float)-l[0], (float)-l[1], (float)-l[2]);
    sun.intensity = (float)e;
    sun.color = lx_v3(1.0f, 0.5f, 0.25f);
    sun.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
    baked b;
    bake_floor(scene, (lx_bake_desc){.padding = LX_PADDING_NONE}, &b);
    lx_scene_destroy(scene);
    double worst = 0.0;
    const double axis[4] = {Y0_D, Y1_D * l[1], Y1_D * l[2], Y1_D * l[0]};
    for (size_t p = 0; p < 64; p++)
        for (int ch = 0; ch < 3; ch++) {
            double ec = e * color[ch];
            for (int c = 0; c < 4; c++) {
                double want = ec * axis[c];
                double got = b.sh[c].data[3 * p + ch];
                worst = fmax(worst, fabs(got - want) / ec);
                assert_true(fabs(got - want) <= 2e-6 * ec);
            }
            /* the L1 irradiance of the floor's normal and of tilted ones */
            double up[3] = {0, 1, 0};
            lx_test_assert_rel(sh_irradiance(&b, p, ch, up), ec * (0.25 + 0.5 * l[1]), 1e-5);
            for (int a = 10; a <= 60; a += 25) {
                double t = a * PI_D / 180.0;
                double n[3] = {sin(t), cos(t), 0.0};
                double ln = l[0] * n[0] + l[1] * n[1] + l[2] * n[2];
                lx_test_assert_rel(sh_irradiance(&b, p, ch, n), ec * (0.25 + 0.5 * ln), 1e-5);
                /* L1's known error for a delta: it gives 1/4 + c/2 for the
                 * exact c = l . n, at most 1/4 of E off for c in [0, 1] */
                assert_true(fabs(sh_irradiance(&b, p, ch, n) - ec * ln) <= 0.25 * ec + 1e-3);
            }
            /* the dominant direction is the light's, the rebalancing the
             * floor's half-Lambert */
            const float *d = b.dominant.data + 4 * p;
            for (int k = 0; k < 3; k++)
                assert_true(fabs((2.0 * d[k] - 1.0) - l[k]) <= 2e-6);
            assert_true(fabs(d[3] - (0.5 * l[1] + 0.5)) <= 2e-6);
        }
    printf("directional light: worst coefficient error %.3g of E\n", worst);
    baked_free(&b);
}

static void test_ambient(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("ambient");
    scene->ambient = lx_v3(3.0f, 2.0f, 1.0f);
    baked b;
    bake_floor(scene, (lx_bake_desc){.padding = LX_PADDING_NONE}, &b);
    lx_scene_destroy(scene);
    const double a[3] = {3.0, 2.0, 1.0};
    for (size_t p = 0; p < 64; p++)
        for (int ch = 0; ch < 3; ch++) {
            lx_test_assert_rel(b.sh[0].data[3 * p + ch], 4.0 * Y0_D * a[ch], 1e-6);
            for (int c = 1; c < 4; c++)
                assert_true(b.sh[c].data[3 * p + ch] == 0.0f);
            /* no direction: directionality 0 */
            for (int k = 0; k < 3; k++)
                assert_true(b.dominant.data[4 * p + k] == 0.5f);
        }
    baked_free(&b);
}

static void test_sky_unshadowed(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, constant_env);
    lx_scene *scene = lx_test_new_scene("sky");
    lx_bake_desc d = {.padding = LX_PADDING_NONE};
    d.sky.environment = &env;
    baked b;
    bake_floor(scene, d, &b);
    lx_scene_destroy(scene);
    const double L[3] = {2.0, 1.0, 0.5};
    for (size_t p = 0; p < 64; p++)
        for (int ch = 0; ch < 3; ch++) {
            lx_test_assert_rel(b.sh[0].data[3 * p + ch], 4.0 * PI_D * Y0_D * L[ch], 1e-4);
            for (int c = 1; c < 4; c++)
                assert_true(fabs(b.sh[c].data[3 * p + ch]) <= 1e-4 * L[ch]);
        }
    baked_free(&b);
    lx_cubemap_free(&env);
}

static void test_sky_shadowed(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, constant_env);
    lx_scene *scene = lx_test_new_scene("sky");
    lx_bake_desc d = {.padding = LX_PADDING_NONE};
    d.sky.environment = &env;
    d.sky.shadows = true;
    d.sky.samples = 256;
    baked b;
    bake_floor(scene, d, &b);
    lx_scene_destroy(scene);
    const double L[3] = {2.0, 1.0, 0.5};
    double mean[4][3] = {{0}}, worst_texel = 0.0, worst_tilt = 0.0;
    for (size_t p = 0; p < 64; p++)
        for (int ch = 0; ch < 3; ch++) {
            for (int c = 0; c < 4; c++)
                mean[c][ch] += b.sh[c].data[3 * p + ch] / 64.0;
            double want0 = 2.0 * PI_D * Y0_D * L[ch];
            worst_texel = fmax(worst_texel, fabs(b.sh[0].data[3 * p + ch] - want0) / want0);
            for (int a = 0; a <= 60; a += 20) {
                double t = a * PI_D / 180.0, n[3] = {sin(t), cos(t), 0.0};
                double want = PI_D * L[ch] * (1.0 + cos(t)) / 2.0;
                worst_tilt = fmax(worst_tilt, fabs(sh_irradiance(&b, p, ch, n) - want) / want);
            }
        }
    printf("sky with shadows: texels' L00 within %.3g%%, tilted irradiance within %.3g%%\n",
           100.0 * worst_texel, 100.0 * worst_tilt);
    for (int ch = 0; ch < 3; ch++) {
        double want0 = 2.0 * PI_D * Y0_D * L[ch], want1 = PI_D * Y1_D * L[ch];
        printf("  ch %d: L00 %.5f (want %.5f), L1 y %.5f (want %.5f), z %.2g, x %.2g\n", ch,
               mean[0][ch], want0, mean[1][ch], want1, mean[2][ch], mean[3][ch]);
        lx_test_assert_rel(mean[0][ch], want0, 1e-4);
        lx_test_assert_rel(mean[1][ch], want1, 1e-4);
        assert_true(fabs(mean[2][ch]) <= 0.003 * want1);
        assert_true(fabs(mean[3][ch]) <= 0.003 * want1);
    }
    /* L0 is exact per texel (up to float sums); L1 across the normal is
     * the noisy part: measured 1.75% at 256 rays */
    assert_true(worst_texel <= 1e-4);
    assert_true(worst_tilt <= 0.035);
    baked_free(&b);
    lx_cubemap_free(&env);
}

static void linear_env(double x, double y, double z, float out[3])
{
    (void)x, (void)z;
    out[0] = out[1] = out[2] = (float)(1.0 + y);
}

/* L = 1 + y over the hemisphere of +Y: L00 = Y00 (2 pi + pi), L1 y = Y1
 * (pi + 2 pi / 3) (int y dw = pi, int y^2 dw = 2 pi / 3); the radiance
 * changes with elevation, which the weights of lx_sh_ray_weight do not
 * follow within a stratum (and the rays read the sky's 32-texel lookup
 * at its nearest texel): measured +0.73% and -0.005%. */
static void test_sky_linear(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, linear_env);
    lx_scene *scene = lx_test_new_scene("sky");
    lx_bake_desc d = {.padding = LX_PADDING_NONE};
    d.sky.environment = &env;
    d.sky.shadows = true;
    d.sky.samples = 256;
    baked b;
    bake_floor(scene, d, &b);
    lx_scene_destroy(scene);
    double m0 = 0.0, m1 = 0.0;
    for (size_t p = 0; p < 64; p++) {
        m0 += b.sh[0].data[3 * p] / 64.0;
        m1 += b.sh[1].data[3 * p] / 64.0;
    }
    double want0 = Y0_D * 3.0 * PI_D, want1 = Y1_D * (PI_D + 2.0 * PI_D / 3.0);
    printf("sky 1 + y: L00 %.5f (want %.5f, %.3g%%), L1 y %.5f (want %.5f, %.3g%%)\n", m0, want0,
           100.0 * (m0 / want0 - 1.0), m1, want1, 100.0 * (m1 / want1 - 1.0));
    lx_test_assert_rel(m0, want0, 0.015);
    lx_test_assert_rel(m1, want1, 0.001);
    baked_free(&b);
    lx_cubemap_free(&env);
}

/* A floor under a lit block with a bounce, sky shadows and denoising: the
 * same bytes for 1 and 2 threads. */
static void bake_room(int threads, baked *out)
{
    lx_cubemap env = lx_test_make_env(16, constant_env);
    lx_scene *scene = lx_test_new_scene("room");
    lx_mesh box = lx_test_box("block", lx_v3(-0.2f, 0.1f, -0.2f), lx_v3(0.2f, 0.4f, 0.2f), false);
    lx_test_add(scene, &box);
    lx_test_mesh_free(&box);
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_normalize(lx_v3(-0.4f, -1.0f, 0.2f));
    sun.intensity = 500.0f;
    sun.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
    lx_bake_desc d = {.padding = 2,
                      .threads = threads,
                      .bounces = 1,
                      .gi_samples = 16,
                      .denoise = LX_DENOISE_INDIRECT};
    d.sky.environment = &env;
    d.sky.shadows = true;
    d.sky.samples = 16;
    bake_floor(scene, d, out);
    lx_scene_destroy(scene);
    lx_cubemap_free(&env);
}

static void test_threads(void **state)
{
    (void)state;
    baked one, two;
    bake_room(1, &one);
    bake_room(2, &two);
    size_t n = (size_t)one.sh[0].width * one.sh[0].height * 3;
    for (int c = 0; c < 4; c++)
        assert_memory_equal(one.sh[c].data, two.sh[c].data, n * sizeof(float));
    assert_memory_equal(one.dominant.data, two.dominant.data, n / 3 * 4 * sizeof(float));
    /* the sun dominates the open floor: most texels' direction is near it */
    lx_vec3 l = lx_normalize(lx_v3(0.4f, 1.0f, -0.2f));
    int near = 0, lit = 0;
    for (size_t p = 0; p < n / 3; p++) {
        const float *d = one.dominant.data + 4 * p;
        lx_vec3 v = lx_v3(2 * d[0] - 1, 2 * d[1] - 1, 2 * d[2] - 1);
        if (one.irradiance.data[3 * p + 1] > 300.0f) {
            lit++;
            near += lx_dot(lx_normalize(v), l) > 0.95f;
        }
    }
    printf("sunlit texels %d, dominant direction within 18 degrees of the sun: %d\n", lit, near);
    assert_true(lit > 0 && near == lit);
    baked_free(&one);
    baked_free(&two);
}

/* Denoising keeps the directions: under a sun alone every texel's
 * radiance is a delta from l (L1 = sqrt 3 L00 l) or nothing; the filter
 * gives the four coefficient planes the same weights, so every filtered
 * texel still has direction l, directionality 1, while the block's shadow
 * edge is smoothed (some L00 changes). */
static void test_denoise_keeps_direction(void **state)
{
    (void)state;
    baked plain, filtered;
    for (int k = 0; k < 2; k++) {
        lx_scene *scene = lx_test_new_scene("shadow");
        lx_mesh box =
            lx_test_box("block", lx_v3(-0.1f, 0.05f, -0.1f), lx_v3(0.1f, 0.3f, 0.1f), false);
        lx_test_add(scene, &box);
        lx_test_mesh_free(&box);
        lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
        sun.direction = lx_normalize(lx_v3(-0.6f, -1.0f, 0.3f));
        sun.intensity = 800.0f;
        sun.shadow = LX_SHADOW_HARD;
        assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
        lx_bake_desc d = {.padding = LX_PADDING_NONE,
                          .denoise = k ? LX_DENOISE_ALL : LX_DENOISE_OFF};
        bake_floor(scene, d, k ? &filtered : &plain);
        lx_scene_destroy(scene);
    }
    lx_vec3 l = lx_normalize(lx_v3(0.6f, 1.0f, -0.3f));
    int changed = 0, lit = 0;
    for (size_t p = 0; p < 64; p++) {
        const float *c0 = filtered.sh[0].data + 3 * p;
        changed += c0[0] != plain.sh[0].data[3 * p];
        if (!(c0[0] > 0.0f))
            continue;
        lit++;
        const float *d = filtered.dominant.data + 4 * p;
        assert_true(fabs(2.0 * d[0] - 1.0 - l.x) <= 1e-5);
        assert_true(fabs(2.0 * d[1] - 1.0 - l.y) <= 1e-5);
        assert_true(fabs(2.0 * d[2] - 1.0 - l.z) <= 1e-5);
    }
    int irr_changed = 0;
    for (size_t p = 0; p < 64; p++)
        irr_changed += filtered.irradiance.data[3 * p] != plain.irradiance.data[3 * p];
    printf("irradiance changed at %d\n", irr_changed);
    printf("denoised: %d texels changed, %d lit texels all with the sun's direction\n", changed,
           lit);
    assert_true(changed > 0 && lit > 0);
    baked_free(&plain);
    baked_free(&filtered);
}

static void test_refused(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("off");
    scene->ambient = lx_v3(1.0f, 1.0f, 1.0f);
    lx_mesh floor = lx_test_plane("floor", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    lx_baker *baker;
    lx_bake_desc d = {.resolution = 8, .directional = (lx_directional_mode)7};
    assert_int_equal(lx_baker_create(scene, &d, &baker), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "directional"));
    d.directional = LX_DIRECTIONAL_OFF;
    assert_int_equal(lx_baker_create(scene, &d, &baker), LX_OK);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image sh[4], dom;
    assert_int_equal(lx_baker_sh(baker, 0, sh), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "no directional data"));
    assert_null(sh[0].data);
    assert_int_equal(lx_baker_dominant(baker, 0, &dom), LX_ERR_INVALID);
    assert_int_equal(lx_baker_sh(baker, 5, sh), LX_ERR_INVALID);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_directional_light),
        cmocka_unit_test(test_ambient),
        cmocka_unit_test(test_sky_unshadowed),
        cmocka_unit_test(test_sky_shadowed),
        cmocka_unit_test(test_sky_linear),
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_denoise_keeps_direction),
        cmocka_unit_test(test_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
