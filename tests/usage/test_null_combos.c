/* NULL pointers that are allowed alone but not together, or only with a
 * count of 0 (tests/usage/null_optional.txt names them; test_null_args
 * covers every other pointer of the public API). Each call must fail with
 * LX_ERR_INVALID and a message, never crash. */
#include "helpers.h"
#include "luxel/luxel.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

static void expect_invalid(lx_status st, const char *what)
{
    if (st != LX_ERR_INVALID)
        fail_msg("%s: %s (%s), want LX_ERR_INVALID", what, lx_status_name(st), lx_last_error());
    if (!lx_last_error()[0])
        fail_msg("%s: no message", what);
}

/* A frame rendered into neither out nor light_map is refused. */
static void light2d_render_needs_an_output(void **state)
{
    (void)state;
    lx_image casters;
    assert_int_equal(lx_image_alloc(&casters, 8, 8, 4), LX_OK);
    lx_light2d *ctx = NULL;
    if (lx_light2d_create(&casters, NULL, &ctx) != LX_OK)
        fail_msg("lx_light2d_create: %s", lx_last_error());
    float out[8 * 8 * 3];
    assert_int_equal(lx_light2d_render(ctx, lx_v3(0.1f, 0.1f, 0.1f), NULL, out, NULL), LX_OK);
    assert_int_equal(lx_light2d_render(ctx, lx_v3(0.1f, 0.1f, 0.1f), NULL, NULL, out), LX_OK);
    expect_invalid(lx_light2d_render(ctx, lx_v3(0.1f, 0.1f, 0.1f), NULL, NULL, NULL),
                   "lx_light2d_render with out and light_map NULL");
    lx_light2d_destroy(ctx);
    lx_image_free(&casters);
}

/* A NULL list is an empty list only when its count says so. */
static void null_lists_need_a_zero_count(void **state)
{
    (void)state;
    lx_scene *scene = NULL;
    assert_int_equal(lx_scene_create("combos", &scene), LX_OK);
    lx_mat4 world = lx_mat4_identity();
    assert_int_equal(lx_scene_add_node(scene, "empty", &world, NULL, 0, NULL), LX_OK);
    expect_invalid(lx_scene_add_node(scene, "two", &world, NULL, 2, NULL),
                   "lx_scene_add_node with meshes NULL and mesh_count 2");
    lx_scene_destroy(scene);

    lx_image casters;
    assert_int_equal(lx_image_alloc(&casters, 8, 8, 4), LX_OK);
    lx_light2d *ctx = NULL;
    if (lx_light2d_create(&casters, NULL, &ctx) != LX_OK)
        fail_msg("lx_light2d_create: %s", lx_last_error());
    assert_int_equal(lx_light2d_set_lights(ctx, NULL, 0), LX_OK);
    expect_invalid(lx_light2d_set_lights(ctx, NULL, 3), "lx_light2d_set_lights with NULL and 3");
    lx_light2d_destroy(ctx);
    lx_image_free(&casters);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(light2d_render_needs_an_output),
        cmocka_unit_test(null_lists_need_a_zero_count),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
