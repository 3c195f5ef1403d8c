/* Per-node bake settings (lx_node.bake) as scenes bring them and lights
 * files change them, and sky domes:
 * - zero is the default: a node lx_scene_add_node adds casts shadows, gets
 *   a lightmap, takes part in bounces, at scale 1;
 * - glTF node extras (what Blender exports of custom properties): true/false
 *   and Blender's integers 1/0, the lightmap scale; a bad value fails the
 *   load naming the file, the node and the key; an unknown luxel_* key is
 *   one warning;
 * - the lights JSON's "nodes" section: exact names and glob patterns, later
 *   entries over earlier ones, over the extras; unknown keys, wrong types,
 *   out-of-range scales, repeated keys are errors that leave the scene as
 *   it was; a pattern matching no node is one warning;
 * - sky domes: an unlit mesh enclosing the rest at least LX_SKY_DOME_RATIO
 *   times its diagonal is marked (one warning naming it) and left out of
 *   lx_scene_bounds; a lit one, an unlit one that does not enclose, or one
 *   whose extras say luxel_sky false is not;
 * - backdrops: a node with more than half the lightmapped area spanning at
 *   least LX_BACKDROP_RATIO times the rest is marked (one warning), its
 *   lightmap scale lowered to leave it LX_BACKDROP_SHARE of the texels
 *   (the closed form s^2 A / (s^2 A + A_rest)), and the default camera
 *   frames the rest exactly as lx_camera_frame frames its bounds; a ground
 *   under the ratio, or whose extras set its scale, is not.
 * Scenes are generated glTF files (tests/common/gltf_writer.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* An axis-aligned box [lo, hi] as a glTF mesh with material mat. */
static int box_mesh(lx_test_gltf *g, const char *name, lx_vec3 lo, lx_vec3 hi, bool inward, int mat)
{
    lx_mesh m = lx_test_box(name, lo, hi, inward);
    lx_test_primitive p = {.vertex_count = (int)m.vertex_count,
                           .position = &m.positions[0].x,
                           .normal = &m.normals[0].x,
                           .uv0 = &m.uv[0][0].x,
                           .index_count = 3 * (int)m.triangle_count,
                           .indices = m.indices,
                           .material = mat};
    int mesh = lx_test_gltf_mesh(g, name, &p, 1);
    lx_test_mesh_free(&m);
    return mesh;
}

static const lx_node *node_named(const lx_scene *s, const char *name)
{
    return &s->nodes[lx_test_node_named(s, name)];
}

static bool bake_default(const lx_node_bake *b)
{
    return !b->no_cast_shadows && !b->no_lightmap && !b->no_contribute_gi && !b->sky &&
           lx_node_lightmap_scale(b) == 1.0f;
}

/* Four walls and a floor; the walls' extras as given. */
static void write_walls(const char *path, const char *const extras[4])
{
    lx_test_gltf *g = lx_test_gltf_new();
    int mat = lx_test_gltf_material(g, "{\"name\":\"plaster\"}");
    lx_test_gltf_node(g, "Floor",
                      box_mesh(g, "floor", lx_v3(-2, -0.1f, -2), lx_v3(2, 0, 2), false, mat), "");
    for (int k = 0; k < 4; k++) {
        char name[16], members[256] = "";
        snprintf(name, sizeof name, "Wall_%d", k + 1);
        if (extras[k])
            snprintf(members, sizeof members, "\"extras\":%s", extras[k]);
        float x = -2.0f + (float)k;
        lx_test_gltf_node(g, name,
                          box_mesh(g, name, lx_v3(x, 0, 2), lx_v3(x + 0.5f, 2, 2.2f), false, mat),
                          members);
    }
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void test_defaults_are_zero(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("zero");
    lx_mesh m = lx_test_plane("plane", 1, 0, 0, 0, 1);
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    assert_true(bake_default(&s->nodes[0].bake));
    lx_scene_destroy(s);
}

static void test_extras(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_node_settings_extras");
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/walls.gltf", dir);
    const char *extras[4] = {
        /* Blender 3+ booleans */
        "{\"luxel_cast_shadows\":false,\"luxel_lightmap\":false}",
        /* Blender's integer properties, and a scale */
        "{\"luxel_contribute_gi\":0,\"luxel_lightmap_scale\":0.5,\"other_tool\":\"x\"}",
        /* a sky by hand, and an unknown luxel_ key */
        "{\"luxel_sky\":1,\"luxel_lightmap_scal\":2}", NULL};
    write_walls(path, extras);
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    const lx_node_bake *b = &node_named(s, "Wall_1")->bake;
    assert_true(b->no_cast_shadows && b->no_lightmap && !b->no_contribute_gi && !b->sky);
    b = &node_named(s, "Wall_2")->bake;
    assert_true(!b->no_cast_shadows && !b->no_lightmap && b->no_contribute_gi);
    assert_true(lx_node_lightmap_scale(b) == 0.5f);
    b = &node_named(s, "Wall_3")->bake;
    assert_true(b->sky && b->no_cast_shadows && b->no_lightmap && b->no_contribute_gi);
    assert_true(bake_default(&node_named(s, "Wall_4")->bake));
    assert_true(bake_default(&node_named(s, "Floor")->bake));
    /* one warning, naming the unknown key */
    assert_int_equal(book.warnings, 1);
    assert_non_null(strstr(book.text, "luxel_lightmap_scal'"));
    assert_non_null(strstr(book.text, "Wall_3"));

    /* the lights JSON over the extras: later entries over earlier ones */
    const char *json = "{\"nodes\": {\"Wall_*\": {\"cast_shadows\": true, \"lightmap_scale\": 2},"
                       " \"Wall_2\": {\"lightmap_scale\": 3},"
                       " \"Wall_3\": {\"sky\": false}, \"Wal?_4\": {\"contribute_gi\": false}}}";
    assert_int_equal(lx_lights_json_apply_text(s, json, strlen(json), "l.json"), LX_OK);
    b = &node_named(s, "Wall_1")->bake;
    assert_true(!b->no_cast_shadows && b->no_lightmap && lx_node_lightmap_scale(b) == 2.0f);
    b = &node_named(s, "Wall_2")->bake;
    assert_true(b->no_contribute_gi && lx_node_lightmap_scale(b) == 3.0f);
    /* "sky": false unmarks and turns the three back on; the glob's scale stays */
    b = &node_named(s, "Wall_3")->bake;
    assert_true(!b->sky && !b->no_cast_shadows && !b->no_lightmap && !b->no_contribute_gi);
    assert_true(lx_node_lightmap_scale(b) == 2.0f);
    b = &node_named(s, "Wall_4")->bake;
    assert_true(b->no_contribute_gi && !b->no_cast_shadows && lx_node_lightmap_scale(b) == 2.0f);
    assert_true(bake_default(&node_named(s, "Floor")->bake));
    lx_scene_destroy(s);
}

/* A bad extras value fails the load: file, node, key. */
static void test_extras_errors(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_node_settings_extras_bad");
    static const struct {
        const char *extras, *message;
    } cases[] = {
        {"{\"luxel_cast_shadows\":\"no\"}",
         "node 2 ('Wall_2'): extras: luxel_cast_shadows must be true or false (or 1 or 0)"},
        {"{\"luxel_lightmap\":2}",
         "node 2 ('Wall_2'): extras: luxel_lightmap must be true or false (or 1 or 0)"},
        {"{\"luxel_lightmap_scale\":0}",
         "node 2 ('Wall_2'): extras: luxel_lightmap_scale must be a number from 1/1024 to 1024"},
        {"{\"luxel_lightmap_scale\":\"2\"}",
         "node 2 ('Wall_2'): extras: luxel_lightmap_scale must be a number from 1/1024 to 1024"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char path[PATH_MAX];
        snprintf(path, sizeof path, "%s/bad%zu.gltf", dir, i);
        const char *extras[4] = {NULL, cases[i].extras, NULL, NULL};
        write_walls(path, extras);
        lx_scene *s = NULL;
        assert_int_equal(lx_scene_load(path, NULL, &s), LX_ERR_FORMAT);
        assert_null(s);
        char want[PATH_MAX + 200];
        snprintf(want, sizeof want, "%s: %s", path, cases[i].message);
        assert_string_equal(lx_last_error(), want);
    }
}

static void test_json_nodes(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("room.glb");
    const char *names[] = {"Floor", "Wall_1", "Wall_2", "Sky[1]"};
    for (int k = 0; k < 4; k++) {
        lx_mesh m = lx_test_plane(names[k], 1, (float)k, 0, 0, 1);
        lx_test_add(s, &m);
        lx_test_mesh_free(&m);
    }
    /* a pattern matching nothing is a warning; brackets in a name match
     * it exactly as well as by pattern */
    const char *json = "{\"nodes\": {\"Wall_*\": {\"lightmap\": false},"
                       " \"Sky[1]\": {\"sky\": true}, \"Ceiling*\": {\"lightmap\": false},"
                       " \"Door\": {\"cast_shadows\": false}}}";
    lx_status st = lx_lights_json_apply_text(s, json, strlen(json), "l.json");
    assert_int_equal(st, LX_OK);
    assert_true(s->nodes[1].bake.no_lightmap && s->nodes[2].bake.no_lightmap);
    assert_true(bake_default(&s->nodes[0].bake));
    assert_true(s->nodes[3].bake.sky && s->nodes[3].bake.no_cast_shadows);

    /* errors name the file, the entry and the key, and change nothing */
    static const struct {
        const char *json, *message;
        lx_status status;
    } cases[] = {
        {"{\"nodes\": {\"Floor\": {\"cast_shadow\": false}}}",
         "l.json: nodes ('Floor'): unknown key 'cast_shadow'", LX_ERR_FORMAT},
        {"{\"nodes\": {\"Floor\": {\"lightmap\": 0}}}",
         "l.json: nodes ('Floor'): lightmap must be true or false", LX_ERR_FORMAT},
        {"{\"nodes\": {\"Floor\": {\"lightmap_scale\": 0}}}",
         "l.json: nodes ('Floor'): lightmap_scale 0 is outside 1/1024..1024", LX_ERR_INVALID},
        {"{\"nodes\": {\"Floor\": {\"lightmap_scale\": \"2\"}}}",
         "l.json: nodes ('Floor'): lightmap_scale must be a number", LX_ERR_FORMAT},
        {"{\"nodes\": {\"Floor\": true}}",
         "l.json: nodes ('Floor'): must be an object of cast_shadows, lightmap, contribute_gi, "
         "lightmap_scale or sky",
         LX_ERR_FORMAT},
        {"{\"nodes\": [\"Floor\"]}", "l.json: nodes: must be an object of node names or patterns",
         LX_ERR_FORMAT},
        {"{\"nodes\": {\"Floor\": {}, \"Floor\": {}}}", "l.json: nodes: 'Floor' appears twice",
         LX_ERR_FORMAT},
        {"{\"nodes\": {\"\": {}}}", "l.json: nodes: an empty name matches no node", LX_ERR_FORMAT},
        /* the whole file is checked before anything changes */
        {"{\"nodes\": {\"Floor\": {\"lightmap\": false}}, \"ambient\": [1, 2]}",
         "l.json: ambient must be an array of 3 numbers, not 2", LX_ERR_FORMAT},
    };
    /* more entries than a section may have (each is checked against the
     * ones before it) */
    size_t cap = 4097 * 24 + 64, len = 0;
    char *many = malloc(cap);
    assert_non_null(many);
    len += (size_t)snprintf(many + len, cap - len, "{\"nodes\": {");
    for (int k = 0; k < 4097; k++)
        len += (size_t)snprintf(many + len, cap - len, "%s\"n%d\": {}", k ? ", " : "", k);
    len += (size_t)snprintf(many + len, cap - len, "}}");
    assert_int_equal(lx_lights_json_apply_text(s, many, len, "l.json"), LX_ERR_INVALID);
    assert_string_equal(lx_last_error(),
                        "l.json: nodes: 4097 entries are more than the 4096 allowed");
    free(many);
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        st = lx_lights_json_apply_text(s, cases[i].json, strlen(cases[i].json), "l.json");
        if (st != cases[i].status || strcmp(lx_last_error(), cases[i].message) != 0)
            fail_msg("case %zu: status %d, '%s'", i, (int)st, lx_last_error());
        assert_true(bake_default(&s->nodes[0].bake));
    }
    lx_scene_destroy(s);
}

static lx_test_logbook warn_book;

static void to_book(void *user, lx_log_level level, const char *message)
{
    (void)user;
    if (level != LX_LOG_WARN)
        return;
    warn_book.warnings++;
    size_t n = strlen(warn_book.text);
    snprintf(warn_book.text + n, sizeof warn_book.text - n, "%s\n", message);
}

static void test_json_unmatched_warning(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("room.glb");
    lx_mesh m = lx_test_plane("Floor", 1, 0, 0, 0, 1);
    lx_test_add(s, &m);
    lx_test_mesh_free(&m);
    const char *json = "{\"nodes\": {\"Sky*\": {\"lightmap\": false}, \"Dome\": {},"
                       " \"F*\": {\"lightmap_scale\": 4}}}";
    memset(&warn_book, 0, sizeof warn_book);
    lx_set_log_callback(to_book, NULL);
    lx_status st = lx_lights_json_apply_text(s, json, strlen(json), "l.json");
    lx_set_log_callback(NULL, NULL);
    assert_int_equal(st, LX_OK);
    assert_int_equal(warn_book.warnings, 1);
    assert_string_equal(warn_book.text,
                        "l.json: nodes: 'Sky*' matches no node of room.glb (nor do 1 more)\n");
    assert_true(lx_node_lightmap_scale(&s->nodes[0].bake) == 4.0f);
    lx_scene_destroy(s);
}

/* A room (a floor and a box), and around it a box `dome_size` metres
 * across whose material is unlit when `unlit`; its extras as given. */
static void write_domed(const char *path, float dome_size, bool unlit, const char *dome_extras)
{
    lx_test_gltf *g = lx_test_gltf_new();
    int lit = lx_test_gltf_material(g, "{\"name\":\"plaster\"}");
    int sky = lx_test_gltf_material(
        g, unlit ? "{\"name\":\"sky\",\"extensions\":{\"KHR_materials_unlit\":{}}}"
                 : "{\"name\":\"sky\"}");
    if (unlit)
        lx_test_gltf_use_extension(g, "KHR_materials_unlit");
    lx_test_gltf_node(g, "Floor",
                      box_mesh(g, "floor", lx_v3(-5, -0.1f, -5), lx_v3(5, 0, 5), false, lit), "");
    lx_test_gltf_node(g, "Crate", box_mesh(g, "crate", lx_v3(0, 0, 0), lx_v3(1, 1, 1), false, lit),
                      "");
    float h = 0.5f * dome_size;
    char members[200] = "";
    if (dome_extras)
        snprintf(members, sizeof members, "\"extras\":%s", dome_extras);
    lx_test_gltf_node(g, "SkyDome",
                      box_mesh(g, "dome", lx_v3(-h, -h, -h), lx_v3(h, h, h), true, sky), members);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void test_sky_dome(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_node_settings_dome");
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/domed.gltf", dir);
    /* the room's diagonal: 10 x 1.1 x 10 m, 14.18 m; a 2 km dome */
    write_domed(path, 2000.0f, true, NULL);
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    const lx_node_bake *b = &node_named(s, "SkyDome")->bake;
    assert_true(b->sky && b->no_cast_shadows && b->no_lightmap && b->no_contribute_gi);
    assert_true(bake_default(&node_named(s, "Floor")->bake));
    assert_true(bake_default(&node_named(s, "Crate")->bake));
    assert_int_equal(book.warnings, 1);
    char want[PATH_MAX + 256];
    snprintf(want, sizeof want,
             "%s: node 'SkyDome' is an unlit mesh enclosing the scene (a sky dome): it casts no "
             "shadows and gets no lightmap (\"sky\": false in the lights JSON's \"nodes\" bakes "
             "it)\n",
             path);
    assert_string_equal(book.text, want);
    assert_true(s->materials[s->meshes[node_named(s, "SkyDome")->meshes[0]].material].unlit);
    /* the bounds are the room's */
    lx_vec3 lo, hi;
    assert_true(lx_scene_bounds(s, &lo, &hi));
    lx_test_assert_vec3(lo, -5, -0.1, -5);
    lx_test_assert_vec3(hi, 5, 1, 5);
    lx_scene_destroy(s);

    /* not a dome: lit; unlit but within the ratio (a 30 m box: its
     * diagonal 3.7 times the room's); unlit and huge but told it is no sky */
    struct {
        float size;
        bool unlit;
        const char *extras;
    } not_dome[] = {
        {2000.0f, false, NULL}, {30.0f, true, NULL}, {2000.0f, true, "{\"luxel_sky\":false}"}};
    for (int k = 0; k < 3; k++) {
        write_domed(path, not_dome[k].size, not_dome[k].unlit, not_dome[k].extras);
        s = lx_test_load_logged(path, NULL, &book);
        const lx_node_bake *d = &node_named(s, "SkyDome")->bake;
        assert_false(d->sky || d->no_cast_shadows || d->no_lightmap || d->no_contribute_gi);
        /* the lit 2 km box is baked, as a backdrop (test_backdrop): its
         * one warning says so */
        assert_int_equal(book.warnings, d->backdrop ? 1 : 0);
        assert_true(d->backdrop == (not_dome[k].size > 1000.0f && k == 0));
        lx_scene_destroy(s);
    }
    /* 40 m: 4.9 room diagonals, a dome */
    write_domed(path, 40.0f, true, NULL);
    s = lx_test_load_logged(path, NULL, &book);
    assert_true(node_named(s, "SkyDome")->bake.sky);
    lx_scene_destroy(s);
}

/* A ground of side `ground` m (0.1 m thick) under a 50 x 10 x 50 m town;
 * the ground's extras as given. */
static void write_town(const char *path, float ground, const char *ground_extras)
{
    lx_test_gltf *g = lx_test_gltf_new();
    int mat = lx_test_gltf_material(g, "{\"name\":\"grass\"}");
    float h = 0.5f * ground;
    char members[200] = "";
    if (ground_extras)
        snprintf(members, sizeof members, "\"extras\":%s", ground_extras);
    lx_test_gltf_node(g, "Ground",
                      box_mesh(g, "ground", lx_v3(-h, -0.1f, -h), lx_v3(h, 0, h), false, mat),
                      members);
    lx_test_gltf_node(g, "Town",
                      box_mesh(g, "town", lx_v3(-25, 0, -25), lx_v3(25, 10, 25), false, mat), "");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void test_backdrop(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_node_settings_backdrop");
    char path[PATH_MAX];
    snprintf(path, sizeof path, "%s/town.gltf", dir);
    write_town(path, 2000.0f, NULL);
    lx_test_logbook book;
    lx_scene *s = lx_test_load_logged(path, NULL, &book);
    const lx_node *ground = node_named(s, "Ground"), *town = node_named(s, "Town");
    assert_true(ground->bake.backdrop);
    assert_false(ground->bake.sky || ground->bake.no_lightmap || ground->bake.no_cast_shadows);
    assert_true(bake_default(&town->bake) && !town->bake.backdrop);
    assert_int_equal(book.warnings, 1);
    assert_non_null(strstr(book.text, "node 'Ground' spans 2e+03 m around the rest's 50 m"));
    /* areas in closed form: the ground 2 x 2000^2 + 4 x 2000 x 0.1, the
     * town 2 x 50^2 + 4 x 50 x 10 */
    double a_ground = 2.0 * 2000.0 * 2000.0 + 4.0 * 2000.0 * 0.1, a_town = 2.0 * 2500.0 + 2000.0;
    lx_test_assert_rel(lx_node_world_area(s, (uint32_t)(ground - s->nodes)), a_ground, 1e-5);
    double sc = ground->bake.lightmap_scale;
    double share = sc * sc * a_ground / (sc * sc * a_ground + a_town);
    printf("backdrop: lightmap scale %.4g, its share of the texels %.4g\n", sc, share);
    lx_test_assert_rel(share, LX_BACKDROP_SHARE, 1e-4);
    /* the default camera frames the town as lx_camera_frame frames its box */
    lx_camera cam, want = lx_camera_frame(lx_v3(-25, 0, -25), lx_v3(25, 10, 25), LX_VIEW_ISO,
                                          LX_DEG2RAD(LX_RENDER_DEFAULT_FOV_DEGREES), 16.0f / 9.0f);
    assert_int_equal(lx_camera_auto(s, NULL, NULL, 0.0f, 16.0f / 9.0f, &cam, NULL), LX_OK);
    lx_test_assert_vec3(cam.eye, want.eye.x, want.eye.y, want.eye.z);
    lx_test_assert_vec3(cam.target, want.target.x, want.target.y, want.target.z);
    lx_scene_destroy(s);

    /* not a backdrop: a 300 m ground (6 times the town), or one whose
     * extras set its scale */
    const char *extras[2] = {NULL, "{\"luxel_lightmap_scale\":0.5}"};
    const float sides[2] = {300.0f, 2000.0f};
    for (int k = 0; k < 2; k++) {
        write_town(path, sides[k], extras[k]);
        s = lx_test_load_logged(path, NULL, &book);
        assert_false(node_named(s, "Ground")->bake.backdrop);
        assert_int_equal(book.warnings, 0);
        assert_true(node_named(s, "Ground")->bake.lightmap_scale == (k ? 0.5f : 0.0f));
        lx_scene_destroy(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults_are_zero),      cmocka_unit_test(test_extras),
        cmocka_unit_test(test_extras_errors),          cmocka_unit_test(test_json_nodes),
        cmocka_unit_test(test_json_unmatched_warning), cmocka_unit_test(test_sky_dome),
        cmocka_unit_test(test_backdrop),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
