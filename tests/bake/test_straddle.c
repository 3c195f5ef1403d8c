/* Texels that straddle a wall (straddle.c): a floor with a wall standing
 * on it, the wall's faces between texel centres. Floor texels the wall
 * only partly covers have their centre sample under the wall; they must
 * bake as their visible part does:
 * - on the sunny side, lit like their open neighbours: E = I cos(theta)
 *   exactly (the directional light's closed form), not dark;
 * - on the shadowed side, black like their shadowed neighbours: nothing
 *   leaks from the lit side through the wall;
 * both with one sample a texel and with 4 x 4 supersampling (the points
 * under the wall are left out, the rest are all lit or all dark). */
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

#define RES 32
#define SIZE 2.0
#define INTENSITY 1000.0f

/* wall faces at x = W0 and W1 (texel centres lie at -1 + (i + 0.5) / 16) */
#define W0 0.2037
#define W1 0.4137

static void straddling_texels_bake_as_their_visible_part(void **state)
{
    (void)state;
    /* sun travelling toward +x and down at 45 degrees: the wall (1 m
     * high) shades the floor from x = W1 to W1 + 1 */
    const lx_vec3 dir = lx_v3(1.0f, -1.0f, 0.0f);
    const double lit_value = INTENSITY * cos(0.78539816339744830962);
    for (int n = 1; n <= 4; n += 3) {
        lx_scene *scene = lx_test_new_scene("straddle");
        lx_mesh floor = lx_test_plane("floor", (float)SIZE, 0.0f, 0.0f, 0.0f, 1);
        lx_test_add(scene, &floor);
        lx_test_mesh_free(&floor);
        lx_mesh wall = lx_test_box("wall", lx_v3((float)W0, 0.0f, -1.5f),
                                   lx_v3((float)W1, 1.0f, 1.5f), false);
        lx_test_add(scene, &wall);
        lx_test_mesh_free(&wall);
        lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
        sun.direction = lx_normalize(dir);
        sun.intensity = INTENSITY;
        assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
        lx_bake_desc d = {.resolution = RES, .supersample = n};
        lx_baker *b;
        assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
        assert_int_equal(lx_baker_bake(b), LX_OK);
        lx_scene_destroy(scene);
        uint32_t map = lx_test_map_of(b, 0);
        lx_image img;
        assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
        int sunny = 0, shaded = 0;
        const double texel = SIZE / RES;
        for (int y = 0; y < RES; y++)
            for (int x = 0; x < RES; x++) {
                double x0 = -1.0 + x * texel, x1 = x0 + texel;
                double centre = (x0 + x1) / 2.0;
                float v = img.data[3 * ((size_t)y * RES + x)];
                /* partly under the wall, centre under it */
                bool under = centre > W0 && centre < W1;
                if (under && x0 < W0) {
                    sunny++;
                    lx_test_assert_rel(v, lit_value, 1e-5);
                } else if (under && x1 > W1) {
                    shaded++;
                    if (v != 0.0f)
                        fail_msg("supersample %d: texel (%d, %d) on the wall's shadowed side "
                                 "is %g, not 0",
                                 n, x, y, (double)v);
                } else if (x1 <= W0) {
                    lx_test_assert_rel(v, lit_value, 1e-5); /* open floor */
                } else if (x0 >= W1 && x1 <= W1 + 1.0) {
                    assert_true(v == 0.0f); /* in the wall's shadow */
                }
            }
        assert_int_equal(sunny, RES);
        assert_int_equal(shaded, RES);
        lx_image_free(&img);
        lx_baker_destroy(b);
    }
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(straddling_texels_bake_as_their_visible_part),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
