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
 *   so G[R_k] = pi L rho^k exactly, at every texel, corners included.
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parallel_squares),
        cmocka_unit_test(test_furnace),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
