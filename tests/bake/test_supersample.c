/* Texel supersampling (lx_bake_desc.supersample) against values computed
 * here, without the baker:
 * - a rod narrower than a texel, above a floor lit straight down: the
 *   shadowed texel's value is E times the share of its N x N cell centres
 *   outside the rod's shadow (counted here), within 1/N of the exact
 *   uncovered width share; with one sample it is 0 or E;
 * - a hard shadow edge crossing texels diagonally (a large rotated slab):
 *   every texel is E times its grid points' lit share (counted here), and
 *   that is within 1/(2N) of the exact lit area (the square clipped by the
 *   half-plane, shoelace area): a straight edge misclassifies at most half
 *   a point per column of the grid;
 * - unshadowed light (ambient and a slanted sun on a bare floor) gives the
 *   same bytes at any N;
 * - 1 and 2 threads give the same bytes with soft shadows and a sky;
 * - N outside 1..16 fails with a message. */
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

#define RES 8
#define INTENSITY 1000.0f

static lx_scene *floor_scene(void)
{
    lx_scene *scene = lx_test_new_scene("supersample");
    lx_mesh floor = lx_test_plane("floor", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    return scene;
}

static void add_sun(lx_scene *scene, lx_vec3 dir, lx_shadow_mode shadow)
{
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_normalize(dir);
    sun.intensity = INTENSITY;
    sun.shadow = shadow;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
}

/* A box whose points are rotated by angle about +Y (x' = x c + z s,
 * z' = -x s + z c), normals with them. */
static void add_rotated_box(lx_scene *scene, lx_vec3 lo, lx_vec3 hi, float angle)
{
    lx_mesh box = lx_test_box("occluder", lo, hi, false);
    float c = cosf(angle), s = sinf(angle);
    for (uint32_t v = 0; v < box.vertex_count; v++) {
        lx_vec3 p = box.positions[v], n = box.normals[v];
        box.positions[v] = lx_v3(p.x * c + p.z * s, p.y, -p.x * s + p.z * c);
        box.normals[v] = lx_v3(n.x * c + n.z * s, n.y, -n.x * s + n.z * c);
    }
    lx_test_add(scene, &box);
    lx_test_mesh_free(&box);
}

/* The floor's baked values (RES x RES, R channel) and coverage. */
static void bake_floor(lx_scene *scene, int n, int threads, float *out, uint8_t *mask)
{
    lx_bake_desc d = {.resolution = RES, .supersample = n, .threads = threads};
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    uint32_t map = lx_test_map_of(b, 0);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    assert_int_equal(img.width, RES);
    const uint8_t *m = lx_baker_mask(b, map);
    for (int p = 0; p < RES * RES; p++) {
        out[p] = img.data[3 * p];
        mask[p] = m[p];
    }
    lx_image_free(&img);
    lx_baker_destroy(b);
}

/* lx_test_plane: texel (x, y) covers world x in [-0.5 + x / RES, ...],
 * z likewise with y. */
static double texel_x0(int x)
{
    return -0.5 + (double)x / RES;
}

static void thin_rod_gives_its_covered_share(void **state)
{
    (void)state;
    /* a rod 0.05 m wide (a texel is 0.125 m) at x in [0.01, 0.06], 0.5 m
     * up, straight-down sun: its shadow lies in texel column 4 */
    const double r0 = 0.01, r1 = 0.06;
    const int column = 4;
    for (int n = 1; n <= 16; n *= 2) {
        lx_scene *scene = floor_scene();
        add_rotated_box(scene, lx_v3((float)r0, 0.5f, -1.0f), lx_v3((float)r1, 0.55f, 1.0f), 0.0f);
        add_sun(scene, lx_v3(0.0f, -1.0f, 0.0f), LX_SHADOW_HARD);
        float v[RES * RES];
        uint8_t mask[RES * RES];
        bake_floor(scene, n, 0, v, mask);
        lx_scene_destroy(scene);
        /* the cell centres of column 4 outside the shadow */
        int lit = 0;
        for (int b = 0; b < n; b++) {
            double x = texel_x0(column) + (b + 0.5) / (RES * n);
            lit += !(x > r0 && x < r1);
        }
        double share = (double)lit / n;
        double exact = 1.0 - (r1 - r0) * RES;
        for (int y = 0; y < RES; y++)
            for (int x = 0; x < RES; x++) {
                assert_true(mask[y * RES + x]);
                double got = v[y * RES + x] / INTENSITY;
                if (x != column) {
                    lx_test_assert_rel(got, 1.0, 1e-6);
                    continue;
                }
                lx_test_assert_rel(got, share, 1e-6);
                if (n == 1)
                    assert_true(got == 0.0 || fabs(got - 1.0) < 1e-6);
                else
                    assert_true(fabs(got - exact) <= 1.0 / n + 1e-6);
            }
        printf("supersample %2d: rod texel %.4f of lit (exact uncovered share %.4f)\n", n,
               v[column], exact);
    }
}

/* Area of the unit-less square [x0, x1] x [z0, z1] where
 * x cos(a) - z sin(a) < c: the square clipped by the half-plane
 * (Sutherland-Hodgman), shoelace area. */
static double lit_area(double x0, double x1, double z0, double z1, double a, double c)
{
    double px[4] = {x0, x1, x1, x0}, pz[4] = {z0, z0, z1, z1};
    double qx[8], qz[8];
    int m = 0;
    for (int k = 0; k < 4; k++) {
        int j = (k + 1) % 4;
        double fk = px[k] * cos(a) - pz[k] * sin(a) - c;
        double fj = px[j] * cos(a) - pz[j] * sin(a) - c;
        if (fk < 0) {
            qx[m] = px[k], qz[m] = pz[k], m++;
        }
        if ((fk < 0) != (fj < 0)) {
            double t = fk / (fk - fj);
            qx[m] = px[k] + t * (px[j] - px[k]);
            qz[m] = pz[k] + t * (pz[j] - pz[k]);
            m++;
        }
    }
    double area = 0.0;
    for (int k = 0; k < m; k++) {
        int j = (k + 1) % m;
        area += qx[k] * qz[j] - qx[j] * qz[k];
    }
    return fabs(area) / 2.0;
}

static void diagonal_edge_gives_the_lit_area(void **state)
{
    (void)state;
    /* a slab 0.5 m up whose local x >= c half shades the floor: world
     * shadow where x cos(a) - z sin(a) >= c */
    const double a = 0.4, c = 0.0211;
    const double size = 1.0 / RES;
    for (int n = 1; n <= 8; n *= 2) {
        lx_scene *scene = floor_scene();
        add_rotated_box(scene, lx_v3((float)c, 0.5f, -3.0f), lx_v3((float)c + 6.0f, 0.6f, 3.0f),
                        (float)a);
        add_sun(scene, lx_v3(0.0f, -1.0f, 0.0f), LX_SHADOW_HARD);
        float v[RES * RES];
        uint8_t mask[RES * RES];
        bake_floor(scene, n, 0, v, mask);
        lx_scene_destroy(scene);
        double worst = 0.0, sum = 0.0;
        int crossed = 0;
        for (int y = 0; y < RES; y++)
            for (int x = 0; x < RES; x++) {
                double x0 = texel_x0(x), z0 = texel_x0(y);
                int lit = 0;
                for (int k = 0; k < n * n; k++) {
                    double px = x0 + (k % n + 0.5) * size / n, pz = z0 + (k / n + 0.5) * size / n;
                    double f = px * cos(a) - pz * sin(a) - c;
                    /* no point near the edge: float rounding cannot flip it */
                    assert_true(fabs(f) > 1e-4);
                    lit += f < 0;
                }
                double got = v[y * RES + x] / INTENSITY;
                lx_test_assert_rel(got, (double)lit / (n * n), 1e-6);
                double area = lit_area(x0, x0 + size, z0, z0 + size, a, c) / (size * size);
                if (area > 0.0 && area < 1.0) {
                    crossed++;
                    worst = fmax(worst, fabs(got - area));
                    sum += fabs(got - area);
                }
                if (n > 1)
                    assert_true(fabs(got - area) <= 0.5 / n + 1e-6);
            }
        assert_true(crossed >= RES);
        printf("supersample %d: %d edge texels, error against the lit area mean %.4f worst %.4f\n",
               n, crossed, sum / crossed, worst);
    }
}

static void unshadowed_light_is_unchanged(void **state)
{
    (void)state;
    float ref[RES * RES];
    uint8_t mask[RES * RES];
    for (int n = 1; n <= 5; n += 2) {
        lx_scene *scene = floor_scene();
        scene->ambient = lx_v3(3.0f, 2.0f, 1.0f);
        add_sun(scene, lx_v3(0.3f, -1.0f, 0.2f), LX_SHADOW_HARD);
        float v[RES * RES];
        bake_floor(scene, n, 0, n == 1 ? ref : v, mask);
        lx_scene_destroy(scene);
        if (n > 1)
            assert_memory_equal(v, ref, sizeof ref);
    }
}

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    float v[2][RES * RES];
    uint8_t mask[RES * RES];
    for (int t = 0; t < 2; t++) {
        lx_scene *scene = floor_scene();
        add_rotated_box(scene, lx_v3(-0.1f, 0.3f, -0.2f), lx_v3(0.05f, 0.35f, 0.3f), 0.3f);
        lx_light rect = lx_light_defaults(LX_LIGHT_RECT);
        rect.position = lx_v3(0.1f, 1.0f, 0.0f);
        rect.direction = lx_v3(0.0f, -1.0f, 0.0f);
        rect.width = rect.height = 0.4f;
        rect.intensity = 500.0f;
        rect.shadow = LX_SHADOW_SOFT;
        assert_int_equal(lx_scene_add_light(scene, &rect), LX_OK);
        add_sun(scene, lx_v3(0.2f, -1.0f, 0.1f), LX_SHADOW_HARD);
        bake_floor(scene, 3, t + 1, v[t], mask);
        lx_scene_destroy(scene);
    }
    assert_memory_equal(v[0], v[1], sizeof v[0]);
}

static void bad_supersample_fails(void **state)
{
    (void)state;
    const int bad[] = {-1, 17};
    for (int k = 0; k < 2; k++) {
        lx_scene *scene = floor_scene();
        lx_bake_desc d = {.resolution = RES, .supersample = bad[k]};
        lx_baker *b = NULL;
        assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_INVALID);
        assert_null(b);
        assert_non_null(strstr(lx_last_error(), "supersample"));
        lx_scene_destroy(scene);
    }
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(thin_rod_gives_its_covered_share),
        cmocka_unit_test(diagonal_edge_gives_the_lit_area),
        cmocka_unit_test(unshadowed_light_is_unchanged),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(bad_supersample_fails),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
