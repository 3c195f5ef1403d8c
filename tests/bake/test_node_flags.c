/* Per-node bake control (lx_node.bake) against closed forms and
 * invariants computed here:
 * - cast shadows off: a plate between a point light and the ground leaves
 *   the ground at the unshadowed E = I cos / d^2 at every texel, and its AO
 *   at 1 (nothing else above it); with the default the same plate's
 *   shadow is black (the check can tell);
 * - lightmap off: the plate, without any UVs, gets no lightmap and the
 *   bake succeeds; its shadow is still there;
 * - contribute to bounces off: two facing plates under an ambient A; the
 *   lower one's bounce is A rho F (Howell C-11) when the upper takes part,
 *   and exactly 0 (E = A to the float) when it does not, nor does it emit
 *   when emissive; the upper still receives the lower's bounce;
 * - lightmap scale: a lightmap's side at a density T is T s sqrt(world
 *   area / UV area) (rounded up to 4), at a fixed resolution N it is N s;
 *   the unwrapper's charts take s^2 the texels;
 * - the same bytes for 1 and 2 threads with flags set. */
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

#define PI_D 3.14159265358979323846

static uint32_t add_plane(lx_scene *s, const char *name, float size, float height, float cx,
                          float cz, int n)
{
    lx_mesh m = lx_test_plane(name, size, height, cx, cz, n);
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    return s->node_count - 1;
}

static lx_baker *bake(const lx_scene *s, const lx_bake_desc *d)
{
    lx_baker *b = NULL;
    if (lx_baker_create(s, d, &b) != LX_OK)
        fail_msg("lx_baker_create: %s", lx_last_error());
    if (lx_baker_bake(b) != LX_OK)
        fail_msg("lx_baker_bake: %s", lx_last_error());
    return b;
}

/* E = I cos / d^2 of a point light at l on a floor facing +Y at p. */
static double point_e(double intensity, lx_vec3 l, lx_vec3 p)
{
    double dx = (double)l.x - p.x, dy = (double)l.y - p.y, dz = (double)l.z - p.z;
    double d = sqrt(dx * dx + dy * dy + dz * dz);
    return dy > 0.0 ? intensity * (dy / d) / (d * d) : 0.0;
}

#define RES 64
static const float SIZE = 4.0f, OCC = 1.0f, OCC_H = 1.0f;
static const lx_vec3 LIGHT = {-0.1f, 3.0f, 0.05f};
static const float INTENSITY = 50.0f;

/* The ground, a plate above it and a point light. */
static lx_scene *occluder_scene(uint32_t *ground, uint32_t *plate)
{
    lx_scene *s = lx_test_new_scene("flags");
    *ground = add_plane(s, "ground", SIZE, 0.0f, 0.0f, 0.0f, 4);
    *plate = add_plane(s, "plate", OCC, OCC_H, 0.0f, 0.0f, 1);
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "bulb");
    l.position = LIGHT;
    l.intensity = INTENSITY;
    assert_int_equal(lx_scene_add_light(s, &l), LX_OK);
    return s;
}

/* The ground's worst relative error against the unshadowed closed form,
 * and its value at the texel nearest the centre. */
static double ground_error(const lx_baker *b, uint32_t ground, double *centre)
{
    uint32_t map = lx_test_map_of(b, ground);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    double worst = 0.0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            lx_texel_sample ts;
            assert_true(lx_baker_texel(b, map, x, y, &ts));
            double want = point_e(INTENSITY, LIGHT, ts.position);
            double got = img.data[3 * (y * RES + x)];
            worst = fmax(worst, fabs(got - want) / want);
        }
    *centre = img.data[3 * ((RES / 2) * RES + RES / 2)];
    lx_image_free(&img);
    return worst;
}

static void cast_shadows_off(void **state)
{
    (void)state;
    uint32_t ground, plate;
    lx_scene *s = occluder_scene(&ground, &plate);
    lx_bake_desc d = {.resolution = RES};
    double centre;
    /* the default: the plate's shadow is black at the centre */
    lx_baker *b = bake(s, &d);
    double worst = ground_error(b, ground, &centre);
    assert_true(centre == 0.0 && worst == 1.0);
    lx_baker_destroy(b);

    s->nodes[plate].bake.no_cast_shadows = true;
    b = bake(s, &d);
    worst = ground_error(b, ground, &centre);
    printf("cast shadows off: ground against I cos / d^2, worst %.3g\n", worst);
    /* float arithmetic against the double closed form: measured 2.8e-7 in
     * test_bake_analytic's lit texels; bound 1e-6 */
    assert_true(worst < 1e-6);
    /* the plate itself still receives its light */
    uint32_t map = lx_test_map_of(b, plate);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    lx_texel_sample ts;
    assert_true(lx_baker_texel(b, map, RES / 2, RES / 2, &ts));
    lx_test_assert_rel(img.data[3 * ((RES / 2) * RES + RES / 2)],
                       point_e(INTENSITY, LIGHT, ts.position), 1e-6);
    lx_image_free(&img);
    /* AO: nothing above the ground casts, so every ray escapes: 1 exactly */
    lx_ao_desc ad = {.distance = 2.0f, .samples = 64};
    assert_int_equal(lx_baker_ao(b, lx_test_map_of(b, ground), &ad, &img), LX_OK);
    for (int i = 0; i < RES * RES; i++)
        if (img.data[i] != 1.0f)
            fail_msg("AO texel %d is %g, not 1", i, img.data[i]);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

static void lightmap_off(void **state)
{
    (void)state;
    uint32_t ground, plate;
    lx_scene *s = occluder_scene(&ground, &plate);
    /* no UVs at all on the plate: none are needed */
    lx_mesh *m = &s->meshes[s->nodes[plate].meshes[0]];
    for (int k = 0; k < LX_MAX_UV_SETS; k++) {
        free(m->uv[k]);
        m->uv[k] = NULL;
    }
    s->nodes[plate].bake.no_lightmap = true;
    lx_bake_desc d = {.resolution = RES};
    lx_baker *b = bake(s, &d);
    assert_int_equal(lx_baker_lightmap_count(b), 1);
    uint32_t map;
    float so[4];
    assert_false(lx_baker_node_lightmap(b, plate, &map, so));
    assert_true(lx_baker_node_lightmap(b, ground, &map, so));
    /* it still casts: the centre under it is dark, the open ground lit */
    double centre;
    double worst = ground_error(b, ground, &centre);
    assert_true(centre == 0.0 && worst == 1.0);
    lx_baker_destroy(b);

    /* also through an unwrap: the plate is left out of the pages */
    lx_unwrap_desc ud = {.texel_density = 8.0f};
    lx_unwrap *u;
    assert_int_equal(lx_unwrap_scene(s, &ud, &u), LX_OK);
    assert_int_equal(u->nodes[plate].page, UINT32_MAX);
    assert_true(u->nodes[ground].page != UINT32_MAX);
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
}

/* Between equal parallel rectangles a x b, c apart (Howell C-11). */
static double plate_factor(double a, double b, double c)
{
    double x = a / c, y = b / c;
    double sx = sqrt(1.0 + x * x), sy = sqrt(1.0 + y * y);
    double t = 0.5 * log((1.0 + x * x) * (1.0 + y * y) / (1.0 + x * x + y * y)) +
               x * sy * atan(x / sy) + y * sx * atan(y / sx) - x * atan(x) - y * atan(y);
    return 2.0 * t / (PI_D * x * y);
}

/* Two facing unit squares 1 m apart under an ambient: the lower white,
 * the upper of albedo rho emitting le. */
static lx_scene *plates(float rho, float le, float ambient)
{
    lx_scene *scene = lx_test_new_scene("plates");
    lx_mesh lower = lx_test_plane("lower", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add_with_material(scene, &lower, lx_test_grey_material(scene, "white", 1.0f, 0.0f));
    lx_mesh upper = lx_test_plane("upper", 1.0f, 1.0f, 0.0f, 0.0f, 1);
    for (uint32_t v = 0; v < upper.vertex_count; v++)
        upper.normals[v] = lx_v3(0.0f, -1.0f, 0.0f);
    for (uint32_t t = 0; t < 3 * upper.triangle_count; t += 3) {
        uint32_t k = upper.indices[t + 1];
        upper.indices[t + 1] = upper.indices[t + 2];
        upper.indices[t + 2] = k;
    }
    lx_test_add_with_material(scene, &upper, lx_test_grey_material(scene, "grey", rho, le));
    scene->ambient = lx_v3(ambient, ambient, ambient);
    return scene;
}

/* Mean bounce (E - a) over a lightmap's covered texels, and the largest
 * |E - a| / a. */
static double mean_bounce(const lx_baker *b, uint32_t node, double a, double *worst)
{
    uint32_t map = lx_test_map_of(b, node);
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, map);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    double sum = 0.0;
    int n = 0;
    *worst = 0.0;
    for (int y = 0; y < info->height; y++)
        for (int x = 0; x < info->width; x++) {
            lx_texel_sample ts;
            if (!lx_baker_texel(b, map, x, y, &ts))
                continue;
            double e = img.data[3 * ((size_t)y * info->width + x)] - a;
            sum += e;
            *worst = fmax(*worst, fabs(e) / a);
            n++;
        }
    lx_image_free(&img);
    return sum / n;
}

static void contribute_gi_off(void **state)
{
    (void)state;
    const float rho = 0.5f, a = 4.0f;
    lx_bake_desc d = {.resolution = 16, .bounces = 1, .gi_samples = 1024};
    double plate = a * plate_factor(1.0, 1.0, 1.0), worst;

    /* the default: the lower square's bounce is a rho F (test_gi measured
     * the mean within 0.09% of it; bound 0.5%) */
    lx_scene *s = plates(rho, 0.0f, a);
    lx_baker *b = bake(s, &d);
    double lower = mean_bounce(b, 0, a, &worst);
    printf("both take part: lower bounce %.6g, a rho F %.6g\n", lower, rho * plate);
    assert_true(fabs(lower - rho * plate) < 0.005 * rho * plate);
    lx_baker_destroy(b);

    /* the upper out of the bounces, and emitting: the lower gets nothing
     * from it, E = a exactly; the upper still gets the lower's bounce,
     * a * 1 * F */
    lx_scene_destroy(s);
    s = plates(rho, 100.0f, a);
    s->nodes[1].bake.no_contribute_gi = true;
    b = bake(s, &d);
    lower = mean_bounce(b, 0, a, &worst);
    printf("upper out of the bounces: lower bounce %.3g (worst %.3g)\n", lower, worst);
    assert_true(worst == 0.0);
    double upper = mean_bounce(b, 1, a, &worst);
    printf("upper's own bounce %.6g, a F %.6g\n", upper, plate);
    assert_true(fabs(upper - plate) < 0.005 * plate);
    lx_baker_destroy(b);

    /* the same bytes for any thread count, flags and all */
    lx_image one, two;
    d.threads = 1;
    b = bake(s, &d);
    assert_int_equal(lx_baker_apply_alloc(b, lx_test_map_of(b, 1), &one), LX_OK);
    lx_baker_destroy(b);
    d.threads = 2;
    b = bake(s, &d);
    assert_int_equal(lx_baker_apply_alloc(b, lx_test_map_of(b, 1), &two), LX_OK);
    lx_baker_destroy(b);
    assert_memory_equal(one.data, two.data, sizeof(float) * 3 * (size_t)one.width * one.height);
    lx_image_free(&one);
    lx_image_free(&two);
    lx_scene_destroy(s);
}

/* ceil(r / 4) * 4, the baker's rounding of a density size */
static int round4(double r)
{
    return (int)(ceil(r / 4.0) * 4.0);
}

static void lightmap_scale(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("scale");
    /* 4 m squares, UVs over the unit square: world / UV area = 16 m^2 */
    add_plane(s, "one", 4.0f, 0.0f, 0.0f, 0.0f, 2);
    add_plane(s, "two", 4.0f, 0.0f, 10.0f, 0.0f, 2);
    add_plane(s, "half", 4.0f, 0.0f, 20.0f, 0.0f, 2);
    add_plane(s, "odd", 4.0f, 0.0f, 30.0f, 0.0f, 2);
    s->nodes[1].bake.lightmap_scale = 2.0f;
    s->nodes[2].bake.lightmap_scale = 0.5f;
    s->nodes[3].bake.lightmap_scale = 1.3f;
    const float scale[4] = {1.0f, 2.0f, 0.5f, 1.3f};
    lx_light l = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    l.direction = lx_v3(0, -1, 0);
    assert_int_equal(lx_scene_add_light(s, &l), LX_OK);
    const double t = 8.0;
    lx_bake_desc d = {.texel_density = (float)t};
    lx_baker *b;
    assert_int_equal(lx_baker_create(s, &d, &b), LX_OK);
    for (uint32_t n = 0; n < 4; n++) {
        const lx_lightmap_info *info = lx_baker_lightmap_info(b, lx_test_map_of(b, n));
        int want = round4(t * scale[n] * sqrt(16.0 / 1.0));
        if (info->width != want || info->height != want)
            fail_msg("node %u: %dx%d, want %d", n, info->width, info->height, want);
    }
    lx_baker_destroy(b);
    /* a fixed resolution: N s */
    d = (lx_bake_desc){.resolution = 32};
    assert_int_equal(lx_baker_create(s, &d, &b), LX_OK);
    const int fixed[4] = {32, 64, 16, round4(32 * 1.3)};
    for (uint32_t n = 0; n < 4; n++)
        assert_int_equal(lx_baker_lightmap_info(b, lx_test_map_of(b, n))->width, fixed[n]);
    lx_baker_destroy(b);

    /* unwrapped, a page per node: a square chart of T s 4 texels a side
     * covers (T s 4)^2 texels, up to a ring more at its border */
    lx_unwrap_desc ud = {.texel_density = (float)t, .page_per_node = true, .padding = 2};
    lx_unwrap *u;
    assert_int_equal(lx_unwrap_scene(s, &ud, &u), LX_OK);
    for (uint32_t n = 0; n < 4; n++) {
        double side = t * scale[n] * 4.0;
        uint32_t covered = u->pages[u->nodes[n].page].covered_texels;
        printf("unwrapped at scale %g: %u texels covered, (T s 4)^2 = %g\n", (double)scale[n],
               covered, side * side);
        assert_true(covered >= side * side && covered <= (side + 2.0) * (side + 2.0));
    }
    lx_unwrap_destroy(u);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(cast_shadows_off),
        cmocka_unit_test(lightmap_off),
        cmocka_unit_test(contribute_gi_off),
        cmocka_unit_test(lightmap_scale),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
