/* Tests of the brute-force irradiance (src/ibl/irradiance.c): a constant
 * environment L gives pi L everywhere; a single bright texel gives
 * L * (integral over the texel of max(0, n.w) dw), computed here by a fine
 * midpoint rule on the face plane (dw = da db / (1 + a^2 + b^2)^(3/2)),
 * which follows the cosine law around the texel's direction; the
 * downsampled source keeps its flux; results are byte-identical for 1, 2
 * and 3 threads; progress, cancellation and bad input. */
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

static lx_cubemap constant_env(int size, float r, float g, float b)
{
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, size), LX_OK);
    for (size_t i = 0; i < (size_t)6 * size * size; i++)
        c.data[3 * i] = r, c.data[3 * i + 1] = g, c.data[3 * i + 2] = b;
    return c;
}

static void constant_environment_gives_pi_l(void **state)
{
    (void)state;
    /* the default 32^2 source, and a 64^2 one downsampled to 32^2 */
    const int sizes[] = {32, 64, 12};
    for (int k = 0; k < 3; k++) {
        lx_cubemap env = constant_env(sizes[k], 1.0f, 0.25f, 3.0f), irr;
        assert_int_equal(lx_irradiance_brute(&env, 12, 0, NULL, &irr), LX_OK);
        assert_int_equal(irr.size, 12);
        const double L[3] = {1.0, 0.25, 3.0};
        /* 12^2 output texels look in directions that cut the source's
         * texels at every angle */
        double worst = 0.0;
        for (size_t i = 0; i < (size_t)6 * 12 * 12 * 3; i++) {
            double rel = fabs(irr.data[i] / (PI_D * L[i % 3]) - 1.0);
            worst = rel > worst ? rel : worst;
        }
        printf("source %d: worst relative error %.2g\n", sizes[k], worst);
        /* measured: 1.6e-5 (32^2 and 64^2 sources) and 1.8e-5 (12^2, split
         * finer at the horizon but coarser), the sub-texel sums of the
         * texels the horizon cuts; bound 5e-5 */
        assert_true(worst < 5e-5);
        lx_cubemap_free(&irr);
        lx_cubemap_free(&env);
    }
}

/* L times the integral of max(0, n.w) over texel (x, y) of a face of size
 * n, by an m x m midpoint rule. */
static double texel_cosine_integral(int face, int n, int x, int y, const double nrm[3], int m)
{
    double h = 2.0 / n / m, sum = 0.0;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            double a = -1.0 + 2.0 * x / n + (i + 0.5) * h, b = -1.0 + 2.0 * y / n + (j + 0.5) * h;
            double v[3];
            lx_test_face_vec(face, a, b, v);
            double len2 = 1.0 + a * a + b * b, len = sqrt(len2);
            double c = (nrm[0] * v[0] + nrm[1] * v[1] + nrm[2] * v[2]) / len;
            if (c > 0.0)
                sum += c / (len2 * len);
        }
    return sum * h * h;
}

/* The texel's irradiance vector Phi = integral of w over texel (x, y), by
 * the same rule: the irradiance of a normal that sees the whole texel is
 * L n.Phi (the cosine law about Phi's direction). */
static void texel_irradiance_vector(int face, int n, int x, int y, int m, double phi[3])
{
    double h = 2.0 / n / m;
    phi[0] = phi[1] = phi[2] = 0.0;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            double a = -1.0 + 2.0 * x / n + (i + 0.5) * h, b = -1.0 + 2.0 * y / n + (j + 0.5) * h;
            double v[3];
            lx_test_face_vec(face, a, b, v);
            double len2 = 1.0 + a * a + b * b, len = sqrt(len2);
            for (int k = 0; k < 3; k++)
                phi[k] += v[k] / len * h * h / (len2 * len);
        }
}

static void single_texel_follows_cosine_law(void **state)
{
    (void)state;
    const int n = 16, out_size = 8, face = LX_FACE_PY, tx = 5, ty = 9;
    const float L = 1000.0f;
    lx_cubemap env = constant_env(n, 0.0f, 0.0f, 0.0f), irr;
    float *t = lx_test_cube_texel(&env, face, tx, ty);
    t[0] = t[1] = t[2] = L;
    assert_int_equal(lx_irradiance_brute(&env, out_size, n, NULL, &irr), LX_OK);

    double c[3];
    texel_irradiance_vector(face, n, tx, ty, 64, c);
    double peak = L * sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    for (int k = 0; k < 3; k++)
        c[k] *= L / peak; /* unit */
    int lit = 0;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < out_size; y++)
            for (int x = 0; x < out_size; x++) {
                double nv[3];
                lx_test_texel_dir(f, out_size, x, y, nv);
                double want = L * texel_cosine_integral(face, n, tx, ty, nv, 64);
                const float *e = lx_test_cube_texel(&irr, f, x, y);
                /* measured: within 9.3e-5 of the peak, bound 3e-4 */
                if (fabs(e[1] - want) > 3e-4 * peak)
                    fail_msg("face %d texel (%d, %d): %.6f, expected %.6f", f, x, y, e[1], want);
                assert_true(e[0] == e[1] && e[1] == e[2]);
                /* the cosine law: away from the horizon E = L |Phi| cos, the
                 * angle measured from Phi's direction. Measured: within 9.5e-7
                 * (float rounding), bound 3e-6 */
                double cosang = nv[0] * c[0] + nv[1] * c[1] + nv[2] * c[2];
                if (cosang > 0.2) {
                    assert_true(fabs(e[1] / peak - cosang) < 3e-6);
                    lit++;
                } else if (cosang < -0.2) {
                    assert_true(e[1] == 0.0f);
                }
            }
    assert_true(lit > 50);
    lx_cubemap_free(&irr);
    lx_cubemap_free(&env);
}

/* Each texel of the half-size map is a solid-angle weighted mean, so the
 * sum of L * Omega over the sphere (the flux) is kept. */
static void downsample_keeps_flux(void **state)
{
    (void)state;
    lx_cubemap env;
    assert_int_equal(lx_cubemap_alloc(&env, 16), LX_OK);
    for (size_t i = 0; i < (size_t)6 * 16 * 16 * 3; i++)
        env.data[i] = (float)((i * 2654435761u) % 1000) / 100.0f;
    lx_cubemap half;
    assert_int_equal(lx_cubemap_downsample(&env, 0, NULL, &half), LX_OK);
    assert_int_equal(half.size, 8);
    double flux[2] = {0, 0};
    const lx_cubemap *maps[2] = {&env, &half};
    for (int m = 0; m < 2; m++) {
        int n = maps[m]->size;
        for (int f = 0; f < 6; f++)
            for (int y = 0; y < n; y++)
                for (int x = 0; x < n; x++)
                    flux[m] += lx_test_texel_solid_angle(n, x, y) *
                               lx_test_cube_texel(maps[m], f, x, y)[0];
    }
    /* measured: 1.5e-9 (each texel's float rounding), bound 5e-9 */
    assert_true(fabs(flux[1] / flux[0] - 1.0) < 5e-9);
    lx_cubemap_free(&half);

    /* odd sizes keep a constant constant: measured exactly 2 (a weighted
     * mean of 2s, each term scaled by a power of two); bound one float ulp */
    lx_cubemap odd = constant_env(5, 2.0f, 2.0f, 2.0f);
    assert_int_equal(lx_cubemap_downsample(&odd, 0, NULL, &half), LX_OK);
    assert_int_equal(half.size, 2);
    for (int i = 0; i < 6 * 2 * 2 * 3; i++)
        assert_float_equal(half.data[i], 2.0f, 2.4e-7f);
    lx_cubemap_free(&half);
    lx_cubemap_free(&odd);
    lx_cubemap_free(&env);
}

static lx_cubemap pattern_env(int size)
{
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, size), LX_OK);
    for (size_t i = 0; i < (size_t)6 * size * size * 3; i++)
        c.data[i] = (float)((i * 2246822519u) % 977) / 97.0f;
    return c;
}

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    lx_cubemap env = pattern_env(24), out[3];
    for (int t = 0; t < 3; t++) {
        lx_ibl_desc d = {.threads = t + 1};
        assert_int_equal(lx_irradiance_brute(&env, 20, 12, &d, &out[t]), LX_OK);
    }
    size_t bytes = sizeof(float) * 6 * 20 * 20 * 3;
    assert_memory_equal(out[0].data, out[1].data, bytes);
    assert_memory_equal(out[0].data, out[2].data, bytes);
    for (int t = 0; t < 3; t++)
        lx_cubemap_free(&out[t]);
    lx_cubemap_free(&env);
}

static void progress_and_cancel(void **state)
{
    (void)state;
    lx_cubemap env = pattern_env(8), out;
    lx_test_progress p = lx_test_progress_make(0);
    lx_ibl_desc d = {.threads = 2, .progress = lx_test_progress_fn, .progress_user = &p};
    assert_int_equal(lx_irradiance_brute(&env, 40, 8, &d, &out), LX_OK);
    assert_true(p.calls >= 2 && p.monotone);
    assert_float_equal(p.last, 1.0f, 0.0f);
    lx_cubemap_free(&out);

    p = lx_test_progress_make(1);
    assert_int_equal(lx_irradiance_brute(&env, 40, 8, &d, &out), LX_ERR_CANCELLED);
    assert_null(out.data);
    assert_int_equal(out.size, 0);
    assert_non_null(strstr(lx_last_error(), "cancelled"));
    lx_cubemap_free(&env);
}

static void bad_input(void **state)
{
    (void)state;
    lx_cubemap env = pattern_env(4), out;
    assert_int_equal(lx_irradiance_brute(&env, -1, 0, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "face size -1"));
    assert_null(out.data);
    assert_int_equal(lx_irradiance_brute(&env, 8, -5, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "source size -5"));
    assert_int_equal(lx_irradiance_brute(&env, LX_MAX_CUBE_SIZE + 1, 0, NULL, &out),
                     LX_ERR_INVALID);
    lx_ibl_desc d = {.threads = -2};
    assert_int_equal(lx_irradiance_brute(&env, 8, 0, &d, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "thread count -2"));
    assert_int_equal(lx_irradiance_brute(&env, 8, 0, NULL, NULL), LX_ERR_INVALID);
    assert_int_equal(lx_irradiance_brute(NULL, 8, 0, NULL, &out), LX_ERR_INVALID);
    lx_test_cube_texel(&env, 3, 2, 2)[2] = NAN;
    assert_int_equal(lx_irradiance_brute(&env, 8, 0, NULL, &out), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "1 of 288 values are NaN or infinite"));
    assert_null(out.data);
    assert_int_equal(lx_cubemap_downsample(&env, 0, NULL, &out), LX_ERR_INVALID);
    assert_null(out.data);
    lx_cubemap_free(&env);
}

int main(void)
{
    lx_test_watchdog(60);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(constant_environment_gives_pi_l),
        cmocka_unit_test(single_texel_follows_cosine_law),
        cmocka_unit_test(downsample_keeps_flux),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(progress_and_cancel),
        cmocka_unit_test(bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
