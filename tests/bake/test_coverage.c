/* A lightmap that covers no texel is never a silent black result: with UVs
 * one tile off ([1,2] x [0,1], wholly outside the lightmap) on every node
 * lx_baker_create fails naming the node; on one node of two it builds, and
 * a warning names that node. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char logged[4096];

static void capture(void *user, lx_log_level level, const char *message)
{
    (void)user;
    if (level >= LX_LOG_WARN && strlen(logged) + strlen(message) + 2 < sizeof logged) {
        strcat(logged, message);
        strcat(logged, "\n");
    }
}

/* Two 1 m floors, "near" and "far"; the UVs of those named in `off` moved
 * one tile along u. */
static lx_scene *floors(bool near_off, bool far_off)
{
    lx_scene *scene = lx_test_new_scene("coverage");
    const char *names[2] = {"near", "far"};
    bool off[2] = {near_off, far_off};
    for (int k = 0; k < 2; k++) {
        lx_mesh m = lx_test_plane(names[k], 1.0f, 0.0f, 3.0f * (float)k, 0.0f, 2);
        if (off[k])
            for (uint32_t v = 0; v < m.vertex_count; v++)
                m.uv[1][v].x += 1.0f;
        lx_test_add(scene, &m);
        lx_test_mesh_free(&m);
    }
    return scene;
}

static void every_node_off(void **state)
{
    (void)state;
    lx_scene *scene = floors(true, true);
    lx_bake_desc d = {.resolution = 16};
    lx_baker *b = NULL;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_INVALID);
    assert_null(b);
    const char *e = lx_last_error();
    assert_non_null(strstr(e, "'near'"));
    assert_non_null(strstr(e, "cover no texel"));
    lx_scene_destroy(scene);
}

static void one_node_off(void **state)
{
    (void)state;
    lx_scene *scene = floors(false, true);
    logged[0] = '\0';
    lx_set_log_callback(capture, NULL);
    lx_bake_desc d = {.resolution = 16};
    lx_baker *b = NULL;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    lx_set_log_callback(NULL, NULL);
    /* the near floor covers every texel of its own map, the far one none */
    assert_int_equal(lx_baker_lightmap_info(b, lx_test_map_of(b, 0))->used_texels, 16 * 16);
    assert_int_equal(lx_baker_lightmap_info(b, lx_test_map_of(b, 1))->used_texels, 0);
    assert_non_null(strstr(logged, "node 'far': its lightmap UVs cover no texel"));
    assert_null(strstr(logged, "node 'near'"));
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(every_node_off),
        cmocka_unit_test(one_node_off),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
