/* Tests of the cube map geometry (src/ibl/cubemap.c) against values worked
 * out here independently: the face table of luxel/ibl.h written out again
 * in double, texel solid angles against the closed form of a rectangle's
 * solid angle (cube_reference.h) and against 4 pi for the whole sphere, direction <-> face
 * coordinates round trips, bilinear sampling that stays continuous across every cube edge (no jump
 * larger than the path's step can explain), and the equirect mapping against the documented formula
 * d = (sin t sin p, cos t, -sin t cos p), p = 2 pi (u - 0.5), t = pi v. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cube_reference.h"
#include "luxel/ibl.h"
#include "cube_reference.h"
#include "core/internal.h"

#define PI_D 3.14159265358979323846

typedef struct v3d {
    double x, y, z;
} v3d;

/* The face table of luxel/ibl.h (not normalised), sc, tc in [-1, 1]. */
static v3d table_dir(int face, double sc, double tc)
{
    v3d r;
    switch (face) {
    case 0:
        r = (v3d){1, -tc, -sc};
        break;
    case 1:
        r = (v3d){-1, -tc, sc};
        break;
    case 2:
        r = (v3d){sc, 1, tc};
        break;
    case 3:
        r = (v3d){sc, -1, -tc};
        break;
    case 4:
        r = (v3d){sc, -tc, 1};
        break;
    default:
        r = (v3d){-sc, -tc, -1};
        break;
    }
    double n = sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
    return (v3d){r.x / n, r.y / n, r.z / n};
}

static lx_vec3 to_f(v3d a)
{
    return lx_v3((float)a.x, (float)a.y, (float)a.z);
}

/* ---- solid angles ---------------------------------------------------------- */

static void test_solid_angles_sum_to_4pi(void **state)
{
    (void)state;
    const int sizes[] = {1, 2, 3, 7, 16, 64, 255};
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        int n = sizes[k];
        double sum = 0.0;
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                double w = lx_cube_texel_solid_angle(n, x, y);
                assert_true(w > 0.0);
                sum += w;
            }
        sum *= 6.0;
        /* measured: within 1.5e-13 (double sums of up to 255^2 terms),
         * bound 5e-13 */
        if (fabs(sum - 4.0 * PI_D) > 5e-13)
            fail_msg("size %d: solid angles sum to %.12f, not 4 pi", n, sum);
    }
    /* one face of size 1 is a sixth of the sphere: measured one double ulp
     * off (4.4e-16), bound two */
    assert_true(fabs(lx_cube_texel_solid_angle(1, 0, 0) - 4.0 * PI_D / 6.0) < 9e-16);
}

/* Against the closed form S(a1, b1) - S(a0, b1) - S(a1, b0) + S(a0, b0),
 * S(a, b) = atan2(a b, sqrt(a^2 + b^2 + 1)), written in cube_reference.c.
 * Measured: within 3.6e-15 relative (double rounding), bound 1e-14. */
static void test_solid_angle_matches_closed_form(void **state)
{
    (void)state;
    const int cases[][3] = {{1, 0, 0}, {2, 0, 1},   {4, 1, 2},    {8, 0, 0},   {8, 3, 4},
                            {8, 7, 0}, {32, 16, 5}, {32, 31, 31}, {64, 0, 63}, {64, 20, 40}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        int n = cases[k][0], x = cases[k][1], y = cases[k][2];
        double want = lx_test_texel_solid_angle(n, x, y);
        double got = lx_cube_texel_solid_angle(n, x, y);
        if (fabs(got - want) > 1e-14 * want)
            fail_msg("size %d texel (%d, %d): %.17g sr, closed form %.17g sr", n, x, y, got, want);
    }
    /* symmetry: mirrored texels have equal solid angles (measured: within
     * 1.1e-16, double rounding of values near 0.05; bound 4e-16) */
    for (int x = 0; x < 9; x++)
        for (int y = 0; y < 9; y++) {
            double w = lx_cube_texel_solid_angle(9, x, y);
            assert_true(fabs(w - lx_cube_texel_solid_angle(9, 8 - x, y)) < 4e-16);
            assert_true(fabs(w - lx_cube_texel_solid_angle(9, y, x)) < 4e-16);
        }
}

/* ---- directions and face coordinates ------------------------------------- */

static void test_direction_table(void **state)
{
    (void)state;
    /* Float directions: one float ulp at 1 is 1.2e-7. Face centres are the
     * axes: measured exactly, bound one ulp. */
    const double axes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 6; f++) {
        lx_vec3 d = lx_cube_direction(f, 0.5f, 0.5f);
        assert_true(fabs(d.x - axes[f][0]) < 1.2e-7 && fabs(d.y - axes[f][1]) < 1.2e-7 &&
                    fabs(d.z - axes[f][2]) < 1.2e-7);
    }
    /* every texel centre of a 5 x 5 face and some corners against the table:
     * measured within 4.6e-8, bound one ulp */
    for (int f = 0; f < 6; f++)
        for (int y = 0; y <= 5; y++)
            for (int x = 0; x <= 5; x++) {
                double s = x / 5.0, t = y / 5.0;
                v3d want = table_dir(f, 2 * s - 1, 2 * t - 1);
                lx_vec3 d = lx_cube_direction(f, (float)s, (float)t);
                if (fabs(d.x - want.x) > 1.2e-7 || fabs(d.y - want.y) > 1.2e-7 ||
                    fabs(d.z - want.z) > 1.2e-7)
                    fail_msg("face %s (%g, %g): (%g, %g, %g), want (%g, %g, %g)",
                             lx_cube_face_name(f), s, t, d.x, d.y, d.z, want.x, want.y, want.z);
            }
    /* +Y's t = 1 edge meets +Z's t = 0 edge (+Y adjoins the top of +Z):
     * measured the same floats, bound one ulp */
    lx_vec3 a = lx_cube_direction(LX_FACE_PY, 0.3f, 1.0f),
            b = lx_cube_direction(LX_FACE_PZ, 0.3f, 0.0f);
    assert_true(fabs(a.x - b.x) < 1.2e-7 && fabs(a.y - b.y) < 1.2e-7 && fabs(a.z - b.z) < 1.2e-7);
    const char *names[6] = {"px", "nx", "py", "ny", "pz", "nz"};
    for (int f = 0; f < 6; f++)
        assert_string_equal(lx_cube_face_name(f), names[f]);
}

static void test_face_coords_round_trip(void **state)
{
    (void)state;
    const int n = 37;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                float s = (x + 0.5f) / n, t = (y + 0.5f) / n;
                lx_vec3 d = lx_cube_direction(f, s, t);
                int face;
                float s2, t2;
                /* any length works; measured within 6.7e-8 of (s, t), bound
                 * 2e-7 */
                lx_cube_face_coords(lx_scale(d, 3.7f), &face, &s2, &t2);
                assert_int_equal(face, f);
                assert_true(fabsf(s2 - s) < 2e-7f && fabsf(t2 - t) < 2e-7f);
            }
    /* a direction from the table with independent face selection */
    for (int k = 0; k < 1000; k++) {
        v3d d = {lx_random(7, k, 0, 0) * 2 - 1, lx_random(7, k, 1, 0) * 2 - 1,
                 lx_random(7, k, 2, 0) * 2 - 1};
        double ax = fabs(d.x), ay = fabs(d.y), az = fabs(d.z);
        int want = ax >= ay && ax >= az ? (d.x >= 0 ? 0 : 1)
                   : ay >= az           ? (d.y >= 0 ? 2 : 3)
                                        : (d.z >= 0 ? 4 : 5);
        int face;
        float s, t;
        lx_cube_face_coords(to_f(d), &face, &s, &t);
        assert_int_equal(face, want);
        /* measured: within 6.3e-8, bound 2e-7 */
        v3d back = table_dir(face, 2.0 * s - 1.0, 2.0 * t - 1.0);
        double len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        assert_true(fabs(back.x - d.x / len) < 2e-7 && fabs(back.y - d.y / len) < 2e-7 &&
                    fabs(back.z - d.z / len) < 2e-7);
    }
}

/* ---- sampling across edges ------------------------------------------------- */

/* Random texel values in [0, 1): any seam shows as a jump. */
static void fill_random(lx_cubemap *c, uint32_t seed)
{
    size_t n = 6 * (size_t)c->size * c->size * 3;
    for (size_t i = 0; i < n; i++)
        c->data[i] = lx_random(seed, (uint32_t)i, 0, 0);
}

static void test_sampling_continuous_across_edges(void **state)
{
    (void)state;
    const int size = 8;
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, size), LX_OK);
    fill_random(&c, 11);
    /* Walk from 1.5 texels inside each edge of each face to 1.5 texels
     * beyond it (the table extended past the face), in steps of 1/400
     * texel. Bilinear values are Lipschitz with constant <= 2 per texel
     * for values in [0, 1), so a step can change a sample by at most
     * 2 / 400, the bound (measured 0.0025); a seam would jump by a good
     * part of a texel's value. */
    const int steps = 1200;
    const double texel = 2.0 / size;
    double worst = 0.0;
    for (int f = 0; f < 6; f++)
        for (int edge = 0; edge < 4; edge++)
            for (int k = 0; k < 5; k++) {
                double along = -0.85 + 0.4 * k; /* away from the corners */
                float prev[3];
                for (int i = 0; i <= steps; i++) {
                    double across = 1.0 - 1.5 * texel + 3.0 * texel * i / steps;
                    double sc = edge < 2 ? (edge == 0 ? across : -across) : along;
                    double tc = edge < 2 ? along : (edge == 2 ? across : -across);
                    v3d d = table_dir(f, sc, tc);
                    float v[3];
                    lx_cubemap_sample(&c, to_f(d), v);
                    if (i > 0)
                        for (int ch = 0; ch < 3; ch++) {
                            double jump = fabs(v[ch] - prev[ch]);
                            if (jump > worst)
                                worst = jump;
                            if (jump > 2.0 / 400.0 + 1e-6)
                                fail_msg("face %s edge %d at %g: sample jumps by %g at step %d",
                                         lx_cube_face_name(f), edge, along, jump, i);
                        }
                    memcpy(prev, v, sizeof prev);
                }
            }
    print_message("largest step change across edges: %g\n", worst);
    lx_cubemap_free(&c);
}

static void test_sampling_texel_centres(void **state)
{
    (void)state;
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, 5), LX_OK);
    fill_random(&c, 3);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < 5; y++)
            for (int x = 0; x < 5; x++) {
                float v[3];
                lx_cubemap_sample(&c, lx_cube_direction(f, (x + 0.5f) / 5, (y + 0.5f) / 5), v);
                const float *t = lx_test_cube_texel(&c, f, x, y);
                for (int k = 0; k < 3; k++)
                    assert_true(fabsf(v[k] - t[k]) < 5e-7f); /* measured 1.8e-7 */
            }
    lx_cubemap_free(&c);
}

/* lx_cubemap_texel addresses the layout ibl.h documents (faces in order,
 * rows top to bottom, 3 floats a texel), which the tests' own
 * lx_test_cube_texel writes out. */
static void test_texel_layout(void **state)
{
    (void)state;
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, 3), LX_OK);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < 3; y++)
            for (int x = 0; x < 3; x++)
                assert_ptr_equal(lx_cubemap_texel(&c, f, x, y), lx_test_cube_texel(&c, f, x, y));
    assert_ptr_equal(lx_test_cube_texel(&c, 5, 2, 2) + 3, c.data + 6 * 3 * 3 * 3);
    lx_cubemap_free(&c);
}

/* ---- equirect ------------------------------------------------------------ */

static void test_equirect_formula(void **state)
{
    (void)state;
    for (int j = 0; j <= 40; j++)
        for (int i = 0; i <= 80; i++) {
            double u = i / 80.0, v = j / 40.0;
            double p = 2 * PI_D * (u - 0.5), t = PI_D * v;
            v3d want = {sin(t) * sin(p), cos(t), -sin(t) * cos(p)};
            lx_vec3 d = lx_equirect_direction((float)u, (float)v);
            /* measured: within 3.2e-7 (u, v rounded to float), bound 1e-6 */
            if (fabs(d.x - want.x) > 1e-6 || fabs(d.y - want.y) > 1e-6 || fabs(d.z - want.z) > 1e-6)
                fail_msg("(u, v) = (%g, %g): (%g, %g, %g), want (%g, %g, %g)", u, v, d.x, d.y, d.z,
                         want.x, want.y, want.z);
        }
    /* landmarks: the centre looks down -Z, a quarter right +X, row 0 up */
    const struct {
        float u, v, x, y, z;
    } marks[] = {{0.5f, 0.5f, 0, 0, -1}, {0.75f, 0.5f, 1, 0, 0}, {0.25f, 0.5f, -1, 0, 0},
                 {0.0f, 0.5f, 0, 0, 1},  {0.5f, 0.0f, 0, 1, 0},  {0.5f, 1.0f, 0, -1, 0}};
    /* measured: within 8.7e-8 (float sin and cos of pi multiples), bound 3e-7 */
    for (size_t k = 0; k < sizeof marks / sizeof marks[0]; k++) {
        lx_vec3 d = lx_equirect_direction(marks[k].u, marks[k].v);
        assert_true(fabsf(d.x - marks[k].x) < 3e-7f && fabsf(d.y - marks[k].y) < 3e-7f &&
                    fabsf(d.z - marks[k].z) < 3e-7f);
    }
    /* and back, away from the poles and the u = 0/1 wrap: measured within
     * 1.4e-7, bound 4e-7 */
    for (int j = 1; j < 40; j++)
        for (int i = 1; i < 80; i++) {
            float u = i / 80.0f, v = j / 40.0f, u2, v2;
            lx_equirect_coords(lx_scale(lx_equirect_direction(u, v), 2.5f), &u2, &v2);
            assert_true(fabsf(u2 - u) < 4e-7f && fabsf(v2 - v) < 4e-7f);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_solid_angles_sum_to_4pi),
        cmocka_unit_test(test_solid_angle_matches_closed_form),
        cmocka_unit_test(test_direction_table),
        cmocka_unit_test(test_face_coords_round_trip),
        cmocka_unit_test(test_sampling_continuous_across_edges),
        cmocka_unit_test(test_sampling_texel_centres),
        cmocka_unit_test(test_texel_layout),
        cmocka_unit_test(test_equirect_formula),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
