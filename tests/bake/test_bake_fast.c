/* The bake's lean loop for point, spot and directional lights (16 texels at
 * a time, shadow rays as packets) against the light model itself: every
 * texel of every lightmap rebuilt from lx_light_evaluate (src/light/light.c)
 * and single-ray occlusion (lx_tracer_occluded) with the shadow-ray rule of
 * docs/ARCHITECTURE.md, summed in the documented order, must be the same
 * bits, on 1 and 3 threads. Also: the real-time buffers a static bake does
 * not need, and nodes built away from the identity and then moved. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bake/direct_fast.h"
#include "helpers.h"

/* ---- the scene --------------------------------------------------------------- */

static void add_light(lx_scene *s, lx_light l)
{
    if (lx_scene_add_light(s, &l) != LX_OK)
        fail_msg("add light: %s", lx_last_error());
}

static lx_light light(lx_light_type type, const char *name, lx_vec3 p, lx_vec3 dir, float value)
{
    lx_light l = lx_light_defaults(type);
    snprintf(l.name, sizeof l.name, "%s", name);
    l.position = p;
    l.direction = lx_normalize(dir);
    l.intensity = value;
    return l;
}

/* A 4 m ground, a box above it and a tilted panel (all with lightmaps),
 * lit by every kind of light the lean loop takes, with a blur-shadowed and
 * an unshadowed light (the general path) in between. */
static lx_scene *fast_scene(void)
{
    lx_scene *s = lx_test_new_scene("fast");
    lx_mesh ground = lx_test_plane("ground", 4.0f, 0.0f, 0.0f, 0.0f, 6);
    lx_test_add(s, &ground);
    lx_test_mesh_free(&ground);
    lx_mesh box = lx_test_box("box", lx_v3(-0.6f, 0.4f, -0.3f), lx_v3(0.2f, 0.9f, 0.5f), false);
    lx_test_add(s, &box);
    lx_test_mesh_free(&box);
    lx_mesh panel = lx_test_plane("panel", 1.0f, 0.0f, 0.0f, 0.0f, 2);
    uint32_t mi;
    assert_int_equal(lx_scene_add_mesh(s, &panel, &mi), LX_OK);
    lx_test_mesh_free(&panel);
    /* tilted 30 degrees about x, lifted and moved aside */
    lx_mat4 world = lx_mat4_identity();
    float c = cosf(0.5236f), sn = sinf(0.5236f);
    world.m[5] = c, world.m[6] = sn, world.m[9] = -sn, world.m[10] = c;
    world.m[12] = 1.2f, world.m[13] = 0.7f, world.m[14] = -0.9f;
    assert_int_equal(lx_scene_add_node(s, "panel", &world, &mi, 1, NULL), LX_OK);
    s->ambient = lx_v3(0.05f, 0.04f, 0.03f);

    lx_light l = light(LX_LIGHT_POINT, "point", lx_v3(0.3f, 2.5f, 0.2f), lx_v3(0, -1, 0), 60.0f);
    l.color = lx_v3(1.0f, 0.9f, 0.8f);
    add_light(s, l);
    l = light(LX_LIGHT_POINT, "ranged", lx_v3(-1.1f, 1.4f, 0.9f), lx_v3(0, -1, 0), 30.0f);
    l.range = 3.0f;
    l.ambient = lx_v3(0.01f, 0.02f, 0.03f);
    add_light(s, l);
    l = light(LX_LIGHT_SPOT, "spot", lx_v3(0.8f, 2.0f, -0.5f), lx_v3(-0.3f, -1, 0.2f), 90.0f);
    l.inner_angle = LX_DEG2RAD(10.0f), l.outer_angle = LX_DEG2RAD(35.0f);
    add_light(s, l);
    l = light(LX_LIGHT_POINT, "blurred", lx_v3(-0.2f, 1.8f, -1.0f), lx_v3(0, -1, 0), 20.0f);
    l.shadow = LX_SHADOW_BLUR;
    add_light(s, l);
    l = light(LX_LIGHT_SPOT, "hard cone", lx_v3(-1.0f, 2.2f, -0.2f), lx_v3(0.4f, -1, 0.1f), 70.0f);
    l.inner_angle = l.outer_angle = LX_DEG2RAD(25.0f);
    l.shadow = LX_SHADOW_NONE;
    add_light(s, l);
    l = light(LX_LIGHT_POINT, "classic", lx_v3(1.0f, 1.2f, 1.0f), lx_v3(0, -1, 0), 8.0f);
    l.model = LX_MODEL_CLASSIC, l.range = 4.0f;
    add_light(s, l);
    l = light(LX_LIGHT_SPOT, "classic spot", lx_v3(0.0f, 2.4f, 1.2f), lx_v3(0.1f, -1, -0.5f), 9.0f);
    l.model = LX_MODEL_CLASSIC, l.range = 5.0f;
    l.inner_angle = LX_DEG2RAD(5.0f), l.outer_angle = LX_DEG2RAD(40.0f);
    add_light(s, l);
    l = light(LX_LIGHT_DIRECTIONAL, "sun", lx_v3(0, 0, 0), lx_v3(0.3f, -1, 0.2f), 2.0f);
    add_light(s, l);
    l = light(LX_LIGHT_DIRECTIONAL, "classic sun", lx_v3(0, 0, 0), lx_v3(-0.5f, -1, 0.1f), 1.5f);
    l.model = LX_MODEL_CLASSIC, l.shadow = LX_SHADOW_NONE;
    l.ambient = lx_v3(0.002f, 0.002f, 0.004f);
    add_light(s, l);
    return s;
}

/* ---- the oracle -------------------------------------------------------------- */

/* The shadow ray of docs/ARCHITECTURE.md: from p lifted along the
 * geometric normal, on the light's side, by base + 4e-6 max|p|, ending
 * 2 bias short of the light. */
static lx_ray shadow_ray(float base, lx_vec3 p, lx_vec3 ng, const lx_light_eval *e)
{
    lx_vec3 side = lx_dot(ng, e->to_light) >= 0.0f ? ng : lx_neg(ng);
    float bias = base + 4e-6f * lx_max_abs_component(p);
    lx_ray r = {lx_madd(p, side, bias), 0.0f, e->to_light,
                isfinite(e->distance) ? e->distance - 2.0f * bias : INFINITY};
    if (r.tmax < 0.0f)
        r.tmax = 0.0f;
    return r;
}

/* A texel's irradiance: the scene ambient, then each light's ambient and
 * (when it reaches the texel and nothing blocks it) its illuminance. */
static lx_vec3 oracle(const lx_scene *s, const lx_tracer *tr, float base, float diagonal,
                      const lx_texel_sample *t)
{
    lx_vec3 e = s->ambient;
    for (uint32_t l = 0; l < s->light_count; l++) {
        const lx_light *light = &s->lights[l];
        lx_light_eval ev;
        bool direct = lx_light_evaluate(light, t->position, t->normal, &ev);
        e = lx_add(e, ev.ambient);
        if (!direct)
            continue;
        if (light->shadow == LX_SHADOW_NONE) {
            e = lx_add(e, ev.illuminance);
            continue;
        }
        lx_ray r = shadow_ray(base, t->position, t->geometric_normal, &ev);
        if (light->shadow == LX_SHADOW_BLUR) {
            float d = lx_tracer_nearest_distance(tr, &r);
            float d_light = isfinite(ev.distance) ? ev.distance : diagonal;
            float vis = isfinite(d) ? lx_light_blur_visibility(light, d, d_light) : 1.0f;
            e = lx_add(e, lx_scale(ev.illuminance, vis));
        } else if (!lx_tracer_occluded(tr, &r)) {
            e = lx_add(e, ev.illuminance);
        }
    }
    return e;
}

static lx_baker *bake(const lx_scene *s, int threads)
{
    lx_bake_desc d = {.resolution = 48, .padding = LX_PADDING_NONE, .threads = threads};
    lx_baker *b;
    if (lx_baker_create(s, &d, &b) != LX_OK || lx_baker_bake(b) != LX_OK ||
        lx_baker_update(b) != LX_OK)
        fail_msg("bake: %s", lx_last_error());
    return b;
}

static void check_lean_loop(const char *build)
{
    lx_scene *s = fast_scene();
    lx_tracer *tr;
    assert_int_equal(lx_tracer_create(s, NULL, &tr), LX_OK);
    lx_vec3 lo, hi;
    assert_true(lx_scene_bounds(s, &lo, &hi));
    float diagonal = lx_length(lx_sub(hi, lo)), base = 1e-5f * diagonal;
    lx_baker *b1 = bake(s, 1), *b3 = bake(s, 3);
    assert_int_equal(lx_baker_lightmap_count(b1), 3);
    uint64_t texels = 0, shadowed = 0, lit = 0;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b1); m++) {
        lx_image one, three;
        assert_int_equal(lx_baker_apply_alloc(b1, m, &one), LX_OK);
        assert_int_equal(lx_baker_apply_alloc(b3, m, &three), LX_OK);
        assert_memory_equal(one.data, three.data, sizeof(float) * 3 * one.width * one.height);
        for (int y = 0; y < one.height; y++)
            for (int x = 0; x < one.width; x++) {
                lx_texel_sample t;
                if (!lx_baker_texel(b1, m, x, y, &t))
                    continue;
                lx_vec3 want = oracle(s, tr, base, diagonal, &t);
                const float *got = &one.data[3 * ((size_t)y * one.width + x)];
                if (memcmp(got, &want, sizeof(float) * 3) != 0)
                    fail_msg("%s build, map %u texel (%d, %d): baked %.9g %.9g %.9g, the model "
                             "%.9g %.9g %.9g",
                             build, m, x, y, got[0], got[1], got[2], want.x, want.y, want.z);
                texels++;
                /* the ground under the box is in its shadow from the point
                 * light, the rest of it lit */
                lx_light_eval ev;
                if (m == 0 && lx_light_evaluate(&s->lights[0], t.position, t.normal, &ev)) {
                    lx_ray r = shadow_ray(base, t.position, t.geometric_normal, &ev);
                    if (lx_tracer_occluded(tr, &r))
                        shadowed++;
                    else
                        lit++;
                }
            }
        lx_image_free(&one);
        lx_image_free(&three);
    }
    assert_true(texels > 2000);
    assert_true(shadowed > 50 && lit > 1000);
    lx_baker_destroy(b1);
    lx_baker_destroy(b3);
    lx_tracer_destroy(tr);
    lx_scene_destroy(s);
}

/* Every build of the lean loop this CPU runs (baseline, AVX2, AVX-512:
 * 4, 8 and 16 lanes a vector) gives the model's bits. */
static void test_lean_loop_is_the_light_model(void **state)
{
    (void)state;
    lx_fast_light_tile_fn builds[3];
    const char *names[3];
    int n = lx_fast_light_tile_builds(builds, names);
    for (int i = 0; i < n; i++) {
        lx_fast_light_tile_use(builds[i]);
        check_lean_loop(names[i]);
        print_message("lean loop, %s build: the model's bits\n", names[i]);
    }
    lx_fast_light_tile_use(NULL);
    /* the directions too (a directional bake): the same bits on each */
    lx_scene *s = fast_scene();
    lx_bake_desc d = {.resolution = 32, .padding = LX_PADDING_NONE, .threads = 2,
                      .directional = LX_DIRECTIONAL_SH};
    lx_image first[4];
    for (int i = 0; i < n; i++) {
        lx_fast_light_tile_use(builds[i]);
        lx_baker *b;
        if (lx_baker_create(s, &d, &b) != LX_OK || lx_baker_bake(b) != LX_OK)
            fail_msg("%s build, directional bake: %s", names[i], lx_last_error());
        lx_image sh[4];
        assert_int_equal(lx_baker_sh(b, 0, i ? sh : first), LX_OK);
        for (int c = 0; i && c < 4; c++) {
            if (memcmp(sh[c].data, first[c].data,
                       sizeof(float) * (size_t)sh[c].channels * sh[c].width * sh[c].height))
                fail_msg("%s build: SH plane %d differs from the baseline build's", names[i], c);
            lx_image_free(&sh[c]);
        }
        lx_baker_destroy(b);
    }
    for (int c = 0; c < 4; c++)
        lx_image_free(&first[c]);
    lx_fast_light_tile_use(NULL);
    lx_scene_destroy(s);
    if (n < 3)
        print_message("(this CPU runs %d of the 3 builds; the others are not tested here)\n", n);
}

/* ---- real-time buffers -------------------------------------------------------- */

/* Without dynamic lights an update changes nothing; a dynamic light is
 * added by the update, to the same bits as baking it statically (its sum
 * comes last either way), whether the scene made it dynamic or
 * lx_baker_set_light did after the baker was made. */
static void test_realtime_made_on_demand(void **state)
{
    (void)state;
    lx_scene *s = fast_scene();
    s->light_count = 2;                    /* point, then ranged, both static */
    s->lights[1].ambient = lx_v3(0, 0, 0); /* its whole sum is one term */
    lx_baker *b = bake(s, 2);
    lx_image want;
    assert_int_equal(lx_baker_apply_alloc(b, 0, &want), LX_OK);
    size_t bytes = sizeof(float) * 3 * want.width * want.height;
    lx_baker_destroy(b);

    /* static only: the update leaves the lightmap as it was */
    s->light_count = 1;
    b = bake(s, 2);
    lx_image before, after;
    assert_int_equal(lx_baker_apply_alloc(b, 0, &before), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(b, 0, &after), LX_OK);
    assert_memory_equal(before.data, after.data, bytes);
    lx_baker_destroy(b);

    /* the second light dynamic in the scene */
    s->light_count = 2;
    s->lights[1].dynamic = true;
    b = bake(s, 2);
    lx_image sum;
    assert_int_equal(lx_baker_apply_alloc(b, 0, &sum), LX_OK);
    assert_memory_equal(sum.data, want.data, bytes);
    lx_image_free(&sum);
    lx_baker_destroy(b);

    /* made dynamic through the baker after a bake and an update without it */
    s->lights[1].dynamic = false;
    lx_light second = s->lights[1];
    b = bake(s, 2); /* with no dynamic light: no real-time buffer yet */
    lx_light off = second;
    off.intensity = 0.0f; /* adds nothing */
    assert_int_equal(lx_baker_set_light(b, 1, &off), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK); /* the first light's contribution */
    lx_light dyn = second;
    dyn.dynamic = true;
    assert_int_equal(lx_baker_set_light(b, 1, &dyn), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(b, 0, &sum), LX_OK);
    assert_memory_equal(sum.data, want.data, bytes);
    lx_baker_destroy(b);
    lx_image_free(&want);
    lx_image_free(&before);
    lx_image_free(&after);
    lx_image_free(&sum);
    lx_scene_destroy(s);
}

/* ---- nodes built away from the identity ----------------------------------------- */

/* The panel (node 2, built tilted) moved to the identity has the texels of
 * the same panel built at the identity, and moved back, its first texels,
 * to the rounding of the transforms. Measured: the same floats; bounds one
 * float ulp of the positions (|p| < 2: 2.4e-7) and of the normals (1.2e-7). */
static void test_moves_of_a_transformed_node(void **state)
{
    (void)state;
    lx_scene *s = fast_scene();
    lx_bake_desc d = {.resolution = 16, .padding = LX_PADDING_NONE, .threads = 2};
    lx_baker *tilted, *flat;
    assert_int_equal(lx_baker_create(s, &d, &tilted), LX_OK);
    lx_mat4 world = s->nodes[2].world, id = lx_mat4_identity();
    s->nodes[2].world = id;
    assert_int_equal(lx_baker_create(s, &d, &flat), LX_OK);
    uint32_t m = lx_test_map_of(tilted, 2);
    assert_int_equal(m, lx_test_map_of(flat, 2));
    lx_texel_sample first[16 * 16];
    bool used[16 * 16];
    for (int k = 0; k < 16 * 16; k++)
        used[k] = lx_baker_texel(tilted, m, k % 16, k / 16, &first[k]);
    assert_int_equal(lx_baker_set_node_transform(tilted, 2, &id), LX_OK);
    int compared = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (int k = 0; k < 16 * 16; k++) {
            lx_texel_sample a, b;
            if (!used[k])
                continue;
            assert_true(lx_baker_texel(tilted, m, k % 16, k / 16, &a));
            if (pass == 0)
                assert_true(lx_baker_texel(flat, m, k % 16, k / 16, &b));
            else
                b = first[k];
            lx_vec3 da = lx_sub(a.position, b.position), dn = lx_sub(a.normal, b.normal);
            if (lx_length(da) > 2.4e-7f || lx_length(dn) > 1.2e-7f)
                fail_msg("pass %d texel %d: (%g %g %g) vs (%g %g %g)", pass, k, a.position.x,
                         a.position.y, a.position.z, b.position.x, b.position.y, b.position.z);
            compared++;
        }
        assert_int_equal(lx_baker_set_node_transform(tilted, 2, &world), LX_OK);
    }
    assert_true(compared > 200);
    lx_baker_destroy(tilted);
    lx_baker_destroy(flat);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lean_loop_is_the_light_model),
        cmocka_unit_test(test_realtime_made_on_demand),
        cmocka_unit_test(test_moves_of_a_transformed_node),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
