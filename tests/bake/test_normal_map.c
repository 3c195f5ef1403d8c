/* Normal maps in the baker: a plane whose material carries a constant
 * tangent-space normal map is lit as if its normal were the tilted one.
 * Expected values are closed forms: with u along +x and v along +z on a +Y
 * plane, the tangent is +x and the glTF bitangent (toward -v) is -z, so
 * m = (mx, my, mz) becomes n' = mx (1,0,0) + my (0,0,-1) + mz (0,1,0).
 * The bounces gather about the vertex normal instead (a furnace). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* Bakes a 4 m plane with a constant normal map encoding m under a
 * directional light of `lux` shining along dir, and checks every covered
 * texel against lux * max(0, n' . -dir). */
static void check_tilt(lx_vec3 m, lx_vec3 dir, bool with_tangents)
{
    lx_scene *scene;
    assert_int_equal(lx_scene_create("normal-map", &scene), LX_OK);
    lx_material mat = {.name = "bumpy", .base_color = {1, 1, 1, 1}, .normal_scale = 1.0f};
    assert_int_equal(lx_image_alloc(&mat.normal_map, 4, 4, 3), LX_OK);
    for (int p = 0; p < 16; p++) {
        mat.normal_map.data[3 * p + 0] = (m.x + 1.0f) * 0.5f;
        mat.normal_map.data[3 * p + 1] = (m.y + 1.0f) * 0.5f;
        mat.normal_map.data[3 * p + 2] = (m.z + 1.0f) * 0.5f;
    }
    assert_int_equal(lx_scene_add_material(scene, &mat, NULL), LX_OK);
    lx_image_free(&mat.normal_map);

    lx_mesh plane = lx_test_plane("plane", 4.0f, 0.0f, 0.0f, 0.0f, 2);
    if (with_tangents) {
        plane.tangents = malloc(sizeof(lx_vec4) * plane.vertex_count);
        for (uint32_t v = 0; v < plane.vertex_count; v++)
            plane.tangents[v] = lx_v4(1, 0, 0, 1);
    }
    lx_test_add(scene, &plane);
    lx_test_mesh_free(&plane);

    const float lux = 1000.0f;
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_normalize(dir);
    sun.intensity = lux;
    sun.shadow = LX_SHADOW_NONE;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);

    lx_bake_desc desc = {.resolution = 16, .padding = LX_PADDING_NONE, .threads = 2};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &img), LX_OK);

    lx_vec3 mn = lx_normalize(m);
    lx_vec3 tilted = lx_normalize(lx_v3(mn.x, mn.z, -mn.y));
    float expected = lux * fmaxf(0.0f, lx_dot(tilted, lx_neg(sun.direction)));
    const uint8_t *mask = lx_baker_mask(baker, 0);
    int covered = 0;
    for (int p = 0; p < img.width * img.height; p++) {
        if (!mask[p])
            continue;
        covered++;
        float got = img.data[3 * p];
        /* measured: within 6.1e-8 relative, bound 2e-7 */
        assert_true(fabsf(got - expected) <= 2e-7f * fmaxf(expected, 1.0f));
    }
    assert_int_equal(covered, 16 * 16);
    lx_image_free(&img);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
}

static void flat_map_changes_nothing(void **state)
{
    (void)state;
    check_tilt(lx_v3(0, 0, 1), lx_v3(0.3f, -1, 0.1f), false);
}

static void tilt_toward_tangent(void **state)
{
    (void)state;
    float a = 0.5f;
    check_tilt(lx_v3(sinf(a), 0, cosf(a)), lx_v3(0, -1, 0), false);
    check_tilt(lx_v3(sinf(a), 0, cosf(a)), lx_v3(-1, -1, 0), false);
}

static void tilt_toward_bitangent(void **state)
{
    (void)state;
    float a = 0.7f;
    /* +Y in the map is "up" in the image: toward -v, which is -z here */
    check_tilt(lx_v3(0, sinf(a), cosf(a)), lx_v3(0, -1, 1), false);
    check_tilt(lx_v3(0, -sinf(a), cosf(a)), lx_v3(0, -1, 1), false);
}

static void tangents_from_the_file(void **state)
{
    (void)state;
    float a = 0.4f;
    check_tilt(lx_v3(sinf(a), sinf(a), 1.0f), lx_v3(-0.5f, -1, 0.5f), true);
}

/* The bounces gather about the vertex normal: in a closed box of albedo
 * rho under an ambient A (light from every direction, whatever the
 * normal), one bounce gives A (1 + rho) at every texel, exactly (the
 * cosine-weighted gather of a uniform radiance), however tilted the
 * normal map; gathered about a normal tilted 53 degrees, the rays under
 * the surface came back dark and the bounce fell short. */
static void bounces_gather_about_the_vertex_normal(void **state)
{
    (void)state;
    const float rho = 0.5f, a = 2.0f;
    lx_scene *scene = lx_test_new_scene("bumpy-furnace");
    lx_material mat = {.name = "bumpy", .base_color = {rho, rho, rho, 1}, .normal_scale = 1.0f};
    assert_int_equal(lx_image_alloc(&mat.normal_map, 4, 4, 3), LX_OK);
    const lx_vec3 m = {0.8f, 0.0f, 0.6f};
    for (int p = 0; p < 16; p++) {
        mat.normal_map.data[3 * p + 0] = (m.x + 1.0f) * 0.5f;
        mat.normal_map.data[3 * p + 1] = (m.y + 1.0f) * 0.5f;
        mat.normal_map.data[3 * p + 2] = (m.z + 1.0f) * 0.5f;
    }
    uint32_t mi;
    assert_int_equal(lx_scene_add_material(scene, &mat, &mi), LX_OK);
    lx_image_free(&mat.normal_map);
    lx_mesh box = lx_test_box("box", lx_v3(-1, -1, -1), lx_v3(1, 1, 1), true);
    lx_test_add_with_material(scene, &box, mi);
    scene->ambient = lx_v3(a, a, a);
    lx_bake_desc d = {.resolution = 24, .bounces = 1, .gi_samples = 9, .threads = 2};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, 0, &img), LX_OK);
    const uint8_t *mask = lx_baker_mask(b, 0);
    double want = a * (1.0 + rho), worst = 0.0;
    for (int p = 0; p < img.width * img.height; p++)
        if (mask[p])
            worst = fmax(worst, fabs(img.data[3 * p] - want) / want);
    printf("normal-mapped furnace, one bounce: want %g, worst relative error %.3g\n", want,
           worst);
    /* float rounding only (test_gi's furnace measures below 1e-6) */
    assert_true(worst < 1e-5);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(flat_map_changes_nothing),
        cmocka_unit_test(tilt_toward_tangent),
        cmocka_unit_test(tilt_toward_bitangent),
        cmocka_unit_test(tangents_from_the_file),
        cmocka_unit_test(bounces_gather_about_the_vertex_normal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
