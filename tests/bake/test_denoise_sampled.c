/* The sampled part of the direct light under --denoise indirect: the
 * shadowed sky's and soft shadows' noise is filtered, apart from the exact
 * lights, which stay as baked.
 * - Linearity: a bake lit by a hard-shadowed point light and a shadowed
 *   sky equals, texel for texel (to float rounding), the point light's
 *   bake plus the sky's bake: the filter never touches the exact light,
 *   so its shadow edge stays as sharp as it is without a sky.
 * - Noise: at 16 sky rays a texel, the default bake's error against a
 *   1024-ray reference (no filter) is well below the raw bake's.
 * - A soft-shadowed sphere light's noise falls the same way.
 * - With a bounce, the filtered bake keeps the raw bake's mean. */
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

static void grey_sky(double x, double y, double z, float out[3])
{
    (void)x, (void)z;
    out[0] = out[1] = out[2] = (float)(1000.0 * (1.0 + 0.5 * y));
}

enum { RES = 48 };

typedef struct lighting {
    bool point, sky, soft;
    uint32_t sky_samples, soft_samples;
    lx_denoise_mode denoise;
    int bounces;
} lighting;

/* A 4 m floor with a box and a tilted board above it (their shadows
 * cross the floor's map), lit as asked; the floor's map into *out. */
static void bake_floor(const lighting *l, const lx_cubemap *env, lx_image *out)
{
    lx_scene *scene = lx_test_new_scene("sampled");
    lx_mesh floor = lx_test_plane("floor", 4.0f, 0.0f, 0.0f, 0.0f, 4);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    lx_mesh box = lx_test_box("box", lx_v3(-0.9f, 0.0f, -0.4f), lx_v3(-0.1f, 0.8f, 0.4f), false);
    lx_test_add(scene, &box);
    lx_test_mesh_free(&box);
    lx_mesh board = lx_test_box("board", lx_v3(0.3f, 1.0f, -1.2f), lx_v3(1.5f, 1.05f, 0.2f), false);
    lx_test_add(scene, &board);
    lx_test_mesh_free(&board);
    if (l->point) {
        lx_light p = lx_light_defaults(LX_LIGHT_POINT);
        snprintf(p.name, sizeof p.name, "point");
        p.position = lx_v3(0.4f, 2.6f, 0.9f);
        p.intensity = 3000.0f;
        p.shadow = LX_SHADOW_HARD;
        assert_int_equal(lx_scene_add_light(scene, &p), LX_OK);
    }
    if (l->soft) {
        lx_light s = lx_light_defaults(LX_LIGHT_SPHERE);
        snprintf(s.name, sizeof s.name, "bulb");
        s.position = lx_v3(-0.3f, 2.2f, -0.2f);
        s.radius = 0.4f;
        s.intensity = 2000.0f;
        s.shadow = LX_SHADOW_SOFT;
        s.samples = l->soft_samples;
        assert_int_equal(lx_scene_add_light(scene, &s), LX_OK);
    }
    lx_bake_desc desc = {.resolution = RES, .padding = LX_PADDING_NONE, .threads = 2,
                         .denoise = l->denoise, .bounces = l->bounces};
    if (l->bounces)
        desc.gi_samples = 64;
    if (l->sky) {
        desc.sky.environment = env;
        desc.sky.shadows = true;
        desc.sky.samples = l->sky_samples;
    }
    lx_baker *b;
    if (lx_baker_create(scene, &desc, &b) != LX_OK || lx_baker_bake(b) != LX_OK)
        fail_msg("bake: %s", lx_last_error());
    lx_scene_destroy(scene);
    assert_int_equal(lx_baker_apply_alloc(b, lx_test_map_of(b, 0), out), LX_OK);
    lx_baker_destroy(b);
}

static void exact_light_is_left_alone(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(8, grey_sky);
    lighting both = {.point = true, .sky = true, .sky_samples = 16,
                     .denoise = LX_DENOISE_INDIRECT};
    lighting point = both, sky = both, raw_sky = both;
    point.sky = false;
    sky.point = false;
    raw_sky.point = false, raw_sky.denoise = LX_DENOISE_OFF;
    lx_image a, p, s, r;
    bake_floor(&both, &env, &a);
    bake_floor(&point, &env, &p);
    bake_floor(&sky, &env, &s);
    bake_floor(&raw_sky, &env, &r);
    double worst = 0.0;
    int changed = 0;
    for (int i = 0; i < RES * RES * 3; i++) {
        double sum = (double)p.data[i] + (double)s.data[i];
        worst = fmax(worst, fabs(a.data[i] - sum) / fmax(sum, 1.0));
        changed += fabs(s.data[i] - r.data[i]) > 0.01 * r.data[i];
    }
    printf("point + sky against point, sky apart: worst %.3g of the value; the filter moved "
           "%.1f%% of the sky's values by over 1%%\n",
           worst, 100.0 * changed / (RES * RES * 3));
    assert_true(worst < 1e-5);                /* float rounding of the two sums */
    assert_true(changed > RES * RES * 3 / 4); /* and the sky's part was filtered */
    lx_image_free(&a);
    lx_image_free(&p);
    lx_image_free(&s);
    lx_image_free(&r);
    lx_cubemap_free(&env);
}

/* RMS of (x - ref) / mean(ref) over the texels where ref is lit. */
static double rms_error(const lx_image *x, const lx_image *ref)
{
    double mean = 0.0, sum = 0.0;
    int n = 0;
    for (int i = 0; i < RES * RES * 3; i++)
        mean += ref->data[i];
    mean /= RES * RES * 3;
    for (int i = 0; i < RES * RES * 3; i++) {
        if (!(ref->data[i] > 0.0f))
            continue;
        double d = (x->data[i] - ref->data[i]) / mean;
        sum += d * d;
        n++;
    }
    return sqrt(sum / (n ? n : 1));
}

static void noise_falls(const lighting *base, const lighting *converged, const lx_cubemap *env,
                        const char *what)
{
    lighting raw = *base, filtered = *base;
    raw.denoise = LX_DENOISE_OFF;
    filtered.denoise = LX_DENOISE_INDIRECT;
    lx_image r, f, ref;
    bake_floor(&raw, env, &r);
    bake_floor(&filtered, env, &f);
    bake_floor(converged, env, &ref);
    double e_raw = rms_error(&r, &ref), e_filtered = rms_error(&f, &ref);
    int off_raw = 0, off_f = 0, lit = 0, far_raw = 0, far_f = 0;
    for (int i = 0; i < RES * RES * 3; i++)
        if (ref.data[i] > 0.0f) {
            lit++;
            off_raw += fabs(r.data[i] - ref.data[i]) > 0.1 * ref.data[i];
            off_f += fabs(f.data[i] - ref.data[i]) > 0.1 * ref.data[i];
            far_raw += fabs(r.data[i] - ref.data[i]) > 0.2 * ref.data[i];
            far_f += fabs(f.data[i] - ref.data[i]) > 0.2 * ref.data[i];
        }
    printf("%s: RMS error against the converged bake: raw %.2f%%, filtered %.2f%%; texels off "
           "by more than 10%%: raw %.2f%%, filtered %.2f%%; by more than 20%%: raw %.2f%%, "
           "filtered %.2f%%\n",
           what, 100.0 * e_raw, 100.0 * e_filtered, 100.0 * off_raw / lit, 100.0 * off_f / lit,
           100.0 * far_raw / lit, 100.0 * far_f / lit);
    assert_true(e_raw > 0.005); /* there is noise to take away */
    assert_true(e_filtered < 0.6 * e_raw);
    lx_image_free(&r);
    lx_image_free(&f);
    lx_image_free(&ref);
}

static void sky_noise_falls(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(8, grey_sky);
    lighting base = {.sky = true, .sky_samples = 16};
    lighting converged = {.sky = true, .sky_samples = 1024, .denoise = LX_DENOISE_OFF};
    noise_falls(&base, &converged, &env, "sky, 16 rays");
    lx_cubemap_free(&env);
}

static void soft_shadow_noise_falls(void **state)
{
    (void)state;
    lx_cubemap none = {0};
    lighting base = {.soft = true, .soft_samples = 16};
    lighting converged = {.soft = true, .soft_samples = 1024, .denoise = LX_DENOISE_OFF};
    noise_falls(&base, &converged, &none, "soft-shadowed sphere light, 16 points");
}

/* With a bounce both parts are filtered (the bounces with their own
 * variance, the sampled sky with its spatial estimate): the mean stays. */
static void with_a_bounce_the_mean_stays(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(8, grey_sky);
    lighting raw = {.point = true, .sky = true, .sky_samples = 16, .bounces = 1,
                    .denoise = LX_DENOISE_OFF};
    lighting filtered = raw;
    filtered.denoise = LX_DENOISE_INDIRECT;
    lx_image r, f;
    bake_floor(&raw, &env, &r);
    bake_floor(&filtered, &env, &f);
    double sr = 0.0, sf = 0.0;
    for (int i = 0; i < RES * RES * 3; i++) {
        assert_true(isfinite(f.data[i]) && f.data[i] >= 0.0f);
        sr += r.data[i];
        sf += f.data[i];
    }
    printf("one bounce: filtered mean / raw mean = %.5f\n", sf / sr);
    assert_true(fabs(sf / sr - 1.0) < 0.01);
    lx_image_free(&r);
    lx_image_free(&f);
    lx_cubemap_free(&env);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(exact_light_is_left_alone),
        cmocka_unit_test(sky_noise_falls),
        cmocka_unit_test(soft_shadow_noise_falls),
        cmocka_unit_test(with_a_bounce_the_mean_stays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
