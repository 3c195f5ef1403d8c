/* Tests of the KHR_lights_punctual reader (src/scene/gltf_lights.c): small
 * .gltf files written here with nested TRS and "matrix" nodes whose world
 * positions and directions are worked out by hand in the comments, spec
 * defaults, Blender's inner == outer cones, unique names, and GLB container
 * and node-graph faults failing cleanly. */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "helpers.h"
#include "luxel/scene.h"

#define PI_D 3.14159265358979323846
#define S45 "0.7071067811865476" /* sin 45 deg = cos 45 deg */

static void tmp_path(char *out, size_t size, const char *name)
{
    const char *dir = getenv("LX_TEST_TMP");
    if (!dir || !dir[0])
        dir = "/tmp";
    mkdir(dir, 0777);
    snprintf(out, size, "%s/test_gltf_lights_%ld_%s", dir, (long)getpid(), name);
}

static void write_file(const char *path, const void *bytes, size_t size)
{
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(bytes, 1, size, fp), size);
    fclose(fp);
}

static lx_status load_text(lx_scene *s, const char *json)
{
    return lx_gltf_lights_load_memory(s, json, strlen(json), "t.gltf");
}

static void expect_fail(const char *json, lx_status want, const char *needle)
{
    lx_scene *s = lx_test_new_scene("test");
    lx_status st = load_text(s, json);
    if (st != want || !strstr(lx_last_error(), needle))
        fail_msg("%s '%s', want %s with '%s'", lx_status_name(st), lx_last_error(),
                 lx_status_name(want), needle);
    assert_int_equal(s->light_count, 0);
    lx_scene_destroy(s);
}

/* node 0 "root": T(1,2,3) R_y(90) S(2), child node 1.
 *   R_y(90) maps x -> -z and z -> x.
 * node 1 "lampnode": T(0,0,1) R_x(90), light 0 (spot "Spot").
 *   R_x(90) maps y -> z and z -> -y, so its -Z becomes +Y.
 *   position = (1,2,3) + R_y(2 * (0,0,1)) = (1,2,3) + (2,0,0) = (3,2,3)
 *   direction = R_y(2 * (0,1,0)) normalized = (0,1,0)
 * node 2 "matrixnode": matrix T(5,0,0) R_x(-90), light 1 (directional "Sun"),
 *   child node 3. R_x(-90) maps y -> -z and z -> y: columns (1,0,0),
 *   (0,0,-1), (0,1,0). direction = R(0,0,-1) = (0,-1,0).
 * node 3 "bulb": T(0,1,0), light 2 (point, unnamed): named after the node,
 *   position = (5,0,0) + R_x(-90)(0,1,0) = (5,0,-1).
 * node 4: light 0 again at the origin: "Spot_2".
 * node 5: not in the scene: ignored. */
static const char *nested =
    "{\"asset\": {\"version\": \"2.0\"},\n"
    " \"extensionsUsed\": [\"KHR_lights_punctual\"],\n"
    " \"extensions\": {\"KHR_lights_punctual\": {\"lights\": [\n"
    "   {\"type\": \"spot\", \"name\": \"Spot\", \"intensity\": 10, \"color\": [1, 0.5, 0.5],\n"
    "    \"range\": 20, \"spot\": {\"innerConeAngle\": 0.3, \"outerConeAngle\": 0.6}},\n"
    "   {\"type\": \"directional\", \"name\": \"Sun\", \"intensity\": 3},\n"
    "   {\"type\": \"point\"}]}},\n"
    " \"scene\": 0,\n"
    " \"scenes\": [{\"nodes\": [0, 2, 4]}],\n"
    " \"nodes\": [\n"
    "   {\"name\": \"root\", \"translation\": [1, 2, 3], \"rotation\": [0, " S45 ", 0, " S45 "],\n"
    "    \"scale\": [2, 2, 2], \"children\": [1]},\n"
    "   {\"name\": \"lampnode\", \"translation\": [0, 0, 1], \"rotation\": [" S45 ", 0, 0, " S45
    "],\n"
    "    \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},\n"
    "   {\"name\": \"matrixnode\", \"matrix\": [1,0,0,0, 0,0,-1,0, 0,1,0,0, 5,0,0,1],\n"
    "    \"children\": [3], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}},\n"
    "   {\"name\": \"bulb\", \"translation\": [0, 1, 0],\n"
    "    \"extensions\": {\"KHR_lights_punctual\": {\"light\": 2}}},\n"
    "   {\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},\n"
    "   {\"name\": \"elsewhere\", \"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}}]}\n";

static void check_nested(const lx_scene *s)
{
    assert_int_equal(s->light_count, 4);
    const lx_light *spot = &s->lights[0];
    assert_string_equal(spot->name, "Spot");
    assert_int_equal(spot->type, LX_LIGHT_SPOT);
    lx_test_assert_vec3(spot->position, 3, 2, 3);
    lx_test_assert_vec3(spot->direction, 0, 1, 0);
    lx_test_assert_vec3(spot->color, 1, 0.5, 0.5);
    assert_true(spot->intensity == 10.0f && spot->range == 20.0f);
    assert_true(spot->inner_angle == 0.3f && spot->outer_angle == 0.6f);
    assert_int_equal(spot->shadow, LX_SHADOW_HARD);

    const lx_light *sun = &s->lights[1];
    assert_string_equal(sun->name, "Sun");
    assert_int_equal(sun->type, LX_LIGHT_DIRECTIONAL);
    lx_test_assert_vec3(sun->direction, 0, -1, 0);
    assert_true(sun->intensity == 3.0f);

    const lx_light *bulb = &s->lights[2];
    assert_string_equal(bulb->name, "bulb");
    assert_int_equal(bulb->type, LX_LIGHT_POINT);
    lx_test_assert_vec3(bulb->position, 5, 0, -1);
    lx_test_assert_vec3(bulb->color, 1, 1, 1); /* spec defaults */
    assert_true(bulb->intensity == 1.0f && bulb->range == 0.0f);

    assert_string_equal(s->lights[3].name, "Spot_2");
    lx_test_assert_vec3(s->lights[3].position, 0, 0, 0);
    lx_test_assert_vec3(s->lights[3].direction, 0, 0, -1);
}

static void test_nested_nodes(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(load_text(s, nested), LX_OK);
    check_nested(s);
    lx_scene_destroy(s);

    char path[512];
    tmp_path(path, sizeof path, "nested.gltf");
    write_file(path, nested, strlen(nested));
    s = lx_test_new_scene("test");
    assert_int_equal(lx_gltf_lights_load(s, path), LX_OK);
    check_nested(s);
    lx_scene_destroy(s);
    remove(path);
}

/* A GLB: header, JSON chunk padded with spaces, and a small BIN chunk. */
static uint8_t *make_glb(const char *json, size_t *size)
{
    size_t jlen = strlen(json), jpad = (jlen + 3) & ~(size_t)3;
    size_t total = 12 + 8 + jpad + 8 + 4;
    uint8_t *b = calloc(1, total);
    uint32_t words[5] = {0x46546C67u, 2, (uint32_t)total, (uint32_t)jpad, 0x4E4F534Au};
    for (int i = 0; i < 5; i++)
        for (int k = 0; k < 4; k++)
            b[i * 4 + k] = (uint8_t)(words[i] >> (8 * k));
    memcpy(b + 20, json, jlen);
    memset(b + 20 + jlen, ' ', jpad - jlen);
    uint32_t bin[2] = {4, 0x004E4942u};
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < 4; k++)
            b[20 + jpad + i * 4 + k] = (uint8_t)(bin[i] >> (8 * k));
    *size = total;
    return b;
}

static void put32(uint8_t *p, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        p[k] = (uint8_t)(v >> (8 * k));
}

static void test_glb(void **state)
{
    (void)state;
    size_t size;
    uint8_t *glb = make_glb(nested, &size);
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(lx_gltf_lights_load_memory(s, glb, size, "t.glb"), LX_OK);
    check_nested(s);
    lx_scene_destroy(s);

    char path[512];
    tmp_path(path, sizeof path, "nested.glb");
    write_file(path, glb, size);
    s = lx_test_new_scene("test");
    assert_int_equal(lx_gltf_lights_load(s, path), LX_OK);
    check_nested(s);

    /* Truncated files, from the file and from memory. */
    const size_t cuts[] = {4, 11, 12, 19, 40, size - 1};
    for (size_t i = 0; i < sizeof cuts / sizeof cuts[0]; i++) {
        write_file(path, glb, cuts[i]);
        assert_int_equal(lx_gltf_lights_load(s, path), LX_ERR_FORMAT);
        assert_non_null(strstr(lx_last_error(), "truncated"));
        assert_non_null(strstr(lx_last_error(), path));
        assert_int_equal(lx_gltf_lights_load_memory(s, glb, cuts[i], "t.glb"), LX_ERR_FORMAT);
        assert_non_null(strstr(lx_last_error(), "t.glb: truncated"));
    }
    remove(path);

    uint8_t *bad = malloc(size);
    /* Bad magic: not a GLB, and not JSON either. */
    memcpy(bad, glb, size);
    bad[3] = 'f';
    assert_int_equal(lx_gltf_lights_load_memory(s, bad, size, "t.glb"), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "nor GLB (no 'glTF' magic)"));
    /* Version 1. */
    memcpy(bad, glb, size);
    put32(bad + 4, 1);
    assert_int_equal(lx_gltf_lights_load_memory(s, bad, size, "t.glb"), LX_ERR_UNSUPPORTED);
    assert_non_null(strstr(lx_last_error(), "GLB version 1"));
    /* The JSON chunk claims more bytes than the file has. */
    memcpy(bad, glb, size);
    put32(bad + 12, (uint32_t)size);
    assert_int_equal(lx_gltf_lights_load_memory(s, bad, size, "t.glb"), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "runs past the end"));
    put32(bad + 12, 0xFFFFFFF0u);
    assert_int_equal(lx_gltf_lights_load_memory(s, bad, size, "t.glb"), LX_ERR_FORMAT);
    /* The header length claims more than the file. */
    memcpy(bad, glb, size);
    put32(bad + 8, (uint32_t)size + 100);
    assert_int_equal(lx_gltf_lights_load_memory(s, bad, size, "t.glb"), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "the header says"));
    /* First chunk is BIN, not JSON. */
    memcpy(bad, glb, size);
    put32(bad + 16, 0x004E4942u);
    assert_int_equal(lx_gltf_lights_load_memory(s, bad, size, "t.glb"), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "not JSON"));
    assert_int_equal(s->light_count, 4);
    free(bad);
    free(glb);
    lx_scene_destroy(s);
}

static void test_blender_cone_and_defaults(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(
        load_text(s, "{\"extensions\": {\"KHR_lights_punctual\": {\"lights\": ["
                     "{\"type\": \"spot\", \"name\": \"Blender\", \"intensity\": 50,"
                     " \"spot\": {\"innerConeAngle\": 0.5, \"outerConeAngle\": 0.5}},"
                     "{\"type\": \"spot\"},"
                     "{\"type\": \"spot\", \"spot\": {\"outerConeAngle\": 1.5707963705062866}}]}},"
                     "\"nodes\": [{\"translation\": [0, 3, 0], \"rotation\": [-" S45 ", 0, 0, " S45
                     "], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
                     "{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}},"
                     "{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 2}}}]}"),
        LX_OK);
    assert_int_equal(s->light_count, 3);
    const lx_light *l = &s->lights[0];
    assert_true(l->inner_angle == 0.5f && l->outer_angle == 0.5f);
    /* R_x(-90) turns -Z into -Y: the spot looks down from 3 m. */
    lx_test_assert_vec3(l->direction, 0, -1, 0);
    lx_light_eval ev;
    float x_in = 3.0f * tanf(0.49f), x_out = 3.0f * tanf(0.51f);
    assert_true(lx_light_evaluate(l, lx_v3(x_in, 0, 0), lx_v3(0, 1, 0), &ev));
    double c = cos(0.49);
    /* measured 6.9e-8 (under half a float ulp at 4.6); bound one ulp */
    assert_true(fabs(ev.illuminance.x - 50.0 * c * c * c / 9.0) < 4.8e-7);
    assert_false(lx_light_evaluate(l, lx_v3(x_out, 0, 0), lx_v3(0, 1, 0), &ev));
    /* No "spot" object: innerConeAngle 0, outerConeAngle pi/4; no names at all. */
    assert_string_equal(s->lights[1].name, "light1");
    assert_true(s->lights[1].inner_angle == 0.0f);
    /* floats: measured 2.2e-8 and 4.4e-8 off; bound one ulp at pi/2 */
    assert_true(fabs(s->lights[1].outer_angle - PI_D / 4) < 1.2e-7);
    /* pi/2 written in double is accepted. */
    assert_true(fabs(s->lights[2].outer_angle - PI_D / 2) < 1.2e-7);
    lx_scene_destroy(s);
}

static void test_no_extension(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(load_text(s, "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [{}]}"), LX_OK);
    assert_int_equal(load_text(s, "{\"extensions\": {\"OTHER\": {}}}"), LX_OK);
    assert_int_equal(s->light_count, 0);
    lx_scene_destroy(s);
}

static void test_scene_choice_and_names(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    /* "scene": 1 picks the second scene only; names collide into _2, _2_2. */
    assert_int_equal(load_text(s, "{\"extensions\": {\"KHR_lights_punctual\": {\"lights\": ["
                                  "{\"type\": \"point\", \"name\": \"L\"},"
                                  "{\"type\": \"point\", \"name\": \"L_2\"}]}},"
                                  "\"scene\": 1, \"scenes\": [{\"nodes\": [0]}, "
                                  "{\"nodes\": [1, 2, 3]}],"
                                  "\"nodes\": ["
                                  "{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}},"
                                  "{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
                                  "{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
                                  "{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 3);
    assert_string_equal(s->lights[0].name, "L");
    assert_string_equal(s->lights[1].name, "L_2");
    assert_string_equal(s->lights[2].name, "L_2_2");
    lx_scene_destroy(s);

    /* No scenes: every parentless node is a root. A 70-byte name is cut. */
    s = lx_test_new_scene("test");
    assert_int_equal(
        load_text(s,
                  "{\"extensions\": {\"KHR_lights_punctual\": {\"lights\": ["
                  "{\"type\": \"point\", \"name\": "
                  "\"0123456789012345678901234567890123456789012345678901234567890123456789\"}]}},"
                  "\"nodes\": [{\"children\": [1], \"translation\": [0, 1, 0]},"
                  "{\"translation\": [0, 1, 0], "
                  "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
                  "{\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}}]}"),
        LX_OK);
    assert_int_equal(s->light_count, 2);
    assert_int_equal(strlen(s->lights[0].name), LX_LIGHT_NAME_MAX - 1);
    lx_test_assert_vec3(s->lights[0].position, 0, 2, 0);
    assert_int_equal(strlen(s->lights[1].name), LX_LIGHT_NAME_MAX - 1);
    assert_non_null(strstr(s->lights[1].name, "_2"));
    assert_string_not_equal(s->lights[0].name, s->lights[1].name);
    lx_scene_destroy(s);
}

#define LIGHTS1 "{\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"point\"}]}},"
#define USE0 "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}"

static void test_bad_graphs(void **state)
{
    (void)state;
    expect_fail(LIGHTS1 "\"nodes\": [{\"children\": [1]}, {\"children\": [0], " USE0 "}]}",
                LX_ERR_FORMAT, "t.gltf: the node hierarchy has a cycle through node");
    expect_fail(LIGHTS1 "\"scenes\": [{\"nodes\": [0]}], \"nodes\": [{\"children\": [1]}, "
                        "{\"children\": [2]}, {\"children\": [1], " USE0 "}]}",
                LX_ERR_FORMAT, "is a child of both node");
    expect_fail(LIGHTS1 "\"nodes\": [{\"name\": \"me\", \"children\": [0]}]}", LX_ERR_FORMAT,
                "node 0 ('me') is its own child");
    expect_fail(LIGHTS1 "\"nodes\": [{\"name\": \"a\", \"children\": [7]}]}", LX_ERR_FORMAT,
                "t.gltf: node 0 ('a'): child 7 is not a node index (1 nodes)");
    expect_fail(LIGHTS1 "\"nodes\": [{\"children\": [0.5]}]}", LX_ERR_FORMAT,
                "child 0.5 is not a node index");
    expect_fail(LIGHTS1 "\"nodes\": [{\"name\": \"n\", \"extensions\": {\"KHR_lights_punctual\": "
                        "{\"light\": 3}}}]}",
                LX_ERR_FORMAT, "node 0 ('n'): light 3 is out of range (1 lights)");
    expect_fail(LIGHTS1 "\"nodes\": [{\"translation\": [1e999, 0, 0], " USE0 "}]}", LX_ERR_FORMAT,
                "node 0: translation must be 3 finite numbers");
    expect_fail(LIGHTS1 "\"nodes\": [{\"rotation\": [0, 0, 0, 0], " USE0 "}]}", LX_ERR_FORMAT,
                "rotation quaternion has zero length");
    expect_fail(LIGHTS1 "\"nodes\": [{\"matrix\": [1, 0, 0], " USE0 "}]}", LX_ERR_FORMAT,
                "matrix must be 16 finite numbers");
    expect_fail(LIGHTS1 "\"nodes\": [{\"scale\": [1e30, 1, 1], \"children\": [1]}, "
                        "{\"scale\": [1e30, 1, 1], " USE0 "}]}",
                LX_ERR_FORMAT, "node 1: world transform is not finite");
    expect_fail(LIGHTS1 "\"scene\": 2, \"scenes\": [{\"nodes\": [0]}], \"nodes\": [{" USE0 "}]}",
                LX_ERR_FORMAT, "'scene' is not a scene index");
    expect_fail(LIGHTS1 "\"scenes\": [{\"nodes\": [4]}], \"nodes\": [{" USE0 "}]}", LX_ERR_FORMAT,
                "scene 0: node 4 is not a node index");
    expect_fail(LIGHTS1 "\"nodes\": 5}", LX_ERR_FORMAT, "'nodes' must be an array");
    expect_fail(LIGHTS1 "\"nodes\": [3]}", LX_ERR_FORMAT, "node 0 is not an object");
}

static void test_bad_lights(void **state)
{
    (void)state;
#define ONE(light)                                                                                 \
    "{\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [" light "]}},"                       \
    "\"nodes\": [{" USE0 "}]}"
    expect_fail(ONE("{\"type\": \"area\", \"name\": \"A\"}"), LX_ERR_FORMAT,
                "t.gltf: KHR_lights_punctual light 0 ('A'): unknown type 'area'");
    expect_fail(ONE("{\"intensity\": 1}"), LX_ERR_FORMAT, "light 0: missing 'type'");
    expect_fail(ONE("{\"type\": \"point\", \"intensity\": -2}"), LX_ERR_INVALID,
                "intensity -2 is negative");
    expect_fail(ONE("{\"type\": \"point\", \"intensity\": 1e999}"), LX_ERR_FORMAT,
                "intensity must be a finite number");
    expect_fail(ONE("{\"type\": \"point\", \"range\": 0}"), LX_ERR_INVALID,
                "range 0 must be above 0");
    expect_fail(ONE("{\"type\": \"point\", \"color\": [1, 1]}"), LX_ERR_FORMAT,
                "color must be 3 finite numbers");
    expect_fail(ONE("{\"type\": \"spot\", \"spot\": {\"innerConeAngle\": 0.7, "
                    "\"outerConeAngle\": 0.5}}"),
                LX_ERR_INVALID, "spot.innerConeAngle 0.7 is above spot.outerConeAngle 0.5");
    expect_fail(ONE("{\"type\": \"spot\", \"spot\": {\"outerConeAngle\": 2}}"), LX_ERR_INVALID,
                "spot.outerConeAngle 2 is outside (0, pi/2]");
    expect_fail(ONE("{\"type\": \"spot\", \"spot\": {\"outerConeAngle\": 0}}"), LX_ERR_INVALID,
                "outside (0, pi/2]");
    expect_fail(ONE("{\"type\": \"spot\", \"spot\": {\"innerConeAngle\": -0.1}}"), LX_ERR_INVALID,
                "spot.innerConeAngle -0.1 is negative");
    expect_fail(ONE("7"), LX_ERR_FORMAT, "KHR_lights_punctual light 0 is not an object");
    expect_fail("{\"extensions\": {\"KHR_lights_punctual\": {\"lights\": {}}}}", LX_ERR_FORMAT,
                "'lights' must be an array");
    /* A spot whose node squashes its -Z axis away has no direction. */
    expect_fail("{\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [{\"type\": \"spot\"}]}},"
                "\"nodes\": [{\"scale\": [1, 1, 0], " USE0 "}]}",
                LX_ERR_FORMAT, "node 0: its transform has no -Z axis");
    expect_fail("[]", LX_ERR_FORMAT, "t.gltf: the top level of the glTF JSON is not an object");
    expect_fail("{\"nodes\": [}", LX_ERR_FORMAT, "t.gltf: line 1, column");
#undef ONE
}

static void test_io_errors(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(lx_gltf_lights_load(s, "/nonexistent/dir/x.gltf"), LX_ERR_IO);
    assert_non_null(strstr(lx_last_error(), "/nonexistent/dir/x.gltf"));
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nested_nodes),
        cmocka_unit_test(test_glb),
        cmocka_unit_test(test_blender_cone_and_defaults),
        cmocka_unit_test(test_no_extension),
        cmocka_unit_test(test_scene_choice_and_names),
        cmocka_unit_test(test_bad_graphs),
        cmocka_unit_test(test_bad_lights),
        cmocka_unit_test(test_io_errors),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
