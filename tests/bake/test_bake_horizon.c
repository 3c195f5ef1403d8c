/* Horizon self-shadowing and AO in the baker (a height per material from
 * the lights JSON's "materials"). Expected values are closed forms on a
 * +Y plane whose material UV equals its lightmap UV, texel for texel with
 * the height image (u along +x = image x, the tangent; v along +z):
 * - a flat height has no horizon and AO 1: the bake is the same bytes as
 *   without it;
 * - a step of H texels lit from +x at elevation e: a low texel d texels
 *   before the step sees it at atan(H / d) (less off the axis, down to
 *   atan(H cos 22.5 / d) at the edge of direction 0's bins); with
 *   tan e < H cos(22.5) / d well past the transition (sin of the horizon
 *   above sin e + 1/8, the hardness 8) the light is gone, with
 *   tan e > H / d the texel is as without the height, and on the plateau
 *   (nothing higher toward the light) it is unchanged;
 * - at the bottom of a cone pit of slope k every direction's horizon is
 *   atan(k), so the AO is cos(atan k) = 1 / sqrt(k^2 + 1) and the ambient
 *   there is scaled by it;
 * - heights integrated from the normal map of a bump field (a "normal"
 *   file, or the material's own normal texture by default) bake close to
 *   the bump field itself: they differ from it by the round trip through
 *   central differences (docs/maps.md: each mode loses cos^2(w/2)), which
 *   the horizon's hardness 8 turns into light differences of up to a few
 *   percent at the shadows' edges. */
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

/* Writes a size x size float height to dir/name (PFM, values as given). */
static void write_height(const char *dir, const char *name, int size,
                         float (*fn)(int x, int y, int size))
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, size, size, 1), LX_OK);
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++)
            img.data[y * size + x] = fn(x, y, size);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    assert_int_equal(lx_image_write(path, &img, NULL), LX_OK);
    lx_image_free(&img);
}

static float flat(int x, int y, int size)
{
    (void)x, (void)y, (void)size;
    return 0.5f;
}

/* 0 on the left half, 1 on the right: a step up at size/2 going +x (and
 * down at the wrap) */
static float step(int x, int y, int size)
{
    (void)y;
    return x >= size / 2 ? 1.0f : 0.0f;
}

static float cone_k = 1.0f;
/* a pit: k times the distance in texels from texel (size/2, size/2) */
static float cone(int x, int y, int size)
{
    double dx = x - size / 2, dy = y - size / 2;
    return (float)(cone_k * sqrt(dx * dx + dy * dy));
}

typedef struct bake_setup {
    int size;         /* lightmap and height texels a side */
    float elevation;  /* of the directional light from +x, degrees; < 0: none */
    lx_vec3 ambient;  /* scene ambient, lux */
    const char *json; /* lights JSON text (NULL: none), applied as dir/lights.json */
    float sky;        /* radiance of a constant unshadowed sky, nits; 0: none */
} bake_setup;

/* The normal texture of material "bumpy" (encoded, rgb = n/2 + 1/2), or
 * none when width 0. */
static lx_image g_normal_texture;

/* Bakes a 4 m plane with material "bumpy" under the setup into *img. */
static void bake(const char *dir, const bake_setup *s, lx_image *img)
{
    lx_scene *scene = lx_test_new_scene("horizon");
    lx_material mat = {.name = "bumpy", .base_color = {1, 1, 1, 1}, .normal_scale = 1.0f};
    mat.normal_map = g_normal_texture;
    assert_int_equal(lx_scene_add_material(scene, &mat, NULL), LX_OK);
    lx_mesh plane = lx_test_plane("plane", 4.0f, 0.0f, 0.0f, 0.0f, 2);
    lx_test_add(scene, &plane);
    lx_test_mesh_free(&plane);
    scene->ambient = s->ambient;
    if (s->elevation >= 0.0f) {
        lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
        double e = s->elevation * LX_PI / 180.0;
        sun.direction = lx_v3((float)-cos(e), (float)-sin(e), 0.0f);
        sun.intensity = 1000.0f;
        sun.shadow = LX_SHADOW_HARD;
        assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
    }
    if (s->json) {
        char name[1024];
        snprintf(name, sizeof name, "%s/lights.json", dir);
        assert_int_equal(lx_lights_json_apply_text(scene, s->json, strlen(s->json), name), LX_OK);
    }
    lx_bake_desc desc = {.resolution = s->size, .padding = LX_PADDING_NONE, .threads = 2};
    lx_cubemap env = {0};
    if (s->sky > 0.0f) {
        assert_int_equal(lx_cubemap_alloc(&env, 8), LX_OK);
        for (int i = 0; i < 6 * 8 * 8 * 3; i++)
            env.data[i] = s->sky;
        desc.sky.environment = &env;
    }
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    lx_cubemap_free(&env);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(baker, 0, img), LX_OK);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
}

static void flat_height_changes_no_byte(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("bake-horizon-flat");
    write_height(dir, "flat.pfm", 16, flat);
    bake_setup s = {16, 30.0f, {3.0f, 2.0f, 1.0f}, NULL, 0.5f};
    lx_image plain, flat_img;
    bake(dir, &s, &plain);
    s.json = "{\"materials\": {\"bumpy\": {\"height\": \"flat.pfm\", \"strength\": 8}}}";
    bake(dir, &s, &flat_img);
    size_t bytes = sizeof(float) * 3 * 16 * 16;
    assert_memory_equal(plain.data, flat_img.data, bytes);
    lx_image_free(&plain);
    lx_image_free(&flat_img);
}

static void step_shadows_where_the_closed_form_says(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("bake-horizon-step");
    const int size = 16;
    const float H = 4.0f, e = 30.0f; /* wall height in texels, light elevation */
    write_height(dir, "step.pfm", size, step);
    bake_setup s = {size, e, {0, 0, 0}, NULL, 0.0f};
    lx_image plain, img;
    bake(dir, &s, &plain);
    s.json = "{\"materials\": {\"bumpy\": {\"height\": \"step.pfm\", \"strength\": 4, "
             "\"ao\": false}}}";
    bake(dir, &s, &img);
    double te = tan(e * LX_PI / 180.0), se = sin(e * LX_PI / 180.0);
    double cos_edge = cos(22.5 * LX_PI / 180.0);
    int dark = 0, same = 0;
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++) {
            size_t p = (size_t)(y * size + x) * 3;
            float got = img.data[p], want = plain.data[p];
            /* unshadowed the plane gets 1000 sin(e) lux */
            lx_test_assert_rel(want, 1000.0 * se, 1e-6);
            if (x >= size / 2) {
                assert_true(got == want); /* the plateau: nothing higher toward +x */
                same++;
                continue;
            }
            double d = size / 2 - x;
            double low = sin(atan(H * cos_edge / (d + 0.5))); /* the lowest bin's horizon */
            if (low > se + 1.0 / 8.0) {
                assert_true(got == 0.0f);
                dark++;
            } else if (te > H / d) {
                assert_true(got == want);
                same++;
            } else {
                assert_true(got >= 0.0f && got <= want);
            }
        }
    /* at least columns d = 1..3 dark; d = 7, 8 and the plateau unchanged */
    assert_true(dark >= 3 * size);
    assert_int_equal(same, (size / 2 + 2) * size);
    lx_image_free(&plain);
    lx_image_free(&img);
}

/* The ambient A (sky 0) or a constant sky of radiance L (ambient 0) at the
 * pit's bottom: A or pi L (the sky's irradiance on an open plane) times
 * 1 / sqrt(k^2 + 1). */
static void check_cone_ao(float k, bool sky)
{
    char tag[64];
    snprintf(tag, sizeof tag, "bake-horizon-cone-%g-%d", k, (int)sky);
    const char *dir = lx_test_dir(tag);
    const int size = 64;
    cone_k = k;
    write_height(dir, "cone.pfm", size, cone);
    bake_setup s = {size, -1.0f, {100.0f, 100.0f, 100.0f}, NULL, 0.0f};
    if (sky) {
        s.ambient = lx_v3(0, 0, 0);
        s.sky = 100.0f / LX_PI;
    }
    s.json = "{\"materials\": {\"bumpy\": {\"height\": \"cone.pfm\", \"strength\": 1, "
             "\"horizon\": false}}}";
    lx_image img;
    bake(dir, &s, &img);
    size_t p = (size_t)(size / 2 * size + size / 2) * 3;
    double want = 100.0 / sqrt((double)k * k + 1.0);
    for (int c = 0; c < 3; c++)
        lx_test_assert_rel(img.data[p + c], want, 1e-5);
    lx_image_free(&img);
}

static void cone_pit_ao_scales_ambient(void **state)
{
    (void)state;
    check_cone_ao(1.0f, false);
    check_cone_ao(0.5f, false);
    check_cone_ao(1.0f, true);
    check_cone_ao(0.5f, true);
}

static void bad_input_is_named(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("bake-horizon-bad");
    char name[1024];
    snprintf(name, sizeof name, "%s/lights.json", dir);
    lx_scene *scene = lx_test_new_scene("horizon-bad");
    lx_material mat = {.name = "bumpy", .base_color = {1, 1, 1, 1}, .normal_scale = 1.0f};
    assert_int_equal(lx_scene_add_material(scene, &mat, NULL), LX_OK);
    lx_mesh plane = lx_test_plane("plane", 4.0f, 0.0f, 0.0f, 0.0f, 2);
    lx_test_add(scene, &plane);
    lx_test_mesh_free(&plane);

    const char *unknown = "{\"materials\": {\"stone\": {\"height\": \"h.png\"}}}";
    assert_int_not_equal(lx_lights_json_apply_text(scene, unknown, strlen(unknown), name), LX_OK);
    assert_non_null(strstr(lx_last_error(), "stone"));
    assert_non_null(strstr(lx_last_error(), "lights.json"));
    assert_null(scene->materials[0].height_map_path);

    const char *key = "{\"materials\": {\"bumpy\": {\"height\": \"h.png\", \"bumps\": 2}}}";
    assert_int_not_equal(lx_lights_json_apply_text(scene, key, strlen(key), name), LX_OK);
    assert_non_null(strstr(lx_last_error(), "bumps"));

    const char *missing = "{\"materials\": {\"bumpy\": {\"height\": \"no-such-height.png\"}}}";
    assert_int_equal(lx_lights_json_apply_text(scene, missing, strlen(missing), name), LX_OK);
    lx_bake_desc desc = {.resolution = 8, .threads = 2};
    lx_baker *baker = NULL;
    assert_int_not_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_null(baker);
    assert_non_null(strstr(lx_last_error(), "no-such-height.png"));
    lx_scene_destroy(scene);
}


/* bumps: 2 x 1 periods of a product of sines over the map (it tiles) */
static float bumps(int x, int y, int size)
{
    double u = 2.0 * LX_PI * x / size, v = 2.0 * LX_PI * y / size;
    return (float)(0.5 + 0.5 * sin(2.0 * u) * cos(v + 0.4));
}

/* Largest difference of two bakes relative to the plain bake's peak, and
 * the mean one. */
static void compare(const lx_image *a, const lx_image *b, double peak, double *max_rel,
                    double *mean_rel)
{
    size_t n = (size_t)a->width * a->height * 3;
    double m = 0.0, sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)a->data[i] - b->data[i]) / peak;
        m = fmax(m, d);
        sum += d;
    }
    *max_rel = m;
    *mean_rel = sum / (double)n;
}

/* The encoded normal map of the bump field at strength S, wrap repeat. */
static void bump_normals(int size, float S, lx_image *encoded)
{
    lx_image h, n;
    assert_int_equal(lx_image_alloc(&h, size, size, 1), LX_OK);
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++)
            h.data[y * size + x] = bumps(x, y, size);
    lx_normalmap_desc nd = {.strength = S};
    assert_int_equal(lx_normal_map(&h, &nd, &n), LX_OK);
    assert_int_equal(lx_normal_encode(&n, encoded), LX_OK);
    lx_image_free(&h);
    lx_image_free(&n);
}

static void heights_from_normals_bake_like_the_heights(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("bake-horizon-normals");
    const int size = 64;
    write_height(dir, "bumps.pfm", size, bumps);
    lx_image encoded;
    bump_normals(size, 6.0f, &encoded);
    char path[1024];
    snprintf(path, sizeof path, "%s/bumps-normal.pfm", dir);
    assert_int_equal(lx_image_write(path, &encoded, NULL), LX_OK);

    /* a low sun (long shadows) and ambient (AO) */
    bake_setup s = {size, 20.0f, {200.0f, 200.0f, 200.0f}, NULL, 0.0f};
    lx_image plain, from_height, from_file, from_texture, with_texture;
    bake(dir, &s, &plain);
    s.json = "{\"materials\": {\"bumpy\": {\"height\": \"bumps.pfm\", \"strength\": 6}}}";
    bake(dir, &s, &from_height);
    s.json = "{\"materials\": {\"bumpy\": {\"normal\": \"bumps-normal.pfm\"}}}";
    bake(dir, &s, &from_file);
    double peak = 1000.0 * sin(20.0 * LX_PI / 180.0) + 200.0;
    double max_rel, mean_rel, max_plain, mean_plain;
    compare(&from_height, &from_file, peak, &max_rel, &mean_rel);
    compare(&from_height, &plain, peak, &max_plain, &mean_plain);
    /* the heights shadow a good part of the plane ... */
    assert_true(mean_plain > 0.05);
    /* ... and the integrated ones the same part: measured max 0.015 and
     * mean 0.0023 of the peak, against 0.08 for the heights themselves
     * (the round trip's ~1% height loss, times the hardness at the
     * shadows' edges; the normal texture case below: 0.017 and 0.0005) */
    if (max_rel > 0.03 || mean_rel > 0.004)
        fail_msg("heights from a normal file: max %g, mean %g of the peak (the heights "
                 "themselves change it by %g on average)",
                 max_rel, mean_rel, mean_plain);

    /* the material's own normal texture by default: compared with the
     * height given, both shaded with that normal texture */
    g_normal_texture = encoded;
    s.json = "{\"materials\": {\"bumpy\": {\"height\": \"bumps.pfm\", \"strength\": 6}}}";
    bake(dir, &s, &with_texture);
    s.json = "{\"materials\": {\"bumpy\": {}}}";
    bake(dir, &s, &from_texture);
    g_normal_texture = (lx_image){0};
    compare(&with_texture, &from_texture, peak, &max_rel, &mean_rel);
    if (max_rel > 0.03 || mean_rel > 0.004)
        fail_msg("heights from the normal texture: max %g, mean %g of the peak", max_rel,
                 mean_rel);
    lx_image *all[] = {&plain, &from_height, &from_file, &from_texture, &with_texture, &encoded};
    for (int i = 0; i < 6; i++)
        lx_image_free(all[i]);
}

/* A progress callback that stops at the first report. */
static bool stop_now(void *user, float f)
{
    (void)f;
    ++*(int *)user;
    return false;
}

static void heights_from_normals_bad_input(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("bake-horizon-normals-bad");
    char name[1024];
    snprintf(name, sizeof name, "%s/lights.json", dir);
    lx_scene *scene = lx_test_new_scene("horizon-normals-bad");
    lx_material mat = {.name = "bumpy", .base_color = {1, 1, 1, 1}, .normal_scale = 1.0f};
    assert_int_equal(lx_scene_add_material(scene, &mat, NULL), LX_OK);
    lx_mesh plane = lx_test_plane("plane", 4.0f, 0.0f, 0.0f, 0.0f, 2);
    lx_test_add(scene, &plane);
    lx_test_mesh_free(&plane);
    static const struct {
        const char *json, *needle;
    } bad[] = {
        {"{\"materials\": {\"bumpy\": {}}}", "no normal texture"},
        {"{\"materials\": {\"bumpy\": {\"height\": \"h.png\", \"normal\": \"n.png\"}}}",
         "not both"},
        {"{\"materials\": {\"bumpy\": {\"height\": \"h.png\", \"green\": \"up\"}}}",
         "'green' is for normal maps"},
        {"{\"materials\": {\"bumpy\": {\"normal\": \"n.png\", \"green\": \"left\"}}}",
         "green"},
        {"{\"materials\": {\"bumpy\": {\"normal\": \"\"}}}", "normal is an empty path"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_not_equal(
            lx_lights_json_apply_text(scene, bad[i].json, strlen(bad[i].json), name), LX_OK);
        if (!strstr(lx_last_error(), bad[i].needle))
            fail_msg("%s: '%s' lacks '%s'", bad[i].json, lx_last_error(), bad[i].needle);
        assert_false(scene->materials[0].height_from_normals);
    }
    /* a missing normal file fails lx_baker_create naming it */
    const char *missing = "{\"materials\": {\"bumpy\": {\"normal\": \"no-such-normal.png\", "
                          "\"green\": \"down\"}}}";
    assert_int_equal(lx_lights_json_apply_text(scene, missing, strlen(missing), name), LX_OK);
    assert_true(scene->materials[0].height_from_normals);
    assert_true(scene->materials[0].height_green_down);
    assert_null(scene->materials[0].height_map_path);
    lx_bake_desc desc = {.resolution = 8, .threads = 2};
    lx_baker *baker = NULL;
    assert_int_not_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_null(baker);
    assert_non_null(strstr(lx_last_error(), "no-such-normal.png"));
    /* building the horizon maps reports progress and stops when told */
    write_height(dir, "flat.pfm", 16, flat);
    const char *ok = "{\"materials\": {\"bumpy\": {\"height\": \"flat.pfm\"}}}";
    assert_int_equal(lx_lights_json_apply_text(scene, ok, strlen(ok), name), LX_OK);
    assert_false(scene->materials[0].height_from_normals);
    int calls = 0;
    desc.progress = stop_now;
    desc.progress_user = &calls;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_ERR_CANCELLED);
    assert_null(baker);
    assert_int_equal(calls, 1);
    lx_scene_destroy(scene);
}

static char g_warning[512];
static int g_warnings;
static void keep_warning(void *user, lx_log_level level, const char *message)
{
    (void)user;
    if (level == LX_LOG_WARN && strstr(message, "UV set")) {
        g_warnings++;
        snprintf(g_warning, sizeof g_warning, "%s", message);
    }
}

/* A height material read at a UV set its mesh lacks: one warning line
 * naming the mesh, the set and the material; the bake is as without it. */
static void missing_uv_set_warns(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("bake-horizon-uvset");
    char name[1024];
    snprintf(name, sizeof name, "%s/lights.json", dir);
    write_height(dir, "step.pfm", 16, step);
    lx_scene *scene = lx_test_new_scene("horizon-uvset");
    lx_material mat = {.name = "bumpy", .base_color = {1, 1, 1, 1}, .normal_scale = 1.0f,
                       .normal_uv_set = 1};
    assert_int_equal(lx_scene_add_material(scene, &mat, NULL), LX_OK);
    lx_mesh plane = lx_test_plane("plane", 4.0f, 0.0f, 0.0f, 0.0f, 2);
    free(plane.uv[1]); /* the lightmap's UVs only */
    plane.uv[1] = NULL;
    lx_test_add(scene, &plane);
    lx_test_mesh_free(&plane);
    assert_null(scene->meshes[0].uv[1]);
    const char *json = "{\"materials\": {\"bumpy\": {\"height\": \"step.pfm\"}}}";
    assert_int_equal(lx_lights_json_apply_text(scene, json, strlen(json), name), LX_OK);
    g_warnings = 0;
    lx_set_log_callback(keep_warning, NULL);
    lx_bake_desc desc = {.resolution = 8, .threads = 2};
    lx_baker *baker = NULL;
    lx_status st = lx_baker_create(scene, &desc, &baker);
    lx_set_log_callback(NULL, NULL);
    assert_int_equal(st, LX_OK);
    assert_int_equal(g_warnings, 1);
    assert_non_null(strstr(g_warning, "'plane'"));
    assert_non_null(strstr(g_warning, "UV set 1"));
    assert_non_null(strstr(g_warning, "'bumpy'"));
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(flat_height_changes_no_byte),
        cmocka_unit_test(step_shadows_where_the_closed_form_says),
        cmocka_unit_test(cone_pit_ao_scales_ambient),
        cmocka_unit_test(bad_input_is_named),
        cmocka_unit_test(heights_from_normals_bake_like_the_heights),
        cmocka_unit_test(heights_from_normals_bad_input),
        cmocka_unit_test(missing_uv_set_warns),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
