/* KHR_materials_pbrSpecularGlossiness (Khronos extension spec, archived):
 * a material's diffuseFactor and diffuseTexture are its albedo, and a
 * pbrMetallicRoughness beside them is only the fallback for readers without
 * the extension (luxel, as three.js did, prefers the extension). From glTF
 * files written here:
 *
 * - a spec-gloss material with diffuseFactor (0.2, 0.5, 0.8) and no
 *   pbrMetallicRoughness loads with that base colour, and bakes as
 *   radiance to E rho / pi under a sun of E lux at normal incidence;
 * - with a fallback pbrMetallicRoughness (another colour and texture) the
 *   extension's factor wins and, without a diffuseTexture, the fallback's
 *   texture is not read;
 * - a diffuseTexture on TEXCOORD_1 (the fallback's texture on TEXCOORD_0
 *   holds other texels) bakes to E x factor x texture / pi, the texture
 *   read as the sRGB formula and bilinear REPEAT filtering say;
 * - a metallic-roughness material alone keeps its baseColorFactor;
 * - a file that requires the extension loads;
 * - a malformed diffuseTexture fails the load naming the material and the
 *   field.
 *
 * Expected values never come from the code under test: the file's own
 * factors, the sRGB formula and the texture oracle (texture_oracle.c). */
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

#define RES 16
#define TEX 8
#define EXT "KHR_materials_pbrSpecularGlossiness"

static const double PI = 3.14159265358979323846;
static const double SUN = 1000.0; /* lux at normal incidence */

/* A quad facing +Y; TEXCOORD_0 and TEXCOORD_1 are different affine maps
 * (so a texture read through the wrong set is caught), the lightmap lies
 * on TEXCOORD_1. Dyadic values: the file's floats are exact. */
static const lx_test_quad QUAD = {
    .o = {-1, 0, 1},
    .e1 = {2, 0, 0},
    .e2 = {0, 0, -2},
    .uv = {{{0.125, 0.25}, {0.75, 0.125}, {-0.25, 1.0}}, {{0, 0}, {1, 0}, {0, 1}}}};

/* The quad with one material (JSON text) and textures 0..n-1 of uris,
 * the extension listed in extensionsUsed (assimp reads it only then), and
 * in extensionsRequired too when required. */
static void write_quad_ex(const char *path, const char *material, const char *const *uris, int n,
                          bool required)
{
    lx_test_gltf *g = lx_test_gltf_new();
    for (int i = 0; i < n; i++)
        lx_test_gltf_texture(g, uris[i]);
    if (required)
        lx_test_gltf_require_extension(g, EXT);
    else
        lx_test_gltf_use_extension(g, EXT);
    int mat = lx_test_gltf_material(g, material);
    lx_test_gltf_node(g, "quad", lx_test_gltf_quad_mesh(g, "quad", &QUAD, mat, NULL), "");
    lx_test_gltf_write(g, path);
    lx_test_gltf_free(g);
}

static void write_quad(const char *path, const char *material, const char *const *uris, int n)
{
    write_quad_ex(path, material, uris, n, false);
}

/* The quad's material (the mesh's, not assimp's default one). */
static const lx_material *quad_material(const lx_scene *s)
{
    assert_int_equal(s->mesh_count, 1);
    assert_true(s->meshes[0].material < s->material_count);
    return &s->materials[s->meshes[0].material];
}

/* The scene lit by a sun straight down (SUN lux on the quad, no shadow),
 * baked as radiance on TEXCOORD_1 at RES x RES. */
static lx_image bake_radiance(lx_scene *scene)
{
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_v3(0, -1, 0);
    sun.intensity = (float)SUN;
    sun.shadow = LX_SHADOW_NONE;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
    lx_bake_desc desc = {.resolution = RES, .quantity = LX_QUANTITY_RADIANCE, .threads = 2};
    return lx_test_bake_applied(scene, &desc, RES * RES);
}

/* Every texel of img within tol (relative) of E rho / pi for constant rho. */
static void assert_uniform_radiance(const lx_image *img, const double rho[3], double tol)
{
    double worst = 0;
    for (int i = 0; i < RES * RES; i++)
        for (int k = 0; k < 3; k++) {
            double want = SUN * rho[k] / PI;
            worst = fmax(worst, fabs(img->data[i * 3 + k] - want) / want);
        }
    if (!(worst < tol))
        fail_msg("radiance off E rho / pi by %.3g relative", worst);
}

static void factor_only(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_spec_gloss_factor");
    char path[1024];
    snprintf(path, sizeof path, "%s/factor.gltf", dir);
    write_quad(path,
               "{\"name\":\"sg\",\"extensions\":{\"" EXT "\":{\"diffuseFactor\":[0.2,0.5,0.8,1],"
               "\"specularFactor\":[0,0,0],\"glossinessFactor\":0.2}}}",
               NULL, 0);
    lx_scene *s = lx_test_load(path);
    const lx_material *m = quad_material(s);
    assert_string_equal(m->name, "sg");
    assert_true(m->base_color.x == 0.2f && m->base_color.y == 0.5f && m->base_color.z == 0.8f);
    assert_true(m->base_color.w == 1.0f);
    assert_int_equal(m->base_color_map.width, 0);
    lx_image img = bake_radiance(s);
    /* measured: float rounding only (about 1e-7) */
    const double rho[3] = {0.2, 0.5, 0.8};
    assert_uniform_radiance(&img, rho, 1e-5);
    lx_image_free(&img);
    lx_scene_destroy(s);

    /* a file that requires the extension loads the same */
    write_quad_ex(
        path, "{\"name\":\"sg\",\"extensions\":{\"" EXT "\":{\"diffuseFactor\":[0.2,0.5,0.8,1]}}}",
        NULL, 0, true);
    s = lx_test_load(path);
    m = quad_material(s);
    assert_true(m->base_color.x == 0.2f && m->base_color.y == 0.5f && m->base_color.z == 0.8f);
    lx_scene_destroy(s);
}

/* One PNG of TEX x TEX random texels (a fixed LCG from seed), their
 * linear values in lin. */
static void noise_png(const char *path, uint32_t seed, double *lin)
{
    uint8_t px[TEX * TEX * 3];
    for (int i = 0; i < TEX * TEX * 3; i++) {
        seed = seed * 1664525u + 1013904223u;
        px[i] = (uint8_t)(20 + (seed >> 24) % 220);
        if (lin)
            lin[i] = lx_test_srgb_decode(px[i]);
    }
    lx_test_write_png(path, TEX, TEX, 3, px);
}

static void fallback_ignored(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_spec_gloss_fallback");
    char png[1024], path[1024];
    snprintf(png, sizeof png, "%s/fallback.png", dir);
    noise_png(png, 7, NULL);
    const char *uri = "fallback.png";
    snprintf(path, sizeof path, "%s/fallback.gltf", dir);
    /* the fallback names another colour and a texture; the extension has
     * no diffuseTexture, so the material has none */
    write_quad(path,
               "{\"name\":\"sg\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.9,0.1,0.1,1],"
               "\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0},"
               "\"extensions\":{\"" EXT "\":{\"diffuseFactor\":[0.2,0.5,0.8,1]}}}",
               &uri, 1);
    lx_scene *s = lx_test_load(path);
    const lx_material *m = quad_material(s);
    assert_true(m->base_color.x == 0.2f && m->base_color.y == 0.5f && m->base_color.z == 0.8f);
    assert_int_equal(m->base_color_map.width, 0);
    assert_null(m->base_color_map_path);
    lx_image img = bake_radiance(s);
    const double rho[3] = {0.2, 0.5, 0.8};
    assert_uniform_radiance(&img, rho, 1e-5);
    lx_image_free(&img);
    lx_scene_destroy(s);

    /* no diffuseFactor: the extension's default (1, 1, 1, 1), not the
     * fallback's colour */
    write_quad(path,
               "{\"name\":\"sg\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.9,0.1,0.1,1]},"
               "\"extensions\":{\"" EXT "\":{\"glossinessFactor\":0.5}}}",
               NULL, 0);
    s = lx_test_load(path);
    m = quad_material(s);
    assert_true(m->base_color.x == 1.0f && m->base_color.y == 1.0f && m->base_color.z == 1.0f);
    lx_scene_destroy(s);
}

static void diffuse_texture(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_spec_gloss_texture");
    double lin[TEX * TEX * 3];
    char png[1024], path[1024];
    snprintf(png, sizeof png, "%s/fallback.png", dir);
    noise_png(png, 7, NULL);
    snprintf(png, sizeof png, "%s/diffuse.png", dir);
    noise_png(png, 12345, lin);
    const char *uris[2] = {"fallback.png", "diffuse.png"};
    snprintf(path, sizeof path, "%s/texture.gltf", dir);
    write_quad(path,
               "{\"name\":\"sg\",\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}},"
               "\"extensions\":{\"" EXT "\":{\"diffuseFactor\":[0.5,1,0.25,1],"
               "\"diffuseTexture\":{\"index\":1,\"texCoord\":1}}}}",
               uris, 2);
    lx_scene *s = lx_test_load(path);
    const lx_material *m = quad_material(s);
    assert_true(m->base_color.x == 0.5f && m->base_color.y == 1.0f && m->base_color.z == 0.25f);
    assert_int_equal(m->base_color_uv_set, 1);
    assert_int_equal(m->base_color_map.width, TEX);
    assert_non_null(m->base_color_map_path);
    assert_non_null(strstr(m->base_color_map_path, "diffuse.png"));
    lx_image img = bake_radiance(s);
    const double factor[3] = {0.5, 1.0, 0.25};
    double worst = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            double st[2], uv[2], tex[3];
            assert_true(
                lx_test_quad_st(&QUAD, 1, (x + 0.5) / RES, (y + 0.5) / RES, &st[0], &st[1]));
            lx_test_quad_uv(&QUAD, 1, st[0], st[1], uv);
            lx_test_bilinear(lin, TEX, TEX, 3, uv[0], uv[1], tex);
            for (int k = 0; k < 3; k++) {
                double want = SUN * factor[k] * tex[k] / PI;
                worst = fmax(worst, fabs(img.data[(y * RES + x) * 3 + k] - want) / want);
            }
        }
    /* measured: about 1e-6 (float UVs over the random texels) */
    if (!(worst < 5e-5))
        fail_msg("diffuse texture: radiance off by %.3g relative", worst);
    lx_image_free(&img);
    lx_scene_destroy(s);
}

static void metal_rough_unchanged(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_spec_gloss_mr");
    char path[1024];
    snprintf(path, sizeof path, "%s/mr.gltf", dir);
    write_quad(path,
               "{\"name\":\"mr\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.25,0.5,0.75,1],"
               "\"metallicFactor\":0}}",
               NULL, 0);
    lx_scene *s = lx_test_load(path);
    const lx_material *m = quad_material(s);
    assert_true(m->base_color.x == 0.25f && m->base_color.y == 0.5f && m->base_color.z == 0.75f);
    lx_scene_destroy(s);
}

static void malformed_texture(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_spec_gloss_bad");
    char png[1024], path[1024];
    snprintf(png, sizeof png, "%s/diffuse.png", dir);
    noise_png(png, 3, NULL);
    const char *uri = "diffuse.png";
    snprintf(path, sizeof path, "%s/bad.gltf", dir);
    write_quad(path,
               "{\"name\":\"sg\",\"extensions\":{\"" EXT "\":{\"diffuseTexture\":{\"index\":0,"
               "\"extensions\":{\"KHR_texture_transform\":{\"rotation\":\"x\"}}}}}}",
               &uri, 1);
    lx_scene *s = NULL;
    assert_int_not_equal(lx_scene_load(path, NULL, &s), LX_OK);
    assert_null(s);
    const char *msg = lx_last_error();
    if (!strstr(msg, "bad.gltf") || !strstr(msg, "'sg'") || !strstr(msg, "diffuseTexture") ||
        !strstr(msg, "rotation"))
        fail_msg("message: %s", msg);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(factor_only),       cmocka_unit_test(fallback_ignored),
        cmocka_unit_test(diffuse_texture),   cmocka_unit_test(metal_rough_unchanged),
        cmocka_unit_test(malformed_texture),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
