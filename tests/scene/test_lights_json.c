/* Tests of the lights JSON reader (src/scene/lights_json.c, the schema of
 * docs/lights-json.md): the documented example with its unit and angle
 * conversions worked out here, area lights with their luminance computed
 * here from the photometric formulas, overrides by name, and every
 * malformed input failing with a message that names the file, light and
 * field. */
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
/* Angles and intensities are floats worked out from the file's numbers:
 * the errors measured are 0 to 6.8e-8 relative (a float's half ulp is
 * 6e-8); the bound sits a small factor above. */
#define FLOAT_TOL 2e-7

static lx_status apply(lx_scene *s, const char *text)
{
    return lx_lights_json_apply_text(s, text, strlen(text), "lights.json");
}

static const char *example =
    "{\"ambient\": [0.02, 0.02, 0.02],\n"
    " \"lights\": [\n"
    "   {\"name\": \"key\", \"type\": \"point\", \"position\": [0, 2, 0], \"color\": [1, 1, 1],\n"
    "    \"intensity\": 800, \"unit\": \"cd\", \"range\": 10, \"shadow\": \"hard\", "
    "\"dynamic\": false},\n"
    "   {\"type\": \"spot\", \"position\": [0, 3, 0], \"direction\": [0, -1, 0], "
    "\"inner_angle\": 20, \"outer_angle\": 30,\n"
    "    \"intensity\": 1200, \"unit\": \"cd\", \"shadow\": \"blur\", \"blur_power\": 1.0, "
    "\"blur_multiplier\": 1.0},\n"
    "   {\"type\": \"directional\", \"direction\": [0.3, -1, 0.2], \"intensity\": 100000, "
    "\"unit\": \"lx\", \"shadow\": \"hard\"},\n"
    "   {\"type\": \"point\", \"position\": [2, 1, 0], \"intensity\": 1, \"range\": 5, "
    "\"model\": \"classic\", \"ambient\": [0.1, 0, 0]}]}\n";

static void test_example(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(apply(s, example), LX_OK);
    assert_int_equal(s->light_count, 4);
    lx_test_assert_vec3(s->ambient, 0.02, 0.02, 0.02);

    const lx_light *k = &s->lights[0];
    assert_string_equal(k->name, "key");
    assert_int_equal(k->type, LX_LIGHT_POINT);
    lx_test_assert_vec3(k->position, 0, 2, 0);
    lx_test_assert_vec3(k->color, 1, 1, 1);
    assert_true(k->intensity == 800.0f && k->range == 10.0f);
    assert_int_equal(k->shadow, LX_SHADOW_HARD);
    assert_int_equal(k->model, LX_MODEL_PHYSICAL);
    assert_false(k->dynamic);

    const lx_light *sp = &s->lights[1];
    assert_string_equal(sp->name, "");
    assert_int_equal(sp->type, LX_LIGHT_SPOT);
    lx_test_assert_vec3(sp->direction, 0, -1, 0);
    lx_test_assert_rel(sp->inner_angle, 20.0 * PI_D / 180.0, FLOAT_TOL);
    lx_test_assert_rel(sp->outer_angle, 30.0 * PI_D / 180.0, FLOAT_TOL);
    assert_true(sp->intensity == 1200.0f);
    assert_int_equal(sp->shadow, LX_SHADOW_BLUR);
    assert_true(sp->blur_power == 1.0f && sp->blur_multiplier == 1.0f);

    const lx_light *d = &s->lights[2];
    double len = sqrt(0.09 + 1.0 + 0.04);
    assert_int_equal(d->type, LX_LIGHT_DIRECTIONAL);
    lx_test_assert_vec3(d->direction, 0.3 / len, -1.0 / len, 0.2 / len);
    assert_true(d->intensity == 100000.0f);

    const lx_light *c = &s->lights[3];
    assert_int_equal(c->model, LX_MODEL_CLASSIC);
    lx_test_assert_vec3(c->ambient, 0.1, 0, 0);
    assert_true(c->range == 5.0f && c->intensity == 1.0f);
    assert_int_equal(c->shadow, LX_SHADOW_HARD); /* default */
    lx_scene_destroy(s);
}

static void test_units(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(apply(s,
                           "{\"lights\": ["
                           "{\"name\": \"a\", \"type\": \"point\", \"position\": [0,0,0], "
                           "\"intensity\": 1000, \"unit\": \"lm\"},"
                           "{\"name\": \"b\", \"type\": \"point\", \"position\": [0,0,0], "
                           "\"intensity\": 10, \"unit\": \"W\"},"
                           "{\"name\": \"c\", \"type\": \"spot\", \"position\": [0,0,0], "
                           "\"direction\": [0,0,-1], \"outer_angle\": 30, \"intensity\": 1000, "
                           "\"unit\": \"lumen\"},"
                           "{\"name\": \"d\", \"type\": \"spot\", \"position\": [0,0,0], "
                           "\"direction\": [0,0,-1], \"outer_angle\": 30, \"intensity\": 1000, "
                           "\"unit\": \"lm\", \"spot_conversion\": \"cone\"},"
                           "{\"name\": \"e\", \"type\": \"directional\", \"direction\": [0,-2,0], "
                           "\"intensity\": 5}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 5);
    lx_test_assert_rel(s->lights[0].intensity, 1000.0 / (4 * PI_D), FLOAT_TOL);
    lx_test_assert_rel(s->lights[1].intensity, 6830.0 / (4 * PI_D), FLOAT_TOL);
    lx_test_assert_rel(s->lights[2].intensity, 1000.0 / PI_D, FLOAT_TOL);
    lx_test_assert_rel(s->lights[3].intensity, 1000.0 / (2 * PI_D * (1 - cos(PI_D / 6))),
                       FLOAT_TOL);
    assert_true(s->lights[4].intensity == 5.0f);
    lx_test_assert_vec3(s->lights[4].direction, 0, -1, 0);
    /* Defaults of a new light. */
    lx_test_assert_vec3(s->lights[0].color, 1, 1, 1);
    assert_true(s->lights[0].range == 0.0f);
    lx_test_assert_rel(s->lights[0].outer_angle, PI_D / 4, FLOAT_TOL);
    lx_scene_destroy(s);
}

static void test_override(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    lx_light lamp = lx_light_defaults(LX_LIGHT_SPOT);
    strcpy(lamp.name, "lamp");
    lamp.position = lx_v3(1, 2, 3);
    lamp.direction = lx_v3(0, 0, -1);
    lamp.intensity = 50.0f;
    lamp.range = 7.0f;
    lamp.inner_angle = 0.2f;
    lamp.outer_angle = 0.5f;
    assert_int_equal(lx_scene_add_light(s, &lamp), LX_OK);
    s->ambient = lx_v3(0.5f, 0.5f, 0.5f);

    /* Only the given keys change; type, position, direction stay. */
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"lamp\", \"intensity\": 100, "
                              "\"shadow\": \"none\", \"dynamic\": true}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 1);
    const lx_light *l = &s->lights[0];
    assert_int_equal(l->type, LX_LIGHT_SPOT);
    lx_test_assert_vec3(l->position, 1, 2, 3);
    lx_test_assert_vec3(l->direction, 0, 0, -1);
    assert_true(l->intensity == 100.0f && l->range == 7.0f);
    assert_true(l->inner_angle == 0.2f && l->outer_angle == 0.5f);
    assert_int_equal(l->shadow, LX_SHADOW_NONE);
    assert_true(l->dynamic);
    lx_test_assert_vec3(s->ambient, 0.5, 0.5, 0.5); /* no "ambient": unchanged */

    /* A later entry of the same file overrides an earlier one the same way. */
    assert_int_equal(apply(s, "{\"lights\": ["
                              "{\"name\": \"new\", \"type\": \"point\", \"position\": [4,5,6], "
                              "\"intensity\": 3},"
                              "{\"name\": \"new\", \"color\": [1, 0, 0]}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 2);
    assert_string_equal(s->lights[1].name, "new");
    lx_test_assert_vec3(s->lights[1].position, 4, 5, 6);
    lx_test_assert_vec3(s->lights[1].color, 1, 0, 0);
    assert_true(s->lights[1].intensity == 3.0f);

    /* Lumens over an overridden spot use its (possibly new) cone. */
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"lamp\", \"outer_angle\": 60, "
                              "\"intensity\": 100, \"unit\": \"lm\", "
                              "\"spot_conversion\": \"cone\"}]}"),
                     LX_OK);
    lx_test_assert_rel(s->lights[0].intensity, 100.0 / (2 * PI_D * 0.5), FLOAT_TOL);
    lx_scene_destroy(s);
}

typedef struct bad_case {
    const char *json;
    lx_status status;
    const char *message;
} bad_case;

static const bad_case bad_cases[] = {
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0]}, {\"type\": \"point\", "
     "\"position\": [0,0,0]}, {\"type\": \"point\", \"position\": [0,0,0], \"intesity\": 5}]}",
     LX_ERR_FORMAT, "lights.json: lights[2]: unknown key 'intesity'"},
    {"{\"light\": []}", LX_ERR_FORMAT, "lights.json: unknown key 'light'"},
    {"{\"lights\": [{\"type\": \"area\", \"position\": [0,0,0]}]}", LX_ERR_FORMAT,
     "lights[0]: unknown type 'area' (expected point, spot, directional, sphere, disk, rect, "
     "tube)"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": 1e999}]}",
     LX_ERR_FORMAT, "lights[0]: intensity is not a finite number"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,-1e999,0]}]}", LX_ERR_FORMAT,
     "position[1] is not a finite number"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"range\": 1e39}]}", LX_ERR_FORMAT,
     "range is not a finite number"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": NaN}]}",
     LX_ERR_FORMAT, "lights.json: line 1, column"},
    {"{\"lights\": [{\"name\": \"key\", \"type\": \"point\", \"position\": [0,0,0], "
     "\"intensity\": -5}]}",
     LX_ERR_INVALID, "lights.json: lights[0] ('key'): intensity -5 is negative"},
    {"{\"lights\": [{\"name\": \"key\", \"type\": \"spot\", \"position\": [0,0,0], "
     "\"direction\": [0,-1,0], \"inner_angle\": 40, \"outer_angle\": 30}]}",
     LX_ERR_INVALID, "lights[0] ('key'): inner_angle 40 deg is above outer_angle 30 deg"},
    {"{\"lights\": [{\"type\": \"spot\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"outer_angle\": 120}]}",
     LX_ERR_INVALID, "outer_angle 120 deg is above 90 deg"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,1]}]}", LX_ERR_FORMAT,
     "lights[0]: position must be an array of 3 numbers, not 2"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,\"1\",2]}]}", LX_ERR_FORMAT,
     "position[1] must be a number"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": {\"x\": 1}}]}", LX_ERR_FORMAT,
     "position must be an array of 3 numbers"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"color\": [1,1,1,1]}]}",
     LX_ERR_FORMAT, "color must be an array of 3 numbers, not 4"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"color\": [1,-1,1]}]}",
     LX_ERR_INVALID, "color [1, -1, 1] has a negative component"},
    {"{\n  \"lights\": [\n    {\"type\": \"point\",, \"position\": [0,0,0]}\n  ]\n}", LX_ERR_FORMAT,
     "lights.json: line 3, column 23: malformed JSON"},
    {"{\"lights\": [", LX_ERR_FORMAT, "unexpected end"},
    {"", LX_ERR_FORMAT, "lights.json: line 1, column 1"},
    {"{\"lights\": []} trailing", LX_ERR_FORMAT, "line 1, column 16"},
    {"[1, 2, 3]", LX_ERR_FORMAT, "lights.json: the top level must be an object"},
    {"\"lights\"", LX_ERR_FORMAT, "top level must be an object"},
    {"{\"lights\": {}}", LX_ERR_FORMAT, "lights must be an array"},
    {"{\"lights\": [42]}", LX_ERR_FORMAT, "lights[0]: must be an object"},
    {"{\"ambient\": [0, 0]}", LX_ERR_FORMAT, "ambient must be an array of 3 numbers, not 2"},
    {"{\"ambient\": [0, -0.1, 0]}", LX_ERR_INVALID, "ambient [0, -0.1, 0]"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": 1, "
     "\"unit\": \"kW\"}]}",
     LX_ERR_FORMAT, "unknown unit 'kW' (expected cd, lm, W, lx or nt)"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"shadow\": \"sharp\"}]}",
     LX_ERR_FORMAT, "unknown shadow 'sharp' (expected hard, none, blur, soft)"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"model\": \"fancy\"}]}",
     LX_ERR_FORMAT, "unknown model 'fancy'"},
    {"{\"lights\": [{\"type\": \"spot\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"intensity\": 1, \"unit\": \"lm\", \"spot_conversion\": \"sphere\"}]}",
     LX_ERR_FORMAT, "unknown spot_conversion 'sphere'"},
    {"{\"lights\": [{\"type\": 3, \"position\": [0,0,0]}]}", LX_ERR_FORMAT,
     "type must be a string"},
    {"{\"lights\": [{\"type\": \"directional\", \"direction\": [0,0,0]}]}", LX_ERR_INVALID,
     "lights[0]: direction [0, 0, 0] has zero length"},
    {"{\"lights\": [{\"name\": \"sun\", \"type\": \"directional\", \"direction\": [0,-1,0], "
     "\"intensity\": 5, \"unit\": \"W\"}]}",
     LX_ERR_INVALID, "lights[0] ('sun'): unit: directional lights take lux, not W"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": 5, "
     "\"unit\": \"lux\"}]}",
     LX_ERR_INVALID, "point lights take cd, lm or W, not lx"},
    {"{\"lights\": [{\"position\": [0,0,0]}]}", LX_ERR_FORMAT, "lights[0]: missing 'type'"},
    {"{\"lights\": [{\"type\": \"point\"}]}", LX_ERR_FORMAT, "missing 'position'"},
    {"{\"lights\": [{\"type\": \"spot\", \"position\": [0,0,0]}]}", LX_ERR_FORMAT,
     "missing 'direction'"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"model\": \"classic\"}]}",
     LX_ERR_INVALID, "classic model needs a range above 0"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"range\": -1}]}", LX_ERR_INVALID,
     "range -1 is negative"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"blur_power\": -1}]}",
     LX_ERR_INVALID, "blur_power -1 is negative"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"type\": \"spot\"}]}",
     LX_ERR_FORMAT, "key 'type' appears twice"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"dynamic\": \"yes\"}]}",
     LX_ERR_FORMAT, "dynamic must be true or false"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"unit\": \"lm\"}]}",
     LX_ERR_FORMAT, "'unit' is given without 'intensity'"},
    {"{\"lights\": [{\"name\": 5, \"type\": \"point\", \"position\": [0,0,0]}]}", LX_ERR_FORMAT,
     "name must be a string"},
    {"{\"lights\": [{\"name\": \"0123456789012345678901234567890123456789012345678901234567890"
     "123456789\", \"type\": \"point\", \"position\": [0,0,0]}]}",
     LX_ERR_INVALID, "is longer than 63 bytes"},
    /* area lights */
    {"{\"lights\": [{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
     "\"length\": -1.2}]}",
     LX_ERR_INVALID, "lights.json: lights[0]: length -1.2 is negative"},
    {"{\"lights\": [{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
     "\"length\": 0, \"radius\": 0}]}",
     LX_ERR_INVALID, "lights[0]: a tube with radius 0 (a linear light) needs a length above 0"},
    {"{\"lights\": [{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
     "\"radius\": 0, \"intensity\": 5, \"unit\": \"nt\"}]}",
     LX_ERR_INVALID, "lights[0]: a linear tube (radius 0) has no area for nt"},
    {"{\"lights\": [{\"type\": \"tube\", \"position\": [0, 2, 0]}]}", LX_ERR_FORMAT,
     "lights[0]: missing 'direction' for a tube light"},
    {"{\"lights\": [{\"type\": \"disk\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
     "\"length\": 1}]}",
     LX_ERR_INVALID, "lights[0]: length is for tube lights, not a disk light"},
    {"{\"lights\": [{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
     "\"length\": \"long\"}]}",
     LX_ERR_FORMAT, "lights[0]: length must be a number"},
    {"{\"lights\": [{\"name\": \"ball\", \"type\": \"sphere\", \"position\": [0,0,0], "
     "\"radius\": -0.1}]}",
     LX_ERR_INVALID, "lights.json: lights[0] ('ball'): radius -0.1 is negative"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"radius\": -1}]}", LX_ERR_INVALID,
     "lights[0]: radius -1 is negative"},
    {"{\"lights\": [{\"type\": \"disk\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"radius\": 0}]}",
     LX_ERR_INVALID, "lights[0]: radius 0 must be above 0 for a disk light"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"radius\": 1e999}]}",
     LX_ERR_FORMAT, "lights[0]: radius is not a finite number"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"radius\": \"big\"}]}",
     LX_ERR_FORMAT, "lights[0]: radius must be a number"},
    {"{\"lights\": [{\"type\": \"rect\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"width\": 0, \"height\": 1}]}",
     LX_ERR_INVALID, "lights[0]: width 0 must be above 0"},
    {"{\"lights\": [{\"type\": \"rect\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"width\": 1, \"height\": -0.5}]}",
     LX_ERR_INVALID, "lights[0]: height -0.5 must be above 0"},
    {"{\"lights\": [{\"name\": \"panel\", \"type\": \"rect\", \"position\": [0,0,0], "
     "\"direction\": [0,-1,0], \"up\": [0,2,0]}]}",
     LX_ERR_INVALID, "lights[0] ('panel'): up [0, 2, 0] is parallel to direction [0, -1, 0]"},
    {"{\"lights\": [{\"type\": \"rect\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"up\": [0,0,0]}]}",
     LX_ERR_INVALID, "lights[0]: up [0, 0, 0] has zero length"},
    {"{\"lights\": [{\"type\": \"rect\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"up\": [0,1]}]}",
     LX_ERR_FORMAT, "lights[0]: up must be an array of 3 numbers, not 2"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"samples\": 0}]}",
     LX_ERR_INVALID, "lights[0]: samples 0 is outside 1..1024"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"samples\": 5000}]}",
     LX_ERR_INVALID, "lights[0]: samples 5000 is outside 1..1024"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"samples\": 2.5}]}",
     LX_ERR_FORMAT, "lights[0]: samples 2.5 is not a whole number"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"samples\": \"16\"}]}",
     LX_ERR_FORMAT, "lights[0]: samples must be a whole number"},
    {"{\"lights\": [{\"name\": \"bulb\", \"type\": \"point\", \"position\": [0,0,0], "
     "\"shadow\": \"soft\"}]}",
     LX_ERR_INVALID, "lights[0] ('bulb'): shadow 'soft' needs an area light"},
    {"{\"lights\": [{\"type\": \"spot\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"shadow\": \"soft\"}]}",
     LX_ERR_INVALID, "not a spot light"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"radius\": 0, "
     "\"shadow\": \"soft\"}]}",
     LX_ERR_INVALID, "shadow 'soft' needs an area light"},
    {"{\"lights\": [{\"type\": \"spot\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"radius\": 0.1}]}",
     LX_ERR_INVALID,
     "lights[0]: radius is for sphere, disk, tube and point lights, not a spot light"},
    {"{\"lights\": [{\"type\": \"rect\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"radius\": 0.1}]}",
     LX_ERR_INVALID, "radius is for sphere, disk, tube and point lights, not a rect light"},
    {"{\"lights\": [{\"type\": \"disk\", \"position\": [0,0,0], \"direction\": [0,-1,0], "
     "\"width\": 1}]}",
     LX_ERR_INVALID, "lights[0]: width is for rect lights, not a disk light"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"up\": [0,1,0]}]}",
     LX_ERR_INVALID,
     "lights[0]: up is for rect lights and lights with an ies profile, not a sphere light"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"samples\": 8}]}", LX_ERR_INVALID,
     "samples is for area lights (sphere, disk, rect, tube), not a point light"},
    {"{\"lights\": [{\"type\": \"disk\", \"position\": [0,0,0], \"radius\": 0.1}]}", LX_ERR_FORMAT,
     "lights[0]: missing 'direction' for a disk light"},
    {"{\"lights\": [{\"type\": \"rect\", \"direction\": [0,-1,0]}]}", LX_ERR_FORMAT,
     "lights[0]: missing 'position' for a rect light"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"intensity\": 5, "
     "\"unit\": \"lx\"}]}",
     LX_ERR_INVALID, "lights[0]: unit: sphere lights take nt, cd, lm or W, not lx"},
    {"{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": 5, "
     "\"unit\": \"nt\"}]}",
     LX_ERR_INVALID, "lights[0]: unit: point lights take cd, lm or W, not nt"},
    {"{\"lights\": [{\"type\": \"directional\", \"direction\": [0,-1,0], \"intensity\": 5, "
     "\"unit\": \"nits\"}]}",
     LX_ERR_INVALID, "lights[0]: unit: directional lights take lux, not nt"},
    {"{\"lights\": [{\"type\": \"sphere\", \"position\": [0,0,0], \"intensity\": -5}]}",
     LX_ERR_INVALID, "lights[0]: intensity -5 is negative"},
    /* the sky */
    {"{\"sky\": {\"intensity\": 2}}", LX_ERR_FORMAT, "sky: missing 'environment'"},
    {"{\"sky\": \"sky.hdr\"}", LX_ERR_FORMAT, "sky: must be an object"},
    {"{\"sky\": {\"environment\": \"\"}}", LX_ERR_FORMAT, "sky: environment is an empty path"},
    {"{\"sky\": {\"environment\": \"s.hdr\", \"samples\": 0}}", LX_ERR_INVALID,
     "sky: samples 0 is outside 1..65536"},
    {"{\"sky\": {\"environment\": \"s.hdr\", \"samples\": 2.5}}", LX_ERR_FORMAT,
     "sky: samples must be a whole number"},
    {"{\"sky\": {\"environment\": \"s.hdr\", \"shadows\": \"yes\"}}", LX_ERR_FORMAT,
     "sky: shadows must be true or false"},
    {"{\"sky\": {\"environment\": \"s.hdr\", \"intensity\": -1}}", LX_ERR_INVALID,
     "sky: intensity -1 is negative"},
    {"{\"sky\": {\"environment\": \"s.hdr\", \"intensity\": 0}}", LX_ERR_INVALID,
     "sky: intensity must be above 0"},
    /* a valid sky in a file that fails later (fuzzing: the sky's path leaked) */
    {"{\"sky\": {\"environment\": \"cn\", \"samples\": 7}, \"lights\": {\"lights\": []}}",
     LX_ERR_FORMAT, "lights must be an array of objects"},
    {"{\"sky\": {\"environment\": \"s.hdr\", \"exposure\": 1}}", LX_ERR_FORMAT,
     "sky: unknown key 'exposure'"},
};

/* "sky" names an environment relative to the JSON file; intensity,
 * shadows and samples are kept for the baker; a bad file leaves the
 * scene's sky as it was. */
static void test_sky(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    const char *text = "{\"sky\": {\"environment\": \"env/sky.hdr\", \"intensity\": 0.5, "
                       "\"shadows\": true, \"samples\": 128}}";
    assert_int_equal(lx_lights_json_apply_text(s, text, strlen(text), "scenes/night.json"), LX_OK);
    assert_string_equal(s->sky.environment, "scenes/env/sky.hdr");
    assert_true(s->sky.intensity == 0.5f && s->sky.shadows && s->sky.samples == 128);
    text = "{\"sky\": {\"environment\": \"/abs/day.exr\"}}";
    assert_int_equal(lx_lights_json_apply_text(s, text, strlen(text), "x.json"), LX_OK);
    assert_string_equal(s->sky.environment, "/abs/day.exr");
    assert_true(s->sky.intensity == 1.0f && !s->sky.shadows && s->sky.samples == 0);
    text = "{\"sky\": {\"environment\": \"other.hdr\"}, \"lights\": [{\"type\": \"nope\"}]}";
    assert_int_not_equal(lx_lights_json_apply_text(s, text, strlen(text), "x.json"), LX_OK);
    assert_string_equal(s->sky.environment, "/abs/day.exr");
    lx_scene_destroy(s);
}

static void test_bad_input(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; i++) {
        lx_scene *s = lx_test_new_scene("test");
        lx_status st = apply(s, bad_cases[i].json);
        if (st != bad_cases[i].status || !strstr(lx_last_error(), bad_cases[i].message))
            fail_msg("case %zu: %s '%s', want %s with '%s'", i, lx_status_name(st), lx_last_error(),
                     lx_status_name(bad_cases[i].status), bad_cases[i].message);
        assert_int_equal(s->light_count, 0);
        lx_scene_destroy(s);
    }
}

static void test_bad_bytes(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    const char with_nul[] = "{\"lights\": []}\0{}";
    assert_int_equal(lx_lights_json_apply_text(s, with_nul, sizeof with_nul - 1, "x.json"),
                     LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "x.json: byte 14 is a NUL byte"));
    /* Not NUL-terminated: only size bytes are read. */
    const char cut[] = "{\"lights\": []}XXXX";
    assert_int_equal(lx_lights_json_apply_text(s, cut, 14, "x.json"), LX_OK);
    /* A UTF-8 byte order mark is fine. */
    const char bom[] = "\xEF\xBB\xBF{\"ambient\": [1, 2, 3]}";
    assert_int_equal(lx_lights_json_apply_text(s, bom, strlen(bom), "x.json"), LX_OK);
    lx_test_assert_vec3(s->ambient, 1, 2, 3);
    /* More than 64 MiB is refused before parsing. */
    size_t big = ((size_t)64 << 20) + 1;
    char *text = malloc(big);
    assert_non_null(text);
    memset(text, ' ', big);
    assert_int_equal(lx_lights_json_apply_text(s, text, big, "big.json"), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), "64 MiB"));
    free(text);
    lx_scene_destroy(s);
}

/* An invalid file changes nothing, even when its first lights are good. */
static void test_all_or_nothing(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"a\", \"type\": \"point\", "
                              "\"position\": [0,0,0], \"intensity\": 2}]}"),
                     LX_OK);
    assert_int_equal(apply(s, "{\"ambient\": [9, 9, 9], \"lights\": ["
                              "{\"name\": \"a\", \"intensity\": 7},"
                              "{\"name\": \"b\", \"type\": \"point\", \"position\": [0,0,0]},"
                              "{\"name\": \"c\", \"type\": \"point\", \"position\": [0,0,0], "
                              "\"intensity\": -1}]}"),
                     LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "lights[2] ('c'): intensity -1 is negative"));
    assert_int_equal(s->light_count, 1);
    assert_true(s->lights[0].intensity == 2.0f);
    lx_test_assert_vec3(s->ambient, 0, 0, 0);
    lx_scene_destroy(s);
}

/* Colours given as sRGB or kelvin: sRGB through the IEC 61966-2-1 curve
 * (0.5 -> 0.214041), kelvin through lx_temperature_to_rgb (tested on its
 * own against the Planckian locus). */
static void test_colour_forms(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(apply(s,
                           "{\"lights\": ["
                           "{\"type\": \"point\", \"position\": [0,1,0], \"srgb\": [0.5, 1, 0]},"
                           "{\"type\": \"point\", \"position\": [0,1,0], \"temperature\": 2700}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 2);
    lx_test_assert_vec3(s->lights[0].color, 0.214041, 1.0, 0.0);
    lx_vec3 warm;
    assert_int_equal(lx_temperature_to_rgb(2700.0f, &warm), LX_OK);
    lx_test_assert_vec3(s->lights[1].color, warm.x, warm.y, warm.z);
    lx_scene_destroy(s);

    const char *bad[] = {
        "{\"lights\": [{\"type\": \"point\", \"position\": [0,1,0], \"srgb\": [1.5, 0, 0]}]}",
        "{\"lights\": [{\"type\": \"point\", \"position\": [0,1,0], \"temperature\": 300}]}",
        "{\"lights\": [{\"type\": \"point\", \"position\": [0,1,0], \"temperature\": 3000, "
        "\"color\": [1, 1, 1]}]}"};
    const char *say[] = {"srgb", "temperature", "not several"};
    for (int i = 0; i < 3; i++) {
        s = lx_test_new_scene("test");
        assert_int_not_equal(apply(s, bad[i]), LX_OK);
        assert_non_null(strstr(lx_last_error(), say[i]));
        assert_int_equal(s->light_count, 0);
        lx_scene_destroy(s);
    }
}

/* Area lights: luminance from lumens and watts by the photometric
 * formulas (sphere P / (4 pi^2 r^2), disk P / (pi^2 r^2), rect P / (pi W
 * H), 683 lm/W), from candela through the area facing the axis, nits as
 * is. */
static void test_area_lights(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(
        apply(s, "{\"lights\": ["
                 "{\"type\": \"sphere\", \"position\": [1, 1, 0], \"radius\": 0.1, "
                 "\"intensity\": 1000, \"unit\": \"lm\", \"shadow\": \"soft\", \"samples\": 64},"
                 "{\"type\": \"disk\", \"position\": [0, 3, 0], \"direction\": [0, -1, 0], "
                 "\"radius\": 0.3, \"intensity\": 2000, \"unit\": \"lm\"},"
                 "{\"type\": \"rect\", \"position\": [0, 2.5, 0], \"direction\": [0, -1, 0], "
                 "\"up\": [0, 0, 1], \"width\": 1.0, \"height\": 0.5, \"intensity\": 40, "
                 "\"unit\": \"W\"}]}"),
        LX_OK);
    assert_int_equal(s->light_count, 3);
    const lx_light *sp = &s->lights[0];
    assert_int_equal(sp->type, LX_LIGHT_SPHERE);
    lx_test_assert_vec3(sp->position, 1, 1, 0);
    assert_true(sp->radius == 0.1f);
    lx_test_assert_rel(sp->intensity, 1000.0 / (4.0 * PI_D * PI_D * 0.01), FLOAT_TOL);
    assert_int_equal(sp->shadow, LX_SHADOW_SOFT);
    assert_int_equal(sp->samples, 64);

    const lx_light *d = &s->lights[1];
    assert_int_equal(d->type, LX_LIGHT_DISK);
    lx_test_assert_vec3(d->position, 0, 3, 0);
    lx_test_assert_vec3(d->direction, 0, -1, 0);
    assert_true(d->radius == 0.3f);
    lx_test_assert_rel(d->intensity, 2000.0 / (PI_D * PI_D * 0.09), FLOAT_TOL);
    assert_int_equal(d->shadow, LX_SHADOW_HARD); /* the default: one ray to the centre */
    assert_int_equal(d->samples, 0);

    const lx_light *r = &s->lights[2];
    assert_int_equal(r->type, LX_LIGHT_RECT);
    lx_test_assert_vec3(r->position, 0, 2.5, 0);
    lx_test_assert_vec3(r->direction, 0, -1, 0);
    lx_test_assert_vec3(r->up, 0, 0, 1);
    assert_true(r->width == 1.0f && r->height == 0.5f);
    lx_test_assert_rel(r->intensity, 40.0 * 683.0 / (PI_D * 0.5), FLOAT_TOL);
    lx_scene_destroy(s);

    /* Nits by default and by name; candela over pi r^2 and W H; the rect's
     * default up (+Y, or +Z when it faces straight up or down) and a
     * given up normalized; a sphere needs no direction; sizes default to
     * 10 cm. */
    s = lx_test_new_scene("test");
    assert_int_equal(
        apply(s, "{\"lights\": ["
                 "{\"type\": \"sphere\", \"position\": [0, 1, 0], \"radius\": 0.2, "
                 "\"intensity\": 5000},"
                 "{\"type\": \"disk\", \"position\": [0, 1, 0], \"direction\": [0, -1, 0], "
                 "\"radius\": 0.5, \"intensity\": 5000, \"unit\": \"nits\"},"
                 "{\"type\": \"disk\", \"position\": [0, 1, 0], \"direction\": [1, 0, 0], "
                 "\"radius\": 0.5, \"intensity\": 100, \"unit\": \"cd\"},"
                 "{\"type\": \"rect\", \"position\": [0, 1, 0], \"direction\": [0, 0, -2], "
                 "\"width\": 2, \"height\": 0.5, \"intensity\": 10, \"unit\": \"cd\"},"
                 "{\"type\": \"rect\", \"position\": [0, 1, 0], \"direction\": [0, 2, 0]},"
                 "{\"type\": \"rect\", \"position\": [0, 1, 0], \"direction\": [1, 0, 0], "
                 "\"up\": [0, 0, 3], \"width\": 1, \"height\": 1, \"intensity\": 10, "
                 "\"unit\": \"lm\"},"
                 "{\"type\": \"sphere\", \"position\": [0, 1, 0], \"shadow\": \"soft\"}]}"),
        LX_OK);
    assert_int_equal(s->light_count, 7);
    assert_true(s->lights[0].intensity == 5000.0f);
    assert_true(s->lights[1].intensity == 5000.0f);
    lx_test_assert_rel(s->lights[2].intensity, 100.0 / (PI_D * 0.25), FLOAT_TOL);
    lx_test_assert_vec3(s->lights[3].direction, 0, 0, -1);
    lx_test_assert_vec3(s->lights[3].up, 0, 1, 0);
    lx_test_assert_rel(s->lights[3].intensity, 10.0 / (2.0 * 0.5), FLOAT_TOL);
    lx_test_assert_vec3(s->lights[4].up, 0, 0, 1);
    assert_true(s->lights[4].width == 0.1f && s->lights[4].height == 0.1f);
    assert_true(s->lights[4].intensity == 1.0f);
    lx_test_assert_vec3(s->lights[5].up, 0, 0, 1);
    lx_test_assert_rel(s->lights[5].intensity, 10.0 / PI_D, FLOAT_TOL);
    assert_int_equal(s->lights[6].type, LX_LIGHT_SPHERE);
    assert_true(s->lights[6].radius == 0.1f);
    assert_int_equal(s->lights[6].shadow, LX_SHADOW_SOFT);
    assert_int_equal(s->lights[6].samples, 0); /* 0: the library's default count */
    lx_scene_destroy(s);
}

/* Tubes: lumens through the capsule's area,
 * L = P / (pi (2 pi r len + 4 pi r^2)); candela across the axis through
 * 2 r len + pi r^2; a linear tube (radius 0) in candela per metre, P /
 * (pi^2 len) or I / len; the defaults (1 m, 2 cm) and soft shadows. */
static void test_tube_lights(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(
        apply(s, "{\"lights\": ["
                 "{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
                 "\"length\": 1.2, \"radius\": 0.02, \"intensity\": 3000, \"unit\": \"lm\"},"
                 "{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [0, 0, 2], "
                 "\"length\": 2, \"radius\": 0, \"intensity\": 3000, \"unit\": \"lm\", "
                 "\"shadow\": \"soft\", \"samples\": 32},"
                 "{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
                 "\"length\": 0.5, \"radius\": 0, \"intensity\": 100, \"unit\": \"cd\"},"
                 "{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
                 "\"intensity\": 100, \"unit\": \"cd\"},"
                 "{\"type\": \"tube\", \"position\": [0, 2, 0], \"direction\": [1, 0, 0], "
                 "\"intensity\": 2500}]}"),
        LX_OK);
    assert_int_equal(s->light_count, 5);
    const lx_light *t = &s->lights[0];
    assert_int_equal(t->type, LX_LIGHT_TUBE);
    lx_test_assert_vec3(t->direction, 1, 0, 0);
    assert_true(t->length == 1.2f && t->radius == 0.02f);
    lx_test_assert_rel(t->intensity,
                       3000.0 / (PI_D * (2.0 * PI_D * 0.02 * 1.2 + 4.0 * PI_D * 0.02 * 0.02)),
                       FLOAT_TOL);
    const lx_light *lin = &s->lights[1];
    lx_test_assert_vec3(lin->direction, 0, 0, 1);
    assert_true(lin->radius == 0.0f);
    lx_test_assert_rel(lin->intensity, 3000.0 / (PI_D * PI_D * 2.0), FLOAT_TOL);
    assert_int_equal(lin->shadow, LX_SHADOW_SOFT);
    assert_int_equal(lin->samples, 32);
    lx_test_assert_rel(s->lights[2].intensity, 100.0 / 0.5, FLOAT_TOL);
    /* defaults: 1 m long, 2 cm radius */
    assert_true(s->lights[3].length == 1.0f && s->lights[3].radius == 0.02f);
    lx_test_assert_rel(s->lights[3].intensity, 100.0 / (2.0 * 0.02 * 1.0 + PI_D * 0.02 * 0.02),
                       FLOAT_TOL);
    assert_true(s->lights[4].intensity == 2500.0f); /* nits by default */
    lx_scene_destroy(s);

    /* A point light turned into a tube by an override keeps its candela
     * across the axis; a tube turned linear keeps it too. */
    s = lx_test_new_scene("test");
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"a\", \"type\": \"point\", "
                              "\"position\": [0, 2, 0], \"intensity\": 300},"
                              "{\"name\": \"a\", \"type\": \"tube\", \"direction\": [1, 0, 0], "
                              "\"length\": 0.6, \"radius\": 0.05},"
                              "{\"name\": \"b\", \"type\": \"tube\", \"position\": [0, 2, 0], "
                              "\"direction\": [1, 0, 0], \"length\": 0.6, \"radius\": 0.05, "
                              "\"intensity\": 300, \"unit\": \"cd\"},"
                              "{\"name\": \"b\", \"radius\": 0}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 2);
    double across = 2.0 * 0.05 * 0.6 + PI_D * 0.05 * 0.05;
    assert_int_equal(s->lights[0].type, LX_LIGHT_TUBE);
    lx_test_assert_rel(s->lights[0].intensity * across, 300.0, FLOAT_TOL);
    lx_test_assert_rel(s->lights[1].intensity * 0.6, 300.0, FLOAT_TOL);
    lx_scene_destroy(s);
}

/* A point light is a sphere of radius 0 (as in Filament): given a radius above 0
 * it becomes a sphere whose intensity keeps the point light's units (cd
 * by default: luminance I / (pi r^2); lumens: P / (4 pi^2 r^2)); a radius
 * of 0 leaves it a point light. */
static void test_point_with_radius(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(apply(s, "{\"lights\": ["
                              "{\"type\": \"point\", \"position\": [0, 2, 0], \"radius\": 0.05, "
                              "\"intensity\": 800, \"shadow\": \"soft\", \"samples\": 8},"
                              "{\"type\": \"point\", \"position\": [0, 2, 0], \"radius\": 0.1, "
                              "\"intensity\": 1000, \"unit\": \"lm\"},"
                              "{\"type\": \"point\", \"position\": [0, 2, 0], \"radius\": 0, "
                              "\"intensity\": 800},"
                              "{\"type\": \"point\", \"position\": [0, 2, 0], \"radius\": 0.5}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 4);
    assert_int_equal(s->lights[0].type, LX_LIGHT_SPHERE);
    lx_test_assert_vec3(s->lights[0].position, 0, 2, 0);
    assert_true(s->lights[0].radius == 0.05f);
    lx_test_assert_rel(s->lights[0].intensity, 800.0 / (PI_D * 0.0025), FLOAT_TOL);
    assert_int_equal(s->lights[0].shadow, LX_SHADOW_SOFT);
    assert_int_equal(s->lights[0].samples, 8);
    assert_int_equal(s->lights[1].type, LX_LIGHT_SPHERE);
    lx_test_assert_rel(s->lights[1].intensity, 1000.0 / (4.0 * PI_D * PI_D * 0.01), FLOAT_TOL);
    assert_int_equal(s->lights[2].type, LX_LIGHT_POINT);
    assert_true(s->lights[2].intensity == 800.0f);
    /* no intensity: the point light's default 1 cd */
    assert_int_equal(s->lights[3].type, LX_LIGHT_SPHERE);
    lx_test_assert_rel(s->lights[3].intensity, 1.0 / (PI_D * 0.25), FLOAT_TOL);
    lx_scene_destroy(s);
}

/* Overrides by name on area lights: a scene's point light given a radius
 * becomes a sphere with the same candela (luminance I / (pi r^2)); only the
 * given keys change; back to a point light, the candela is L pi r^2; a
 * rect turned toward its old up takes the default up. */
static void test_area_override(void **state)
{
    (void)state;
    lx_scene *s = lx_test_new_scene("test");
    lx_light lamp = lx_light_defaults(LX_LIGHT_POINT);
    strcpy(lamp.name, "lamp");
    lamp.position = lx_v3(1, 2, 3);
    lamp.intensity = 800.0f;
    assert_int_equal(lx_scene_add_light(s, &lamp), LX_OK);

    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"lamp\", \"radius\": 0.05, "
                              "\"shadow\": \"soft\", \"samples\": 32}]}"),
                     LX_OK);
    assert_int_equal(s->light_count, 1);
    const lx_light *l = &s->lights[0];
    assert_int_equal(l->type, LX_LIGHT_SPHERE);
    lx_test_assert_vec3(l->position, 1, 2, 3);
    assert_true(l->radius == 0.05f);
    double nits = 800.0 / (PI_D * 0.0025);
    lx_test_assert_rel(l->intensity, nits, FLOAT_TOL);
    assert_int_equal(l->shadow, LX_SHADOW_SOFT);
    assert_int_equal(l->samples, 32);

    /* A new radius keeps the luminance. */
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"lamp\", \"radius\": 0.1}]}"), LX_OK);
    assert_true(l->radius == 0.1f);
    lx_test_assert_rel(l->intensity, nits, FLOAT_TOL);
    assert_int_equal(l->samples, 32);

    /* Back to a point light: soft shadows must go too. */
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"lamp\", \"type\": \"point\"}]}"),
                     LX_ERR_INVALID);
    assert_non_null(
        strstr(lx_last_error(), "lights[0] ('lamp'): shadow 'soft' needs an area light"));
    assert_int_equal(l->type, LX_LIGHT_SPHERE);
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"lamp\", \"type\": \"point\", "
                              "\"shadow\": \"hard\"}]}"),
                     LX_OK);
    assert_int_equal(l->type, LX_LIGHT_POINT);
    assert_true(l->radius == 0.0f);
    lx_test_assert_rel(l->intensity, nits * PI_D * 0.01, FLOAT_TOL); /* 3200 cd */

    /* A rect turned to face along its old up. */
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"panel\", \"type\": \"rect\", "
                              "\"position\": [0, 2, 0], \"direction\": [0, -1, 0], "
                              "\"width\": 2, \"height\": 1, \"intensity\": 100}]}"),
                     LX_OK);
    const lx_light *r = &s->lights[1];
    lx_test_assert_vec3(r->up, 0, 0, 1);
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"panel\", \"width\": 3}]}"), LX_OK);
    assert_true(r->width == 3.0f && r->height == 1.0f && r->intensity == 100.0f);
    lx_test_assert_vec3(r->up, 0, 0, 1);
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"panel\", \"direction\": [0, 0, 1]}]}"),
                     LX_OK);
    lx_test_assert_vec3(r->direction, 0, 0, 1);
    lx_test_assert_vec3(r->up, 0, 1, 0);
    assert_int_equal(apply(s, "{\"lights\": [{\"name\": \"panel\", \"up\": [0, 0, -1]}]}"),
                     LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "('panel'): up [0, 0, -1] is parallel to direction"));
    lx_test_assert_vec3(r->up, 0, 1, 0);
    lx_scene_destroy(s);
}

static const char *tmp_dir(void)
{
    const char *dir = getenv("LX_TEST_TMP");
    if (!dir || !dir[0])
        dir = "/tmp";
    mkdir(dir, 0777);
    return dir;
}

static void test_file(void **state)
{
    (void)state;
    char path[512];
    snprintf(path, sizeof path, "%s/test_lights_json_%ld.json", tmp_dir(), (long)getpid());
    FILE *fp = fopen(path, "wb");
    assert_non_null(fp);
    fputs(example, fp);
    fclose(fp);
    lx_scene *s = lx_test_new_scene("test");
    assert_int_equal(lx_lights_json_apply(s, path), LX_OK);
    assert_int_equal(s->light_count, 4);

    /* Errors name the path as given. */
    fp = fopen(path, "wb");
    fputs("{\"lights\": [{\"type\": \"lamp\"}]}", fp);
    fclose(fp);
    assert_int_equal(lx_lights_json_apply(s, path), LX_ERR_FORMAT);
    assert_non_null(strstr(lx_last_error(), path));
    assert_non_null(strstr(lx_last_error(), "unknown type 'lamp'"));

    /* Files over 64 MiB are refused without reading them. */
    fp = fopen(path, "wb");
    assert_int_equal(fseek(fp, (long)(64 << 20), SEEK_SET), 0);
    fputc(' ', fp);
    fclose(fp);
    assert_int_not_equal(lx_lights_json_apply(s, path), LX_OK);
    assert_non_null(strstr(lx_last_error(), path));
    remove(path);

    assert_int_equal(lx_lights_json_apply(s, path), LX_ERR_IO);
    assert_int_equal(s->light_count, 4);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_example),       cmocka_unit_test(test_units),
        cmocka_unit_test(test_override),      cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_bad_bytes),     cmocka_unit_test(test_all_or_nothing),
        cmocka_unit_test(test_file),          cmocka_unit_test(test_colour_forms),
        cmocka_unit_test(test_area_lights),   cmocka_unit_test(test_point_with_radius),
        cmocka_unit_test(test_tube_lights),   cmocka_unit_test(test_sky),
        cmocka_unit_test(test_area_override),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
