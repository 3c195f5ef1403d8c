/* Textures decoded at the density a bake reads them (lx_scene_load_desc's
 * texture_density, scene.h): glTF quads written here, whose world and UV
 * areas are known, with a 1024 x 1024 base colour and normal texture.
 * The size each map keeps is the rule worked out here from those areas:
 * the fewest pixels, halving from 1024, with at least
 * LX_TEXTURE_TEXELS_PER_TEXEL^2 texture pixels per lightmap texel
 * (density^2 x world area texels over the UV area) on the node that needs
 * the most and LX_TEXTURE_MIN_PIXELS - with a UV square half as wide, a
 * node scaled three times, KHR_texture_transform's repeats, a density
 * per node, UVs without area (kept whole); the halvings are recorded; no
 * density keeps the file's size and the very floats of a plain load. */
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

#define TEX 1024

static char tex_dir[1100];

/* The textures, once: a colour gradient and a normal-ish one. */
static int setup(void **state)
{
    (void)state;
    snprintf(tex_dir, sizeof tex_dir, "%s", lx_test_dir("texture_size"));
    uint8_t *px = malloc((size_t)TEX * TEX * 3);
    assert_non_null(px);
    for (int y = 0; y < TEX; y++)
        for (int x = 0; x < TEX; x++) {
            uint8_t *p = px + 3 * ((size_t)y * TEX + x);
            p[0] = (uint8_t)(x / 4);
            p[1] = (uint8_t)(y / 4);
            p[2] = (uint8_t)((x + y) / 8);
        }
    char path[1200];
    snprintf(path, sizeof path, "%s/color.png", tex_dir);
    lx_test_write_png(path, TEX, TEX, 3, px);
    snprintf(path, sizeof path, "%s/normal.png", tex_dir);
    lx_test_write_png(path, TEX, TEX, 3, px);
    free(px);
    return 0;
}

/* A scene of quads of side `side` m (e1 along x, e2 along -z) whose
 * TEXCOORD_0 spans uv_side x uv_side (0 = every corner at one point), one
 * node per entry of scales (a uniform node scale), one material reading
 * both textures through TEXCOORD_0 with an optional transform. */
static lx_scene *quads(const char *name, double side, double uv_side, const double *scales,
                       int nodes, const char *transform, const lx_scene_load_desc *desc)
{
    lx_test_quad q = {.o = {0, 0, 0},
                      .e1 = {side, 0, 0},
                      .e2 = {0, 0, -side},
                      .uv = {{{0, 0}, {uv_side, 0}, {0, uv_side}}, {{0, 0}, {1, 0}, {0, 1}}}};
    lx_test_gltf *g = lx_test_gltf_new();
    lx_test_gltf_texture(g, "color.png");
    lx_test_gltf_texture(g, "normal.png");
    char material[600];
    char ext[300] = "";
    if (transform) {
        lx_test_gltf_use_extension(g, "KHR_texture_transform");
        snprintf(ext, sizeof ext, ",\"extensions\":{\"KHR_texture_transform\":%s}", transform);
    }
    snprintf(material, sizeof material,
             "{\"name\":\"m\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0%s}},"
             "\"normalTexture\":{\"index\":1%s}}",
             ext, ext);
    int mat = lx_test_gltf_material(g, material);
    int mesh = lx_test_gltf_quad_mesh(g, "quad", &q, mat, NULL);
    for (int n = 0; n < nodes; n++) {
        char node[32], members[200];
        snprintf(node, sizeof node, "quad%d", n);
        snprintf(members, sizeof members, "\"translation\":[%d,0,0],\"scale\":[%g,%g,%g]", 10 * n,
                 scales[n], scales[n], scales[n]);
        lx_test_gltf_node(g, node, mesh, members);
    }
    char path[1200];
    snprintf(path, sizeof path, "%s/%s.gltf", tex_dir, name);
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
    lx_scene *s = NULL;
    if (lx_scene_load(path, desc, &s) != LX_OK)
        fail_msg("%s", lx_last_error());
    return s;
}

/* The side the rule gives a TEX x TEX texture needing `need` pixels. */
static int side_for(double need)
{
    double keep = need > (double)LX_TEXTURE_MIN_PIXELS ? need : (double)LX_TEXTURE_MIN_PIXELS;
    int side = TEX;
    while (side > 1 && (double)(side / 2) * (side / 2) >= keep)
        side /= 2;
    return side;
}

/* Pixels needed by a node of world area `world` m^2 read over UV area
 * `uv` at density d. */
static double need(double d, double world, double uv)
{
    double k = LX_TEXTURE_TEXELS_PER_TEXEL;
    return k * k * d * d * world / uv;
}

static int halvings_of(int side)
{
    int h = 0;
    while ((TEX >> h) > side)
        h++;
    return h;
}

static void expect_side(const lx_scene *s, int side)
{
    const lx_material *m = &s->materials[0];
    assert_int_equal(m->base_color_map.width, side);
    assert_int_equal(m->base_color_map.height, side);
    assert_int_equal(m->normal_map.width, side);
    assert_int_equal(m->normal_map.height, side);
    assert_int_equal(m->base_color_map_halvings, halvings_of(side));
    assert_int_equal(m->normal_map_halvings, halvings_of(side));
    assert_non_null(m->base_color_map_path);
    assert_non_null(m->normal_map_path);
}

static void test_density(void **state)
{
    (void)state;
    const double one[] = {1.0};
    const float densities[] = {100.0f, 150.0f, 200.0f, 300.0f, 20.0f};
    for (size_t i = 0; i < sizeof densities / sizeof densities[0]; i++) {
        lx_scene_load_desc d = {.texture_density = densities[i]};
        lx_scene *s = quads("unit", 1.0, 1.0, one, 1, NULL, &d);
        int side = side_for(need(densities[i], 1.0, 1.0));
        expect_side(s, side);
        lx_scene_destroy(s);
    }
    /* the cases cover every step: 1024 (300), 512 (150, 200), 256 (100, 20) */
    assert_int_equal(side_for(need(300, 1, 1)), 1024);
    assert_int_equal(side_for(need(200, 1, 1)), 512);
    assert_int_equal(side_for(need(100, 1, 1)), 256);
}

static void test_areas(void **state)
{
    (void)state;
    const double one[] = {1.0}, two[] = {1.0, 3.0};
    /* a UV square half as wide: four times the pixels per texel needed */
    lx_scene_load_desc d = {.texture_density = 100.0f};
    lx_scene *s = quads("half_uv", 1.0, 0.5, one, 1, NULL, &d);
    expect_side(s, side_for(need(100, 1.0, 0.25)));
    assert_int_equal(s->materials[0].base_color_map.width, 512);
    lx_scene_destroy(s);
    /* a second node scaled 3x: nine times the world area, the larger need */
    s = quads("scaled", 1.0, 1.0, two, 2, NULL, &d);
    expect_side(s, side_for(need(100, 9.0, 1.0)));
    assert_int_equal(s->materials[0].base_color_map.width, 1024);
    lx_scene_destroy(s);
    /* KHR_texture_transform's scale 2 x 4: the texture repeats 8 times
     * over the quad, each repeat read again: 8 times the UV area */
    d.texture_density = 600.0f;
    s = quads("repeat", 1.0, 1.0, one, 1, "{\"scale\":[2,4]}", &d);
    expect_side(s, side_for(need(600, 1.0, 8.0)));
    assert_int_equal(s->materials[0].base_color_map.width, 512);
    lx_scene_destroy(s);
    /* UVs of no area: whatever the density, the texture is kept whole */
    d.texture_density = 1.0f;
    s = quads("no_uv_area", 1.0, 0.0, one, 1, NULL, &d);
    expect_side(s, TEX);
    lx_scene_destroy(s);
}

/* Per node: node 0 is read at no density, node 1 (scaled 3x) at 50/m. */
static float per_node(void *user, const lx_scene *scene, uint32_t node)
{
    int *calls = user;
    (*calls)++;
    assert_true(node < scene->node_count);
    assert_int_equal(scene->mesh_count, 1); /* the geometry is there */
    return node == 1 ? 50.0f : 0.0f;
}

static void test_density_fn(void **state)
{
    (void)state;
    const double two[] = {1.0, 3.0};
    int calls = 0;
    lx_scene_load_desc d = {
        .texture_density = 1000.0f, .texture_density_fn = per_node, .texture_density_user = &calls};
    lx_scene *s = quads("per_node", 1.0, 1.0, two, 2, NULL, &d);
    assert_int_equal(calls, 2);
    expect_side(s, side_for(need(50, 9.0, 1.0)));
    assert_int_equal(s->materials[0].base_color_map.width, 512);
    lx_scene_destroy(s);
}

/* No density: the file's size, and the floats of a plain image load. */
static void test_no_density(void **state)
{
    (void)state;
    const double one[] = {1.0};
    lx_scene *s = quads("plain", 1.0, 1.0, one, 1, NULL, NULL);
    expect_side(s, TEX);
    char path[1200];
    snprintf(path, sizeof path, "%s/color.png", tex_dir);
    lx_image img;
    lx_image_load_desc ld = {.channels = 4};
    assert_int_equal(lx_image_load(path, &ld, &img), LX_OK);
    assert_memory_equal(img.data, s->materials[0].base_color_map.data,
                        sizeof(float) * TEX * TEX * 4);
    lx_image_free(&img);
    lx_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_density),
        cmocka_unit_test(test_areas),
        cmocka_unit_test(test_density_fn),
        cmocka_unit_test(test_no_density),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
