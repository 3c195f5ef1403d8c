/* The bounces' per-texel variance (lx_lightmap.gi_variance), the
 * denoiser's guide, against the error it stands for: a floor lit by a
 * point light and by what a white box beside it reflects, one bounce at
 * S gather rays a texel; the raw bake's squared error against a bake of
 * 64 S rays (the converged reference, its own noise 1/64 of the
 * variance), averaged over the floor, is what the variance says it is
 * on average. The estimate ignores the rays' stratification, so it may
 * only be larger than the real error, by the share stratification
 * removes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bake/bake_internal.h"
#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define RES 32
#define SAMPLES 32u

static lx_scene *box_scene(void)
{
    lx_scene *scene = lx_test_new_scene("variance");
    uint32_t grey = lx_test_grey_material(scene, "grey", 0.5f, 0.0f);
    uint32_t white = lx_test_grey_material(scene, "white", 0.9f, 0.0f);
    lx_mesh floor = lx_test_plane("floor", 4.0f, 0.0f, 0.0f, 0.0f, 4);
    floor.material = grey;
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    lx_mesh box = lx_test_box("box", lx_v3(0.5f, 0.0f, -1.0f), lx_v3(1.0f, 1.5f, 1.0f), false);
    box.material = white;
    lx_test_add(scene, &box);
    lx_test_mesh_free(&box);
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "lamp");
    l.position = lx_v3(1.6f, 1.2f, 0.0f);
    l.intensity = 500.0f;
    assert_int_equal(lx_scene_add_light(scene, &l), LX_OK);
    return scene;
}

static lx_baker *bake_adaptive(const lx_scene *scene, uint32_t samples, lx_denoise_mode denoise,
                               bool adaptive)
{
    lx_bake_desc d = {.resolution = RES,
                      .bounces = 1,
                      .gi_samples = samples,
                      .denoise = denoise,
                      .gi_adaptive = adaptive};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    return b;
}

static lx_baker *bake(const lx_scene *scene, uint32_t samples, lx_denoise_mode denoise)
{
    return bake_adaptive(scene, samples, denoise, false);
}

/* Mean squared luminance error of map's covered texels against ref's,
 * and how many texels are off by more than 5%. */
static double squared_error(const lx_lightmap *x, const lx_lightmap *ref, int *off)
{
    double err2 = 0.0;
    int texels = 0;
    *off = 0;
    for (size_t p = 0; p < (size_t)RES * RES; p++) {
        if (!ref->mask[p])
            continue;
        double got = lx_luminance(x->baked + 3 * p), want = lx_luminance(ref->baked + 3 * p);
        err2 += (got - want) * (got - want);
        *off += fabs(got - want) > 0.05 * want;
        texels++;
    }
    return err2 / texels;
}

/* Adaptive gathers against the 64x reference: each texel stops once its
 * estimate's standard error is within LX_GI_ADAPTIVE_NOISE of it or at
 * 4x the base count, so on this noisy floor (most texels reach the cap)
 * the error is well below the fixed gather's at the base count, and the
 * same bytes come out of 1 and 2 threads. */
static void adaptive_gathers_converge(void **state)
{
    (void)state;
    lx_scene *scene = box_scene();
    lx_baker *fixed = bake(scene, SAMPLES, LX_DENOISE_OFF);
    lx_baker *ada = bake_adaptive(scene, SAMPLES, LX_DENOISE_OFF, true);
    lx_baker *ref = bake(scene, 64 * SAMPLES, LX_DENOISE_OFF);
    uint32_t map = lx_test_map_of(ref, 0);
    int off_fixed, off_ada;
    double e_fixed = squared_error(&fixed->maps[map], &ref->maps[map], &off_fixed);
    double e_ada = squared_error(&ada->maps[map], &ref->maps[map], &off_ada);
    printf("adaptive gathers (base %u rays): mean squared error %.4g against %.4g fixed, texels "
           "off by 5%%: %d against %d\n",
           SAMPLES, e_ada, e_fixed, off_ada, off_fixed);
    /* measured 2.06x less squared error (4x at most: the cap), 334
     * texels off by 5% against 372 */
    assert_true(e_ada * 1.5 < e_fixed);
    assert_true(off_ada < off_fixed);
    lx_bake_desc d = {.resolution = RES, .bounces = 1, .gi_samples = SAMPLES,
                      .gi_adaptive = true, .threads = 1};
    lx_baker *one;
    assert_int_equal(lx_baker_create(scene, &d, &one), LX_OK);
    assert_int_equal(lx_baker_bake(one), LX_OK);
    assert_memory_equal(one->maps[map].baked, ada->maps[map].baked, sizeof(float) * 3 * RES * RES);
    lx_baker_destroy(one);
    lx_baker_destroy(fixed);
    lx_baker_destroy(ada);
    lx_baker_destroy(ref);
    lx_scene_destroy(scene);
}

static void variance_is_the_error_it_guides(void **state)
{
    (void)state;
    lx_scene *scene = box_scene();
    lx_baker *guided = bake(scene, SAMPLES, LX_DENOISE_INDIRECT);
    lx_baker *raw = bake(scene, SAMPLES, LX_DENOISE_OFF);
    lx_baker *ref = bake(scene, 64 * SAMPLES, LX_DENOISE_OFF);
    uint32_t map = lx_test_map_of(raw, 0);
    const lx_lightmap *g = &guided->maps[map], *r = &raw->maps[map], *f = &ref->maps[map];
    assert_non_null(g->gi_variance);
    assert_null(r->gi_variance);
    double err2 = 0.0, var = 0.0;
    int texels = 0;
    for (size_t p = 0; p < (size_t)RES * RES; p++) {
        if (!r->mask[p])
            continue;
        double got = lx_luminance(r->baked + 3 * p), want = lx_luminance(f->baked + 3 * p);
        assert_true(g->gi_variance[p] >= 0.0f && isfinite(g->gi_variance[p]));
        err2 += (got - want) * (got - want);
        var += g->gi_variance[p];
        texels++;
    }
    err2 /= texels;
    var /= texels;
    printf("one bounce at %u rays a texel over %d floor texels: mean squared error %.4g, mean "
           "estimated variance %.4g (ratio %.3f)\n",
           SAMPLES, texels, err2, var, err2 / var);
    /* measured 0.477: the error is what the variance says, less the part
     * stratification removes; an estimate off by 2x either way fails */
    assert_true(err2 / var > 0.2);
    assert_true(err2 / var < 1.2);
    lx_baker_destroy(guided);
    lx_baker_destroy(raw);
    lx_baker_destroy(ref);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(variance_is_the_error_it_guides),
        cmocka_unit_test(adaptive_gathers_converge),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
