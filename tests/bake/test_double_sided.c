/* Double-sided materials (glTF doubleSided; lx_bake_desc.double_sided,
 * src/bake/sides.c), on planes written as glTF files here, lit by a sun
 * of E = 1000 lx with hard shadows:
 *
 * - a pond: a water plane facing down (-Y) 0.2 m over an up-facing bed.
 *   Its front is closed in, its back open: AUTO bakes the back, E at
 *   every texel (the sun straight down on an up-facing surface); FRONT
 *   bakes the front, 0 (Unity's and Bakery's choice); the same plane
 *   single-sided bakes 0 in AUTO. The bed under the water is in shadow
 *   (0). The bytes are the same on 1 and 2 threads, and in tiles (each
 *   lightmap built again under the smallest memory limit).
 * - a ground plane facing down over nothing: both faces look into the
 *   open, AUTO bakes the lit one, E cos(theta) for a sun theta from the
 *   zenith; FRONT 0.
 * - a closed room of six double-sided planes facing in, the sun outside:
 *   the inside keeps its fronts, so every texel is 0 (its back faces would
 *   hold the sun).
 * - the bounces read the face a texel bakes: a small single-sided ceiling
 *   facing down over the ground plane (turned) gets rho x E x the form
 *   factor to the lit part of the plane (its own shadow left out: Howell's
 *   C-11 by superposition), within the gathers' noise; with FRONT the plane
 *   holds 0 and the ceiling gets 0.
 *
 * Expected values never come from the code under test: the cosine law,
 * shadows, the form factor catalogue, and 0 where no light can arrive. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "texture_oracle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RES 32
static const double SUN = 1000.0;

static const char *const DOUBLE_MAT =
    "{\"name\":\"two\",\"doubleSided\":true,\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,"
    "0.5,0.5,1],\"metallicFactor\":0}}";
static const char *const SINGLE_MAT =
    "{\"name\":\"one\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,0.5,0.5,1],"
    "\"metallicFactor\":0}}";

/* A horizontal square of side `side` centred on (0, y, 0) as node name,
 * facing down (-Y) or up, with material mat; both UV sets cover it. */
static void square(lx_test_gltf *g, const char *name, double side, double y, bool down, int mat)
{
    double h = side / 2;
    lx_test_quad q = {.o = {-h, y, -h}, .uv = {{{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}}};
    /* e1 x e2 is the normal: x then z faces down, z then x up */
    double ex[3] = {side, 0, 0}, ez[3] = {0, 0, side};
    memcpy(q.e1, down ? ex : ez, sizeof ex);
    memcpy(q.e2, down ? ez : ex, sizeof ex);
    lx_test_gltf_node(g, name, lx_test_gltf_quad_mesh(g, name, &q, mat, NULL), "");
}

/* The box [-h, h] x [0, 2h] x [-h, h] as six squares facing in. */
static void room(lx_test_gltf *g, double h, int mat)
{
    const double d = 2 * h;
    static const char *const names[6] = {"floor", "roof", "west", "east", "north", "south"};
    /* corner o and edges e1, e2 with e1 x e2 pointing into the box */
    const double faces[6][3][3] = {
        {{-h, 0, -h}, {0, 0, d}, {d, 0, 0}}, /* floor, +Y */
        {{-h, d, -h}, {d, 0, 0}, {0, 0, d}}, /* roof, -Y */
        {{-h, 0, -h}, {0, d, 0}, {0, 0, d}}, /* west, +X */
        {{h, 0, -h}, {0, 0, d}, {0, d, 0}},  /* east, -X */
        {{-h, 0, -h}, {d, 0, 0}, {0, d, 0}}, /* north, +Z */
        {{-h, 0, h}, {0, d, 0}, {d, 0, 0}},  /* south, -Z */
    };
    for (int f = 0; f < 6; f++) {
        lx_test_quad q = {.uv = {{{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}}};
        memcpy(q.o, faces[f][0], sizeof q.o);
        memcpy(q.e1, faces[f][1], sizeof q.e1);
        memcpy(q.e2, faces[f][2], sizeof q.e2);
        /* facing in: e1 x e2 points toward the box's centre (0, h, 0) */
        const double *e1 = faces[f][1], *e2 = faces[f][2], *o = faces[f][0];
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        assert_true(n[0] * -o[0] + n[1] * (h - o[1]) + n[2] * -o[2] > 0);
        lx_test_gltf_node(g, names[f], lx_test_gltf_quad_mesh(g, names[f], &q, mat, NULL), "");
    }
}

/* A sun of SUN lux toward unit dir, hard shadows. */
static void add_sun(lx_scene *s, lx_vec3 dir)
{
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = dir;
    sun.intensity = (float)SUN;
    sun.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(s, &sun), LX_OK);
}

typedef struct baked {
    lx_baker *baker;
    lx_image img[8];
    uint32_t count;
} baked;

static lx_bake_desc bake_desc(lx_double_sided mode, int threads, int bounces, uint32_t gi_samples)
{
    return (lx_bake_desc){.resolution = RES,
                          .double_sided = mode,
                          .threads = threads,
                          .bounces = bounces,
                          .gi_samples = gi_samples,
                          .gi_sampling = LX_GI_SAMPLING_COSINE};
}

static baked bake_with(const lx_scene *s, lx_bake_desc d)
{
    baked out = {0};
    if (lx_baker_create(s, &d, &out.baker) != LX_OK)
        fail_msg("lx_baker_create: %s", lx_last_error());
    assert_int_equal(lx_baker_bake(out.baker), LX_OK);
    out.count = lx_baker_lightmap_count(out.baker);
    assert_true(out.count <= 8);
    for (uint32_t m = 0; m < out.count; m++)
        assert_int_equal(lx_baker_apply_alloc(out.baker, m, &out.img[m]), LX_OK);
    return out;
}

static baked bake(const lx_scene *s, lx_double_sided mode, int threads, int bounces,
                  uint32_t gi_samples)
{
    return bake_with(s, bake_desc(mode, threads, bounces, gi_samples));
}

/* The smallest memory limit lx_baker_create takes for s under d: the
 * baker then works in tiles, building each lightmap again. */
static uint64_t smallest_limit(const lx_scene *s, lx_bake_desc d)
{
    uint64_t lo = 1, hi = (uint64_t)1 << 32; /* lo fails, hi bakes */
    while (hi - lo > 1) {
        uint64_t mid = lo + (hi - lo) / 2;
        d.memory_limit = mid;
        lx_baker *b;
        lx_status st = lx_baker_create(s, &d, &b);
        assert_true(st == LX_OK || st == LX_ERR_NOMEM);
        if (st == LX_OK) {
            lx_baker_destroy(b);
            hi = mid;
        } else {
            lo = mid;
        }
    }
    return hi;
}

static void baked_free(baked *b)
{
    for (uint32_t m = 0; m < b->count; m++)
        lx_image_free(&b->img[m]);
    lx_baker_destroy(b->baker);
}

/* The lightmap of node `name`: every texel within tol of want (relative,
 * or absolute for 0). */
static void assert_node(const baked *b, const lx_scene *s, const char *name, double want,
                        double tol)
{
    uint32_t m = lx_test_map_of(b->baker, lx_test_node_named(s, name));
    const lx_image *img = &b->img[m];
    const uint8_t *mask = lx_baker_mask(b->baker, m);
    double worst = 0;
    int covered = 0;
    for (int i = 0; i < img->width * img->height; i++) {
        if (!mask[i])
            continue;
        covered++;
        for (int k = 0; k < 3; k++) {
            double got = img->data[3 * i + k];
            double err = want != 0 ? fabs(got - want) / want : fabs(got);
            worst = fmax(worst, err);
        }
    }
    assert_int_equal(covered, RES * RES);
    if (!(worst <= tol))
        fail_msg("node '%s': off %g by %.3g (%s)", name, want, worst,
                 want != 0 ? "relative" : "absolute");
}

static void write_pond(const char *path, bool double_sided)
{
    lx_test_gltf *g = lx_test_gltf_new();
    int single = lx_test_gltf_material(g, SINGLE_MAT);
    int water_mat = double_sided ? lx_test_gltf_material(g, DOUBLE_MAT) : single;
    square(g, "bed", 4, 0, false, single);
    square(g, "water", 2, 0.2, true, water_mat);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void pond(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_double_sided_pond");
    char path[1024];
    snprintf(path, sizeof path, "%s/pond.gltf", dir);
    write_pond(path, true);
    lx_scene *s = lx_test_load(path);
    assert_true(
        s->materials[s->meshes[s->nodes[lx_test_node_named(s, "water")].meshes[0]].material].double_sided);
    assert_false(
        s->materials[s->meshes[s->nodes[lx_test_node_named(s, "bed")].meshes[0]].material].double_sided);
    add_sun(s, lx_v3(0, -1, 0));
    baked a = bake(s, LX_DOUBLE_SIDED_AUTO, 2, 0, 0);
    /* measured: float rounding only */
    assert_node(&a, s, "water", SUN, 1e-5);
    /* the bed under the water: its centre texel is in shadow */
    uint32_t bm = lx_test_map_of(a.baker, lx_test_node_named(s, "bed"));
    int c = (RES / 2) * RES + RES / 2;
    assert_true(a.img[bm].data[3 * c] == 0.0f);
    baked one = bake(s, LX_DOUBLE_SIDED_AUTO, 1, 0, 0);
    for (uint32_t m = 0; m < a.count; m++)
        assert_memory_equal(a.img[m].data, one.img[m].data,
                            sizeof(float) * 3 * (size_t)a.img[m].width * a.img[m].height);
    baked_free(&one);
    /* tiled: each map built again turns the same texels */
    lx_bake_desc td = bake_desc(LX_DOUBLE_SIDED_AUTO, 2, 0, 0);
    td.memory_limit = smallest_limit(s, td);
    baked tiled = bake_with(s, td);
    assert_true(lx_baker_tile_count(tiled.baker) >= 2);
    for (uint32_t m = 0; m < a.count; m++)
        assert_memory_equal(a.img[m].data, tiled.img[m].data,
                            sizeof(float) * 3 * (size_t)a.img[m].width * a.img[m].height);
    baked_free(&tiled);
    baked_free(&a);
    baked f = bake(s, LX_DOUBLE_SIDED_FRONT, 2, 0, 0);
    assert_node(&f, s, "water", 0.0, 0.0);
    baked_free(&f);
    lx_scene_destroy(s);

    /* single-sided: its front is what it has */
    write_pond(path, false);
    s = lx_test_load(path);
    add_sun(s, lx_v3(0, -1, 0));
    baked one_sided = bake(s, LX_DOUBLE_SIDED_AUTO, 2, 0, 0);
    assert_node(&one_sided, s, "water", 0.0, 0.0);
    baked_free(&one_sided);
    lx_scene_destroy(s);
}

static void ground_over_nothing(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_double_sided_ground");
    char path[1024];
    snprintf(path, sizeof path, "%s/ground.gltf", dir);
    lx_test_gltf *g = lx_test_gltf_new();
    square(g, "ground", 4, 0, true, lx_test_gltf_material(g, DOUBLE_MAT));
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = lx_test_load(path);
    add_sun(s, lx_v3(0.6f, -0.8f, 0.0f));
    baked a = bake(s, LX_DOUBLE_SIDED_AUTO, 2, 0, 0);
    assert_node(&a, s, "ground", SUN * 0.8, 1e-5);
    baked_free(&a);
    baked f = bake(s, LX_DOUBLE_SIDED_FRONT, 2, 0, 0);
    assert_node(&f, s, "ground", 0.0, 0.0);
    baked_free(&f);
    lx_scene_destroy(s);
}

static void closed_room_keeps_fronts(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_double_sided_room");
    char path[1024];
    snprintf(path, sizeof path, "%s/room.gltf", dir);
    lx_test_gltf *g = lx_test_gltf_new();
    room(g, 2, lx_test_gltf_material(g, DOUBLE_MAT));
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = lx_test_load(path);
    add_sun(s, lx_v3(0.6f, -0.8f, 0.0f));
    baked a = bake(s, LX_DOUBLE_SIDED_AUTO, 2, 0, 0);
    static const char *const names[6] = {"floor", "roof", "west", "east", "north", "south"};
    for (int f = 0; f < 6; f++)
        assert_node(&a, s, names[f], 0.0, 0.0);
    baked_free(&a);
    lx_scene_destroy(s);
}

/* Form factor from (px, pz) at height c to the rectangle [x0, x1] x
 * [z0, z1] below it, by superposing Howell's corner configuration. */
static double rect_ff(double px, double pz, double c, double x0, double x1, double z0, double z1)
{
    x0 -= px, x1 -= px, z0 -= pz, z1 -= pz;
    return lx_test_corner_form_factor(x1, z1, c) - lx_test_corner_form_factor(x0, z1, c) -
           lx_test_corner_form_factor(x1, z0, c) + lx_test_corner_form_factor(x0, z0, c);
}

static void bounce_reads_the_baked_face(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_double_sided_bounce");
    char path[1024];
    snprintf(path, sizeof path, "%s/ceiling.gltf", dir);
    lx_test_gltf *g = lx_test_gltf_new();
    int two = lx_test_gltf_material(g, DOUBLE_MAT), one = lx_test_gltf_material(g, SINGLE_MAT);
    square(g, "ground", 8, 0, true, two);
    square(g, "ceiling", 1, 1, true, one);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = lx_test_load(path);
    add_sun(s, lx_v3(0, -1, 0));
    baked a = bake(s, LX_DOUBLE_SIDED_AUTO, 2, 1, 1024);
    uint32_t m = lx_test_map_of(a.baker, lx_test_node_named(s, "ceiling"));
    /* the ceiling's texels against rho E x (the plane - the shadow), the
     * ceiling's own shadow the square below it */
    double got = 0, want = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            /* texel centre on the ceiling: x along +x, y along +z */
            double px = -0.5 + (x + 0.5) / RES, pz = -0.5 + (y + 0.5) / RES;
            want += 0.5 * SUN *
                    (rect_ff(px, pz, 1, -4, 4, -4, 4) - rect_ff(px, pz, 1, -0.5, 0.5, -0.5, 0.5));
            got += a.img[m].data[3 * (y * RES + x)];
        }
    got /= RES * RES;
    want /= RES * RES;
    if (getenv("LX_TEST_VERBOSE"))
        printf("ceiling: %.4g lx, form factors %.4g lx (%.3g)\n", got, want, got / want - 1);
    /* the mean of 1024 cosine rays over 1024 texels, and the ground's
     * lightmap blurring its shadow's edge over a texel (1/4 m) */
    lx_test_assert_rel(got, want, 0.015); /* measured: 0.26% */
    baked_free(&a);
    baked f = bake(s, LX_DOUBLE_SIDED_FRONT, 2, 1, 64);
    assert_node(&f, s, "ground", 0.0, 0.0);
    assert_node(&f, s, "ceiling", 0.0, 0.0);
    baked_free(&f);
    lx_scene_destroy(s);
}

static void bad_mode(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("bad");
    lx_mesh p = lx_test_plane("p", 1, 0, 0, 0, 1);
    lx_test_add(s, &p);
    lx_test_mesh_free(&p);
    add_sun(s, lx_v3(0, -1, 0));
    lx_bake_desc d = {.resolution = 8, .double_sided = (lx_double_sided)7};
    lx_baker *b = NULL;
    assert_int_equal(lx_baker_create(s, &d, &b), LX_ERR_INVALID);
    assert_null(b);
    assert_non_null(strstr(lx_last_error(), "double-sided"));
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(pond),
        cmocka_unit_test(ground_over_nothing),
        cmocka_unit_test(closed_room_keeps_fronts),
        cmocka_unit_test(bounce_reads_the_baked_face),
        cmocka_unit_test(bad_mode),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
