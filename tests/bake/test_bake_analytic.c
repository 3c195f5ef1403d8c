/* Bakes checked against closed forms computed here, in double precision,
 * from each texel's world position: the inverse-square law with the smooth
 * range window, the spot cone, the directional cosine law, the geometric
 * projection of an occluder, a closed room, grazing light, ambient (scene and
 * per light), the radiance quantity and dilation. */
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

#define PI_D 3.14159265358979323846
/* Bounds sit a small factor above the largest error measured, stated
 * beside each. Where the expected value is exact and the result a float,
 * a few half-ulps (6e-8 relative) are the floor: */
#define FLOAT_TOL 2e-7

/* ---- helpers ---------------------------------------------------------------- */

static double window_ref(double d, double r)
{
    if (r <= 0.0)
        return 1.0;
    double f = 1.0 - pow(d / r, 4.0);
    return f > 0.0 ? f * f : 0.0;
}

/* Filament's smooth spot attenuation, written out. */
static double spot_ref(double cos_angle, double inner, double outer)
{
    double t = (cos_angle - cos(outer)) / (cos(inner) - cos(outer));
    t = t < 0 ? 0 : (t > 1 ? 1 : t);
    return t * t;
}

/* Illuminance (lux, before colour) of a point or spot light at p with
 * normal n, unshadowed. */
static double point_ref(const lx_light *l, lx_vec3 p, lx_vec3 n)
{
    double lx = (double)l->position.x - p.x, ly = (double)l->position.y - p.y,
           lz = (double)l->position.z - p.z;
    double d = sqrt(lx * lx + ly * ly + lz * lz);
    double cos_t = (lx * n.x + ly * n.y + lz * n.z) / d;
    if (cos_t <= 0)
        return 0;
    double e = l->intensity * cos_t / (d * d) * window_ref(d, l->range);
    if (l->type == LX_LIGHT_SPOT) {
        double ca = -(lx * l->direction.x + ly * l->direction.y + lz * l->direction.z) / d;
        e *= spot_ref(ca, l->inner_angle, l->outer_angle);
    }
    return e;
}

static void check_close(double got, double want, double rel, double abs_floor, const char *what,
                        int x, int y)
{
    if (!(fabs(got - want) <= rel * fabs(want) + abs_floor))
        fail_msg("%s texel (%d, %d): got %.9g, want %.9g (rel %g, floor %g)", what, x, y, got, want,
                 rel, abs_floor);
}

static lx_scene *new_scene(void)
{
    lx_scene *s;
    assert_int_equal(lx_scene_create("analytic", &s), LX_OK);
    return s;
}

static uint32_t add_plane(lx_scene *s, const char *name, float size, float height, float cx,
                          float cz, int n)
{
    lx_mesh m = lx_test_plane(name, size, height, cx, cz, n);
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    return s->node_count - 1;
}

static void add_light(lx_scene *s, lx_light l)
{
    assert_int_equal(lx_scene_add_light(s, &l), LX_OK);
}

static lx_light point_light(const char *name, lx_vec3 pos, float intensity, float range)
{
    lx_light l = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.position = pos;
    l.intensity = intensity;
    l.range = range;
    return l;
}

static lx_light dir_light(const char *name, lx_vec3 dir, float lux)
{
    lx_light l = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.direction = lx_normalize(dir);
    l.intensity = lux;
    return l;
}

static lx_baker *bake(const lx_scene *s, int resolution, int padding, lx_quantity q)
{
    lx_bake_desc d = {.resolution = resolution, .padding = padding, .quantity = q};
    lx_baker *b = NULL;
    lx_status st = lx_baker_create(s, &d, &b);
    if (st != LX_OK)
        fail_msg("lx_baker_create: %s", lx_last_error());
    st = lx_baker_bake(b);
    if (st != LX_OK)
        fail_msg("lx_baker_bake: %s", lx_last_error());
    return b;
}

static lx_image apply(const lx_baker *b, uint32_t map)
{
    lx_image img;
    if (lx_baker_apply_alloc(b, map, &img) != LX_OK)
        fail_msg("apply: %s", lx_last_error());
    return img;
}

/* Position of texel (x, y) of a lx_test_plane through its UV layout. */
static lx_vec3 plane_uv_to_world(float size, float height, float cx, float cz, int x, int y, int w,
                                 int h)
{
    double u = (x + 0.5) / w, v = (y + 0.5) / h;
    return lx_v3((float)(cx - size / 2.0 + u * size), height, (float)(cz - size / 2.0 + v * size));
}

typedef double (*irradiance_fn)(const void *ctx, lx_vec3 p, lx_vec3 n);

static double point_fn(const void *ctx, lx_vec3 p, lx_vec3 n)
{
    return point_ref((const lx_light *)ctx, p, n);
}

static double dir_fn(const void *ctx, lx_vec3 p, lx_vec3 n)
{
    const lx_light *l = ctx;
    double c = -((double)l->direction.x * n.x + (double)l->direction.y * n.y +
                 (double)l->direction.z * n.z);
    (void)p;
    return c > 0 ? l->intensity * c : 0.0;
}

/* Bakes a 4 x 4 m plane at y = 0 under one light; checks every texel's
 * position against the plane's UV layout and its value against fn.
 * Returns the number of texels with a non-zero expected value. */
static int check_plane_light(lx_light light, irradiance_fn fn, double rel, double floor_rel,
                             int *zero_count)
{
    const float size = 4.0f, height = 0.0f, cx = 0.25f, cz = -0.5f;
    const int res = 64;
    lx_scene *s = new_scene();
    uint32_t node = add_plane(s, "ground", size, height, cx, cz, 4);
    add_light(s, light);
    lx_baker *b = bake(s, res, LX_PADDING_NONE, LX_QUANTITY_IRRADIANCE);
    uint32_t map = lx_test_map_of(b, node);
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, map);
    assert_int_equal(info->width, res);
    assert_int_equal(info->height, res);
    assert_int_equal(info->used_texels, res * res); /* the plane fills its UV square */
    lx_image img = apply(b, map);
    const uint8_t *mask = lx_baker_mask(b, map);

    double peak = 0;
    for (int y = 0; y < res; y++)
        for (int x = 0; x < res; x++) {
            lx_texel_sample ts;
            if (lx_baker_texel(b, map, x, y, &ts))
                peak = fmax(peak, fn(&light, ts.position, lx_v3(0, 1, 0)));
        }
    int lit = 0, zero = 0;
    for (int y = 0; y < res; y++)
        for (int x = 0; x < res; x++) {
            assert_int_equal(mask[y * res + x], 1);
            lx_texel_sample ts;
            assert_true(lx_baker_texel(b, map, x, y, &ts));
            lx_vec3 want_p = plane_uv_to_world(size, height, cx, cz, x, y, res, res);
            /* measured 0 (the same float arithmetic); half an ulp at 2.25 m
             * is 1.2e-7 */
            check_close(ts.position.x, want_p.x, 0, 5e-7, "position.x", x, y);
            check_close(ts.position.y, want_p.y, 0, 5e-7, "position.y", x, y);
            check_close(ts.position.z, want_p.z, 0, 5e-7, "position.z", x, y);
            check_close(ts.normal.y, 1.0, 0, FLOAT_TOL, "normal.y", x, y);
            /* the expected value from the analytic position, not the sample's */
            double e = fn(&light, want_p, lx_v3(0, 1, 0));
            const float *px = &img.data[3 * (y * res + x)];
            const float col[3] = {light.color.x, light.color.y, light.color.z};
            for (int c = 0; c < 3; c++)
                check_close(px[c], e * col[c], rel, floor_rel * peak, "irradiance", x, y);
            if (e > 0)
                lit++;
            else {
                zero++;
                for (int c = 0; c < 3; c++)
                    assert_true(px[c] == 0.0f);
            }
        }
    if (zero_count)
        *zero_count = zero;
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
    return lit;
}

/* ---- (a) closed forms -------------------------------------------------------- */

static void test_point_light_inverse_square(void **state)
{
    (void)state;
    lx_light l = point_light("bulb", lx_v3(0.3f, 1.5f, -0.2f), 120.0f, 3.0f);
    l.color = lx_v3(1.0f, 0.5f, 0.25f);
    /* range 3 < the farthest corner (3.4 m): the window goes to 0 inside the
     * plane, and its float rounding near there is absolute: 2e-6 relative
     * with a floor of 5e-8 of the peak; the largest error measured uses 0.31
     * of that */
    int zero = 0;
    int lit = check_plane_light(l, point_fn, 2e-6, 5e-8, &zero);
    assert_true(lit > 1000);
    assert_true(zero > 0);
    /* unlimited range, no shadows: measured 3.0e-7 */
    l.range = 0.0f;
    l.shadow = LX_SHADOW_NONE;
    assert_int_equal(check_plane_light(l, point_fn, 1e-6, 0.0, NULL), 64 * 64);
}

static void test_spot_light_cone(void **state)
{
    (void)state;
    lx_light l = lx_light_defaults(LX_LIGHT_SPOT);
    strcpy(l.name, "spot");
    l.position = lx_v3(0.2f, 2.5f, -0.4f);
    l.direction = lx_normalize(lx_v3(0.2f, -1.0f, 0.1f));
    l.inner_angle = LX_DEG2RAD(15.0f);
    l.outer_angle = LX_DEG2RAD(30.0f);
    l.intensity = 300.0f;
    l.range = 20.0f;
    int zero = 0;
    /* the ramp (t^2, t from float cosines) loses relative precision toward
     * its bottom: 3e-5 relative with a floor of 5e-7 of the peak; the
     * largest error measured uses 0.37 of that */
    int lit = check_plane_light(l, point_fn, 3e-5, 5e-7, &zero);
    assert_true(lit > 200);
    assert_true(zero > 200);
    /* a hard-edged cone: inner == outer */
    l.inner_angle = l.outer_angle;
    lx_scene *s = new_scene();
    uint32_t node = add_plane(s, "ground", 4.0f, 0.0f, 0.25f, -0.5f, 4);
    add_light(s, l);
    lx_baker *b = bake(s, 64, LX_PADDING_NONE, LX_QUANTITY_IRRADIANCE);
    uint32_t map = lx_test_map_of(b, node);
    lx_image img = apply(b, map);
    int inside = 0, outside = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            lx_texel_sample ts;
            assert_true(lx_baker_texel(b, map, x, y, &ts));
            lx_vec3 d = lx_sub(ts.position, l.position);
            double ca = lx_dot(d, l.direction) / lx_length(d);
            double margin = ca - cos(l.outer_angle);
            float v = img.data[3 * (y * 64 + x)];
            if (margin > 1e-5) {
                double want = point_ref(&(lx_light){.type = LX_LIGHT_POINT,
                                                    .position = l.position,
                                                    .intensity = l.intensity,
                                                    .range = l.range},
                                        ts.position, lx_v3(0, 1, 0));
                check_close(v, want, 1e-6, 0, "hard cone inside", x, y); /* 3.2e-7 */
                inside++;
            } else if (margin < -1e-5) {
                assert_true(v == 0.0f);
                outside++;
            }
        }
    assert_true(inside > 100 && outside > 100);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

static void test_directional_cosine(void **state)
{
    (void)state;
    lx_light l = dir_light("sun", lx_v3(0.3f, -1.0f, 0.2f), 5.0f);
    l.color = lx_v3(0.9f, 0.8f, 0.7f);
    assert_int_equal(check_plane_light(l, dir_fn, FLOAT_TOL, 0.0, NULL), 64 * 64); /* 6.5e-8 */
    /* the value itself: lux * cos(theta); the float direction's rounding,
     * measured 1.3e-8, bound 5e-8 */
    double c = 1.0 / sqrt(0.09 + 1.0 + 0.04);
    lx_test_assert_rel(dir_fn(&l, lx_v3(0, 0, 0), lx_v3(0, 1, 0)), 5.0 * c, 5e-8);
}

/* ---- (b) occluder: the shadow is the projection of the square --------------- */

static void test_occluder_projection(void **state)
{
    (void)state;
    const float size = 4.0f, occ = 1.0f, occ_h = 1.0f, ocx = 0.3f, ocz = 0.2f;
    const int res = 64;
    const double texel = size / res;
    lx_scene *s = new_scene();
    uint32_t ground = add_plane(s, "ground", size, 0.0f, 0.0f, 0.0f, 4);
    uint32_t occluder = add_plane(s, "occluder", occ, occ_h, ocx, ocz, 1);
    lx_light l = point_light("bulb", lx_v3(-0.1f, 3.0f, 0.05f), 50.0f, 0.0f);
    add_light(s, l);
    lx_baker *b = bake(s, res, LX_PADDING_NONE, LX_QUANTITY_IRRADIANCE);

    /* projection of the occluder square from the light onto y = 0 */
    double k = l.position.y / (l.position.y - occ_h);
    double x0 = l.position.x + (ocx - occ / 2.0 - l.position.x) * k;
    double x1 = l.position.x + (ocx + occ / 2.0 - l.position.x) * k;
    double z0 = l.position.z + (ocz - occ / 2.0 - l.position.z) * k;
    double z1 = l.position.z + (ocz + occ / 2.0 - l.position.z) * k;

    uint32_t map = lx_test_map_of(b, ground);
    lx_image img = apply(b, map);
    int shadowed = 0, lit = 0, edge = 0;
    for (int y = 0; y < res; y++)
        for (int x = 0; x < res; x++) {
            lx_texel_sample ts;
            assert_true(lx_baker_texel(b, map, x, y, &ts));
            double px = ts.position.x, pz = ts.position.z;
            /* signed distance to the projected square's border (> 0 inside) */
            double inside = fmin(fmin(px - x0, x1 - px), fmin(pz - z0, z1 - pz));
            float v = img.data[3 * (y * res + x)];
            if (inside > texel) {
                if (v != 0.0f)
                    fail_msg("texel (%d,%d) at (%g, %g) is %g inside the shadow", x, y, px, pz, v);
                shadowed++;
            } else if (inside < -texel) {
                check_close(v, point_ref(&l, ts.position, lx_v3(0, 1, 0)), 1e-6, 0, "lit", x,
                            y); /* measured 2.8e-7 */
                lit++;
            } else {
                edge++;
            }
        }
    /* the shadow covers about (1.5 m)^2 / (1/16 m)^2 = 576 texels */
    assert_true(shadowed > 400);
    assert_true(lit > 2500);
    assert_true(edge < 400);
    lx_image_free(&img);

    /* the occluder's own top is fully lit */
    map = lx_test_map_of(b, occluder);
    img = apply(b, map);
    int n = 0;
    for (int y = 0; y < res; y++)
        for (int x = 0; x < res; x++) {
            lx_texel_sample ts;
            if (!lx_baker_texel(b, map, x, y, &ts))
                continue;
            check_close(img.data[3 * (y * res + x)], point_ref(&l, ts.position, lx_v3(0, 1, 0)),
                        1e-6, 0, "occluder top", x, y); /* measured 2.6e-7 */
            n++;
        }
    assert_int_equal(n, res * res);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

/* ---- (c) closed box: no light gets in ------------------------------------------ */

static void assert_all_zero(const lx_baker *b, uint32_t map, const char *what)
{
    lx_image img = apply(b, map);
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, map);
    assert_true(info->used_texels > 0);
    for (int i = 0; i < img.width * img.height * 3; i++)
        if (img.data[i] != 0.0f)
            fail_msg("%s: texel (%d, %d) channel %d is %g, want exactly 0", what,
                     (i / 3) % img.width, (i / 3) / img.width, i % 3, img.data[i]);
    lx_image_free(&img);
}

static void test_closed_room_dark(void **state)
{
    (void)state;
    lx_scene *s = new_scene();
    lx_mesh room = lx_test_box("room", lx_v3(-1, -1, -1), lx_v3(1, 1, 1), true);
    lx_test_add(s, &room);
    lx_test_mesh_free(&room);
    add_light(s, point_light("above", lx_v3(0.3f, 4.0f, 0.2f), 100.0f, 0.0f));
    add_light(s, point_light("side", lx_v3(3.0f, 0.1f, -0.4f), 100.0f, 0.0f));
    add_light(s, dir_light("sun", lx_v3(0.5f, -0.7f, 0.3f), 10.0f));
    lx_baker *b = bake(s, 64, 0, LX_QUANTITY_IRRADIANCE);
    assert_all_zero(b, lx_test_map_of(b, 0), "inside the room");
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

static void test_plane_inside_box_dark(void **state)
{
    (void)state;
    lx_scene *s = new_scene();
    lx_mesh box = lx_test_box("box", lx_v3(-1, -1, -1), lx_v3(1, 1, 1), false);
    lx_test_add(s, &box);
    lx_test_mesh_free(&box);
    uint32_t plane = add_plane(s, "inner", 1.6f, -0.5f, 0.0f, 0.0f, 2);
    add_light(s, point_light("above", lx_v3(0.3f, 4.0f, 0.2f), 100.0f, 0.0f));
    add_light(s, dir_light("sun", lx_v3(-0.4f, -0.8f, 0.2f), 10.0f));
    lx_baker *b = bake(s, 64, 0, LX_QUANTITY_IRRADIANCE);
    assert_all_zero(b, lx_test_map_of(b, plane), "plane inside the box");
    /* the box's outside is lit: the lights are really there */
    lx_image img = apply(b, lx_test_map_of(b, 0));
    double sum = 0;
    for (int i = 0; i < img.width * img.height * 3; i++)
        sum += img.data[i];
    assert_true(sum > 0);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

/* ---- (d) grazing light: no acne ------------------------------------------------ */

static void grazing_case(float size, float cx, float cz, int n, float elevation_deg)
{
    lx_scene *s = new_scene();
    uint32_t node = add_plane(s, "ground", size, 0.0f, cx, cz, n);
    float e = LX_DEG2RAD(elevation_deg), a = LX_DEG2RAD(30.0f);
    const float lux = 1000.0f;
    add_light(s,
              dir_light("low sun", lx_v3(-cosf(e) * cosf(a), -sinf(e), -cosf(e) * sinf(a)), lux));
    const lx_light *l = &s->lights[0];
    double want = lux * -(double)l->direction.y;  /* lux * sin(elevation) */
    lx_test_assert_rel(want, lux * sin(e), 5e-7); /* float angles: measured 1.7e-7 */
    lx_baker *b = bake(s, 64, LX_PADDING_NONE, LX_QUANTITY_IRRADIANCE);
    uint32_t map = lx_test_map_of(b, node);
    lx_image img = apply(b, map);
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            float v = img.data[3 * (y * 64 + x)];
            if (!(fabs(v - want) <= FLOAT_TOL * want)) /* measured 3.9e-8 */
                fail_msg("plane %g m at (%g, %g), elevation %g deg: texel (%d, %d) is %g, "
                         "want %g",
                         size, cx, cz, elevation_deg, x, y, v, want);
        }
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

static void test_grazing_no_acne(void **state)
{
    (void)state;
    const float elevations[] = {1.0f, 2.0f, 3.0f, 5.0f};
    for (int i = 0; i < 4; i++) {
        grazing_case(100.0f, 0.0f, 0.0f, 16, elevations[i]);
        grazing_case(20.0f, 1000.0f, -700.0f, 8, elevations[i]);
        grazing_case(1.0f, 5000.0f, 5000.0f, 4, elevations[i]);
    }
}

/* ---- (e) ambient ------------------------------------------------------------- */

static void test_scene_ambient_adds(void **state)
{
    (void)state;
    const lx_vec3 amb = lx_v3(0.1f, 0.2f, 0.3f);
    lx_scene *s = new_scene();
    uint32_t node = add_plane(s, "ground", 4.0f, 0.0f, 0.0f, 0.0f, 4);
    s->ambient = amb;
    lx_baker *b = bake(s, 32, LX_PADDING_NONE, LX_QUANTITY_IRRADIANCE);
    uint32_t map = lx_test_map_of(b, node);
    lx_image img = apply(b, map);
    for (int i = 0; i < 32 * 32; i++) {
        assert_true(img.data[3 * i] == amb.x);
        assert_true(img.data[3 * i + 1] == amb.y);
        assert_true(img.data[3 * i + 2] == amb.z);
    }
    lx_image_free(&img);
    lx_baker_destroy(b);

    lx_light l = point_light("bulb", lx_v3(0.5f, 2.0f, 0.0f), 40.0f, 0.0f);
    l.shadow = LX_SHADOW_NONE;
    add_light(s, l);
    b = bake(s, 32, LX_PADDING_NONE, LX_QUANTITY_IRRADIANCE);
    img = apply(b, map);
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            lx_texel_sample ts;
            assert_true(lx_baker_texel(b, map, x, y, &ts));
            double e = point_ref(&l, ts.position, lx_v3(0, 1, 0));
            const float *px = &img.data[3 * (y * 32 + x)];
            /* measured 1.5e-7 */
            check_close(px[0], e + amb.x, 5e-7, 0, "ambient + light r", x, y);
            check_close(px[1], e + amb.y, 5e-7, 0, "ambient + light g", x, y);
            check_close(px[2], e + amb.z, 5e-7, 0, "ambient + light b", x, y);
        }
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

static void test_light_ambient_falloff_and_blend(void **state)
{
    (void)state;
    lx_scene *s = new_scene();
    uint32_t node = add_plane(s, "ground", 6.0f, 0.0f, 0.0f, 0.0f, 6);
    /* below the plane: no direct light, only their ambient reaches it */
    lx_light red = point_light("red", lx_v3(-1.5f, -0.5f, 0.0f), 10.0f, 2.0f);
    red.ambient = lx_v3(0.4f, 0.0f, 0.0f);
    lx_light blue = point_light("blue", lx_v3(1.5f, -0.5f, 0.3f), 10.0f, 2.0f);
    blue.ambient = lx_v3(0.0f, 0.0f, 0.6f);
    add_light(s, red);
    add_light(s, blue);
    lx_baker *b = bake(s, 64, LX_PADDING_NONE, LX_QUANTITY_IRRADIANCE);
    uint32_t map = lx_test_map_of(b, node);
    lx_image img = apply(b, map);
    int only_red = 0, only_blue = 0, both = 0, neither = 0;
    for (int y = 0; y < 64; y++)
        for (int x = 0; x < 64; x++) {
            lx_texel_sample ts;
            assert_true(lx_baker_texel(b, map, x, y, &ts));
            double dr = lx_length(lx_sub(ts.position, red.position));
            double db = lx_length(lx_sub(ts.position, blue.position));
            double wr = window_ref(dr, red.range), wb = window_ref(db, blue.range);
            const float *px = &img.data[3 * (y * 64 + x)];
            /* the window's float rounding near its edge is absolute: the
             * largest error measured uses 0.32 (red) and 0.39 (blue) of
             * these */
            check_close(px[0], 0.4 * wr, 2e-6, 3e-8, "red ambient", x, y);
            check_close(px[1], 0.0, 0, 0, "green", x, y);
            check_close(px[2], 0.6 * wb, 2e-6, 3e-8, "blue ambient", x, y);
            if (wr > 0 && wb > 0)
                both++;
            else if (wr > 0)
                only_red++;
            else if (wb > 0)
                only_blue++;
            else {
                neither++;
                assert_true(px[0] == 0.0f && px[2] == 0.0f);
            }
        }
    assert_true(only_red > 50 && only_blue > 50 && both > 10 && neither > 50);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

/* ---- (f) radiance = irradiance x base colour / pi -------------------------------- */

static void test_radiance_quantity(void **state)
{
    (void)state;
    lx_scene *s = new_scene();
    lx_material mat = {.name = "paint", .base_color = {0.5f, 0.25f, 0.8f, 1.0f}};
    assert_int_equal(lx_scene_add_material(s, &mat, NULL), LX_OK);
    uint32_t node = add_plane(s, "ground", 4.0f, 0.0f, 0.0f, 0.0f, 4);
    assert_int_equal(s->meshes[0].material, 0);
    lx_light p = point_light("bulb", lx_v3(0.2f, 1.8f, 0.3f), 60.0f, 8.0f);
    lx_light d = dir_light("sun", lx_v3(0.1f, -1.0f, -0.3f), 3.0f);
    add_light(s, p);
    add_light(s, d);
    lx_baker *b = bake(s, 32, LX_PADDING_NONE, LX_QUANTITY_RADIANCE);
    uint32_t map = lx_test_map_of(b, node);
    lx_image img = apply(b, map);
    const double albedo[3] = {0.5, 0.25, 0.8};
    for (int y = 0; y < 32; y++)
        for (int x = 0; x < 32; x++) {
            lx_texel_sample ts;
            assert_true(lx_baker_texel(b, map, x, y, &ts));
            double e = point_ref(&p, ts.position, lx_v3(0, 1, 0)) +
                       dir_fn(&d, ts.position, lx_v3(0, 1, 0));
            for (int c = 0; c < 3; c++)
                check_close(img.data[3 * (y * 32 + x) + c], e * albedo[c] / PI_D, 1e-6, 0,
                            "radiance", x, y); /* measured 3.0e-7 */
        }
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(s);
}

/* ---- (g) dilation -------------------------------------------------------------- */

/* A plane whose UV chart is [0.26, 0.76]^2: at 32 texels its borders fall
 * at 8.32 and 24.32, inside texel columns 8 and 24. */
static lx_scene *chart_scene(uint32_t *node)
{
    lx_scene *s = new_scene();
    lx_mesh m = lx_test_plane("chart", 2.0f, 0.0f, 0.0f, 0.0f, 2);
    for (uint32_t v = 0; v < m.vertex_count; v++)
        for (int k = 0; k < 2; k++)
            m.uv[k][v] = lx_v2(0.26f + 0.5f * m.uv[k][v].x, 0.26f + 0.5f * m.uv[k][v].y);
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    *node = s->node_count - 1;
    add_light(s, dir_light("sun", lx_v3(0.2f, -1.0f, 0.1f), 2.0f));
    return s;
}

static void test_dilation(void **state)
{
    (void)state;
    const int res = 32;
    uint32_t node;
    lx_scene *s = chart_scene(&node);
    double want = 2.0 * -(double)s->lights[0].direction.y;

    for (int pass = 0; pass < 2; pass++) {
        int padding = pass == 0 ? 2 : LX_PADDING_NONE;
        lx_baker *b = bake(s, res, padding, LX_QUANTITY_IRRADIANCE);
        uint32_t map = lx_test_map_of(b, node);
        const uint8_t *mask = lx_baker_mask(b, map);
        /* covered: every texel whose square overlaps the chart, columns and
         * rows 8..24 (24 only partly: pass 2 of the texel map) */
        for (int y = 0; y < res; y++)
            for (int x = 0; x < res; x++) {
                int expect = x >= 8 && x <= 24 && y >= 8 && y <= 24;
                if (mask[y * res + x] != expect)
                    fail_msg("mask (%d, %d) is %d, want %d", x, y, mask[y * res + x], expect);
            }
        lx_image img = apply(b, map);
        for (int y = 0; y < res; y++)
            for (int x = 0; x < res; x++) {
                /* rings from the chart: Chebyshev distance to a used texel */
                int ring = 1 << 20;
                for (int v = 0; v < res; v++)
                    for (int u = 0; u < res; u++)
                        if (mask[v * res + u]) {
                            int d = abs(u - x) > abs(v - y) ? abs(u - x) : abs(v - y);
                            ring = d < ring ? d : ring;
                        }
                const float *px = &img.data[3 * (y * res + x)];
                if (ring == 0 || (padding == 2 && ring <= 2)) {
                    check_close(px[0], want, FLOAT_TOL, 0, "filled", x, y); /* measured 0 */
                    assert_true(px[0] > 0.0f);
                } else {
                    if (px[0] != 0.0f || px[1] != 0.0f || px[2] != 0.0f)
                        fail_msg("padding %d: texel (%d, %d) %d rings out is %g, want 0", padding,
                                 x, y, ring, px[0]);
                }
            }
        lx_image_free(&img);
        lx_baker_destroy(b);
    }
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_light_inverse_square),
        cmocka_unit_test(test_spot_light_cone),
        cmocka_unit_test(test_directional_cosine),
        cmocka_unit_test(test_occluder_projection),
        cmocka_unit_test(test_closed_room_dark),
        cmocka_unit_test(test_plane_inside_box_dark),
        cmocka_unit_test(test_grazing_no_acne),
        cmocka_unit_test(test_scene_ambient_adds),
        cmocka_unit_test(test_light_ambient_falloff_and_blend),
        cmocka_unit_test(test_radiance_quantity),
        cmocka_unit_test(test_dilation),
    };
    lx_test_watchdog(60);
    return cmocka_run_group_tests(tests, NULL, NULL);
}
