/* Edge supersampling (lx_bake_desc.edge_supersample) against a closed
 * form: a point light over a floor, a square plate between them. A floor
 * point q is in the plate's shadow when the segment to the light crosses
 * the plate's square (a test on its plane, no rays), so each texel's true
 * value is the mean of E(q) V(q) over its footprint, taken here on a
 * 32 x 32 grid of points. Texels that a shadow edge crosses get within a
 * few percent of it with 4 x 4 points, where their centre alone is off
 * by up to E; every other texel keeps the bits of the bake without. A
 * wall standing on the floor beside the light: the lit floor along its
 * foot takes no darkness from points under the wall. */
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

#define RES 64
#define FLOOR 4.0
#define GRID 32

static const double light_pos[3] = {0.0, 3.0, 0.0};
static const double intensity = 900.0; /* candela */
/* the plate: a square at y = 1 */
static const double plate_x0 = -0.2, plate_x1 = 0.8, plate_z0 = -0.4, plate_z1 = 0.6,
                    plate_y = 1.0;

static double irradiance(double x, double z)
{
    double dx = light_pos[0] - x, dy = light_pos[1], dz = light_pos[2] - z;
    double d2 = dx * dx + dy * dy + dz * dz;
    return intensity * (dy / sqrt(d2)) / d2;
}

static bool shadowed(double x, double z)
{
    double t = plate_y / light_pos[1];
    double px = x + (light_pos[0] - x) * t, pz = z + (light_pos[2] - z) * t;
    return px > plate_x0 && px < plate_x1 && pz > plate_z0 && pz < plate_z1;
}

static lx_scene *plate_scene(void)
{
    lx_scene *scene = lx_test_new_scene("edges");
    uint32_t grey = lx_test_grey_material(scene, "grey", 0.5f, 0.0f);
    lx_mesh floor = lx_test_plane("floor", (float)FLOOR, 0.0f, 0.0f, 0.0f, 4);
    floor.material = grey;
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    lx_mesh plate = lx_test_plane("plate", (float)(plate_x1 - plate_x0), (float)plate_y,
                                  (float)(0.5 * (plate_x0 + plate_x1)),
                                  (float)(0.5 * (plate_z0 + plate_z1)), 1);
    plate.material = grey;
    lx_test_add(scene, &plate);
    lx_test_mesh_free(&plate);
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "lamp");
    l.position = lx_v3((float)light_pos[0], (float)light_pos[1], (float)light_pos[2]);
    l.intensity = (float)intensity;
    assert_int_equal(lx_scene_add_light(scene, &l), LX_OK);
    return scene;
}

static lx_baker *bake(const lx_scene *scene, int edge, int threads)
{
    lx_bake_desc d = {.resolution = RES, .edge_supersample = edge, .threads = threads};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    return b;
}

static void shadow_edges_match_the_footprint_mean(void **state)
{
    (void)state;
    lx_scene *scene = plate_scene();
    lx_baker *b[2] = {bake(scene, 0, 2), bake(scene, 4, 2)};
    lx_image img[2];
    uint32_t map = lx_test_map_of(b[0], 0);
    for (int k = 0; k < 2; k++)
        assert_int_equal(lx_baker_apply_alloc(b[k], map, &img[k]), LX_OK);
    double sum2[2] = {0.0, 0.0}, worst[2] = {0.0, 0.0};
    int edges = 0, inner = 0, inner_changed = 0;
    const double texel = FLOOR / RES;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            lx_texel_sample t;
            if (!lx_baker_texel(b[0], map, x, y, &t))
                continue;
            /* the footprint: the texel's square of the floor (its UVs
             * are the square's, so texel steps are world steps) */
            double cx = -0.5 * FLOOR + (x + 0.5) * texel, cz = -0.5 * FLOOR + (y + 0.5) * texel;
            assert_true(fabs(cx - t.position.x) < 1e-4 && fabs(cz - t.position.z) < 1e-4);
            double mean = 0.0;
            int dark = 0;
            for (int a = 0; a < GRID; a++)
                for (int c = 0; c < GRID; c++) {
                    double qx = cx + ((c + 0.5) / GRID - 0.5) * texel;
                    double qz = cz + ((a + 0.5) / GRID - 0.5) * texel;
                    bool s = shadowed(qx, qz);
                    dark += s;
                    mean += s ? 0.0 : irradiance(qx, qz);
                }
            mean /= GRID * GRID;
            size_t at = 3 * ((size_t)y * RES + x);
            /* within a texel of an edge, or clear of it */
            bool near = false;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    near |= shadowed(cx + 1.5 * dx * texel, cz + 1.5 * dy * texel) !=
                            shadowed(cx, cz);
            if (!near) {
                inner++;
                inner_changed += memcmp(&img[0].data[at], &img[1].data[at], 3 * sizeof(float));
                continue;
            }
            if (dark == 0 || dark == GRID * GRID)
                continue;
            edges++;
            double e = irradiance(cx, cz);
            for (int k = 0; k < 2; k++) {
                double err = (img[k].data[at] - mean) / e;
                sum2[k] += err * err;
                worst[k] = fmax(worst[k], fabs(err));
            }
        }
    double rms[2] = {sqrt(sum2[0] / edges), sqrt(sum2[1] / edges)};
    printf("plate's shadow: %d texels an edge crosses, off the footprint mean by rms %.4f "
           "(worst %.3f) of E with the centre alone, %.4f (worst %.3f) with 4 x 4 points; "
           "%d of %d texels away from edges changed\n",
           edges, rms[0], worst[0], rms[1], worst[1], inner_changed, inner);
    assert_true(edges > 50);
    /* measured: centre alone rms 0.317, worst 0.516; 4 x 4 points rms
     * 0.0253, worst 0.081 (16 steps across an edge along an axis) */
    assert_true(rms[1] < 0.06);
    assert_true(worst[1] < 0.2);
    assert_true(rms[1] * 4.0 < rms[0]);
    assert_int_equal(inner_changed, 0);
    /* the same bytes on one thread */
    lx_baker *one = bake(scene, 4, 1);
    lx_image img1;
    assert_int_equal(lx_baker_apply_alloc(one, map, &img1), LX_OK);
    assert_memory_equal(img1.data, img[1].data, sizeof(float) * 3 * RES * RES);
    lx_image_free(&img1);
    lx_baker_destroy(one);
    for (int k = 0; k < 2; k++) {
        lx_image_free(&img[k]);
        lx_baker_destroy(b[k]);
    }
    lx_scene_destroy(scene);
}

/* A thick wall (a closed box) standing on the floor, the light on one
 * side: the lit floor along the wall's foot is lit in full (nothing
 * shadows it); its texels' footprints run under the wall, whose points
 * are left out rather than counted dark. */
static void wall_foot_stays_lit(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("wall");
    uint32_t grey = lx_test_grey_material(scene, "grey", 0.5f, 0.0f);
    lx_mesh floor = lx_test_plane("floor", (float)FLOOR, 0.0f, 0.0f, 0.0f, 4);
    floor.material = grey;
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    /* the wall: x in [0.49, 0.555], all z: the texel centres at 0.46875
     * (lit) and 0.53125 (inside, nearer the dark face: straddle.c moves
     * it there), so a shadow edge runs between them */
    lx_mesh wall = lx_test_box("wall", lx_v3(0.49f, -0.1f, -2.5f), lx_v3(0.555f, 1.0f, 2.5f),
                               false);
    wall.material = grey;
    free(wall.uv[0]);
    wall.uv[0] = NULL;
    free(wall.uv[1]);
    wall.uv[1] = NULL;
    lx_test_add(scene, &wall);
    lx_test_mesh_free(&wall);
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "lamp");
    l.position = lx_v3(-1.0f, 2.0f, 0.0f);
    l.intensity = 900.0f;
    assert_int_equal(lx_scene_add_light(scene, &l), LX_OK);
    lx_baker *b = bake(scene, 4, 2), *plain = bake(scene, 0, 2);
    uint32_t map = lx_test_map_of(b, 0);
    lx_image img, centre;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(plain, map, &centre), LX_OK);
    double worst = 0.0;
    int foot = 0, supersampled = 0;
    const double texel = FLOOR / RES;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            lx_texel_sample t;
            if (!lx_baker_texel(b, map, x, y, &t))
                continue;
            double cx = -0.5 * FLOOR + (x + 0.5) * texel;
            /* the lit side's texels whose footprint reaches the wall */
            if (!(cx < 0.49 && cx + 0.5 * texel > 0.49))
                continue;
            double dx = -1.0 - t.position.x, dy = 2.0, dz = -t.position.z;
            double d2 = dx * dx + dy * dy + dz * dz;
            double want = 900.0 * (dy / sqrt(d2)) / d2;
            size_t at = 3 * ((size_t)y * RES + x);
            worst = fmax(worst, fabs(img.data[at] - want) / want);
            supersampled += img.data[at] != centre.data[at];
            foot++;
        }
    printf("wall's foot: %d lit texels along it (%d supersampled), worst relative error %.3g\n",
           foot, supersampled, worst);
    /* E at the texel's centre against the mean of its footprint's points
     * off the wall: the light's gradient over a texel, measured 0.005;
     * with the points under the wall counted (dark), 0.187 */
    assert_true(foot >= RES - 2);
    assert_true(supersampled >= foot / 2);
    assert_true(worst < 0.03);
    lx_image_free(&img);
    lx_image_free(&centre);
    lx_baker_destroy(plain);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(shadow_edges_match_the_footprint_mean),
        cmocka_unit_test(wall_foot_stays_lit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
