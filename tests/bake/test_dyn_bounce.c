/* The dynamic lights' one bounce in lx_baker_update
 * (lx_bake_desc.dynamic_bounce_samples) against the static bake:
 * - a dynamic point light's bounce (apply after an update, less the same
 *   update without the bounce) is lx_baker_bake's first bounce of the same
 *   light made static (bounces 1, 64x the samples as the reference), within
 *   the noise of N samples: no bias beyond 4 standard errors of the mean
 *   over the texels, and an RMS error the size of the static gather's own
 *   at N samples (both are one N-sample estimate of the same integral);
 * - moving the light changes the bounce, and the moved bounce again
 *   matches the static bake of the light where it went;
 * - texels inside geometry (the floor under a block) are filled from their
 *   valid neighbours, never left with light of their own;
 * - 1 and 2 threads give the same bytes; zero samples is the direct-only
 *   update; bad counts fail with a message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifndef N_SAMPLES
#define N_SAMPLES 16u
#endif

/* A 4 x 3 x 4 m room (walls of albedo 0.6, inward) with a 1 m block of
 * albedo 0.3 sunk half a metre into its floor (the floor texels inside it
 * are invalid) and one point light. */
/* The room with a block of half-width `half` standing through its floor. */
static lx_scene *room_with_block(lx_vec3 light_at, bool dynamic, float half)
{
    lx_scene *scene = lx_test_new_scene("room");
    uint32_t walls = lx_test_grey_material(scene, "walls", 0.6f, 0.0f);
    uint32_t block = lx_test_grey_material(scene, "block", 0.3f, 0.0f);
    lx_mesh box = lx_test_box("room", lx_v3(-2, 0, -2), lx_v3(2, 3, 2), true);
    box.material = walls;
    lx_test_add(scene, &box);
    lx_test_mesh_free(&box);
    lx_mesh cube = lx_test_box("block", lx_v3(-half, -0.5f, -half), lx_v3(half, 1, half), false);
    cube.material = block;
    lx_test_add(scene, &cube);
    lx_test_mesh_free(&cube);
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "bulb");
    l.position = light_at;
    l.intensity = 100.0f;
    l.dynamic = dynamic;
    assert_int_equal(lx_scene_add_light(scene, &l), LX_OK);
    return scene;
}

static lx_scene *room(lx_vec3 light_at, bool dynamic)
{
    return room_with_block(light_at, dynamic, 0.5f);
}

/* Every map's applied texels (covered ones) of a baker, in order. */
static double *texels(const lx_baker *b, size_t *count)
{
    size_t n = 0, cap = 0;
    double *out = NULL;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++) {
        lx_image img;
        assert_int_equal(lx_baker_apply_alloc(b, m, &img), LX_OK);
        const uint8_t *mask = lx_baker_mask(b, m);
        for (int p = 0; p < img.width * img.height; p++) {
            if (!mask[p])
                continue;
            if (n + 3 > cap) {
                cap = cap ? 2 * cap : 4096;
                out = realloc(out, sizeof(double) * cap);
                assert_non_null(out);
            }
            for (int c = 0; c < 3; c++)
                out[n++] = img.data[3 * p + c];
        }
        lx_image_free(&img);
    }
    *count = n;
    return out;
}

static lx_baker *make(const lx_scene *scene, int bounces, uint32_t gi, uint32_t dyn, int threads)
{
    lx_bake_desc d = {.resolution = 24,
                      .bounces = bounces,
                      .gi_samples = gi,
                      .dynamic_bounce_samples = dyn,
                      .threads = threads};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    return b;
}

/* The indirect light of a static bake of the light at p: bounces 1 at gi
 * samples less bounces 0. */
static double *static_bounce(lx_vec3 p, uint32_t gi, size_t *count)
{
    lx_scene *s = room(p, false);
    lx_baker *b1 = make(s, 1, gi, 0, 0), *b0 = make(s, 0, gi, 0, 0);
    size_t n1, n0;
    double *e1 = texels(b1, &n1), *e0 = texels(b0, &n0);
    assert_int_equal(n1, n0);
    for (size_t i = 0; i < n1; i++)
        e1[i] -= e0[i];
    free(e0);
    lx_baker_destroy(b1);
    lx_baker_destroy(b0);
    lx_scene_destroy(s);
    *count = n1;
    return e1;
}

/* The dynamic bounce of baker b (its light dynamic, nothing static) after
 * placing the light at p: the update with the bounce less the direct
 * light (the update of a baker without it). */
static double *dynamic_bounce(lx_baker *b, lx_vec3 p, size_t *count)
{
    lx_light l = *lx_baker_light(b, 0);
    l.position = p;
    assert_int_equal(lx_baker_set_light(b, 0, &l), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    lx_scene *s = room(p, true);
    lx_baker *direct = make(s, 0, 0, 0, 0);
    assert_int_equal(lx_baker_update(direct), LX_OK);
    size_t n, n0;
    double *e = texels(b, &n), *e0 = texels(direct, &n0);
    assert_int_equal(n, n0);
    for (size_t i = 0; i < n; i++)
        e[i] -= e0[i];
    free(e0);
    lx_baker_destroy(direct);
    lx_scene_destroy(s);
    *count = n;
    return e;
}

typedef struct stats {
    double mean_ref, bias, stderr_bias, rms;
} stats;

/* got against ref over the texels where the reference has light. */
static stats compare(const double *got, const double *ref, size_t n)
{
    double sum_ref = 0, sum_d = 0, sum_d2 = 0;
    size_t k = 0;
    for (size_t i = 0; i < n; i += 3) { /* grey light: one channel */
        double d = got[i] - ref[i];
        sum_ref += ref[i];
        sum_d += d;
        sum_d2 += d * d;
        k++;
    }
    stats s;
    s.mean_ref = sum_ref / (double)k;
    s.bias = sum_d / (double)k;
    double var = sum_d2 / (double)k - s.bias * s.bias;
    s.stderr_bias = sqrt(fmax(var, 0.0) / (double)k);
    s.rms = sqrt(sum_d2 / (double)k);
    return s;
}

static void check_against_static(const double *dyn, lx_vec3 p, const char *what)
{
    size_t n_ref, n_same;
    double *ref = static_bounce(p, 64 * N_SAMPLES, &n_ref);
    double *same = static_bounce(p, N_SAMPLES, &n_same);
    stats d = compare(dyn, ref, n_ref), s = compare(same, ref, n_ref);
    printf("%s: mean bounce %.4g lux; dynamic (N=%u) bias %.3g (standard error %.3g), rms %.4g; "
           "static at N=%u rms %.4g (ratio %.3f)\n",
           what, d.mean_ref, N_SAMPLES, d.bias, d.stderr_bias, d.rms, N_SAMPLES, s.rms,
           d.rms / s.rms);
    /* unbiased: the mean difference within 4 standard errors (the
     * reference's own noise, 1/8 of N's, is part of the spread; measured
     * 0.9 and 2.2 standard errors at N = 16, 0.4 and 1.0 at N = 64) */
    assert_true(fabs(d.bias) < 4.0 * d.stderr_bias + 1e-6 * d.mean_ref);
    /* the same estimator at the same count: the same RMS noise, within the
     * spread of an RMS over a few thousand texels (measured ratios 1.07
     * and 1.10 at N = 16, 0.94 and 0.97 at N = 64; bound 1.3) */
    assert_true(d.rms < 1.3 * s.rms);
    assert_true(d.rms > s.rms / 1.3);
    /* and the noise is that of N samples, falling as 1/sqrt(N): RMS
     * measured 0.34 and 0.45 of the mean bounce at N = 16 (0.12 and 0.15
     * at N = 64), bound 2.5 / sqrt(N) of it (0.625 at N = 16) */
    assert_true(d.rms < 2.5 / sqrt((double)N_SAMPLES) * d.mean_ref);
    free(ref);
    free(same);
}

static void one_bounce_is_the_static_first_bounce(void **state)
{
    (void)state;
    lx_vec3 p = lx_v3(1.0f, 2.5f, 0.5f);
    lx_scene *s = room(p, true);
    lx_baker *b = make(s, 0, 0, N_SAMPLES, 0);
    lx_scene_destroy(s);
    size_t n;
    double *dyn = dynamic_bounce(b, p, &n);
    check_against_static(dyn, p, "light at (1, 2.5, 0.5)");

    /* moved: a different bounce, again the static one */
    lx_vec3 q = lx_v3(-1.5f, 0.5f, -1.0f);
    size_t n2;
    double *moved = dynamic_bounce(b, q, &n2);
    assert_int_equal(n, n2);
    double change = 0, total = 0;
    for (size_t i = 0; i < n; i++) {
        change += fabs(moved[i] - dyn[i]);
        total += dyn[i];
    }
    printf("moving the light changes the bounce by %.3g of its mean\n", change / total);
    assert_true(change / total > 0.2);
    check_against_static(moved, q, "light moved to (-1.5, 0.5, -1)");
    free(dyn);
    free(moved);
    lx_baker_destroy(b);
}

/* The floor texels inside the block are inside geometry: their own rays
 * would leave them dark (direct light blocked, back faces all round);
 * they are invalid and take their valid neighbours' average (ring by
 * ring from the block's edge), so each is lit, and no brighter than the
 * brightest valid floor texel (an average of averages). The block is 2 m
 * wide here: floor texels are 0.56 x 0.37 m, and a texel only partly
 * under the block moves its sample out from under it (straddle.c), so
 * the texels near the centre are the ones wholly inside. */
static void invalid_texels_are_filled(void **state)
{
    (void)state;
    lx_vec3 p = lx_v3(1.5f, 2.5f, 1.5f);
    lx_scene *s = room_with_block(p, true, 1.0f);
    lx_baker *b = make(s, 0, 0, N_SAMPLES, 0);
    lx_scene_destroy(s);
    assert_int_equal(lx_baker_update(b), LX_OK);
    uint32_t map = lx_test_map_of(b, 0);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    int inside = 0, lit_inside = 0;
    float lowest = INFINITY, brightest_outside = 0.0f;
    for (int pass = 0; pass < 2; pass++)
        for (int y = 0; y < img.height; y++)
            for (int x = 0; x < img.width; x++) {
                lx_texel_sample t;
                if (!lx_baker_texel(b, map, x, y, &t) || fabsf(t.position.y) > 1e-3f)
                    continue; /* the floor only */
                float v = img.data[3 * ((size_t)y * img.width + x)];
                bool in = fabsf(t.position.x) < 0.45f && fabsf(t.position.z) < 0.45f;
                bool out = fabsf(t.position.x) > 1.05f || fabsf(t.position.z) > 1.05f;
                if (pass == 0 && out)
                    brightest_outside = fmaxf(brightest_outside, v);
                if (pass == 1 && in) {
                    inside++;
                    lit_inside += v > 0.0f && v <= brightest_outside;
                    lowest = fminf(lowest, v);
                }
            }
    printf("%d floor texels inside the block: %d lit within the valid floor's range (lowest "
           "%.4g, the valid floor's brightest %.4g)\n",
           inside, lit_inside, lowest, brightest_outside);
    assert_true(inside > 0);
    assert_int_equal(lit_inside, inside);
    lx_image_free(&img);
    lx_baker_destroy(b);
}

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    double *e[2];
    size_t n[2];
    for (int t = 1; t <= 2; t++) {
        lx_scene *s = room(lx_v3(0.5f, 2.0f, 1.0f), true);
        lx_baker *b = make(s, 0, 0, 9, t);
        lx_scene_destroy(s);
        assert_int_equal(lx_baker_update(b), LX_OK);
        e[t - 1] = texels(b, &n[t - 1]);
        lx_baker_destroy(b);
    }
    assert_int_equal(n[0], n[1]);
    assert_memory_equal(e[0], e[1], sizeof(double) * n[0]);
    free(e[0]);
    free(e[1]);
}

static void bad_counts_fail(void **state)
{
    (void)state;
    lx_scene *s = room(lx_v3(0, 2, 0), true);
    lx_bake_desc d = {.dynamic_bounce_samples = LX_MAX_DYNAMIC_BOUNCE_SAMPLES + 1};
    lx_baker *b = NULL;
    assert_int_equal(lx_baker_create(s, &d, &b), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "dynamic bounce samples"));
    assert_null(b);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(one_bounce_is_the_static_first_bounce),
        cmocka_unit_test(invalid_texels_are_filled),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(bad_counts_fail),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
