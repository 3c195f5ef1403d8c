/* Textures in the baker, texel by texel, through glTF files written here:
 *
 * - base colour: a checker PNG (two colours, 4-pixel checks) on a quad
 *   whose TEXCOORD_0 is skewed and reaches outside [0,1] (REPEAT), baked as
 *   radiance: every texel must be E x baseColorFactor x texture / pi, with
 *   the texture sRGB-decoded and filtered bilinearly at the texel's UV;
 * - normal maps: a gradient normal map (red grows with x, green with y, so
 *   a flipped V or swapped channels fail) with normalTexture.scale, under a
 *   directional light, with tangents from the file and computed, for UV
 *   layouts with either handedness: every texel's irradiance must be
 *   E_sun x max(0, n . l) for the glTF tangent frame (tangent along +u,
 *   bitangent cross(n, t) * w toward -v, green up);
 * - a mesh without UVs casts shadows: a UV-less triangle over a floor, in
 *   its own node and in the floor's node; every floor texel is dark exactly
 *   when a ray from it toward the light hits the triangle;
 * - a node whose meshes do not all have TEXCOORD_1 bakes all of them on
 *   TEXCOORD_0, with one warning per mesh saying what happens to it.
 *
 * Expected values come from texture_oracle.c (the sRGB formula, bilinear
 * REPEAT filtering and the quads' affine UV maps, in double) and from an
 * independent ray-triangle test (Moller & Trumbore 1997) here; none calls
 * the code under test. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "gltf_writer.h"
#include "helpers.h"
#include "reference.h"
#include "texture_oracle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RES 32

static const double PI = 3.14159265358979323846;

/* A directional light of `lux` shining along dir (normalized in double,
 * stored as the float the baker sees), no shadows. */
static lx_light sun_along(const double dir_in[3], float lux, double dir_out[3])
{
    double d[3] = {dir_in[0], dir_in[1], dir_in[2]};
    lx_ref_normalize(d);
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_v3((float)d[0], (float)d[1], (float)d[2]);
    sun.intensity = lux;
    sun.shadow = LX_SHADOW_NONE;
    snprintf(sun.name, sizeof sun.name, "sun");
    dir_out[0] = sun.direction.x;
    dir_out[1] = sun.direction.y;
    dir_out[2] = sun.direction.z;
    return sun;
}

/* Writes quad q with material `material` (JSON) and optional tangents as
 * DIR/name.gltf and loads it. */
static lx_scene *load_quad(const char *dir, const char *name, const lx_test_quad *q,
                           const char *material, const char *texture_uri, const float tangent[16])
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s.gltf", dir, name);
    lx_test_write_quad_gltf(path, q, material, &texture_uri, 1, tangent);
    return lx_test_load(path);
}

/* Bakes scene's one lightmap at RES^2 without padding. */
static lx_image bake(lx_scene *scene, lx_quantity quantity)
{
    lx_bake_desc desc = {.resolution = RES, .quantity = quantity, .threads = 2};
    lx_baker *baker;
    if (lx_baker_create(scene, &desc, &baker) != LX_OK)
        fail_msg("lx_baker_create: %s", lx_last_error());
    assert_int_equal(lx_baker_lightmap_count(baker), 1);
    assert_int_equal(lx_baker_lightmap_info(baker, 0)->uv_set, 1);
    assert_int_equal(lx_baker_lightmap_info(baker, 0)->used_texels, RES * RES);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &img), LX_OK);
    lx_baker_destroy(baker);
    return img;
}

/* The (s, t) of lightmap texel (x, y) on q (lightmap UVs are set 1). */
static void texel_st(const lx_test_quad *q, int x, int y, double *s, double *t)
{
    assert_true(lx_test_quad_st(q, 1, (x + 0.5) / RES, (y + 0.5) / RES, s, t));
}

/* ---- base colour --------------------------------------------------------- */

static void checker_radiance(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("test_textures_checker");
    /* two colours in 4x4-pixel checks over 16x16 pixels */
    enum { W = 16, CHECK = 4 };
    static const uint8_t colour[2][3] = {{200, 40, 90}, {30, 180, 250}};
    uint8_t px[W * W * 3];
    double lin[W * W * 3];
    for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++)
            for (int c = 0; c < 3; c++) {
                int which = (x / CHECK + y / CHECK) % 2;
                px[(y * W + x) * 3 + c] = colour[which][c];
                lin[(y * W + x) * 3 + c] = lx_test_srgb_decode(colour[which][c]);
            }
    char png[1024];
    snprintf(png, sizeof png, "%s/checker.png", dir);
    lx_test_write_png(png, W, W, 3, px);

    /* a 2 m quad facing +Y; TEXCOORD_0 skewed, reaching [-0.375, 1.75] in u
     * and [0.125, 1.625] in v (REPEAT); TEXCOORD_1 the unit square. Values
     * are dyadic, so the file's floats hold them exactly. */
    lx_test_quad q = {
        .o = {-1, 0, 1},
        .e1 = {2, 0, 0},
        .e2 = {0, 0, -2},
        .uv = {{{-0.25, 0.125}, {1.5, 0.25}, {-0.125, 1.25}}, {{0, 0}, {1, 0}, {0, 1}}}};
    const double factor[3] = {0.75, 0.5, 0.875};
    lx_scene *scene = load_quad(dir, "checker", &q,
                                "{\"name\":\"checker\",\"pbrMetallicRoughness\":{"
                                "\"baseColorFactor\":[0.75,0.5,0.875,1],"
                                "\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0}}",
                                "checker.png", NULL);
    assert_int_equal(scene->material_count, 2); /* the file's and assimp's default */
    assert_int_equal(scene->materials[0].base_color_map.width, W);
    double d[3];
    const double dir_in[3] = {0.3, -1, 0.2};
    lx_light sun = sun_along(dir_in, 1000.0f, d);
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
    const double e = 1000.0 * -d[1]; /* the quad's normal is +Y */

    lx_image rad = bake(scene, LX_QUANTITY_RADIANCE);
    lx_image irr = bake(scene, LX_QUANTITY_IRRADIANCE);
    double worst = 0, worst_irr = 0;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            double s, t, uv[2], tex[3];
            texel_st(&q, x, y, &s, &t);
            lx_test_quad_uv(&q, 0, s, t, uv);
            lx_test_bilinear(lin, W, W, 3, uv[0], uv[1], tex);
            for (int c = 0; c < 3; c++) {
                double want = e * factor[c] * tex[c] / PI;
                double got = rad.data[(y * RES + x) * 3 + c];
                worst = fmax(worst, fabs(got - want) / want);
                worst_irr = fmax(worst_irr, fabs(irr.data[(y * RES + x) * 3 + c] - e) / e);
            }
        }
    if (getenv("LX_TEST_VERBOSE"))
        printf("checker: radiance %.3g, irradiance %.3g\n", worst, worst_irr);
    /* measured: 4.3e-7 (float UVs and products); irradiance 3.2e-8 */
    if (!(worst < 1.5e-6 && worst_irr < 1.5e-7))
        fail_msg("radiance off by %.3g relative, irradiance by %.3g", worst, worst_irr);
    lx_image_free(&rad);
    lx_image_free(&irr);
    lx_scene_destroy(scene);
}

/* ---- normal maps ----------------------------------------------------------- */

/* glTF's tangent frame of planar quad q for UV set 0: t along dP/du, the
 * bitangent cross(n, t) * w with w chosen so it points along -dP/dv. */
static void quad_frame(const lx_test_quad *q, double n[3], double t[3], double b[3], double *w)
{
    lx_ref_cross(q->e1, q->e2, n);
    lx_ref_normalize(n);
    /* J = d(u, v)/d(s, t); dP/du and dP/dv from its inverse */
    double bu = q->uv[0][1][0], bv = q->uv[0][1][1], cu = q->uv[0][2][0], cv = q->uv[0][2][1];
    double det = bu * cv - cu * bv;
    double ds_du = cv / det, dt_du = -bv / det, ds_dv = -cu / det, dt_dv = bu / det;
    double dpdu[3], dpdv[3];
    for (int k = 0; k < 3; k++) {
        dpdu[k] = q->e1[k] * ds_du + q->e2[k] * dt_du;
        dpdv[k] = q->e1[k] * ds_dv + q->e2[k] * dt_dv;
    }
    for (int k = 0; k < 3; k++)
        t[k] = dpdu[k];
    lx_ref_normalize(t);
    double c[3];
    lx_ref_cross(n, t, c);
    *w = lx_ref_dot(c, dpdv) > 0 ? -1.0 : 1.0;
    for (int k = 0; k < 3; k++)
        b[k] = c[k] * *w;
}

/* The shading normal from a tangent-space sample m (raw [0,1] values)
 * with normalTexture.scale. */
static void perturbed(const double raw[3], double scale, const double n[3], const double t[3],
                      const double b[3], double out[3])
{
    double m[3] = {(2 * raw[0] - 1) * scale, (2 * raw[1] - 1) * scale, 2 * raw[2] - 1};
    for (int k = 0; k < 3; k++)
        out[k] = m[0] * t[k] + m[1] * b[k] + m[2] * n[k];
    lx_ref_normalize(out);
}

static void check_normal_map(const char *tag, const lx_test_quad *q, bool file_tangents)
{
    const char *dir = lx_test_dir(tag);
    enum { W = 8 };
    uint8_t px[W * W * 3];
    double raw[W * W * 3];
    lx_test_gradient_normal_map(W, 180, 5, px, raw);
    char png[1024];
    snprintf(png, sizeof png, "%s/bumps.png", dir);
    lx_test_write_png(png, W, W, 3, px);

    double n[3], t[3], b[3], w;
    quad_frame(q, n, t, b, &w);
    float tangent[16];
    for (int i = 0; i < 4; i++) {
        for (int k = 0; k < 3; k++)
            tangent[4 * i + k] = (float)t[k];
        tangent[4 * i + 3] = (float)w;
    }
    const double scale = 0.625;
    lx_scene *scene = load_quad(
        dir, "bumps", q, "{\"name\":\"bumpy\",\"normalTexture\":{\"index\":0,\"scale\":0.625}}",
        "bumps.png", file_tangents ? tangent : NULL);
    assert_true(scene->materials[0].normal_map.width == W);
    assert_true(fabsf(scene->materials[0].normal_scale - (float)scale) == 0.0f);
    assert_true((scene->meshes[0].tangents != NULL) == file_tangents);
    double d[3];
    const double dir_in[3] = {0.4, -1, -0.3};
    lx_light sun = sun_along(dir_in, 1000.0f, d);
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);

    lx_image img = bake(scene, LX_QUANTITY_IRRADIANCE);
    double worst = 0;
    int varied = 0;
    double first = -1;
    for (int y = 0; y < RES; y++)
        for (int x = 0; x < RES; x++) {
            double s, tt, uv[2], m[3], np[3];
            texel_st(q, x, y, &s, &tt);
            lx_test_quad_uv(q, 0, s, tt, uv);
            lx_test_bilinear(raw, W, W, 3, uv[0], uv[1], m);
            perturbed(m, scale, n, t, b, np);
            double want = 1000.0 * fmax(0.0, -lx_ref_dot(np, d));
            double got = img.data[(y * RES + x) * 3];
            worst = fmax(worst, fabs(got - want));
            if (first < 0)
                first = want;
            varied += fabs(want - first) > 50.0;
        }
    if (getenv("LX_TEST_VERBOSE"))
        printf("%s: %.3g lux\n", tag, worst);
    /* measured: 2.1e-4 lux of ~1000 (float frames and UVs) */
    if (!(worst < 8e-4))
        fail_msg("%s: irradiance off by %.3g lux", tag, worst);
    assert_true(varied > RES * RES / 4); /* the map really tilts the normal */
    lx_image_free(&img);
    lx_scene_destroy(scene);
}

/* u along +x, v along -z (e2): the bitangent (toward -v) is +z while
 * cross(n, t) = cross(+y, +x) = -z, so w = -1 (a mirrored layout). */
static const lx_test_quad QUAD_MIRRORED = {
    .o = {-1, 0, 1},
    .e1 = {2, 0, 0},
    .e2 = {0, 0, -2},
    .uv = {{{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}}};
/* v runs the other way: w = +1. The lightmap is rotated against the
 * texture so sampling the normal map at lightmap UVs fails. */
static const lx_test_quad QUAD_PLAIN = {
    .o = {-1, 0, 1},
    .e1 = {2, 0, 0},
    .e2 = {0, 0, -2},
    .uv = {{{0, 1}, {1, 0}, {0, -1}}, {{1, 0}, {0, 1}, {-1, 0}}}};
/* Skewed texture UVs on a tilted quad (t and b not orthogonal). */
static const lx_test_quad QUAD_SKEWED = {
    .o = {-1, 0.5, 1},
    .e1 = {2, 0.5, 0},
    .e2 = {0, 0.25, -2},
    .uv = {{{0.25, 0}, {0.75, 0.25}, {-0.25, 1}}, {{0, 0}, {1, 0}, {0, 1}}}};

static void normal_map_mirrored(void **state)
{
    (void)state;
    check_normal_map("test_textures_nm_mirrored", &QUAD_MIRRORED, false);
    check_normal_map("test_textures_nm_mirrored_t", &QUAD_MIRRORED, true);
}

static void normal_map_plain(void **state)
{
    (void)state;
    check_normal_map("test_textures_nm_plain", &QUAD_PLAIN, false);
    check_normal_map("test_textures_nm_plain_t", &QUAD_PLAIN, true);
}

static void normal_map_skewed(void **state)
{
    (void)state;
    check_normal_map("test_textures_nm_skewed", &QUAD_SKEWED, false);
    check_normal_map("test_textures_nm_skewed_t", &QUAD_SKEWED, true);
}

/* ---- a mesh without UVs casts shadows -------------------------------------- */

/* Moller-Trumbore: does the ray o + r d (r > 0) hit triangle abc? *margin
 * gets how far inside (or outside, negative) the hit is, in barycentric
 * units. */
static bool ray_hits(const double o[3], const double d[3], const double a[3], const double b[3],
                     const double c[3], double *margin)
{
    double e1[3], e2[3], p[3], s[3], qv[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = b[k] - a[k];
        e2[k] = c[k] - a[k];
        s[k] = o[k] - a[k];
    }
    lx_ref_cross(d, e2, p);
    double det = lx_ref_dot(e1, p);
    double u = lx_ref_dot(s, p) / det;
    lx_ref_cross(s, e1, qv);
    double v = lx_ref_dot(d, qv) / det;
    double r = lx_ref_dot(e2, qv) / det;
    *margin = fmin(u, fmin(v, 1 - u - v));
    return r > 0 && *margin >= 0;
}

static int warnings_no_uv;
static void count_warnings(void *user, lx_log_level level, const char *msg)
{
    (void)user;
    if (level == LX_LOG_WARN && strstr(msg, "has no UVs") && strstr(msg, "casts shadows"))
        warnings_no_uv++;
}

static void check_uvless_shadow(bool same_node)
{
    lx_scene *scene = lx_test_new_scene("shadow");
    lx_material white = {.name = "white", .base_color = {1, 1, 1, 1}};
    assert_int_equal(lx_scene_add_material(scene, &white, NULL), LX_OK);
    lx_mesh floor = lx_test_plane("floor", 4.0f, 0.0f, 0.0f, 0.0f, 2);
    const double tri[3][3] = {{-0.9, 1.0, -0.5}, {0.8, 1.25, -0.75}, {0.125, 0.875, 1.125}};
    lx_vec3 p[3], nrm[3];
    for (int i = 0; i < 3; i++) {
        p[i] = lx_v3((float)tri[i][0], (float)tri[i][1], (float)tri[i][2]);
        nrm[i] = lx_v3(0, -1, 0);
    }
    uint32_t idx[3] = {0, 2, 1};
    lx_mesh occ = {.name = "occluder",
                   .vertex_count = 3,
                   .triangle_count = 1,
                   .positions = p,
                   .normals = nrm,
                   .indices = idx}; /* no uv[0], no uv[1] */
    uint32_t mi[2];
    assert_int_equal(lx_scene_add_mesh(scene, &floor, &mi[0]), LX_OK);
    assert_int_equal(lx_scene_add_mesh(scene, &occ, &mi[1]), LX_OK);
    lx_test_mesh_free(&floor);
    lx_mat4 id = lx_mat4_identity();
    if (same_node) {
        assert_int_equal(lx_scene_add_node(scene, "both", &id, mi, 2, NULL), LX_OK);
    } else {
        assert_int_equal(lx_scene_add_node(scene, "floor", &id, &mi[0], 1, NULL), LX_OK);
        assert_int_equal(lx_scene_add_node(scene, "occluder", &id, &mi[1], 1, NULL), LX_OK);
    }
    double d[3];
    const double dir_in[3] = {0.35, -1, 0.25};
    lx_light sun = sun_along(dir_in, 1000.0f, d);
    sun.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);

    enum { R = 64 };
    lx_bake_desc desc = {.resolution = R, .threads = 2};
    lx_baker *baker;
    warnings_no_uv = 0;
    lx_set_log_callback(count_warnings, NULL);
    lx_status st = lx_baker_create(scene, &desc, &baker);
    lx_set_log_callback(NULL, NULL);
    if (st != LX_OK)
        fail_msg("lx_baker_create: %s", lx_last_error());
    /* only the floor has texels; the UV-less mesh is named once */
    assert_int_equal(lx_baker_lightmap_count(baker), 1);
    assert_int_equal(warnings_no_uv, 1);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, 0, &img), LX_OK);
    lx_baker_destroy(baker);

    const double lit = 1000.0 * -d[1];
    const double to_light[3] = {-d[0], -d[1], -d[2]};
    int dark = 0, bright = 0, near_edge = 0;
    for (int y = 0; y < R; y++)
        for (int x = 0; x < R; x++) {
            /* lx_test_plane: u along +x, v along +z over [-2, 2] */
            double o[3] = {-2 + 4 * (x + 0.5) / R, 0, -2 + 4 * (y + 0.5) / R};
            double margin;
            bool blocked = ray_hits(o, to_light, tri[0], tri[1], tri[2], &margin);
            /* rays through the triangle's edge are left out: the shadow ray
             * starts lifted by the bias (~1e-4 m here), which moves it by
             * about that in barycentric units */
            if (fabs(margin) < 2e-3) {
                near_edge++;
                continue;
            }
            double got = img.data[(y * R + x) * 3];
            double want = blocked ? 0.0 : lit;
            /* measured: within 1.2e-8 of lit (lit's own float rounding);
             * bound one float ulp (1.2e-7) */
            if (fabs(got - want) > 1.2e-7 * lit)
                fail_msg("texel (%d, %d): %g lux, want %g (%s)", x, y, got, want,
                         blocked ? "shadowed" : "lit");
            dark += blocked;
            bright += !blocked;
        }
    if (getenv("LX_TEST_VERBOSE"))
        printf("shadow: %d dark, %d lit, %d near an edge\n", dark, bright, near_edge);
    /* the triangle's shadow covers ~8% of the floor */
    assert_true(dark > R * R / 20);
    assert_true(bright > R * R / 2);
    assert_true(near_edge < R * R / 50);
    lx_image_free(&img);
    lx_scene_destroy(scene);
}

static void uvless_occluder_own_node(void **state)
{
    (void)state;
    check_uvless_shadow(false);
}

static void uvless_occluder_same_node(void **state)
{
    (void)state;
    check_uvless_shadow(true);
}

/* ---- the lightmap UV set of a node -------------------------------------------- */

static int warn_no_uv1, warn_unused_uv1, warn_more_nodes, warnings;
static void count_uv_warnings(void *user, lx_log_level level, const char *msg)
{
    (void)user;
    if (level != LX_LOG_WARN)
        return;
    warnings++;
    warn_no_uv1 += strstr(msg, "'half' has no TEXCOORD_1; its lightmap uses TEXCOORD_0") != NULL;
    warn_unused_uv1 += strstr(msg, "the TEXCOORD_1 of its 1 other mesh goes unused") != NULL;
    warn_more_nodes += strstr(msg, "so do 14 more nodes with such a mesh") != NULL;
}

/* A node whose meshes do not all have TEXCOORD_1 bakes every mesh on
 * TEXCOORD_0 (one lightmap UV space per node), with one warning saying
 * what happens to its meshes; 15 such nodes give one warning, not 15.
 * Texel counts are closed forms: "full" covers the left half of
 * TEXCOORD_0 (16 of 32 columns), "half" the right half. */
static void texcoord0_for_the_whole_node(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("uv-sets");
    lx_material white = {.name = "white", .base_color = {1, 1, 1, 1}};
    assert_int_equal(lx_scene_add_material(scene, &white, NULL), LX_OK);
    lx_mesh a = lx_test_plane("full", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_mesh b = lx_test_plane("half", 1.0f, 0.0f, 2.0f, 0.0f, 1);
    for (uint32_t v = 0; v < a.vertex_count; v++) {
        a.uv[0][v].x *= 0.5f;                      /* TEXCOORD_0: the left half */
        b.uv[0][v].x = 0.5f + 0.5f * b.uv[0][v].x; /* the right half */
    }
    free(b.uv[1]);
    b.uv[1] = NULL;
    uint32_t mi[2];
    assert_int_equal(lx_scene_add_mesh(scene, &a, &mi[0]), LX_OK);
    assert_int_equal(lx_scene_add_mesh(scene, &b, &mi[1]), LX_OK);
    lx_test_mesh_free(&a);
    lx_test_mesh_free(&b);
    lx_mat4 id = lx_mat4_identity();
    assert_int_equal(lx_scene_add_node(scene, "pair", &id, mi, 2, NULL), LX_OK);
    lx_bake_desc desc = {.resolution = RES, .threads = 2};
    lx_baker *baker;
    warn_no_uv1 = warn_unused_uv1 = 0;
    lx_set_log_callback(count_uv_warnings, NULL);
    lx_status st = lx_baker_create(scene, &desc, &baker);
    lx_set_log_callback(NULL, NULL);
    assert_int_equal(st, LX_OK);
    const lx_lightmap_info *info = lx_baker_lightmap_info(baker, 0);
    assert_int_equal(info->uv_set, 0);
    assert_int_equal(info->used_texels, RES * RES);
    assert_int_equal(info->overlap_texels, 0);
    assert_int_equal(warn_no_uv1, 1);
    assert_int_equal(warn_unused_uv1, 1);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);

    scene = lx_test_new_scene("uv-sets-many");
    assert_int_equal(lx_scene_add_material(scene, &white, NULL), LX_OK);
    for (int n = 0; n < 15; n++) {
        lx_mesh m = lx_test_plane(n == 0 ? "half" : "plane", 1.0f, 0.0f, 2.0f * (float)n, 0.0f, 1);
        free(m.uv[1]);
        m.uv[1] = NULL;
        uint32_t index;
        assert_int_equal(lx_scene_add_mesh(scene, &m, &index), LX_OK);
        lx_test_mesh_free(&m);
        char name[16];
        snprintf(name, sizeof name, "n%d", n);
        assert_int_equal(lx_scene_add_node(scene, name, &id, &index, 1, NULL), LX_OK);
    }
    warn_no_uv1 = warn_more_nodes = warnings = 0;
    lx_set_log_callback(count_uv_warnings, NULL);
    st = lx_baker_create(scene, &desc, &baker);
    lx_set_log_callback(NULL, NULL);
    assert_int_equal(st, LX_OK);
    assert_int_equal(warnings, 1);
    assert_int_equal(warn_no_uv1, 1);
    assert_int_equal(warn_more_nodes, 1);
    lx_baker_destroy(baker);
    lx_scene_destroy(scene);
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(checker_radiance),
        cmocka_unit_test(normal_map_mirrored),
        cmocka_unit_test(normal_map_plain),
        cmocka_unit_test(normal_map_skewed),
        cmocka_unit_test(uvless_occluder_own_node),
        cmocka_unit_test(uvless_occluder_same_node),
        cmocka_unit_test(texcoord0_for_the_whole_node),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
