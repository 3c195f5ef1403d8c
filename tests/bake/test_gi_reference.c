/* The brute-force bounce reference (tests/common/bounce_reference.c)
 * against closed forms, so that it can stand as the oracle for the
 * baker's indirect light:
 *
 * - two parallel unit squares half a unit apart, the lower one emitting
 *   L = 1 nit: the irradiance at the upper one's texel centres is
 *   pi L F with F the parallel-rectangle form factor
 *   (lx_ref_rect_parallel_illuminance, the catalogue's corner formula);
 * - the furnace: inside a closed box whose walls all emit L and reflect
 *   with albedo rho, every point sees emitters over its whole hemisphere,
 *   so G[R_k] = pi L rho^k exactly, at every texel, corners included;
 * - the baker's bounces against the reference in a room with a block.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "bounce_reference.h"

/* The baker against the reference in the room (4096 gather rays a
 * texel): measured 0.125 of a texel's indirect light at the worst texel
 * and 0.031 in the worst chart's mean (the block's underside, which sees
 * the floor at grazing distance; the baker reads its sources bilinearly,
 * the reference texel by texel); the others within 1.6%. */
#define TEXEL_TOL 0.25
#define CHART_TOL 0.06
#include "helpers.h"

typedef struct material {
    uint32_t emitter_node; /* UINT32_MAX: every node emits */
    float emitted, albedo;
} material;

static void material_fn(void *user, uint32_t node, const lx_ref_texel *t, lx_vec3 *albedo,
                        lx_vec3 *emitted)
{
    (void)t;
    const material *m = user;
    bool emits = m->emitter_node == UINT32_MAX || node == m->emitter_node;
    float e = emits ? m->emitted : 0.0f;
    *emitted = lx_v3(e, e, e);
    *albedo = lx_v3(m->albedo, m->albedo, m->albedo);
}

/* Measured against the closed form: 4.1e-8 at the worst texel (float
 * rounding; the transfer is exact per piece). */
#define PARALLEL_TOL 4e-7

static void test_parallel_squares(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("parallel");
    lx_mesh lower = lx_test_plane("lower", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_mesh upper = lx_test_plane("upper", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(scene, &lower);
    lx_test_add(scene, &upper);
    /* the upper square: rotated half a turn about x (normal -y), at y = h */
    const float h = 0.5f;
    scene->nodes[1].world = lx_mat4_trs(lx_v3(0, h, 0), lx_v4(1, 0, 0, 0), lx_v3(1, 1, 1));
    uint32_t nodes[2] = {0, 1};
    material mat = {.emitter_node = 0, .emitted = 1.0f, .albedo = 0.0f};
    lx_bref_desc d = {.scene = scene, .nodes = nodes, .node_count = 2, .width = 16,
                      .height = 16, .sub = 2, .bounces = 1, .material = material_fn,
                      .user = &mat};
    lx_bref_result r;
    lx_bref_run(&d, &r);
    double worst = 0.0;
    int checked = 0;
    for (int t = 0; t < 16 * 16; t++) {
        const lx_ref_texel *tx = &r.maps[1].texels[t];
        if (!tx->used)
            continue;
        /* the foot of the texel on the lower square's plane, in its
         * coordinates (the square spans [-1/2, 1/2] in x and z) */
        double x = tx->position.x, z = tx->position.z;
        double want = lx_ref_rect_parallel_illuminance(-0.5 - x, 0.5 - x, -0.5 - z, 0.5 - z, h,
                                                       1.0);
        double got = r.irradiance[1][t].x;
        worst = fmax(worst, fabs(got - want) / want);
        checked++;
        /* the emitter's own texels receive nothing: they face away */
        assert_true(r.irradiance[0][t].x == 0.0f);
    }
    printf("parallel squares: %d texels, worst relative error %.3g\n", checked, worst);
    assert_int_equal(checked, 256);
    assert_true(worst < PARALLEL_TOL);
    lx_bref_free(&r);
    lx_test_mesh_free(&lower);
    lx_test_mesh_free(&upper);
    lx_scene_destroy(scene);
}

/* Every texel, corners included: measured exactly pi L rho^k in float
 * (the pieces tile the walls and their transfer is exact); the bound is
 * float rounding, as for the parallel squares. */
#define FURNACE_TOL 4e-7

static void test_furnace(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("furnace");
    lx_mesh box = lx_test_box("box", lx_v3(0, 0, 0), lx_v3(1, 1, 1), true);
    lx_test_add(scene, &box);
    uint32_t node = 0;
    const float rho = 0.5f, L = 1.0f;
    material mat = {.emitter_node = UINT32_MAX, .emitted = L, .albedo = rho};
    const int W = 24, H = 16, bounces = 3; /* 3x2 charts of 8x8 texels */
    lx_bref_desc d = {.scene = scene, .nodes = &node, .node_count = 1, .width = W,
                      .height = H, .sub = 2, .bounces = bounces, .material = material_fn,
                      .user = &mat};
    lx_bref_result r;
    lx_bref_run(&d, &r);
    for (int k = 0; k <= bounces; k++) {
        double want = LX_PI * L * pow(rho, k), sum = 0.0, worst = 0.0;
        int n = 0;
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++) {
                int t = y * W + x;
                if (!r.maps[0].texels[t].used)
                    continue;
                double got = r.irradiance[0][(size_t)k * W * H + t].x;
                sum += got;
                n++;
                worst = fmax(worst, fabs(got - want) / want);
            }
        printf("furnace bounce %d: %d texels, worst relative error %.3g, mean %.7g against %.7g\n",
               k, n, worst, sum / n, want);
        assert_int_equal(n, 6 * 64);
        assert_true(worst < FURNACE_TOL);
    }
    lx_bref_free(&r);
    lx_test_mesh_free(&box);
    lx_scene_destroy(scene);
}


/* ---- the baker against the reference ---------------------------------------------
 * A closed room (an inward box, albedo 0.7) with a block hanging in it
 * (an outward box, albedo 0.4, its own lightmap; off the floor, so no
 * texel is inside geometry, where the baker fills from neighbours) lit by one point light
 * under the ceiling with hard shadows: the reference's direct light
 * (lx_ref_shade) and bounces (lx_bref_run) against lx_baker_bake with the
 * same bounce count. Compared at texels whose 3x3 neighbourhood the
 * reference map covers (inside a chart, where the rasterized map samples
 * the same point), texel by texel within the gather's noise, and chart by
 * chart in the mean. */

static uint32_t grey_material(lx_scene *scene, const char *name, float rho)
{
    lx_material mat = {.name = (char *)name, .base_color = {rho, rho, rho, 1.0f},
                       .normal_scale = 1.0f};
    uint32_t idx;
    assert_int_equal(lx_scene_add_material(scene, &mat, &idx), LX_OK);
    return idx;
}

typedef struct room_albedo {
    float rho[2]; /* room, block */
} room_albedo;

static void room_material_fn(void *user, uint32_t node, const lx_ref_texel *t, lx_vec3 *albedo,
                             lx_vec3 *emitted)
{
    (void)t;
    const room_albedo *m = user;
    float a = m->rho[node == 0 ? 0 : 1];
    *albedo = lx_v3(a, a, a);
    *emitted = lx_v3(0, 0, 0);
}

static bool interior(const lx_ref_map *map, int x, int y)
{
    for (int dy = -1; dy <= 1; dy++)
        for (int dx = -1; dx <= 1; dx++) {
            int u = x + dx, v = y + dy;
            if (u < 0 || v < 0 || u >= map->width || v >= map->height ||
                !map->texels[v * map->width + u].used)
                return false;
        }
    return true;
}

static void test_baker_matches_reference(void **state)
{
    (void)state;
    const int res = 24, bounces = 2;
    room_albedo ra = {{0.7f, 0.4f}};
    lx_scene *scene = lx_test_new_scene("room");
    lx_mesh room = lx_test_box("room", lx_v3(0, 0, 0), lx_v3(2, 1.5f, 2), true);
    room.material = grey_material(scene, "room", ra.rho[0]);
    lx_test_add(scene, &room);
    lx_mesh block = lx_test_box("block", lx_v3(0.6f, 0.25f, 0.7f), lx_v3(1.2f, 0.8f, 1.3f), false);
    block.material = grey_material(scene, "block", ra.rho[1]);
    lx_test_add(scene, &block);
    lx_light light = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(light.name, sizeof light.name, "bulb");
    light.position = lx_v3(1.45f, 1.3f, 1.2f);
    light.color = lx_v3(1, 1, 1);
    light.intensity = 50.0f;
    light.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(scene, &light), LX_OK);

    /* the reference: direct light at every reference texel, then bounces */
    uint32_t nodes[2] = {0, 1};
    lx_ref_scene rs;
    lx_ref_scene_build(scene, &rs);
    lx_vec3 *direct[2];
    lx_ref_map dmaps[2];
    for (int i = 0; i < 2; i++) {
        lx_ref_texel_map(scene, nodes[i], res, res, &dmaps[i]);
        direct[i] = calloc((size_t)res * res, sizeof(lx_vec3));
        for (int t = 0; t < res * res; t++) {
            const lx_ref_texel *tx = &dmaps[i].texels[t];
            if (tx->used)
                direct[i][t] = lx_ref_shade(&rs, scene->lights, scene->light_count,
                                            scene->ambient, tx->position, tx->normal,
                                            tx->geometric_normal, 0.0, NULL);
        }
    }
    const lx_vec3 *const dconst[2] = {direct[0], direct[1]};
    lx_bref_desc rd = {.scene = scene, .nodes = nodes, .node_count = 2, .width = res,
                       .height = res, .sub = 2, .bounces = bounces,
                       .material = room_material_fn, .user = &ra, .direct = dconst};
    lx_bref_result ref;
    lx_bref_run(&rd, &ref);

    lx_bake_desc bd = {.resolution = res, .bounces = bounces, .gi_samples = 4096, .threads = 2};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &bd, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    double worst_texel = 0.0, worst_mean = 0.0;
    for (int i = 0; i < 2; i++) {
        lx_image img;
        assert_int_equal(lx_baker_apply_alloc(b, lx_test_map_of(b, nodes[i]), &img), LX_OK);
        assert_int_equal(img.width, res);
        /* the charts: the 3x2 grid cells of lx_test_box */
        double got_sum[6] = {0}, want_sum[6] = {0};
        for (int y = 0; y < res; y++)
            for (int x = 0; x < res; x++) {
                int t = y * res + x;
                if (!interior(&ref.maps[i], x, y))
                    continue;
                lx_vec3 ind = lx_bref_indirect(&ref, (uint32_t)i, t, bounces);
                double want = direct[i][t].x + ind.x, got = img.data[3 * t];
                /* relative to the indirect part, what the gather estimates */
                double err = fabs(got - want) / fmax(ind.x, 1e-6);
                worst_texel = fmax(worst_texel, err);
                int chart = (x * 3 / res) + 3 * (y * 2 / res);
                got_sum[chart] += got - direct[i][t].x;
                want_sum[chart] += ind.x;
            }
        for (int c = 0; c < 6; c++)
            if (want_sum[c] > 0.0)
                worst_mean = fmax(worst_mean, fabs(got_sum[c] - want_sum[c]) / want_sum[c]);
        lx_image_free(&img);
    }
    printf("room, %d bounces: worst texel %.3g of its indirect light, worst chart mean %.3g\n",
           bounces, worst_texel, worst_mean);
    assert_true(worst_texel < TEXEL_TOL);
    assert_true(worst_mean < CHART_TOL);
    lx_baker_destroy(b);
    lx_bref_free(&ref);
    for (int i = 0; i < 2; i++) {
        free(direct[i]);
        lx_ref_map_free(&dmaps[i]);
    }
    lx_ref_scene_free(&rs);
    lx_test_mesh_free(&room);
    lx_test_mesh_free(&block);
    lx_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parallel_squares),
        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_baker_matches_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
