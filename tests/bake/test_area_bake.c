/* Area lights in the baker: soft shadows with nothing in the way equal the
 * unshadowed bake exactly (an invariant of the weighted visible fraction), a rect
 * light half hidden behind an occluder's edge matches an independent
 * quadrature of its visible part (and so does a linear tube's), and soft
 * shadows are the same bytes for any thread count. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static lx_light area_light(lx_light_type type, lx_shadow_mode shadow, uint32_t samples)
{
    lx_light l = lx_light_defaults(type);
    l.position = lx_v3(0.0f, 2.0f, 0.0f);
    l.direction = lx_v3(0.0f, -1.0f, 0.0f);
    l.up = lx_v3(0.0f, 0.0f, 1.0f);
    l.radius = 0.3f;
    l.width = 1.0f;
    l.height = 1.0f;
    l.intensity = 1000.0f; /* nits */
    l.shadow = shadow;
    l.samples = samples;
    return l;
}

/* Bakes a 0.5 m floor (node 0) under light, with an optional occluder
 * covering x < 0 at height 1.9; returns the floor's lightmap. */
static lx_baker *bake(lx_light light, bool occluder, int threads, lx_image *out)
{
    lx_scene *scene;
    assert_int_equal(lx_scene_create("area", &scene), LX_OK);
    lx_mesh floor = lx_test_plane("floor", 0.5f, 0.0f, 0.0f, 0.0f, 2);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    if (occluder) {
        lx_mesh wall = lx_test_plane("occluder", 10.0f, 1.9f, -5.0f, 0.0f, 1);
        lx_test_add(scene, &wall);
        lx_test_mesh_free(&wall);
    }
    assert_int_equal(lx_scene_add_light(scene, &light), LX_OK);
    lx_bake_desc desc = {.resolution = 8, .padding = LX_PADDING_NONE, .threads = threads};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(baker, 0, out), LX_OK);
    lx_scene_destroy(scene);
    return baker;
}

static void soft_unoccluded_equals_unshadowed(void **state)
{
    (void)state;
    /* the last two: a tube along x, and a linear one */
    const lx_light_type types[5] = {LX_LIGHT_SPHERE, LX_LIGHT_DISK, LX_LIGHT_RECT, LX_LIGHT_TUBE,
                                    LX_LIGHT_TUBE};
    for (int t = 0; t < 5; t++) {
        lx_light soft_light = area_light(types[t], LX_SHADOW_SOFT, 16);
        lx_light none_light = area_light(types[t], LX_SHADOW_NONE, 0);
        if (types[t] == LX_LIGHT_TUBE) {
            soft_light.direction = none_light.direction = lx_v3(1.0f, 0.0f, 0.0f);
            soft_light.radius = none_light.radius = t == 4 ? 0.0f : 0.05f;
        }
        lx_image soft, none;
        lx_baker *a = bake(soft_light, false, 2, &soft);
        lx_baker *b = bake(none_light, false, 2, &none);
        for (int p = 0; p < 64 * 3; p++) {
            assert_true(none.data[p] > 0.0f);
            /* exactly: the weighted visible share is visible / total with
             * nothing hidden (measured: no difference at all) */
            assert_true(soft.data[p] == none.data[p]);
        }
        lx_image_free(&soft);
        lx_image_free(&none);
        lx_baker_destroy(a);
        lx_baker_destroy(b);
    }
}

/* Illuminance at p (normal +Y) from the part of the 1 m rect light at
 * height 2 with x > x_min, by a midpoint rule in double. */
static double visible_rect_quadrature(lx_vec3 p, double x_min, double luminance)
{
    const int n = 400;
    double sum = 0.0, cell = 1.0 / n;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double qx = -0.5 + (i + 0.5) * cell, qz = -0.5 + (j + 0.5) * cell;
            if (qx < x_min)
                continue;
            double dx = qx - p.x, dy = 2.0 - p.y, dz = qz - p.z;
            double d2 = dx * dx + dy * dy + dz * dz;
            /* cos at the floor (normal +Y) and at the light (normal -Y) */
            sum += luminance * (dy / sqrt(d2)) * (dy / sqrt(d2)) / d2 * cell * cell;
        }
    return sum;
}

static void half_hidden_rect_matches_quadrature(void **state)
{
    (void)state;
    lx_image img;
    lx_baker *baker = bake(area_light(LX_LIGHT_RECT, LX_SHADOW_SOFT, 1024), true, 2, &img);
    int checked = 0;
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            lx_texel_sample s;
            assert_true(lx_baker_texel(baker, 0, x, y, &s));
            /* the edge at x = 0, y = 1.9 hides light points with
             * q.x < p.x (1 - 2 / 1.9) as seen from p */
            double x_min = s.position.x * (1.0 - 2.0 / 1.9);
            double want = visible_rect_quadrature(s.position, x_min, 1000.0);
            double full = visible_rect_quadrature(s.position, -1.0, 1000.0);
            double got = img.data[3 * (y * 8 + x)];
            assert_true(want > 0.3 * full && want < 0.7 * full); /* about half */
            /* 1024 jittered samples: measured 5.9e-3 (rms 2.3e-3) */
            assert_true(fabs(got - want) <= 0.02 * full);
            checked++;
        }
    assert_int_equal(checked, 64);
    lx_image_free(&img);
    lx_baker_destroy(baker);
}

/* Illuminance at p (normal +Y) from the part of a linear light along x
 * at height 2, x in [-0.5, 0.5], with x > x_min: I sin(alpha) cos(t) / d^2
 * summed along it. */
static double visible_line_quadrature(lx_vec3 p, double x_min, double per_metre)
{
    const int n = 20000;
    double sum = 0.0, dl = 1.0 / n;
    for (int i = 0; i < n; i++) {
        double qx = -0.5 + (i + 0.5) * dl;
        if (qx < x_min)
            continue;
        double dx = qx - p.x, dy = 2.0 - p.y, dz = -p.z;
        double d2 = dx * dx + dy * dy + dz * dz, d = sqrt(d2);
        double sin_a = sqrt(dy * dy + dz * dz) / d;
        sum += per_metre * sin_a * (dy / d) / d2 * dl;
    }
    return sum;
}

static void half_hidden_linear_tube_matches_quadrature(void **state)
{
    (void)state;
    lx_light tube = area_light(LX_LIGHT_TUBE, LX_SHADOW_SOFT, 1024);
    tube.direction = lx_v3(1.0f, 0.0f, 0.0f);
    tube.radius = 0.0f;
    tube.intensity = 200.0f; /* cd per metre */
    lx_image img;
    lx_baker *baker = bake(tube, true, 2, &img);
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            lx_texel_sample s;
            assert_true(lx_baker_texel(baker, 0, x, y, &s));
            double x_min = s.position.x * (1.0 - 2.0 / 1.9);
            double want = visible_line_quadrature(s.position, x_min, 200.0);
            double full = visible_line_quadrature(s.position, -1.0, 200.0);
            double got = img.data[3 * (y * 8 + x)];
            assert_true(want > 0.3 * full && want < 0.7 * full);
            /* 1024 jittered samples: measured 5.5e-3 (rms 2.3e-3) */
            assert_true(fabs(got - want) <= 0.02 * full);
        }
    lx_image_free(&img);
    lx_baker_destroy(baker);
}

/* samples 0 bakes with the light model's default count: the same bytes as
 * asking for lx_light_sample_count's number, and not those of another */
static void default_samples_are_the_models(void **state)
{
    (void)state;
    lx_light zero = area_light(LX_LIGHT_DISK, LX_SHADOW_SOFT, 0);
    lx_image a, b, c;
    lx_baker *ba = bake(zero, true, 2, &a);
    lx_baker *bb =
        bake(area_light(LX_LIGHT_DISK, LX_SHADOW_SOFT, lx_light_sample_count(&zero)), true, 2, &b);
    lx_baker *bc = bake(area_light(LX_LIGHT_DISK, LX_SHADOW_SOFT, lx_light_sample_count(&zero) + 1),
                        true, 2, &c);
    assert_memory_equal(a.data, b.data, sizeof(float) * 64 * 3);
    assert_memory_not_equal(a.data, c.data, sizeof(float) * 64 * 3);
    lx_image_free(&a);
    lx_image_free(&b);
    lx_image_free(&c);
    lx_baker_destroy(ba);
    lx_baker_destroy(bb);
    lx_baker_destroy(bc);
}

static void soft_shadows_are_deterministic(void **state)
{
    (void)state;
    lx_image one, two;
    lx_baker *a = bake(area_light(LX_LIGHT_DISK, LX_SHADOW_SOFT, 37), true, 1, &one);
    lx_baker *b = bake(area_light(LX_LIGHT_DISK, LX_SHADOW_SOFT, 37), true, 2, &two);
    assert_memory_equal(one.data, two.data, sizeof(float) * 64 * 3);
    lx_image_free(&one);
    lx_image_free(&two);
    lx_baker_destroy(a);
    lx_baker_destroy(b);
}

static void soft_shadows_need_an_area_light(void **state)
{
    (void)state;
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    l.shadow = LX_SHADOW_SOFT;
    assert_int_equal(lx_light_validate(&l), LX_ERR_INVALID);
    lx_light r = area_light(LX_LIGHT_RECT, LX_SHADOW_SOFT, 16);
    r.up = r.direction;
    assert_int_equal(lx_light_validate(&r), LX_ERR_INVALID);
    lx_light sph = area_light(LX_LIGHT_SPHERE, LX_SHADOW_SOFT, 16);
    sph.radius = 0.0f;
    assert_int_equal(lx_light_validate(&sph), LX_ERR_INVALID);
    sph.radius = 0.1f;
    sph.samples = LX_MAX_LIGHT_SAMPLES + 1;
    assert_int_equal(lx_light_validate(&sph), LX_ERR_INVALID);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(soft_unoccluded_equals_unshadowed),
        cmocka_unit_test(half_hidden_rect_matches_quadrature),
        cmocka_unit_test(half_hidden_linear_tube_matches_quadrature),
        cmocka_unit_test(soft_shadows_are_deterministic),
        cmocka_unit_test(default_samples_are_the_models),
        cmocka_unit_test(soft_shadows_need_an_area_light),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
