/* Ambient-occlusion lightmaps (lx_baker_ao) against closed forms:
 * - an open plane: every ray escapes, AO exactly 1;
 * - a plane under a large parallel ceiling at height h, AO distance D > h:
 *   a cosine-weighted direction at angle theta from the normal meets the
 *   ceiling within D when cos(theta) > h / D, which has probability
 *   1 - (h/D)^2, so AO = (h/D)^2. With the samples stratified in
 *   u = sin^2(theta) over sx columns, only one column straddles the
 *   threshold: every texel is within 1/sx of it;
 * - D below h: nothing is reached, AO 1;
 * - 1 and 2 threads give the same bytes; bad settings fail. */
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

/* A 2 m floor at y = 0, and with a ceiling a 6 m square facing down at
 * y = h (its lightmap is baked too, but not read): no ray shorter than
 * 2 m from the floor passes its edge. Larger would not do: the rays start
 * off the surface by a bias that grows with the scene (1e-5 of its
 * diagonal), which moves the threshold. */
static lx_scene *floor_scene(bool ceiling, float h)
{
    lx_scene *scene = lx_test_new_scene("ao");
    lx_mesh floor = lx_test_plane("floor", 2.0f, 0.0f, 0.0f, 0.0f, 2);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    if (ceiling) {
        lx_mesh top = lx_test_plane("ceiling", 6.0f, 0.0f, 0.0f, 0.0f, 1);
        lx_test_add(scene, &top);
        lx_test_mesh_free(&top);
        scene->nodes[1].world = lx_mat4_trs(lx_v3(0, h, 0), lx_v4(1, 0, 0, 0), lx_v3(1, 1, 1));
    }
    return scene;
}

static lx_baker *make_baker(lx_scene *scene, int threads)
{
    lx_bake_desc d = {.resolution = 16, .threads = threads};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    return b;
}

/* Worst |AO - want| over the floor's covered texels, and their mean. */
static double floor_error(lx_baker *b, const lx_ao_desc *d, double want, double *mean)
{
    uint32_t map = lx_test_map_of(b, 0);
    lx_image ao;
    assert_int_equal(lx_baker_ao(b, map, d, &ao), LX_OK);
    assert_int_equal(ao.channels, 1);
    const uint8_t *mask = lx_baker_mask(b, map);
    double worst = 0.0, sum = 0.0;
    int n = 0;
    for (int p = 0; p < ao.width * ao.height; p++) {
        if (!mask[p])
            continue;
        worst = fmax(worst, fabs(ao.data[p] - want));
        sum += ao.data[p];
        n++;
    }
    assert_true(n > 100);
    *mean = sum / n;
    lx_image_free(&ao);
    return worst;
}

static void open_plane_is_one(void **state)
{
    (void)state;
    lx_scene *scene = floor_scene(false, 0.0f);
    lx_baker *b = make_baker(scene, 2);
    double mean, worst = floor_error(b, NULL, 1.0, &mean);
    assert_true(worst == 0.0);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

static void ceiling_closes_the_hemisphere(void **state)
{
    (void)state;
    const float h = 0.25f;
    lx_scene *scene = floor_scene(true, h);
    lx_baker *b = make_baker(scene, 2);
    const float distances[3] = {1.0f, 0.5f, 0.3f};
    for (int k = 0; k < 3; k++) {
        lx_ao_desc d = {.distance = distances[k], .samples = 256};
        double want = (h / distances[k]) * (h / distances[k]), mean;
        double worst = floor_error(b, &d, want, &mean);
        printf("ceiling at %g, distance %g: AO %.4f (mean), want %.4f, worst texel off by %.4f\n",
               (double)h, (double)distances[k], mean, want, worst);
        assert_true(worst <= 1.0 / 16.0 + 1e-6); /* one of 16 columns */
        /* the mean is unbiased: the straddling column's share varies by
         * at most 1/16 a texel, over ~300 texels a standard deviation
         * below 1/16 / sqrt(12 * 300) = 1.0e-3; the bias moves the
         * threshold by 3e-4 at most */
        assert_true(fabs(mean - want) < 4e-3);
    }
    /* out of reach */
    lx_ao_desc d = {.distance = 0.2f, .samples = 64};
    double mean, worst = floor_error(b, &d, 1.0, &mean);
    assert_true(worst == 0.0);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    lx_scene *scene = floor_scene(true, 0.3f);
    lx_image ao[2];
    for (int t = 0; t < 2; t++) {
        lx_baker *b = make_baker(scene, t + 1);
        lx_ao_desc d = {.distance = 0.7f, .samples = 100};
        assert_int_equal(lx_baker_ao(b, lx_test_map_of(b, 0), &d, &ao[t]), LX_OK);
        lx_baker_destroy(b);
    }
    assert_memory_equal(ao[0].data, ao[1].data, sizeof(float) * ao[0].width * ao[0].height);
    lx_image_free(&ao[0]);
    lx_image_free(&ao[1]);
    lx_scene_destroy(scene);
}

static void bad_settings_fail(void **state)
{
    (void)state;
    lx_scene *scene = floor_scene(false, 0.0f);
    lx_baker *b = make_baker(scene, 1);
    lx_image ao;
    lx_ao_desc d = {.distance = -1.0f};
    assert_int_equal(lx_baker_ao(b, 0, &d, &ao), LX_ERR_INVALID);
    assert_null(ao.data);
    d = (lx_ao_desc){.distance = NAN};
    assert_int_equal(lx_baker_ao(b, 0, &d, &ao), LX_ERR_INVALID);
    d = (lx_ao_desc){.samples = LX_MAX_AO_SAMPLES + 1};
    assert_int_equal(lx_baker_ao(b, 0, &d, &ao), LX_ERR_INVALID);
    assert_int_equal(lx_baker_ao(b, 99, NULL, &ao), LX_ERR_INVALID);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(open_plane_is_one),
        cmocka_unit_test(ceiling_closes_the_hemisphere),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(bad_settings_fail),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
