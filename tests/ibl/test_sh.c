/* Tests of order-2 spherical harmonics (src/ibl/sh.c) against values
 * worked out here by hand: the coefficients of polynomial environments
 * from the sphere's moments (the integral of x^2 is 4 pi / 3, of x^4
 * 4 pi / 5, of x^2 y^2 4 pi / 15), the irradiance of a constant
 * environment (pi L) and of band-limited ones from the Funk-Hecke factors
 * of the clamped cosine (A0 = pi, A1 = 2 pi / 3, A2 = pi / 4), the basis'
 * orthonormality, the reconstruction against the irradiance of a smooth
 * environment integrated here (mean and worst error), the same results
 * for any thread count, progress, cancellation, and bad input. Every
 * check compares each value, so each bound is a worst case. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cube_reference.h"
#include "helpers.h"
#include "luxel/ibl.h"

#define PI_D 3.14159265358979323846

/* A set of unit directions spread over the sphere (golden spiral). */
static lx_vec3 spiral(int i, int n)
{
    double z = 1.0 - (2.0 * i + 1.0) / n, r = sqrt(1.0 - z * z);
    double phi = i * PI_D * (3.0 - sqrt(5.0));
    return lx_v3((float)(r * cos(phi)), (float)z, (float)(r * sin(phi)));
}

static void env_constant(double x, double y, double z, float out[3])
{
    (void)x, (void)y, (void)z;
    out[0] = 0.5f, out[1] = 1.0f, out[2] = 2.0f;
}

/* channel 0: 1 + y; channel 1: x^2; channel 2: x z + z / 2 */
static void env_poly(double x, double y, double z, float out[3])
{
    out[0] = (float)(1.0 + y);
    out[1] = (float)(x * x);
    out[2] = (float)(x * z + 0.5 * z);
}

/* ---- coefficients ------------------------------------------------------- */

static void constant_environment_gives_pi_l(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, env_constant);
    lx_sh9 sh;
    assert_int_equal(lx_sh_project(&env, NULL, &sh), LX_OK);
    const double L[3] = {0.5, 1.0, 2.0};
    /* measured: within 8.6e-7 relative (float rounding), bound 3e-6 */
    for (int i = 0; i < 200; i++) {
        float e[3];
        lx_sh_irradiance(&sh, spiral(i, 200), e);
        for (int c = 0; c < 3; c++)
            assert_true(fabs(e[c] / (PI_D * L[c]) - 1.0) < 3e-6);
    }
    lx_cubemap irr;
    assert_int_equal(lx_sh_irradiance_cube(&sh, 8, NULL, &irr), LX_OK);
    assert_int_equal(irr.size, 8);
    for (size_t i = 0; i < 6 * 8 * 8 * 3; i++)
        assert_true(fabs(irr.data[i] / (PI_D * L[i % 3]) - 1.0) < 3e-6);
    lx_cubemap_free(&irr);
    lx_cubemap_free(&env);
}

/* The coefficients of env_poly from the sphere's moments:
 *   int 1 = 4pi, int x^2 = 4pi/3, int x^4 = 4pi/5, int x^2 z^2 = 4pi/15,
 * odd moments vanish. */
static void polynomial_environment_coefficients(void **state)
{
    (void)state;
    const double s = 4.0 * PI_D, m2 = s / 3.0, m4 = s / 5.0, m22 = s / 15.0;
    double want[9][3] = {{0}};
    /* 1 + y */
    want[0][0] = 0.282095 * s;
    want[1][0] = 0.488603 * m2;
    /* x^2 */
    want[0][1] = 0.282095 * m2;
    want[6][1] = 0.315392 * (3.0 * m22 - m2);
    want[8][1] = 0.546274 * (m4 - m22);
    /* x z + z / 2 */
    want[2][2] = 0.5 * 0.488603 * m2;
    want[7][2] = 1.092548 * m22;

    lx_cubemap env = lx_test_make_env(64, env_poly);
    lx_sh9 sh;
    assert_int_equal(lx_sh_project(&env, NULL, &sh), LX_OK);
    /* measured: within 4.7e-5 (1 + |want|) (the 64^2 faces' texel-centre
     * values against the exact moments), bound 2e-4 */
    for (int k = 0; k < 9; k++)
        for (int c = 0; c < 3; c++) {
            double err = fabs(sh.c[k][c] - want[k][c]);
            if (err > 2e-4 * (1.0 + fabs(want[k][c])))
                fail_msg("L[%d] channel %d: %.6f, expected %.6f", k, c, sh.c[k][c], want[k][c]);
        }
    lx_cubemap_free(&env);
}

/* Band-limited environments have exact SH irradiance (Funk-Hecke):
 *   1 + y  ->  pi + (2 pi / 3) n_y
 *   x^2 = 1/3 + (x^2 - 1/3)  ->  pi / 3 + (pi / 4)(n_x^2 - 1/3)
 *   x z + z / 2  ->  (pi / 4) n_x n_z + (2 pi / 3) n_z / 2 */
static void band_limited_irradiance_closed_form(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(64, env_poly);
    lx_sh9 sh;
    assert_int_equal(lx_sh_project(&env, NULL, &sh), LX_OK);
    /* measured: within 2.0e-5 (1 + |want|) (the projection's discretisation,
     * as above), bound 6e-5 */
    for (int i = 0; i < 300; i++) {
        lx_vec3 n = spiral(i, 300);
        double want[3] = {PI_D + 2.0 * PI_D / 3.0 * n.y,
                          PI_D / 3.0 + PI_D / 4.0 * (n.x * n.x - 1.0 / 3.0),
                          PI_D / 4.0 * n.x * n.z + PI_D / 3.0 * n.z};
        float e[3];
        lx_sh_irradiance(&sh, n, e);
        for (int c = 0; c < 3; c++)
            if (fabs(e[c] - want[c]) > 6e-5 * (1.0 + fabs(want[c])))
                fail_msg("n (%.3f %.3f %.3f) channel %d: %.6f, expected %.6f", n.x, n.y, n.z, c,
                         e[c], want[c]);
    }
    lx_cubemap_free(&env);
}

/* sum over a fine cube of Y_i Y_j dOmega = delta_ij (to the constants' six
 * digits); solid angles from a midpoint rule of dA / (1+a^2+b^2)^(3/2).
 * Measured: within 1.6e-4 (the midpoint rule on 48^2 faces), bound 5e-4. */
static void basis_is_orthonormal(void **state)
{
    (void)state;
    const int n = 48;
    double g[9][9] = {{0}};
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                double a = 2.0 * (x + 0.5) / n - 1.0, b = 2.0 * (y + 0.5) / n - 1.0, d[3];
                double w = (2.0 / n) * (2.0 / n) / pow(1.0 + a * a + b * b, 1.5);
                lx_test_face_dir(f, a, b, d);
                float yv[9];
                lx_sh9_basis(lx_v3((float)d[0], (float)d[1], (float)d[2]), yv);
                for (int i = 0; i < 9; i++)
                    for (int j = 0; j < 9; j++)
                        g[i][j] += w * yv[i] * yv[j];
            }
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 9; j++)
            if (fabs(g[i][j] - (i == j)) > 5e-4)
                fail_msg("<Y%d, Y%d> = %.6f", i, j, g[i][j]);
    /* and the paper's values at +z: Y10 = 0.488603, Y20 = 2 * 0.315392 */
    float yv[9];
    lx_sh9_basis(lx_v3(0, 0, 1), yv);
    assert_float_equal(yv[2], 0.488603f, 1e-6f);
    assert_float_equal(yv[6], 0.630784f, 1e-6f);
    lx_sh9_basis(lx_v3(1, 0, 0), yv);
    assert_float_equal(yv[3], 0.488603f, 1e-6f);
    assert_float_equal(yv[8], 0.546274f, 1e-6f);
    assert_float_equal(lx_sh_irradiance_constants[0], 0.429043f, 0.0f);
    assert_float_equal(lx_sh_irradiance_constants[4], 0.247708f, 0.0f);
}

/* a sky: bright up, a broad warm lobe, a darker ground */
static void env_smooth(double x, double y, double z, float out[3])
{
    double lobe = exp(4.0 * (0.6 * x + 0.64 * y + 0.48 * z - 1.0));
    out[0] = (float)(1.0 + 0.6 * y + 5.0 * lobe);
    out[1] = (float)(1.2 + 0.5 * y + 3.0 * lobe + 0.3 * x * z);
    out[2] = (float)(2.0 + 0.9 * y + 1.0 * lobe);
}

/* The irradiance of env_smooth at unit n, integrated here on the function
 * itself: a 96 x 96 midpoint rule per face, cube_reference's directions
 * and solid angles (it differs from 192 x 192 by at most 2.5e-5). */
static void smooth_irradiance(const double n[3], double out[3])
{
    const int m = 96;
    double sum[3] = {0, 0, 0};
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < m; y++)
            for (int x = 0; x < m; x++) {
                double d[3];
                lx_test_texel_dir(f, m, x, y, d);
                double c = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
                if (c <= 0.0)
                    continue;
                double a = 2.0 * (x + 0.5) / m - 1.0, b = 2.0 * (y + 0.5) / m - 1.0;
                double w = c * (2.0 / m) * (2.0 / m) / pow(1.0 + a * a + b * b, 1.5);
                float l[3];
                env_smooth(d[0], d[1], d[2], l);
                for (int k = 0; k < 3; k++)
                    sum[k] += w * l[k];
            }
    for (int k = 0; k < 3; k++)
        out[k] = sum[k];
}

/* Order-2 SH of a smooth sky against its true irradiance: what is left is
 * the truncation of the clamped cosine beyond band 2 (Ramamoorthi and
 * Hanrahan bound it near 3% of the mean for any environment). Measured over
 * 150 normals and 3 channels: mean 0.23%, worst 2.3% (on the dark side,
 * where the irradiance is smallest); bounds 0.5% and 5%. */
static void reconstruction_matches_true_irradiance(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, env_smooth);
    lx_sh9 sh;
    assert_int_equal(lx_sh_project(&env, NULL, &sh), LX_OK);
    double sum = 0.0, worst = 0.0;
    int count = 0;
    for (int i = 0; i < 150; i++) {
        lx_vec3 n = spiral(i, 150);
        double nd[3] = {n.x, n.y, n.z}, want[3];
        smooth_irradiance(nd, want);
        float e[3];
        lx_sh_irradiance(&sh, n, e);
        for (int c = 0; c < 3; c++) {
            double rel = fabs(e[c] - want[c]) / want[c];
            sum += rel;
            worst = rel > worst ? rel : worst;
            count++;
        }
    }
    printf("SH vs the true irradiance: mean %.3f%%, worst %.3f%%\n", 100.0 * sum / count,
           100.0 * worst);
    assert_true(sum / count < 0.005);
    assert_true(worst < 0.05);
    lx_cubemap_free(&env);
}

/* The same coefficients and cube for 1, 2 and 3 threads; progress up to
 * 1; a cancelled projection leaves zeros, a cancelled cube nothing. */
static void threads_progress_cancel(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(40, env_smooth), irr[3];
    lx_sh9 sh[3];
    for (int t = 0; t < 3; t++) {
        lx_ibl_desc d = {.threads = t + 1};
        assert_int_equal(lx_sh_project(&env, &d, &sh[t]), LX_OK);
        assert_int_equal(lx_sh_irradiance_cube(&sh[0], 12, &d, &irr[t]), LX_OK);
    }
    for (int t = 1; t < 3; t++) {
        assert_memory_equal(&sh[0], &sh[t], sizeof sh[0]);
        assert_memory_equal(irr[0].data, irr[t].data, sizeof(float) * 6 * 12 * 12 * 3);
    }
    for (int t = 0; t < 3; t++)
        lx_cubemap_free(&irr[t]);

    lx_test_progress p = lx_test_progress_make(0);
    lx_ibl_desc d = {.threads = 2, .progress = lx_test_progress_fn, .progress_user = &p};
    assert_int_equal(lx_sh_project(&env, &d, &sh[1]), LX_OK);
    assert_true(p.calls >= 2 && p.monotone);
    assert_float_equal(p.last, 1.0f, 0.0f);
    p = lx_test_progress_make(0);
    assert_int_equal(lx_sh_irradiance_cube(&sh[0], 12, &d, &irr[0]), LX_OK);
    assert_true(p.calls >= 2 && p.monotone);
    assert_float_equal(p.last, 1.0f, 0.0f);
    lx_cubemap_free(&irr[0]);

    p = lx_test_progress_make(2);
    assert_int_equal(lx_sh_project(&env, &d, &sh[1]), LX_ERR_CANCELLED);
    assert_non_null(strstr(lx_last_error(), "SH projection cancelled"));
    for (int k = 0; k < 9; k++)
        assert_true(sh[1].c[k][0] == 0.0f && sh[1].c[k][1] == 0.0f && sh[1].c[k][2] == 0.0f);
    p = lx_test_progress_make(2);
    assert_int_equal(lx_sh_irradiance_cube(&sh[0], 12, &d, &irr[0]), LX_ERR_CANCELLED);
    assert_null(irr[0].data);
    lx_cubemap_free(&env);
}

/* ---- no clamping, bad input -------------------------------------------- */

static char g_log[512];
static void keep_log(void *user, lx_log_level level, const char *msg)
{
    (void)user;
    if (level == LX_LOG_WARN)
        snprintf(g_log, sizeof g_log, "%s", msg);
}

/* A small bright light rings below zero. By the addition theorem, a
 * texel of radiance L and solid angle W along c projects to coefficients
 * whose irradiance is L W sum_l A_l (2l+1)/(4 pi) P_l(n.c):
 *   L W (1/4 + (n.c)/2 + (5/32)(3 (n.c)^2 - 1)),
 * lowest at n.c = -8/15 (-0.040, 3.7% of the 1.0625 peak). The values are
 * kept and a warning counts them. */
static double point_light_sh(double c)
{
    return 0.25 + 0.5 * c + 5.0 / 32.0 * (3.0 * c * c - 1.0);
}

static void ringing_is_kept_and_reported(void **state)
{
    (void)state;
    const int n = 8;
    lx_cubemap env;
    assert_int_equal(lx_cubemap_alloc(&env, n), LX_OK);
    /* the four texels around +Y's centre: a small light straight up */
    for (int k = 0; k < 4; k++) {
        float *t = lx_test_cube_texel(&env, LX_FACE_PY, 3 + k % 2, 3 + k / 2);
        t[0] = t[1] = t[2] = 1e4f;
    }
    lx_sh9 sh;
    assert_int_equal(lx_sh_project(&env, NULL, &sh), LX_OK);
    for (int i = 0; i < 100; i++) {
        lx_vec3 nrm = spiral(i, 100);
        double want = 0.0;
        for (int k = 0; k < 4; k++) {
            int x = 3 + k % 2, y = 3 + k / 2;
            double c[3], w = lx_test_texel_omega(n, x, y, 16);
            lx_test_texel_dir(LX_FACE_PY, n, x, y, c);
            want += 1e4 * w * point_light_sh(nrm.x * c[0] + nrm.y * c[1] + nrm.z * c[2]);
        }
        float e[3];
        lx_sh_irradiance(&sh, nrm, e);
        /* measured: within 0.125 (5e-5 of the peak, near 2500), bound 0.3 */
        if (fabs(e[0] - want) > 1e-4 * 1e4 * 0.3)
            fail_msg("n (%.3f %.3f %.3f): %.4f, expected %.4f", nrm.x, nrm.y, nrm.z, e[0], want);
    }
    float e[3];
    double c = -8.0 / 15.0;
    lx_sh_irradiance(&sh, lx_v3((float)sqrt(1.0 - c * c), (float)c, 0.0f), e);
    assert_true(e[0] < 0.0f);
    g_log[0] = '\0';
    lx_set_log_callback(keep_log, NULL);
    lx_cubemap irr;
    assert_int_equal(lx_sh_irradiance_cube(&sh, 8, NULL, &irr), LX_OK);
    lx_set_log_callback(NULL, NULL);
    assert_non_null(strstr(g_log, "negative"));
    float lowest = 0.0f;
    for (size_t i = 0; i < (size_t)6 * 8 * 8 * 3; i++)
        lowest = irr.data[i] < lowest ? irr.data[i] : lowest;
    assert_true(lowest < 0.0f);
    lx_cubemap_free(&irr);
    lx_cubemap_free(&env);
}

static void bad_input(void **state)
{
    (void)state;
    lx_cubemap env;
    assert_int_equal(lx_cubemap_alloc(&env, 4), LX_OK);
    lx_sh9 sh;
    assert_int_equal(lx_sh_project(&env, NULL, NULL), LX_ERR_INVALID);
    assert_int_equal(lx_sh_project(NULL, NULL, &sh), LX_ERR_INVALID);
    lx_test_cube_texel(&env, 2, 1, 1)[1] = NAN;
    lx_test_cube_texel(&env, 4, 0, 3)[0] = INFINITY;
    assert_int_equal(lx_sh_project(&env, NULL, &sh), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "2 of 288 values are NaN or infinite"));
    for (int k = 0; k < 9; k++)
        assert_true(sh.c[k][0] == 0.0f);
    lx_cubemap bad = {0, NULL};
    assert_int_equal(lx_sh_project(&bad, NULL, &sh), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "face size 0"));

    memset(&sh, 0, sizeof sh);
    lx_cubemap out;
    assert_int_equal(lx_sh_irradiance_cube(&sh, -1, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "face size -1"));
    assert_null(out.data);
    /* 0 is the default size */
    assert_int_equal(lx_sh_irradiance_cube(&sh, 0, NULL, &out), LX_OK);
    assert_int_equal(out.size, LX_IRRADIANCE_DEFAULT_SIZE);
    lx_cubemap_free(&out);
    sh.c[3][2] = NAN;
    assert_int_equal(lx_sh_irradiance_cube(&sh, 4, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "coefficient 3 channel 2"));
    assert_null(out.data);
    memset(&sh, 0, sizeof sh);
    lx_ibl_desc d = {.threads = -3};
    assert_int_equal(lx_sh_irradiance_cube(&sh, 4, &d, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "thread count -3"));
    assert_null(out.data);
    lx_test_cube_texel(&env, 2, 1, 1)[1] = 0.0f;
    lx_test_cube_texel(&env, 4, 0, 3)[0] = 0.0f;
    assert_int_equal(lx_sh_project(&env, &d, &sh), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "thread count -3"));
    lx_cubemap_free(&env);
}

int main(void)
{
    lx_test_watchdog(60);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(constant_environment_gives_pi_l),
        cmocka_unit_test(polynomial_environment_coefficients),
        cmocka_unit_test(band_limited_irradiance_closed_form),
        cmocka_unit_test(basis_is_orthonormal),
        cmocka_unit_test(reconstruction_matches_true_irradiance),
        cmocka_unit_test(threads_progress_cancel),
        cmocka_unit_test(ringing_is_kept_and_reported),
        cmocka_unit_test(bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
