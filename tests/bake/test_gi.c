/* Indirect diffuse light (lx_bake_desc.bounces) against closed forms:
 * - furnace: inside a closed box of albedo rho whose walls emit Le, the
 *   irradiance with N bounces is pi Le (1 + rho + ... + rho^N) (the walls'
 *   emission is direct light, sampled as emitters; before emitters were
 *   sampled it came with the first gather, one term fewer); under a
 *   uniform ambient A it is A (1 + rho + ... + rho^N), the geometric
 *   series of the rendering equation's Neumann expansion;
 * - an open floor under a constant sky gets no indirect light: the same
 *   bytes as without bounces (rays that escape are the sky's direct light);
 * - two facing parallel squares under an ambient: one bounce adds rho A F,
 *   F the point-to-parallel-square form factor at each texel (the corner
 *   formula summed over four rectangles; Howell's catalogue, C-11) and, on
 *   average, the square-to-square form factor (C-11's plate formula);
 * - a room lit only from outside its thick closed walls stays exactly
 *   black at every bounce count, the texels along the wall-floor junction
 *   included (the floor runs under the walls: its texels there are inside
 *   geometry, found invalid and left out);
 * - 1 and 2 threads give the same bytes; bounces 0 ignores the other GI
 *   settings; bad settings fail with a message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cube_reference.h"
#include "gltf_writer.h"
#include "helpers.h"
#include "texture_oracle.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_D 3.14159265358979323846

static lx_baker *bake(lx_scene *scene, lx_bake_desc *desc)
{
    lx_baker *b;
    assert_int_equal(lx_baker_create(scene, desc, &b), LX_OK);
    assert_int_equal(lx_baker_bake(b), LX_OK);
    return b;
}

/* Worst relative error of every covered texel of map against want. */
static double worst_error(const lx_baker *b, uint32_t map, double want)
{
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    const uint8_t *mask = lx_baker_mask(b, map);
    double worst = 0.0;
    for (int p = 0; p < img.width * img.height; p++)
        for (int c = 0; c < 3 && mask[p]; c++)
            worst = fmax(worst, fabs(img.data[3 * p + c] - want) / want);
    lx_image_free(&img);
    return worst;
}

static lx_scene *furnace_scene(float rho, float le, float ambient)
{
    lx_scene *scene = lx_test_new_scene("furnace");
    uint32_t mat = lx_test_grey_material(scene, "walls", rho, le);
    lx_mesh box = lx_test_box("box", lx_v3(-1, -1, -1), lx_v3(1, 1, 1), true);
    lx_test_add_with_material(scene, &box, mat);
    scene->ambient = lx_v3(ambient, ambient, ambient);
    return scene;
}

static void furnace_emitter_is_a_geometric_series(void **state)
{
    (void)state;
    const float rho = 0.6f, le = 2.0f;
    for (int n = 1; n <= 4; n++) {
        lx_scene *scene = furnace_scene(rho, le, 0.0f);
        lx_bake_desc d = {.resolution = 24, .bounces = n, .gi_samples = 16, .threads = 2};
        lx_baker *b = bake(scene, &d);
        lx_scene_destroy(scene);
        double series = 0.0;
        for (int k = 0; k <= n; k++)
            series += pow(rho, k);
        double want = PI_D * le * series;
        double worst = worst_error(b, 0, want);
        printf("furnace, emitter, %d bounces: want %.6g, worst relative error %.3g\n", n, want,
               worst);
        /* every ray hits a uniform wall and every emitter sample is
         * visible (the emitters' exact part is all): only float rounding;
         * measured below 1e-6 */
        assert_true(worst < 1e-5);
        lx_baker_destroy(b);
    }
}

static void furnace_ambient_is_a_geometric_series(void **state)
{
    (void)state;
    const float rho = 0.8f, a = 3.0f;
    for (int n = 0; n <= 3; n++) {
        lx_scene *scene = furnace_scene(rho, 0.0f, a);
        lx_bake_desc d = {.resolution = 24, .bounces = n, .gi_samples = 9, .threads = 2};
        lx_baker *b = bake(scene, &d);
        lx_scene_destroy(scene);
        double series = 0.0;
        for (int k = 0; k <= n; k++)
            series += pow(rho, k);
        double worst = worst_error(b, 0, a * series);
        printf("furnace, ambient, %d bounces: want %.6g, worst relative error %.3g\n", n,
               a * series, worst);
        assert_true(worst < 1e-5);
        lx_baker_destroy(b);
    }
}

/* The emissive scale multiplies the emitters (pi Le (1 + rho), one bounce). */
static void emissive_scale_scales_emitters(void **state)
{
    (void)state;
    lx_scene *scene = furnace_scene(0.5f, 1.0f, 0.0f);
    lx_bake_desc d = {.resolution = 16, .bounces = 1, .gi_samples = 4, .emissive_scale = 250.0f};
    lx_baker *b = bake(scene, &d);
    lx_scene_destroy(scene);
    assert_true(worst_error(b, 0, PI_D * 250.0 * 1.5) < 1e-5);
    lx_baker_destroy(b);
}

/* Emission = factor x texture: a constant 0.5 emissive texture on the
 * furnace's walls halves its light (pi Le 0.5 (1 + rho), one bounce). */
static void emissive_texture_scales_emission(void **state)
{
    (void)state;
    lx_scene *scene = furnace_scene(0.5f, 3.0f, 0.0f);
    lx_material *mat = &scene->materials[0];
    assert_int_equal(lx_image_alloc(&mat->emissive_map, 2, 2, 4), LX_OK);
    for (int i = 0; i < 16; i++)
        mat->emissive_map.data[i] = (i % 4) == 3 ? 1.0f : 0.5f;
    lx_bake_desc d = {.resolution = 16, .bounces = 1, .gi_samples = 4};
    lx_baker *b = bake(scene, &d);
    lx_scene_destroy(scene);
    double worst = worst_error(b, 0, PI_D * 3.0 * 0.5 * 1.5);
    printf("emissive texture: worst relative error %.3g\n", worst);
    assert_true(worst < 1e-5);
    lx_baker_destroy(b);
}

/* The loader reads emissiveTexture, its texCoord and KHR_texture_transform,
 * and emissiveFactor x emissiveStrength: the glTF spec's meaning of each. */
static void loader_reads_the_emissive_texture(void **state)
{
    (void)state;
    const char *dir = lx_test_dir("gi_emissive");
    char png[1024], path[1024];
    snprintf(png, sizeof png, "%s/glow.png", dir);
    /* sRGB 188 is linear 0.5029 (IEC 61966-2-1: ((188/255 + 0.055) / 1.055)^2.4) */
    uint8_t px[4 * 3];
    for (int i = 0; i < 12; i++)
        px[i] = 188;
    lx_test_write_png(png, 2, 2, 3, px);
    lx_test_quad q = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {{{0, 0}, {1, 0}, {0, 1}}, {{0, 0}, {1, 0}, {0, 1}}}};
    snprintf(path, sizeof path, "%s/glow.gltf", dir);
    const char *uri = "glow.png";
    lx_test_write_quad_gltf(
        path, &q,
        "{\"emissiveFactor\":[1,0.5,0.25],\"emissiveTexture\":{\"index\":0,\"texCoord\":0,"
        "\"extensions\":{\"KHR_texture_transform\":{\"offset\":[0.25,0.5],\"texCoord\":1}}},"
        "\"extensions\":{\"KHR_materials_emissive_strength\":{\"emissiveStrength\":40}}}",
        &uri, 1, NULL);
    lx_scene *scene;
    assert_int_equal(lx_scene_load(path, NULL, &scene), LX_OK);
    const lx_material *m = &scene->materials[scene->meshes[0].material];
    lx_test_assert_vec3(m->emissive, 40.0, 20.0, 10.0);
    assert_int_equal(m->emissive_map.width, 2);
    double linear = pow((188.0 / 255.0 + 0.055) / 1.055, 2.4);
    assert_true(fabs(m->emissive_map.data[0] - linear) < 1e-4);
    assert_int_equal(m->emissive_uv_set, 1);
    assert_true(m->emissive_transform.enabled);
    assert_true(fabs(m->emissive_transform.offset.x - 0.25f) < 1e-7f);
    assert_true(fabs(m->emissive_transform.offset.y - 0.5f) < 1e-7f);
    assert_non_null(m->emissive_map_path);
    lx_scene_destroy(scene);
}

/* The bytes of every lightmap of a baker. */
static float *all_bytes(const lx_baker *b, size_t *count)
{
    size_t total = 0;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++) {
        const lx_lightmap_info *info = lx_baker_lightmap_info(b, m);
        total += (size_t)info->width * info->height * 3;
    }
    float *out = malloc(sizeof(float) * total);
    size_t at = 0;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++) {
        lx_image img;
        assert_int_equal(lx_baker_apply_alloc(b, m, &img), LX_OK);
        size_t n = (size_t)img.width * img.height * 3;
        memcpy(out + at, img.data, sizeof(float) * n);
        at += n;
        lx_image_free(&img);
    }
    *count = total;
    return out;
}

static void constant_env(double x, double y, double z, float out[3])
{
    (void)x, (void)y, (void)z;
    out[0] = out[1] = out[2] = 2.0f;
}

static void open_floor_under_sky_gets_no_indirect(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, constant_env);
    for (int shadows = 0; shadows <= 1; shadows++) {
        float *bytes[2];
        size_t count[2];
        for (int bounces = 0; bounces <= 2; bounces += 2) {
            lx_scene *scene = lx_test_new_scene("open");
            lx_mesh floor = lx_test_plane("floor", 1.0f, 0.0f, 0.0f, 0.0f, 1);
            lx_test_add_with_material(scene, &floor,
                                      lx_test_grey_material(scene, "white", 1.0f, 0.0f));
            lx_bake_desc d = {.resolution = 8, .bounces = bounces, .gi_samples = 16};
            d.sky.environment = &env;
            d.sky.shadows = shadows;
            d.sky.samples = 16;
            lx_baker *b = bake(scene, &d);
            lx_scene_destroy(scene);
            bytes[bounces / 2] = all_bytes(b, &count[bounces / 2]);
            lx_baker_destroy(b);
        }
        assert_int_equal(count[0], count[1]);
        assert_memory_equal(bytes[0], bytes[1], sizeof(float) * count[0]);
        /* and the sky's pi L is there */
        assert_true(fabs(bytes[1][0] - 2.0 * PI_D) < 1e-4 * 2.0 * PI_D);
        free(bytes[0]);
        free(bytes[1]);
    }
    lx_cubemap_free(&env);
}

/* ... to the rectangle [x0, x1] x [z0, z1] straight across from (px, pz),
 * inside it: four corner rectangles. */
static double point_factor(double px, double pz, double x0, double x1, double z0, double z1,
                           double c)
{
    return lx_test_corner_form_factor(px - x0, pz - z0, c) +
           lx_test_corner_form_factor(x1 - px, pz - z0, c) +
           lx_test_corner_form_factor(px - x0, z1 - pz, c) +
           lx_test_corner_form_factor(x1 - px, z1 - pz, c);
}

/* Between equal parallel rectangles a x b, c apart (Howell C-11). */
static double plate_factor(double a, double b, double c)
{
    double x = a / c, y = b / c;
    double sx = sqrt(1.0 + x * x), sy = sqrt(1.0 + y * y);
    double t = 0.5 * log((1.0 + x * x) * (1.0 + y * y) / (1.0 + x * x + y * y)) +
               x * sy * atan(x / sy) + y * sx * atan(y / sx) - x * atan(x) - y * atan(y);
    return 2.0 * t / (PI_D * x * y);
}

static void facing_squares_match_the_form_factor(void **state)
{
    (void)state;
    const float rho = 0.5f, a = 4.0f, side = 1.0f, gap = 1.0f;
    const int res = 16;
    lx_scene *scene = lx_test_new_scene("plates");
    lx_mesh lower = lx_test_plane("lower", side, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add_with_material(scene, &lower, lx_test_grey_material(scene, "white", 1.0f, 0.0f));
    lx_mesh upper = lx_test_plane("upper", side, gap, 0.0f, 0.0f, 1);
    for (uint32_t v = 0; v < upper.vertex_count; v++)
        upper.normals[v] = lx_v3(0.0f, -1.0f, 0.0f);
    for (uint32_t t = 0; t < 3 * upper.triangle_count; t += 3) {
        uint32_t k = upper.indices[t + 1];
        upper.indices[t + 1] = upper.indices[t + 2];
        upper.indices[t + 2] = k;
    }
    lx_test_add_with_material(scene, &upper, lx_test_grey_material(scene, "grey", rho, 0.0f));
    scene->ambient = lx_v3(a, a, a);
    lx_bake_desc d = {.resolution = res, .bounces = 1, .gi_samples = 1024};
    lx_baker *b = bake(scene, &d);
    lx_scene_destroy(scene);
    uint32_t map = lx_test_map_of(b, 0);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(b, map, &img), LX_OK);
    double sum = 0.0, worst = 0.0, square = 0.0;
    int n = 0;
    for (int y = 0; y < res; y++)
        for (int x = 0; x < res; x++) {
            lx_texel_sample s;
            assert_true(lx_baker_texel(b, map, x, y, &s));
            double f = point_factor(s.position.x, s.position.z, -0.5, 0.5, -0.5, 0.5, gap);
            double want = a * rho * f;
            double got = img.data[3 * ((size_t)y * res + x)] - a;
            worst = fmax(worst, fabs(got - want) / want);
            square += (got - want) * (got - want) / (want * want);
            sum += got;
            n++;
        }
    double mean = sum / n, plate = a * rho * plate_factor(side, side, gap);
    double rms = sqrt(square / n);
    printf("facing squares: bounce mean %.6g, plate form factor gives %.6g (%.3g%%); texels off "
           "their point form factor by %.3g%% rms, %.3g%% at worst\n",
           mean, plate, 100.0 * fabs(mean - plate) / plate, 100.0 * rms, 100.0 * worst);
    /* 1024 stratified rays a texel, each a hit or a miss of the square (F
     * about 0.16: unstratified, 7% noise): measured 1.5% rms, 5.1% at
     * worst, bounds 2.5% and 8%; the mean also carries the midpoint rule's
     * error over 16x16 texels, measured 0.09%, bound 0.5% */
    assert_true(rms < 0.025);
    assert_true(worst < 0.08);
    assert_true(fabs(mean - plate) < 0.005 * plate);
    lx_image_free(&img);
    lx_baker_destroy(b);
}

/* A room (interior [-1,1] x [0,1.5] x [-1,1]) of 0.3 m thick closed walls
 * and ceiling standing on a 6 m floor that runs under them, lit by a
 * directional light from outside. */
static lx_scene *leak_scene(void)
{
    lx_scene *scene = lx_test_new_scene("leak");
    uint32_t white = lx_test_grey_material(scene, "white", 0.8f, 0.0f);
    lx_mesh floor = lx_test_plane("floor", 6.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add_with_material(scene, &floor, white);
    const float lo[5][3] = {{-1.3f, -0.1f, -1.3f},
                            {1.0f, -0.1f, -1.3f},
                            {-1.0f, -0.1f, -1.3f},
                            {-1.0f, -0.1f, 1.0f},
                            {-1.3f, 1.5f, -1.3f}};
    const float hi[5][3] = {
        {-1.0f, 1.6f, 1.3f}, {1.3f, 1.6f, 1.3f}, {1.0f, 1.6f, -1.0f}, {1.0f, 1.6f, 1.3f},
        {1.3f, 1.8f, 1.3f}};
    const char *names[5] = {"wall_w", "wall_e", "wall_n", "wall_s", "ceiling"};
    for (int k = 0; k < 5; k++) {
        lx_mesh box = lx_test_box(names[k], lx_v3(lo[k][0], lo[k][1], lo[k][2]),
                                  lx_v3(hi[k][0], hi[k][1], hi[k][2]), false);
        lx_test_add_with_material(scene, &box, white);
    }
    lx_light sun = lx_light_defaults(LX_LIGHT_DIRECTIONAL);
    sun.direction = lx_normalize(lx_v3(0.5f, -1.0f, 0.3f));
    sun.intensity = 1000.0f;
    sun.shadow = LX_SHADOW_HARD;
    assert_int_equal(lx_scene_add_light(scene, &sun), LX_OK);
    return scene;
}

static void room_lit_from_outside_stays_black(void **state)
{
    (void)state;
    for (int bounces = 0; bounces <= 3; bounces++) {
        lx_scene *scene = leak_scene();
        lx_bake_desc d = {.resolution = 64,
                          .bounces = bounces,
                          .gi_samples = 64,
                          .padding = LX_PADDING_RECOMMENDED};
        lx_baker *b = bake(scene, &d);
        lx_scene_destroy(scene);
        uint64_t inside = 0, junction = 0, lit_outside = 0;
        for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++) {
            const lx_lightmap_info *info = lx_baker_lightmap_info(b, m);
            lx_image img;
            assert_int_equal(lx_baker_apply_alloc(b, m, &img), LX_OK);
            for (int y = 0; y < info->height; y++)
                for (int x = 0; x < info->width; x++) {
                    lx_texel_sample s;
                    if (!lx_baker_texel(b, m, x, y, &s))
                        continue;
                    const float *v = img.data + 3 * ((size_t)y * info->width + x);
                    lx_vec3 p = s.position;
                    const float e = 1e-4f;
                    bool in = p.x > -1.0f - e && p.x < 1.0f + e && p.z > -1.0f - e &&
                              p.z < 1.0f + e && p.y > -e && p.y < 1.5f + e;
                    if (in) {
                        inside++;
                        /* the floor's texels within a texel of a wall */
                        junction += p.y < e && (fabsf(p.x) > 0.9f || fabsf(p.z) > 0.9f);
                        if (v[0] != 0.0f || v[1] != 0.0f || v[2] != 0.0f)
                            fail_msg("%d bounces: map %u texel (%d, %d) at (%g, %g, %g) inside "
                                     "the room is %g, not 0",
                                     bounces, m, x, y, (double)p.x, (double)p.y, (double)p.z,
                                     (double)v[0]);
                    } else if (v[0] > 0.0f) {
                        lit_outside++;
                    }
                }
            lx_image_free(&img);
        }
        printf("%d bounces: %llu texels inside (%llu along the junction) black; %llu lit "
               "outside\n",
               bounces, (unsigned long long)inside, (unsigned long long)junction,
               (unsigned long long)lit_outside);
        assert_true(inside > 1000);
        assert_true(junction > 50);
        assert_true(lit_outside > 1000);
        lx_baker_destroy(b);
    }
}

/* The outside floor next to a lit wall gets more light with bounces. */
static void bounces_add_light_outside(void **state)
{
    (void)state;
    double mean[2];
    for (int k = 0; k < 2; k++) {
        lx_scene *scene = leak_scene();
        lx_bake_desc d = {.resolution = 32, .bounces = k, .gi_samples = 32};
        lx_baker *b = bake(scene, &d);
        lx_scene_destroy(scene);
        lx_image img;
        assert_int_equal(lx_baker_apply_alloc(b, lx_test_map_of(b, 0), &img), LX_OK);
        double s = 0.0;
        for (int p = 0; p < img.width * img.height; p++)
            s += img.data[3 * p];
        mean[k] = s;
        lx_image_free(&img);
        lx_baker_destroy(b);
    }
    assert_true(mean[1] > mean[0] * 1.001);
}

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    float *bytes[2];
    size_t count[2];
    for (int t = 1; t <= 2; t++) {
        lx_scene *scene = leak_scene();
        lx_bake_desc d = {.resolution = 32, .bounces = 2, .gi_samples = 16, .threads = t,
                          .padding = 2};
        lx_baker *b = bake(scene, &d);
        lx_scene_destroy(scene);
        bytes[t - 1] = all_bytes(b, &count[t - 1]);
        lx_baker_destroy(b);
    }
    assert_int_equal(count[0], count[1]);
    assert_memory_equal(bytes[0], bytes[1], sizeof(float) * count[0]);
    free(bytes[0]);
    free(bytes[1]);
}

/* bounces 0 is the direct bake, whatever the bounces' settings say
 * (without emitters: their shadow rays follow gi_samples). */
static void zero_bounces_is_the_direct_bake(void **state)
{
    (void)state;
    float *bytes[2];
    size_t count[2];
    for (int k = 0; k < 2; k++) {
        lx_scene *scene = leak_scene();
        lx_bake_desc d = {.resolution = 32, .padding = 2};
        if (k) {
            d.gi_samples = 7;
            d.emissive_scale = 3.0f;
        }
        lx_baker *b = bake(scene, &d);
        lx_scene_destroy(scene);
        bytes[k] = all_bytes(b, &count[k]);
        lx_baker_destroy(b);
    }
    assert_int_equal(count[0], count[1]);
    assert_memory_equal(bytes[0], bytes[1], sizeof(float) * count[0]);
    free(bytes[0]);
    free(bytes[1]);
}

static void bad_settings_fail(void **state)
{
    (void)state;
    lx_scene *scene = furnace_scene(0.5f, 1.0f, 0.0f);
    lx_baker *b = NULL;
    lx_bake_desc d = {.bounces = -1};
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "bounces"));
    d = (lx_bake_desc){.bounces = LX_MAX_BOUNCES + 1};
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_INVALID);
    d = (lx_bake_desc){.bounces = 1, .gi_samples = LX_MAX_GI_SAMPLES + 1};
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "gi samples"));
    d = (lx_bake_desc){.bounces = 1, .emissive_scale = -1.0f};
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_INVALID);
    d = (lx_bake_desc){.bounces = 1, .emissive_scale = NAN};
    assert_int_equal(lx_baker_create(scene, &d, &b), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "emissive scale"));
    assert_null(b);
    lx_scene_destroy(scene);
}

int main(void)
{
    lx_test_watchdog(600);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(furnace_emitter_is_a_geometric_series),
        cmocka_unit_test(furnace_ambient_is_a_geometric_series),
        cmocka_unit_test(emissive_scale_scales_emitters),
        cmocka_unit_test(emissive_texture_scales_emission),
        cmocka_unit_test(loader_reads_the_emissive_texture),
        cmocka_unit_test(open_floor_under_sky_gets_no_indirect),
        cmocka_unit_test(facing_squares_match_the_form_factor),
        cmocka_unit_test(room_lit_from_outside_stays_black),
        cmocka_unit_test(bounces_add_light_outside),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(zero_bounces_is_the_direct_bake),
        cmocka_unit_test(bad_settings_fail),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
