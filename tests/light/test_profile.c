/* Photometric profiles on lights (Filament's photometric lights): an isotropic profile equals a
 * plain point light, a masked one takes the light's intensity as its
 * average, the profile's planes follow the light's direction and up, the
 * lights JSON loads them relative to its own folder and its "multiplier"
 * scales an unmasked profile's candela (in a bake too), and a baker keeps
 * its profiles alive after the scene is gone. */
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

#define LX_PI_D 3.14159265358979323846
/* Intensities recovered from float illuminance times d^2: measured up to
 * 9.5e-8 relative */
#define CD_TOL 3e-7

/* 100 cd in every direction. */
static const char *isotropic = "IESNA:LM-63-2002\nTILT=NONE\n"
                               "1 -1 1 3 1 1 2 0 0 0\n1 1 0\n0 90 180\n0\n100 100 100\n";
/* Lower hemisphere only: 100 cd in the C0/C180 planes, 10 cd in C90. */
static const char *bilateral = "IESNA:LM-63-2002\nTILT=NONE\n"
                               "1 -1 1 2 3 1 2 0 0 0\n1 1 0\n0 90\n0 90 180\n"
                               "100 100\n10 10\n100 100\n";

static lx_ies_profile *parse(const char *text)
{
    lx_ies_profile *p = NULL;
    assert_int_equal(lx_ies_parse(text, strlen(text), "test.ies", &p), LX_OK);
    return p;
}

/* Intensity toward q: E at q with the normal facing the light, times d^2. */
static double intensity_toward(const lx_light *l, lx_vec3 q)
{
    lx_vec3 to = lx_sub(l->position, q);
    double d2 = lx_dot(to, to);
    lx_light_eval e;
    if (!lx_light_evaluate(l, q, lx_normalize(to), &e))
        return 0.0;
    return e.illuminance.x * d2;
}

static void isotropic_equals_point(void **state)
{
    (void)state;
    lx_ies_profile *p = parse(isotropic);
    lx_light plain = lx_light_defaults(LX_LIGHT_POINT);
    plain.intensity = 100.0f;
    lx_light prof = plain;
    prof.intensity = 7.0f; /* ignored without masking */
    prof.profile = p;
    prof.profile_scale = 1.0f;
    assert_int_equal(lx_light_validate(&prof), LX_OK);
    const lx_vec3 qs[3] = {{0, -2, 0}, {1, 1, 1}, {-3, 0.5f, 2}};
    for (int i = 0; i < 3; i++) /* measured: the same */
        lx_test_assert_rel(intensity_toward(&prof, qs[i]), intensity_toward(&plain, qs[i]), CD_TOL);
    /* masked: the light's 50 cd becomes the average of the profile */
    prof.intensity = 50.0f;
    prof.profile_scale = (float)(50.0 / (lx_ies_total_lumens(p) / (4.0 * LX_PI_D)));
    lx_test_assert_rel(intensity_toward(&prof, qs[1]), 50.0, 1e-6); /* measured 2.7e-7 */
    lx_ies_free(p);
}

static void planes_follow_direction_and_up(void **state)
{
    (void)state;
    lx_ies_profile *p = parse(bilateral);
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    l.direction = lx_v3(0, -1, 0);
    l.up = lx_v3(1, 0, 0); /* C0 toward +x, C90 toward direction x up = +z */
    l.profile = p;
    l.profile_scale = 1.0f;
    lx_test_assert_rel(intensity_toward(&l, lx_v3(1, -1, 0)), 100.0, CD_TOL);
    lx_test_assert_rel(intensity_toward(&l, lx_v3(0, -1, 1)), 10.0, CD_TOL);
    lx_test_assert_rel(intensity_toward(&l, lx_v3(-1, -1, 0)), 100.0, CD_TOL);
    assert_true(intensity_toward(&l, lx_v3(0, 1, 0)) == 0.0); /* upper hemisphere: dark */
    /* turned: C0 toward +z now */
    l.up = lx_v3(0, 0, 1);
    lx_test_assert_rel(intensity_toward(&l, lx_v3(0, -1, 1)), 100.0, CD_TOL);
    lx_ies_free(p);
}

static void lights_json_loads_relative_profiles(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_profile");
    char path[1024];
    snprintf(path, sizeof path, "%s/fixture.ies", dir);
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(isotropic, fp);
    fclose(fp);
    snprintf(path, sizeof path, "%s/lights.json", dir);
    fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs("{\"lights\": [{\"name\": \"fixture\", \"type\": \"point\", \"position\": [0, 3, 0],"
          " \"direction\": [0, -1, 0], \"ies\": \"fixture.ies\", \"masked\": true,"
          " \"intensity\": 1500, \"unit\": \"lm\"}]}",
          fp);
    fclose(fp);
    lx_scene *scene;
    assert_int_equal(lx_scene_create("profiles", &scene), LX_OK);
    assert_int_equal(lx_lights_json_apply(scene, path), LX_OK);
    assert_int_equal(scene->light_count, 1);
    assert_non_null(scene->lights[0].profile);
    /* 1500 lm masked onto an isotropic profile: 1500 / 4 pi cd everywhere */
    double want = 1500.0 / (4.0 * LX_PI_D);
    /* the profile's lumens by quadrature: measured 2.6e-7 */
    lx_test_assert_rel(intensity_toward(&scene->lights[0], lx_v3(2, 0, 1)), want, 1e-6);

    /* a baker keeps the profile when the scene is gone */
    lx_mesh floor = lx_test_plane("floor", 2.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    lx_bake_desc desc = {.resolution = 4, .padding = LX_PADDING_NONE};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    lx_scene_destroy(scene);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &img), LX_OK);
    lx_texel_sample s;
    assert_true(lx_baker_texel(baker, 0, 1, 1, &s));
    lx_vec3 to = lx_sub(lx_v3(0, 3, 0), s.position);
    double e = want * (to.y / lx_length(to)) / lx_dot(to, to);
    lx_test_assert_rel(img.data[3 * (1 * 4 + 1)], e, CD_TOL); /* measured 7.2e-8 */
    lx_image_free(&img);
    lx_baker_destroy(baker);

    /* a missing profile names the light and the file */
    fp = fopen(path, "wb");
    fputs("{\"lights\": [{\"type\": \"point\", \"position\": [0, 3, 0], \"ies\": \"nope.ies\"}]}",
          fp);
    fclose(fp);
    assert_int_equal(lx_scene_create("profiles", &scene), LX_OK);
    assert_int_not_equal(lx_lights_json_apply(scene, path), LX_OK);
    assert_non_null(strstr(lx_last_error(), "nope.ies"));
    assert_non_null(strstr(lx_last_error(), "lights[0]"));
    assert_int_equal(scene->light_count, 0);
    lx_scene_destroy(scene);
}

/* Writes text to dir/name; fails the test if it cannot. */
static void write_file(const char *dir, const char *name, const char *text)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
}

/* Applies lights JSON text as if read from dir/lights.json. */
static lx_status apply(lx_scene *scene, const char *dir, const char *json)
{
    char name[1024];
    snprintf(name, sizeof name, "%s/lights.json", dir);
    return lx_lights_json_apply_text(scene, json, strlen(json), name);
}

/* The lights JSON "multiplier" scales an unmasked profile's own candela:
 * the bilateral file's 100 cd (C0) and 10 cd (C90) times it, read back
 * through the light and through a bake; an override changes it alone; 0 is
 * dark; on a masked profile it is an error, not ignored. */
static void lights_json_multiplier(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_profile_multiplier");
    write_file(dir, "flood.ies", bilateral);
    lx_scene *scene;
    assert_int_equal(lx_scene_create("multiplier", &scene), LX_OK);
    lx_mesh floor = lx_test_plane("floor", 2.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    assert_int_equal(apply(scene, dir,
                           "{\"lights\": [{\"name\": \"flood\", \"type\": \"point\", \"position\": "
                           "[0, 3, 0], \"direction\": [0, -1, 0], \"up\": [1, 0, 0], \"ies\": "
                           "\"flood.ies\", \"multiplier\": 2.5, \"intensity\": 7}]}"),
                     LX_OK);
    assert_int_equal(scene->light_count, 1);
    const lx_light *l = &scene->lights[0];
    assert_true(l->profile_scale == 2.5f);
    /* C0 toward up (+x), C90 toward direction x up (+z); intensity ignored */
    lx_test_assert_rel(intensity_toward(l, lx_v3(1, 2, 0)), 250.0, CD_TOL);
    lx_test_assert_rel(intensity_toward(l, lx_v3(0, 2, 1)), 25.0, CD_TOL);

    /* a bake: each floor texel gets 2.5 x the file's candela toward it,
     * linear in the horizontal angle between C0 (100 cd, +x) and C90
     * (10 cd, +z), mirrored about C0-C180, the same at every vertical angle */
    lx_bake_desc desc = {.resolution = 4, .padding = LX_PADDING_NONE};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &img), LX_OK);
    int checked = 0;
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 4; x++) {
            lx_texel_sample s;
            assert_true(lx_baker_texel(baker, 0, x, y, &s));
            lx_vec3 to = lx_sub(lx_v3(0, 3, 0), s.position);
            double h = fabs(atan2(-(double)to.z, -(double)to.x)) * 180.0 / LX_PI_D; /* 0..180 */
            double cd = h <= 90.0 ? 100.0 - 90.0 * h / 90.0 : 10.0 + 90.0 * (h - 90.0) / 90.0;
            double d2 = lx_dot(to, to);
            double e = 2.5 * cd * (to.y / sqrt(d2)) / d2;
            /* interpolated from float angles: measured 4.0e-7 */
            lx_test_assert_rel(img.data[3 * (y * 4 + x)], e, 1.5e-6);
            checked++;
        }
    lx_image_free(&img);
    lx_baker_destroy(baker);

    /* an override of the multiplier alone keeps the profile */
    assert_int_equal(
        apply(scene, dir, "{\"lights\": [{\"name\": \"flood\", \"multiplier\": 0.5}]}"), LX_OK);
    assert_int_equal(scene->light_count, 1);
    assert_non_null(scene->lights[0].profile);
    lx_test_assert_rel(intensity_toward(&scene->lights[0], lx_v3(1, 2, 0)), 50.0, CD_TOL);
    /* 0 is dark */
    assert_int_equal(apply(scene, dir, "{\"lights\": [{\"name\": \"flood\", \"multiplier\": 0}]}"),
                     LX_OK);
    assert_true(intensity_toward(&scene->lights[0], lx_v3(1, 2, 0)) == 0.0);

    /* a masked profile takes its scale from the intensity: a multiplier
     * there is an error naming it, and the scene is left as it was */
    lx_status st =
        apply(scene, dir,
              "{\"lights\": [{\"name\": \"flood\", \"masked\": true, \"intensity\": 100, "
              "\"multiplier\": 3}]}");
    assert_int_equal(st, LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "lights.json"));
    assert_non_null(strstr(lx_last_error(), "'multiplier' scales an unmasked profile"));
    assert_true(scene->lights[0].profile_scale == 0.0f);
    /* negative, or without a profile */
    assert_int_equal(apply(scene, dir, "{\"lights\": [{\"name\": \"flood\", \"multiplier\": -1}]}"),
                     LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "multiplier -1 is negative"));
    assert_int_not_equal(apply(scene, dir,
                               "{\"lights\": [{\"name\": \"bare\", \"type\": \"point\", "
                               "\"position\": [0, 1, 0], \"multiplier\": 2}]}"),
                         LX_OK);
    assert_non_null(strstr(lx_last_error(), "need an 'ies' profile"));
    assert_int_equal(scene->light_count, 1);
    lx_scene_destroy(scene);
    assert_int_equal(checked, 16);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(isotropic_equals_point),
        cmocka_unit_test(planes_follow_direction_and_up),
        cmocka_unit_test(lights_json_loads_relative_profiles),
        cmocka_unit_test(lights_json_multiplier),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
