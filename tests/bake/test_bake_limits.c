/* The baker at the edges of its inputs (cases a review found): enormous
 * node scales, UVs far outside [0,1], texel densities whose size does not
 * fit an int, and lx_dilate given a channel count it does not handle
 * (rejected, nothing touched). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

static lx_scene *plane_scene(float scale, float uv_offset)
{
    lx_scene *scene;
    assert_int_equal(lx_scene_create("limits", &scene), LX_OK);
    lx_material mat = {.name = "white", .base_color = {1, 1, 1, 1}};
    assert_int_equal(lx_scene_add_material(scene, &mat, NULL), LX_OK);
    lx_mesh plane = lx_test_plane("plane", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    for (uint32_t v = 0; v < plane.vertex_count; v++)
        plane.uv[1][v].x += uv_offset;
    uint32_t mesh;
    assert_int_equal(lx_scene_add_mesh(scene, &plane, &mesh), LX_OK);
    lx_test_mesh_free(&plane);
    lx_mat4 world = lx_mat4_trs(lx_v3(0, 0, 0), lx_v4(0, 0, 0, 1), lx_v3(scale, scale, scale));
    assert_int_equal(lx_scene_add_node(scene, "plane", &world, &mesh, 1, NULL), LX_OK);
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_v3(0, -1, 0);
    sun.intensity = 1000.0f;
    sun.shadow = LX_SHADOW_NONE;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
    return scene;
}

/* A scale of 1e13 overflows a float determinant; normals must survive. */
static void huge_scale_keeps_normals(void **state)
{
    (void)state;
    lx_scene *scene = plane_scene(1e13f, 0.0f);
    lx_bake_desc desc = {.resolution = 8, .padding = LX_PADDING_NONE};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &img), LX_OK);
    /* measured exactly 1000; bound one float ulp at 1000 */
    for (int p = 0; p < 64; p++)
        assert_true(fabsf(img.data[3 * p + 1] - 1000.0f) <= 6.2e-5f);
    lx_image_free(&img);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
}

/* UVs ten million units away (past INT_MAX in texels) cover no texel and
 * cost nothing: the lightmap would be black, so the baker refuses it. */
static void far_uvs_cover_nothing(void **state)
{
    (void)state;
    lx_scene *scene = plane_scene(1.0f, 1e7f);
    lx_bake_desc desc = {.resolution = 256};
    lx_baker *baker = NULL;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_ERR_INVALID);
    assert_null(baker);
    assert_non_null(strstr(lx_last_error(), "cover no texel"));
    lx_scene_destroy(scene);
}

/* 1e9 texels per metre on a 1 m plane is 1e9 texels per side: capped. */
static void density_beyond_int_caps(void **state)
{
    (void)state;
    lx_scene *scene = plane_scene(1.0f, 0.0f);
    lx_bake_desc desc = {.texel_density = 1e9f, .max_resolution = 64};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_int_equal(lx_baker_lightmap_info(baker, 0)->width, 64);
    lx_baker_destroy(baker);
    scene->nodes[0].world = lx_mat4_trs(lx_v3(0, 0, 0), lx_v4(0, 0, 0, 1), lx_v3(1e30f, 1, 1e30f));
    desc.texel_density = 1e6f;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    assert_int_equal(lx_baker_lightmap_info(baker, 0)->width, 64);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
}

static void dilate_rejects_bad_channel_counts(void **state)
{
    (void)state;
    float data[2 * 8] = {1, 2, 3, 4, 5, 6, 7, 8};
    uint8_t mask[2] = {1, 0};
    assert_int_equal(lx_dilate(data, mask, 2, 1, 8, 1, NULL), LX_ERR_INVALID);
    assert_int_equal(mask[1], 0);
    assert_true(data[8] == 0.0f);
}

/* Light values beyond luxel's limits (LX_LIGHT_MAX_*, light.h) fail up
 * front naming the scene and the light: added through the API
 * (lx_scene_add_light) or written into the scene's array afterwards
 * (lx_baker_create checks again); the limits themselves are accepted. */
static void absurd_lights_fail_up_front(void **state)
{
    (void)state;
    lx_scene *scene = plane_scene(1.0f, 0.0f);
    lx_light lamp = lx_light_defaults(LX_LIGHT_POINT);
    strcpy(lamp.name, "lamp");
    lamp.position = lx_v3(0, 1, 0);
    lamp.intensity = LX_LIGHT_MAX_INTENSITY;
    lamp.range = LX_LIGHT_MAX_DISTANCE;
    assert_int_equal(lx_light_validate(&lamp), LX_OK);
    lamp.intensity = nextafterf(LX_LIGHT_MAX_INTENSITY, INFINITY);
    assert_int_equal(lx_light_validate(&lamp), LX_ERR_INVALID);
    lamp.intensity = 1e38f;
    assert_int_equal(lx_scene_add_light(scene, &lamp), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "'lamp'"));
    assert_non_null(strstr(lx_last_error(), "intensity"));

    scene->lights[0].intensity = 1e38f; /* the sun, past the check of add_light */
    lx_baker *baker = NULL;
    lx_bake_desc desc = {.resolution = 8};
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_ERR_INVALID);
    assert_null(baker);
    assert_non_null(strstr(lx_last_error(), "limits: "));
    assert_non_null(strstr(lx_last_error(), "intensity 1e+38 lx"));
    scene->lights[0].intensity = 1000.0f;
    scene->lights[0].color = lx_v3(1, 1, nextafterf(LX_LIGHT_MAX_COLOR, INFINITY));
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "color"));
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(absurd_lights_fail_up_front),
        cmocka_unit_test(huge_scale_keeps_normals),
        cmocka_unit_test(far_uvs_cover_nothing),
        cmocka_unit_test(density_beyond_int_caps),
        cmocka_unit_test(dilate_rejects_bad_channel_counts),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
