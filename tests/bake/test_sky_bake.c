/* Sky light in the baker against closed forms: a constant environment L
 * gives pi L on an open floor, unshadowed (SH) and with sky shadows (every
 * ray escapes); L = 1 + y gives pi + 2 pi / 3 facing up and pi - 2 pi / 3
 * facing down (the cosine integrals of 1 and y over a hemisphere); under a
 * square roof sky shadows take away the roof's form factor, pi L F (Lambert's
 * polygon formula); a single bright texel lights like a directional light of
 * L Omega and is shadowed by a roof; inside a closed box they give exactly 0;
 * the bytes are the same for any thread count; bad sky settings fail with a
 * message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "cube_reference.h"
#include "helpers.h"
#include "reference.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI_D 3.14159265358979323846

/* Environments for lx_test_make_env (cube_reference.h), grey. */
static void constant_env(double x, double y, double z, float out[3])
{
    (void)x, (void)y, (void)z;
    out[0] = out[1] = out[2] = 2.0f;
}

static void linear_env(double x, double y, double z, float out[3])
{
    (void)x, (void)z;
    out[0] = out[1] = out[2] = (float)(1.0 + y);
}

/* Bakes an 8x8 map of a 1 m floor (node 0; facing down when `down`) with
 * optional extra meshes, lit by the sky alone. */
static lx_baker *bake_sky(const lx_cubemap *env, bool shadows, uint32_t samples, bool down,
                          lx_mesh *extra, int extra_count, int threads, lx_image *out)
{
    lx_scene *scene = lx_test_new_scene("sky");
    lx_mesh floor = lx_test_plane("floor", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    if (down)
        for (uint32_t v = 0; v < floor.vertex_count; v++)
            floor.normals[v] = lx_v3(0.0f, -1.0f, 0.0f);
    if (down)
        for (uint32_t t = 0; t < 3 * floor.triangle_count; t += 3) {
            uint32_t k = floor.indices[t + 1];
            floor.indices[t + 1] = floor.indices[t + 2];
            floor.indices[t + 2] = k;
        }
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    for (int i = 0; i < extra_count; i++)
        lx_test_add(scene, &extra[i]);
    lx_bake_desc desc = {.resolution = 8, .padding = LX_PADDING_NONE, .threads = threads};
    desc.sky.environment = env;
    desc.sky.shadows = shadows;
    desc.sky.samples = samples;
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    lx_scene_destroy(scene);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    assert_int_equal(lx_baker_apply_alloc(baker, lx_test_map_of(baker, 0), out), LX_OK);
    return baker;
}

static void check_all(const lx_image *img, double want, double rel_tol, const char *what)
{
    double worst = 0.0;
    for (int i = 0; i < img->width * img->height * 3; i++)
        worst = fmax(worst, fabs(img->data[i] - want) / want);
    printf("%s: worst relative error %.3g%%\n", what, 100.0 * worst);
    for (int i = 0; i < img->width * img->height * 3; i++)
        if (!(fabs(img->data[i] - want) <= rel_tol * want))
            fail_msg("%s: texel value %d is %.7g, want %.7g (tolerance %g)", what, i / 3,
                     (double)img->data[i], want, rel_tol);
}

static void constant_sky_is_pi_l(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, constant_env);
    for (int shadows = 0; shadows <= 1; shadows++) {
        lx_image img;
        lx_baker *b = bake_sky(&env, shadows, 16, false, NULL, 0, 2, &img);
        /* SH: measured 8.6e-7 (float rounding of the projection's sums),
         * bound 3e-6. Rays: measured 2.8e-8, every texel the float nearest
         * 2 pi (the rounding of 2 pi itself); bound 1e-7, about one float
         * ulp at 2 pi (7.6e-8). */
        if (shadows)
            check_all(&img, 2.0 * PI_D, 1e-7, "open floor, sky shadows");
        else
            check_all(&img, 2.0 * PI_D, 3e-6, "open floor");
        lx_image_free(&img);
        lx_baker_destroy(b);
    }
    lx_cubemap_free(&env);
}

static void linear_sky_matches_cosine_integrals(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, linear_env);
    /* up: int (1 + cos t) cos t dw = pi + 2 pi / 3; down: pi - 2 pi / 3 */
    const double up = PI_D + 2.0 * PI_D / 3.0, down = PI_D - 2.0 * PI_D / 3.0;
    lx_image img;
    lx_baker *b = bake_sky(&env, false, 0, false, NULL, 0, 2, &img);
    /* measured: 1.4e-6 and 1.9e-6 (L is of band 1: the SH are exact, the
     * rest is float rounding), bounds 5e-6; with rays 7.8e-4 (1024 strata,
     * the cube's texel-centre values), bound 3e-3 */
    check_all(&img, up, 5e-6, "unshadowed, facing up");
    lx_image_free(&img);
    lx_baker_destroy(b);
    b = bake_sky(&env, false, 0, true, NULL, 0, 2, &img);
    check_all(&img, down, 5e-6, "unshadowed, facing down");
    lx_image_free(&img);
    lx_baker_destroy(b);
    /* rays: stratified over 1024 strata, the box-filtered lookup */
    b = bake_sky(&env, true, 1024, false, NULL, 0, 2, &img);
    check_all(&img, up, 3e-3, "sky shadows, facing up");
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_cubemap_free(&env);
}

/* The centre of texel (x, y) of bake_sky's 8x8 map of its 1 m floor (up):
 * lx_test_plane puts u along +x and v along +z, texel centres at
 * ((x + 0.5) / 8, (y + 0.5) / 8). */
static void floor_texel(int x, int y, double p[3])
{
    p[0] = -0.5 + (x + 0.5) / 8.0;
    p[1] = 0.0;
    p[2] = -0.5 + (y + 0.5) / 8.0;
}

/* The sky a roof hides from an up-facing floor texel: the roof, a square of
 * side `side` centred above the origin at height h, as a rect light of the
 * sky's luminance L (reference.h's catalogue form factor, pi L F). */
static double roof_blocks(const double p[3], double side, double h, double luminance)
{
    double s = side / 2.0;
    return lx_ref_rect_parallel_illuminance(-s - p[0], s - p[0], -s - p[2], s - p[2], h - p[1],
                                            luminance);
}

static void roof_takes_its_form_factor(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, constant_env);
    /* a 1 m roof 0.5 m above the floor's centre */
    lx_mesh roof = lx_test_plane("roof", 1.0f, 0.5f, 0.0f, 0.0f, 1);
    lx_image img;
    lx_baker *b = bake_sky(&env, true, 1024, false, &roof, 1, 2, &img);
    lx_test_mesh_free(&roof);
    /* the sky left over is 2 pi less the roof seen as a rect light of
     * luminance 2. Measured: within 0.63% of 2 pi (the cosine rays' noise
     * along the roof's edges); bound 2%. */
    double worst = 0.0;
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            double p[3];
            floor_texel(x, y, p);
            double blocked = roof_blocks(p, 1.0, 0.5, 2.0);
            double want = 2.0 * PI_D - blocked;
            double got = img.data[3 * (y * 8 + x)];
            assert_true(blocked > 0.2 * 2.0 * PI_D); /* the roof matters */
            worst = fmax(worst, fabs(got - want) / (2.0 * PI_D));
            if (!(fabs(got - want) <= 0.02 * 2.0 * PI_D))
                fail_msg("texel (%d, %d): %.5g, want %.5g", x, y, got, want);
        }
    printf("roof: worst error %.3g%% of pi L\n", 100.0 * worst);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_cubemap_free(&env);
}

/* A dim sky of 100 nits with a "sun": one texel of 1e7 nits on the +Y
 * face, looking up and a little toward +x. On an open floor the texel is a
 * directional light of L Omega (the seed's view of a texel): E = pi 100 +
 * L Omega cos(t). Under a roof that hides it, only the dim sky's visible
 * part is left, pi 100 - (the roof's form factor as a rect light of 100). */
static lx_cubemap sun_env(int *sun_x, int *sun_y)
{
    lx_cubemap env = lx_test_make_env(16, constant_env);
    for (size_t i = 0; i < (size_t)6 * 16 * 16 * 3; i++)
        env.data[i] = 100.0f;
    *sun_x = 9;
    *sun_y = 8;
    float *t = lx_test_cube_texel(&env, LX_FACE_PY, *sun_x, *sun_y);
    t[0] = t[1] = t[2] = 1e7f;
    return env;
}

/* Measured: the open floor within 0.13% of the closed form (the texel
 * taken whole by the peak rays, 128 of them at Halton points within it;
 * the closed form puts its light at the centre, 0.12% of the worst), bound
 * 0.5%; under the roof, with 1024 rays, within 0.58% of pi 100 (the noise
 * of the cosine rays along the roof's edges; 1.9% with 256), bound 2%. */
static void sun_texel_lights_like_a_directional_light(void **state)
{
    (void)state;
    int sx, sy;
    lx_cubemap env = sun_env(&sx, &sy);
    double d[3];
    lx_test_texel_dir(LX_FACE_PY, 16, sx, sy, d);
    double omega = lx_test_texel_omega(16, sx, sy, 64);
    double want = PI_D * 100.0 + 1e7 * omega * d[1];
    lx_image img;
    lx_baker *b = bake_sky(&env, true, 256, false, NULL, 0, 2, &img);
    check_all(&img, want, 0.005, "open floor under a sun texel");
    lx_image_free(&img);
    lx_baker_destroy(b);

    lx_mesh roof = lx_test_plane("roof", 4.0f, 0.5f, 0.0f, 0.0f, 1);
    b = bake_sky(&env, true, 1024, false, &roof, 1, 2, &img);
    lx_test_mesh_free(&roof);
    double worst = 0.0;
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            double p[3];
            floor_texel(x, y, p);
            double shaded = PI_D * 100.0 - roof_blocks(p, 4.0, 0.5, 100.0);
            double got = img.data[3 * (y * 8 + x)];
            worst = fmax(worst, fabs(got - shaded) / (PI_D * 100.0));
            if (!(fabs(got - shaded) <= 0.02 * PI_D * 100.0))
                fail_msg("texel (%d, %d) under the roof: %.5g, want %.5g", x, y, got, shaded);
        }
    printf("under the roof: worst error %.3g%% of pi 100\n", 100.0 * worst);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_cubemap_free(&env);
}

static void closed_box_is_dark(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(8, constant_env);
    lx_mesh box = lx_test_box("box", lx_v3(-2, -1, -2), lx_v3(2, 2, 2), true);
    lx_image img;
    lx_baker *b = bake_sky(&env, true, 64, false, &box, 1, 2, &img);
    lx_test_mesh_free(&box);
    for (int i = 0; i < 64 * 3; i++)
        assert_true(img.data[i] == 0.0f);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_cubemap_free(&env);
}

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, linear_env);
    lx_mesh roof = lx_test_plane("roof", 0.6f, 0.4f, 0.2f, 0.1f, 1);
    lx_image one, three;
    lx_baker *a = bake_sky(&env, true, 37, false, &roof, 1, 1, &one);
    lx_baker *b = bake_sky(&env, true, 37, false, &roof, 1, 3, &three);
    assert_memory_equal(one.data, three.data, sizeof(float) * 64 * 3);
    lx_test_mesh_free(&roof);
    lx_image_free(&one);
    lx_image_free(&three);
    lx_baker_destroy(a);
    lx_baker_destroy(b);
    lx_cubemap_free(&env);
}

static void bad_sky_settings(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(4, constant_env);
    lx_scene *scene = lx_test_new_scene("sky");
    lx_mesh floor = lx_test_plane("floor", 1.0f, 0.0f, 0.0f, 0.0f, 1);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    lx_bake_desc desc = {.resolution = 8};
    desc.sky.environment = &env;
    lx_baker *b = (lx_baker *)&desc;
    desc.sky.intensity = NAN;
    assert_int_equal(lx_baker_create(scene, &desc, &b), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "sky: intensity must be finite"));
    assert_null(b);
    desc.sky.intensity = 1.0f;
    desc.sky.samples = LX_MAX_SKY_SAMPLES + 1;
    assert_int_equal(lx_baker_create(scene, &desc, &b), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "sky: samples"));
    desc.sky.samples = 0;
    env.data[5] = NAN;
    assert_int_equal(lx_baker_create(scene, &desc, &b), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "sky"));
    lx_scene_destroy(scene);
    lx_cubemap_free(&env);
}

int main(void)
{
    lx_test_watchdog(120);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(constant_sky_is_pi_l),
        cmocka_unit_test(linear_sky_matches_cosine_integrals),
        cmocka_unit_test(roof_takes_its_form_factor),
        cmocka_unit_test(sun_texel_lights_like_a_directional_light),
        cmocka_unit_test(closed_box_is_dark),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(bad_sky_settings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
