/* The real-time API (the per-texel lighting article's update frame and
 * Apply kernel): static lights
 * baked once, dynamic lights re-evaluated by lx_baker_update, apply = baked +
 * real-time; moving lights and nodes; the saturated 8-bit apply; bit-identical
 * results for any thread count. Expected values come from separate bakes of
 * each light alone, from closed forms and from the geometry of projections. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"

/* ---- helpers ------------------------------------------------------------------ */

static lx_light point(const char *name, lx_vec3 p, float cd, bool dynamic)
{
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.position = p;
    l.intensity = cd;
    l.dynamic = dynamic;
    return l;
}

static void add_light(lx_scene *s, lx_light l)
{
    if (lx_scene_add_light(s, &l) != LX_OK)
        fail_msg("add light: %s", lx_last_error());
}

static uint32_t add_plane(lx_scene *s, const char *name, float size, float height, float cx,
                          float cz, int n)
{
    lx_mesh m = lx_test_plane(name, size, height, cx, cz, n);
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    return s->node_count - 1;
}

/* ground (node 0, 4 x 4 m) and an occluding plate (node 1) at height 1 */
static lx_scene *base_scene(void)
{
    lx_scene *s;
    assert_int_equal(lx_scene_create("realtime", &s), LX_OK);
    add_plane(s, "ground", 4.0f, 0.0f, 0.0f, 0.0f, 4);
    add_plane(s, "plate", 0.8f, 1.0f, 0.2f, 0.1f, 1);
    return s;
}

static lx_baker *make_baker(const lx_scene *s, int res, int padding, int threads)
{
    lx_bake_desc d = {.resolution = res, .padding = padding, .threads = threads};
    lx_baker *b;
    if (lx_baker_create(s, &d, &b) != LX_OK)
        fail_msg("baker: %s", lx_last_error());
    return b;
}

static lx_image apply(const lx_baker *b, uint32_t map)
{
    lx_image img;
    if (lx_baker_apply_alloc(b, map, &img) != LX_OK)
        fail_msg("apply: %s", lx_last_error());
    return img;
}

/* Bakes scene s (static lights only) and returns the applied map of node. */
static lx_image bake_alone(const lx_scene *s, uint32_t node, int res)
{
    lx_baker *b = make_baker(s, res, 0, 0);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    lx_image img = apply(b, lx_test_map_of(b, node));
    lx_baker_destroy(b);
    return img;
}

static void assert_sum(const lx_image *got, const lx_image *a, const lx_image *b, const char *what)
{
    assert_int_equal(got->width, a->width);
    assert_int_equal(got->width, b->width);
    int n = got->width * got->height * 3;
    int nonzero = 0;
    /* measured: within 6.0e-8 relative (the float sum's rounding, half an
     * ulp), exactly 0 where both are; bound 2e-7 */
    for (int i = 0; i < n; i++) {
        double want = (double)a->data[i] + b->data[i];
        if (!(fabs(got->data[i] - want) <= 2e-7 * fabs(want)))
            fail_msg("%s: value %d (texel %d, %d) is %.9g, want %.9g + %.9g", what, i,
                     (i / 3) % got->width, (i / 3) / got->width, got->data[i], a->data[i],
                     b->data[i]);
        nonzero += got->data[i] != 0.0f;
    }
    assert_true(nonzero > n / 4);
}

static bool images_differ(const lx_image *a, const lx_image *b)
{
    return memcmp(a->data, b->data, sizeof(float) * a->width * a->height * a->channels) != 0;
}

/* ---- baked + dynamic ------------------------------------------------------- */

static void test_apply_is_baked_plus_dynamic(void **state)
{
    (void)state;
    const int res = 48;
    const lx_vec3 ambient = lx_v3(0.02f, 0.03f, 0.04f);
    lx_light stat = point("static", lx_v3(-1.0f, 2.5f, -0.5f), 40.0f, false);
    lx_light dyn = point("dynamic", lx_v3(0.5f, 3.0f, 0.5f), 60.0f, true);
    dyn.color = lx_v3(1.0f, 0.5f, 0.2f);
    dyn.ambient = lx_v3(0.0f, 0.05f, 0.0f);
    dyn.range = 6.0f;

    lx_scene *both = base_scene();
    both->ambient = ambient;
    add_light(both, stat);
    add_light(both, dyn);
    lx_scene *only_static = base_scene();
    only_static->ambient = ambient;
    add_light(only_static, stat);

    lx_baker *b = make_baker(both, res, 0, 0);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    for (uint32_t node = 0; node < 2; node++) {
        uint32_t map = lx_test_map_of(b, node);
        /* before any update: exactly the static bake */
        lx_image before = apply(b, map);
        lx_image s_img = bake_alone(only_static, node, res);
        assert_false(images_differ(&before, &s_img));
        lx_image_free(&before);
        lx_image_free(&s_img);
    }
    assert_int_equal(lx_baker_update(b), LX_OK);

    /* the dynamic light alone, baked as a static one, no scene ambient */
    lx_scene *only_dyn = base_scene();
    lx_light d2 = dyn;
    d2.dynamic = false;
    add_light(only_dyn, d2);
    for (uint32_t node = 0; node < 2; node++) {
        lx_image got = apply(b, lx_test_map_of(b, node));
        lx_image s_img = bake_alone(only_static, node, res);
        lx_image d_img = bake_alone(only_dyn, node, res);
        assert_sum(&got, &s_img, &d_img, node == 0 ? "ground: baked + dynamic" : "plate");
        lx_image_free(&got);
        lx_image_free(&s_img);
        lx_image_free(&d_img);
    }

    /* a second update without changes gives the same result (the real-time
     * buffer is cleared, not accumulated) */
    lx_image first = apply(b, 0);
    assert_int_equal(lx_baker_update(b), LX_OK);
    lx_image second = apply(b, 0);
    assert_false(images_differ(&first, &second));
    lx_image_free(&first);
    lx_image_free(&second);

    /* move the dynamic light: the next update follows it */
    lx_light moved = dyn;
    moved.position = lx_v3(-0.8f, 2.0f, 0.9f);
    assert_int_equal(lx_baker_set_light(b, 1, &moved), LX_OK);
    assert_true(lx_baker_light(b, 1)->position.x == moved.position.x);
    lx_image stale = apply(b, 0);
    assert_int_equal(lx_baker_update(b), LX_OK);
    lx_scene *moved_dyn = base_scene();
    lx_light d3 = moved;
    d3.dynamic = false;
    add_light(moved_dyn, d3);
    lx_image got = apply(b, 0);
    assert_true(images_differ(&got, &stale));
    lx_image s_img = bake_alone(only_static, 0, res);
    lx_image d_img = bake_alone(moved_dyn, 0, res);
    assert_sum(&got, &s_img, &d_img, "after moving the dynamic light");
    lx_image_free(&got);
    lx_image_free(&stale);

    /* changing the static light shows only after the next bake */
    lx_light brighter = stat;
    brighter.intensity = 90.0f;
    assert_int_equal(lx_baker_set_light(b, 0, &brighter), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    got = apply(b, 0);
    assert_sum(&got, &s_img, &d_img, "static change before the bake");
    lx_image_free(&got);
    lx_image_free(&s_img);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    lx_scene *bright_static = base_scene();
    bright_static->ambient = ambient;
    add_light(bright_static, brighter);
    s_img = bake_alone(bright_static, 0, res);
    got = apply(b, 0);
    assert_sum(&got, &s_img, &d_img, "static change after the bake");
    lx_image_free(&got);
    lx_image_free(&s_img);
    lx_image_free(&d_img);

    /* bad light index and invalid lights are refused */
    assert_int_equal(lx_baker_set_light(b, 2, &moved), LX_ERR_INVALID);
    lx_light bad = moved;
    bad.intensity = NAN;
    assert_int_equal(lx_baker_set_light(b, 1, &bad), LX_ERR_INVALID);

    lx_baker_destroy(b);
    lx_scene_destroy(both);
    lx_scene_destroy(only_static);
    lx_scene_destroy(only_dyn);
    lx_scene_destroy(moved_dyn);
    lx_scene_destroy(bright_static);
}

/* ---- moving nodes -------------------------------------------------------------- */

/* Checks the ground's shadow under the plate (node 1, moved by offset) lit
 * by a point light at L: shadowed texels are those inside the projection
 * of the plate, with one texel of tolerance at the edge. */
static void check_projected_shadow(const lx_baker *b, lx_vec3 L, lx_vec3 offset, const char *what)
{
    const double plate = 0.8, h = 1.0 + offset.y, cx = 0.2 + offset.x, cz = 0.1 + offset.z;
    uint32_t map = lx_test_map_of(b, 0);
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, map);
    const double texel = 4.0 / info->width;
    double k = L.y / (L.y - h);
    double x0 = L.x + (cx - plate / 2 - L.x) * k, x1 = L.x + (cx + plate / 2 - L.x) * k;
    double z0 = L.z + (cz - plate / 2 - L.z) * k, z1 = L.z + (cz + plate / 2 - L.z) * k;
    lx_image img = apply(b, map);
    int shadowed = 0, lit = 0;
    for (int y = 0; y < info->height; y++)
        for (int x = 0; x < info->width; x++) {
            lx_texel_sample s;
            assert_true(lx_baker_texel(b, map, x, y, &s));
            double inside = fmin(fmin(s.position.x - x0, x1 - s.position.x),
                                 fmin(s.position.z - z0, z1 - s.position.z));
            float v = img.data[3 * (y * info->width + x)];
            if (inside > texel) {
                if (v != 0.0f)
                    fail_msg("%s: texel (%d, %d) inside the shadow is %g", what, x, y, v);
                shadowed++;
            } else if (inside < -texel) {
                if (!(v > 0.0f))
                    fail_msg("%s: texel (%d, %d) outside the shadow is dark", what, x, y);
                lit++;
            }
        }
    assert_true(shadowed > 50);
    assert_true(lit > 1000);
    lx_image_free(&img);
}

static void test_moving_occluder_moves_shadow(void **state)
{
    (void)state;
    const lx_vec3 L = lx_v3(-0.1f, 3.0f, 0.05f);
    lx_scene *s = base_scene();
    add_light(s, point("lamp", L, 30.0f, true));
    lx_baker *b = make_baker(s, 48, LX_PADDING_NONE, 0);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    check_projected_shadow(b, L, lx_v3(0, 0, 0), "plate in place");

    lx_vec3 offset = lx_v3(-0.9f, 0.4f, -0.6f);
    lx_mat4 t = lx_mat4_translate(offset);
    assert_int_equal(lx_baker_set_node_transform(b, 1, &t), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    check_projected_shadow(b, L, offset, "plate moved");

    /* the plate's own texels moved with it */
    lx_texel_sample ts;
    uint32_t pm = lx_test_map_of(b, 1);
    assert_true(lx_baker_texel(b, pm, 0, 0, &ts));
    assert_true(fabsf(ts.position.y - 1.4f) < 1.2e-7f); /* measured exact; one ulp */

    /* moving back restores the first shadow */
    lx_mat4 id = lx_mat4_identity();
    assert_int_equal(lx_baker_set_node_transform(b, 1, &id), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    check_projected_shadow(b, L, lx_v3(0, 0, 0), "plate moved back");

    /* bad node, singular or non-finite transforms are refused */
    assert_int_equal(lx_baker_set_node_transform(b, 7, &id), LX_ERR_INVALID);
    lx_mat4 flat = id;
    flat.m[5] = 0.0f;
    assert_int_equal(lx_baker_set_node_transform(b, 1, &flat), LX_ERR_INVALID);
    lx_mat4 nan = id;
    nan.m[12] = NAN;
    assert_int_equal(lx_baker_set_node_transform(b, 1, &nan), LX_ERR_INVALID);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

static void test_moving_lit_node_moves_texels(void **state)
{
    (void)state;
    lx_scene *s;
    assert_int_equal(lx_scene_create("moving", &s), LX_OK);
    add_plane(s, "ground", 2.0f, 0.0f, 0.0f, 0.0f, 2);
    lx_light lamp = point("lamp", lx_v3(0.3f, 2.0f, 3.0f), 25.0f, true);
    lamp.shadow = LX_SHADOW_NONE;
    add_light(s, lamp);
    const int res = 32;
    lx_baker *b = make_baker(s, res, LX_PADDING_NONE, 0);
    uint32_t map = lx_test_map_of(b, 0);
    lx_texel_sample *before = calloc(res * res, sizeof *before);
    for (int i = 0; i < res * res; i++)
        assert_true(lx_baker_texel(b, map, i % res, i / res, &before[i]));

    /* tilt the plane up toward the light and move it */
    float ang = LX_DEG2RAD(50.0f);
    lx_vec4 q = lx_v4(sinf(ang / 2), 0, 0, cosf(ang / 2)); /* about +x */
    lx_mat4 m = lx_mat4_trs(lx_v3(0.5f, 0.7f, -0.4f), q, lx_v3(1.5f, 1.0f, 1.5f));
    assert_int_equal(lx_baker_set_node_transform(b, 0, &m), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    lx_image img = apply(b, map);
    /* normal of the transformed +Y plane: rotation of +Y about x by ang
     * (the scale along the plane's own axes does not tilt its normal) */
    lx_vec3 n_want = lx_v3(0.0f, cosf(ang), sinf(ang));
    for (int i = 0; i < res * res; i++) {
        lx_texel_sample now;
        assert_true(lx_baker_texel(b, map, i % res, i / res, &now));
        /* world = M x the old (object == world at identity) position */
        const float *mm = m.m;
        lx_vec3 p = before[i].position;
        double want[3];
        for (int r = 0; r < 3; r++)
            want[r] = (double)mm[r] * p.x + (double)mm[4 + r] * p.y + (double)mm[8 + r] * p.z +
                      mm[12 + r];
        /* measured: positions within 8.2e-8, bound 3e-7; normals exactly
         * n_want, bound one float ulp below 1 */
        assert_true(fabs(now.position.x - want[0]) < 3e-7);
        assert_true(fabs(now.position.y - want[1]) < 3e-7);
        assert_true(fabs(now.position.z - want[2]) < 3e-7);
        assert_true(lx_dot(now.normal, n_want) > 1.0f - 1.2e-7f);
        assert_true(fabsf(lx_dot(now.geometric_normal, n_want)) > 1.0f - 1.2e-7f);
        assert_int_equal(now.mesh, before[i].mesh);
        assert_int_equal(now.triangle, before[i].triangle);
        /* and the dynamic light sees the new place: I cos / d^2 */
        double lx = lamp.position.x - want[0], ly = lamp.position.y - want[1],
               lz = lamp.position.z - want[2];
        double d = sqrt(lx * lx + ly * ly + lz * lz);
        double c = (lx * n_want.x + ly * n_want.y + lz * n_want.z) / d;
        double e = c > 0 ? lamp.intensity * c / (d * d) : 0.0;
        float v = img.data[3 * i];
        /* measured: within 4.3e-7 relative, exactly 0 where e is; bound
         * 1.5e-6 */
        if (!(fabs(v - e) <= 1.5e-6 * e))
            fail_msg("moved texel %d: %g, want %g", i, v, e);
    }
    lx_image_free(&img);
    free(before);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

/* ---- the 8-bit apply ------------------------------------------------------------ */

static double srgb_encode(double v)
{
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static void test_apply_rgba8(void **state)
{
    (void)state;
    lx_scene *s;
    assert_int_equal(lx_scene_create("rgba8", &s), LX_OK);
    add_plane(s, "ground", 4.0f, 0.0f, 0.0f, 0.0f, 4);
    /* 3 lux under the light, about 0.1 lux in the corners */
    add_light(s, point("lamp", lx_v3(0.0f, 1.0f, 0.0f), 3.0f, false));
    const int res = 32;
    lx_baker *b = make_baker(s, res, 0, 0);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    lx_image img = apply(b, 0);
    const uint8_t *mask = lx_baker_mask(b, 0);
    uint8_t *out = malloc(res * res * 4);
    const float exposures[3] = {1.0f, 0.25f, 2.0f};
    for (int e = 0; e < 3; e++)
        for (int srgb = 0; srgb < 2; srgb++) {
            memset(out, 0x5A, res * res * 4);
            assert_int_equal(lx_baker_apply_rgba8(b, 0, exposures[e], srgb, out), LX_OK);
            int saturated = 0, partial = 0;
            for (int i = 0; i < res * res; i++) {
                for (int c = 0; c < 3; c++) {
                    double v = (double)img.data[3 * i + c] * exposures[e];
                    double sat = v < 0 ? 0 : (v > 1 ? 1 : v);
                    if (srgb)
                        sat = srgb_encode(sat);
                    int want = (int)floor(sat * 255.0 + 0.5);
                    int got = out[4 * i + c];
                    if (abs(got - want) > (srgb ? 1 : 0))
                        fail_msg("exposure %g srgb %d texel %d channel %d: %d, want %d (v %g)",
                                 exposures[e], srgb, i, c, got, want, v);
                    if (v > 1.0) {
                        assert_int_equal(got, 255);
                        saturated++;
                    } else if (v > 0.01 && v < 0.99) {
                        partial++;
                    }
                }
                if (mask[i])
                    assert_int_equal(out[4 * i + 3], 255);
            }
            if (exposures[e] >= 1.0f)
                assert_true(saturated > 0);
            assert_true(partial > 0);
        }
    assert_int_equal(lx_baker_apply_rgba8(b, 5, 1.0f, false, out), LX_ERR_INVALID);
    free(out);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

/* ---- determinism ------------------------------------------------------------------ */

static void run_once(const lx_scene *s, int threads, lx_image *maps, uint8_t **bytes)
{
    lx_baker *b = make_baker(s, 64, 0, threads);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++) {
        maps[m] = apply(b, m);
        bytes[m] = malloc((size_t)maps[m].width * maps[m].height * 4);
        assert_int_equal(lx_baker_apply_rgba8(b, m, 0.5f, true, bytes[m]), LX_OK);
    }
    lx_baker_destroy(b);
}

static void test_threads_bit_identical(void **state)
{
    (void)state;
    lx_scene *s = base_scene();
    lx_mesh box = lx_test_box("box", lx_v3(-1.5f, 0.0f, 0.8f), lx_v3(-0.7f, 0.9f, 1.6f), false);
    lx_test_add(s, &box);
    lx_test_mesh_free(&box);
    s->ambient = lx_v3(0.01f, 0.01f, 0.02f);
    add_light(s, point("hard", lx_v3(0.3f, 2.5f, 0.2f), 30.0f, false));
    lx_light blur = point("blur", lx_v3(-1.0f, 2.0f, -1.0f), 20.0f, false);
    blur.shadow = LX_SHADOW_BLUR;
    add_light(s, blur);
    lx_light sp = lx_light_defaults(LX_LIGHT_SPOT);
    strcpy(sp.name, "spot");
    sp.position = lx_v3(1.5f, 2.0f, 1.5f);
    sp.direction = lx_normalize(lx_v3(-1.0f, -1.2f, -1.0f));
    sp.intensity = 80.0f;
    sp.dynamic = true;
    add_light(s, sp);
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    strcpy(sun.name, "sun");
    sun.direction = lx_normalize(lx_v3(0.3f, -1.0f, 0.4f));
    sun.intensity = 0.5f;
    add_light(s, sun);

    lx_image a[3], c[3], d[3];
    uint8_t *ab[3], *cb[3], *db[3];
    run_once(s, 1, a, ab);
    run_once(s, 2, c, cb);
    run_once(s, 3, d, db);
    for (int m = 0; m < 3; m++) {
        size_t n = sizeof(float) * a[m].width * a[m].height * 3;
        assert_int_equal(memcmp(a[m].data, c[m].data, n), 0);
        assert_int_equal(memcmp(a[m].data, d[m].data, n), 0);
        size_t nb = (size_t)a[m].width * a[m].height * 4;
        assert_int_equal(memcmp(ab[m], cb[m], nb), 0);
        assert_int_equal(memcmp(ab[m], db[m], nb), 0);
        lx_image_free(&a[m]);
        lx_image_free(&c[m]);
        lx_image_free(&d[m]);
        free(ab[m]);
        free(cb[m]);
        free(db[m]);
    }
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_apply_is_baked_plus_dynamic),
        cmocka_unit_test(test_moving_occluder_moves_shadow),
        cmocka_unit_test(test_moving_lit_node_moves_texels),
        cmocka_unit_test(test_apply_rgba8),
        cmocka_unit_test(test_threads_bit_identical),
    };
    lx_test_watchdog(60);
    return cmocka_run_group_tests(tests, NULL, NULL);
}
