/* The bake under a memory limit (lx_bake_desc.memory_limit): a scene
 * whose lightmaps do not fit together is baked in tiles of lightmaps, and
 * every output is the untiled bake's to the byte (the invariant: tiles
 * change what is in memory, never a value), with bounces, emission,
 * denoising, radiance, padding, seams, a dynamic light and AO, on 1 and 2
 * threads. The smallest limit that bakes is found by bisection, so the
 * test holds whatever the per-texel figures become; one byte less fails
 * up front with one line naming the memory. Progress stays monotone across
 * tiles and a stop inside a tile cancels the bake. */
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

static uint32_t add_material(lx_scene *scene, const char *name, float r, float g, float b,
                             float le)
{
    lx_material mat = {.name = (char *)name,
                       .base_color = {r, g, b, 1.0f},
                       .emissive = {le, le, le},
                       .normal_scale = 1.0f};
    uint32_t idx;
    assert_int_equal(lx_scene_add_material(scene, &mat, &idx), LX_OK);
    return idx;
}

static void add_mesh(lx_scene *scene, lx_mesh mesh, uint32_t material)
{
    mesh.material = material;
    lx_test_add(scene, &mesh);
    lx_test_mesh_free(&mesh);
}

/* A room (inward box) with a floor, three blocks (one emissive), a static
 * spot, a soft rect light and a dynamic point light: seven lightmaps. */
static lx_scene *room_scene(void)
{
    lx_scene *s = lx_test_new_scene("tiles");
    uint32_t white = add_material(s, "white", 0.8f, 0.8f, 0.8f, 0.0f);
    uint32_t red = add_material(s, "red", 0.8f, 0.2f, 0.1f, 0.0f);
    uint32_t glow = add_material(s, "glow", 0.5f, 0.5f, 0.5f, 40.0f);
    add_mesh(s, lx_test_box("room", lx_v3(-2, 0, -2), lx_v3(2, 3, 2), true), white);
    add_mesh(s, lx_test_plane("floor", 3.0f, 0.01f, 0.0f, 0.0f, 2), red);
    add_mesh(s, lx_test_box("block_a", lx_v3(-1.5f, 0, -1.5f), lx_v3(-0.7f, 1, -0.7f), false), red);
    add_mesh(s, lx_test_box("block_b", lx_v3(0.5f, 0, 0.3f), lx_v3(1.3f, 0.6f, 1.2f), false), white);
    add_mesh(s, lx_test_box("lamp", lx_v3(-0.3f, 2.2f, -0.3f), lx_v3(0.3f, 2.4f, 0.3f), false),
             glow);
    add_mesh(s, lx_test_plane("shelf", 1.0f, 1.5f, 1.2f, -1.2f, 1), white);
    add_mesh(s, lx_test_box("block_c", lx_v3(-1.6f, 0, 0.8f), lx_v3(-1.0f, 2.0f, 1.6f), false), white);
    lx_light spot = lx_light_defaults(LX_LIGHT_SPOT);
    spot.position = lx_v3(0.5f, 2.8f, 0.5f);
    spot.direction = lx_v3(0, -1, 0);
    spot.intensity = 300.0f;
    spot.outer_angle = 1.0f;
    spot.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(s, &spot), LX_OK);
    lx_light rect = lx_light_defaults(LX_LIGHT_RECT);
    snprintf(rect.name, sizeof rect.name, "rect");
    rect.position = lx_v3(-1.0f, 2.9f, 1.0f);
    rect.direction = lx_v3(0, -1, 0);
    rect.width = 0.5f;
    rect.height = 0.5f;
    rect.intensity = 2000.0f;
    rect.samples = 8;
    rect.shadow = LX_SHADOW_SOFT;
    assert_int_equal(lx_scene_add_light(s, &rect), LX_OK);
    lx_light moving = lx_light_defaults(LX_LIGHT_POINT);
    snprintf(moving.name, sizeof moving.name, "moving");
    moving.position = lx_v3(1.0f, 1.0f, -1.0f);
    moving.intensity = 50.0f;
    moving.dynamic = true;
    moving.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(s, &moving), LX_OK);
    s->ambient = lx_v3(0.5f, 0.5f, 0.5f);
    /* the floor's normals a little off unit length, as a caller may set
     * them: a tiled baker's copy must keep these very floats */
    lx_mesh *floor_mesh = &s->meshes[1];
    for (uint32_t v = 0; v < floor_mesh->vertex_count; v++)
        floor_mesh->normals[v] = lx_v3(0.0123f, 1.0000003f, -0.0071f);
    return s;
}

static lx_bake_desc room_desc(int threads, uint64_t limit)
{
    lx_bake_desc d = lx_bake_desc_defaults(NULL);
    d.resolution = 24;
    d.bounces = 2;
    d.gi_samples = 16;
    d.denoise = LX_DENOISE_INDIRECT;
    d.quantity = LX_QUANTITY_RADIANCE;
    d.padding = 2;
    d.stitch_seams = true;
    d.threads = threads;
    d.memory_limit = limit;
    return d;
}

typedef struct outputs {
    uint32_t maps, tiles;
    lx_image light[16], ao[16];
    float ev;
    bool lit;
} outputs;

static void bake_all(lx_scene *scene, const lx_bake_desc *d, outputs *o)
{
    memset(o, 0, sizeof *o);
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, d, &b), LX_OK);
    o->maps = lx_baker_lightmap_count(b);
    o->tiles = lx_baker_tile_count(b);
    assert_true(o->maps <= 16);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_OK);
    for (uint32_t m = 0; m < o->maps; m++)
        assert_int_equal(lx_baker_apply_alloc(b, m, &o->light[m]), LX_OK);
    lx_ao_desc ad = {.samples = 16, .distance = 0.5f};
    for (uint32_t m = 0; m < o->maps; m++)
        assert_int_equal(lx_baker_ao(b, m, &ad, &o->ao[m]), LX_OK);
    lx_baker_meter_ev100(b, &o->ev, &o->lit);
    lx_baker_destroy(b);
}

static void outputs_free(outputs *o)
{
    for (uint32_t m = 0; m < o->maps; m++) {
        lx_image_free(&o->light[m]);
        lx_image_free(&o->ao[m]);
    }
}

static size_t image_bytes(const lx_image *im)
{
    return sizeof(float) * (size_t)im->width * (size_t)im->height * (size_t)im->channels;
}

static void assert_same(const outputs *a, const outputs *b)
{
    assert_int_equal(a->maps, b->maps);
    for (uint32_t m = 0; m < a->maps; m++) {
        assert_int_equal(a->light[m].width, b->light[m].width);
        assert_memory_equal(a->light[m].data, b->light[m].data, image_bytes(&a->light[m]));
        assert_memory_equal(a->ao[m].data, b->ao[m].data, image_bytes(&a->ao[m]));
    }
    assert_true(a->lit && b->lit);
    assert_memory_equal(&a->ev, &b->ev, sizeof a->ev);
}

/* The smallest memory limit lx_baker_create accepts for the scene under
 * d (its memory_limit aside). */
static uint64_t smallest_limit_for(lx_scene *scene, lx_bake_desc d)
{
    uint64_t lo = 1, hi = (uint64_t)1 << 32; /* lo fails, hi bakes */
    lx_baker *b;
    d.memory_limit = lo;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_NOMEM);
    while (hi - lo > 1) {
        uint64_t mid = lo + (hi - lo) / 2;
        d.memory_limit = mid;
        lx_status st = lx_baker_create(scene, &d, &b);
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

static uint64_t smallest_limit(lx_scene *scene, int threads)
{
    return smallest_limit_for(scene, room_desc(threads, 0));
}

static void tiles_match_untiled(void **state)
{
    (void)state;
    lx_scene *scene = room_scene();
    uint64_t limit = smallest_limit(scene, 1); /* threads do not change it */
    for (int threads = 1; threads <= 2; threads++) {
        outputs whole, tiled;
        lx_bake_desc d = room_desc(threads, 0);
        bake_all(scene, &d, &whole);
        assert_int_equal(whole.tiles, 1);
        d.memory_limit = limit;
        bake_all(scene, &d, &tiled);
        /* seven maps of the same size: the smallest limit holds one each */
        assert_int_equal(tiled.maps, 7);
        assert_true(tiled.tiles >= 4);
        assert_same(&whole, &tiled);
        /* a limit between: fewer, larger tiles, the same bytes */
        outputs mid;
        d.memory_limit = limit + (limit / 20);
        bake_all(scene, &d, &mid);
        assert_true(mid.tiles >= 2 && mid.tiles <= tiled.tiles);
        assert_same(&whole, &mid);
        /* one byte less: one line naming what is needed and the limit */
        d.memory_limit = limit - 1;
        lx_baker *b = NULL;
        assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_NOMEM);
        assert_null(b);
        const char *msg = lx_last_error();
        assert_non_null(strstr(msg, "needs"));
        assert_non_null(strstr(msg, "the memory limit asked for is"));
        assert_null(strchr(msg, '\n'));
        outputs_free(&whole);
        outputs_free(&tiled);
        outputs_free(&mid);
    }
    lx_scene_destroy(scene);
}

typedef struct progress_log {
    float last;
    int calls, stop_at;
    bool backwards, outside;
} progress_log;

static bool record(void *user, float f)
{
    progress_log *p = user;
    if (f < p->last)
        p->backwards = true;
    if (!(f >= 0.0f && f <= 1.0f))
        p->outside = true;
    p->last = f;
    p->calls++;
    return p->stop_at == 0 || p->calls < p->stop_at;
}

static void progress_and_cancel(void **state)
{
    (void)state;
    lx_scene *scene = room_scene();
    uint64_t limit = smallest_limit(scene, 2);
    lx_bake_desc d = room_desc(2, limit);
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    lx_baker_destroy(b);
    /* monotone over every tile of every pass */
    progress_log log = {0};
    d.progress = record;
    d.progress_user = &log;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_true(lx_baker_tile_count(b) >= 4);
    log = (progress_log){0};
    assert_int_equal(lx_baker_bake(b), LX_OK);
    int calls = log.calls;
    assert_false(log.backwards);
    assert_false(log.outside);
    assert_true(log.last == 1.0f);
    assert_true(calls > 20);
    /* stopping in the middle (inside some tile's pass) cancels, and the
     * baked light is zero */
    log = (progress_log){.stop_at = calls / 2};
    assert_int_equal(lx_baker_bake(b), LX_ERR_CANCELLED);
    d.progress = NULL;
    lx_image img;
    /* apply reports to the same callback: let it pass now */
    log.stop_at = 0;
    assert_int_equal(lx_baker_apply_alloc(b, 0, &img), LX_OK);
    for (size_t i = 0; i < (size_t)img.width * img.height * 3; i++)
        assert_true(img.data[i] == 0.0f);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

/* The later passes under tiles: directional data (SH and dominant),
 * supersampling (its points and footprint axes are texel map, built again
 * and moved out of walls again per tile), a textured emitter (its
 * emission read from every map) and light probes (read tile by tile):
 * the same bytes as without a limit. The dynamic lights' bounce, which
 * caches every map's texels for per-frame updates, is refused by a tiled
 * baker with one line. */
static void later_passes_tiled(void **state)
{
    (void)state;
    lx_scene *scene = room_scene();
    /* the lamp's emission through a 2x2 texture of two shades */
    lx_material *glow = &scene->materials[2];
    assert_int_equal(lx_image_alloc(&glow->emissive_map, 2, 2, 4), LX_OK);
    for (int i = 0; i < 4; i++) {
        float v = i % 3 == 0 ? 1.0f : 0.5f;
        for (int c = 0; c < 3; c++)
            glow->emissive_map.data[4 * i + c] = v;
        glow->emissive_map.data[4 * i + 3] = 1.0f;
    }
    lx_vec3 points[3] = {{0.0f, 1.5f, 0.0f}, {0.9f, 1.2f, -0.5f}, {-0.2f, 0.4f, 1.0f}};
    lx_probe probes[2][3];
    lx_image sh[2][7][4], dom[2][7];
    uint32_t maps[2] = {0, 0}, tiles[2] = {0, 0};
    for (int pass = 0; pass < 2; pass++) {
        lx_bake_desc d = room_desc(2, 0);
        d.directional = LX_DIRECTIONAL_SH;
        d.supersample = 2;
        d.probes = true;
        if (pass)
            d.memory_limit = smallest_limit_for(scene, d);
        lx_baker *b;
        assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
        maps[pass] = lx_baker_lightmap_count(b);
        tiles[pass] = lx_baker_tile_count(b);
        assert_int_equal(maps[pass], 7);
        assert_int_equal(lx_baker_bake(b), LX_OK);
        for (uint32_t m = 0; m < maps[pass]; m++) {
            assert_int_equal(lx_baker_sh(b, m, sh[pass][m]), LX_OK);
            assert_int_equal(lx_baker_dominant(b, m, &dom[pass][m]), LX_OK);
        }
        lx_probe_desc pd = {.samples = 64};
        assert_int_equal(lx_baker_probes(b, points, 3, &pd, probes[pass]), LX_OK);
        lx_baker_destroy(b);
    }
    assert_int_equal(tiles[0], 1);
    assert_true(tiles[1] >= 4);
    for (uint32_t m = 0; m < maps[0]; m++) {
        for (int c = 0; c < 4; c++) {
            assert_memory_equal(sh[0][m][c].data, sh[1][m][c].data, image_bytes(&sh[0][m][c]));
            lx_image_free(&sh[0][m][c]);
            lx_image_free(&sh[1][m][c]);
        }
        assert_memory_equal(dom[0][m].data, dom[1][m].data, image_bytes(&dom[0][m]));
        lx_image_free(&dom[0][m]);
        lx_image_free(&dom[1][m]);
    }
    for (int k = 0; k < 3; k++) {
        assert_true(probes[0][k].valid && probes[1][k].valid);
        assert_memory_equal(&probes[0][k].sh, &probes[1][k].sh, sizeof(lx_sh9));
    }
    /* the dynamic bounce: refused tiled, one line */
    lx_bake_desc d = room_desc(2, 0);
    d.dynamic_bounce_samples = 4;
    d.memory_limit = smallest_limit_for(scene, d);
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_OK);
    assert_true(lx_baker_tile_count(b) > 1);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    assert_int_equal(lx_baker_update(b), LX_ERR_NOMEM);
    const char *msg = lx_last_error();
    assert_non_null(strstr(msg, "tiles"));
    assert_null(strchr(msg, '\n'));
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(tiles_match_untiled),
        cmocka_unit_test(progress_and_cancel),
        cmocka_unit_test(later_passes_tiled),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
