/* Tests of the specular prefilter (src/ibl/prefilter*.c): a constant
 * environment stays constant at every GGX and Phong level; GGX level 0 at
 * roughness 0 is the source; each level keeps the environment's flux
 * (sum of L * Omega); GGX and Phong levels against brute-force
 * convolutions written here over every source texel (the GGX lobe
 * D(n.h) (n.l) of Karis' N = V = R estimator, the Phong lobe
 * pow(max(0, r.l), n)); no seams across cube edges; byte-identical results
 * for 1, 2 and 3 threads; cancellation and bad input. */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "luxel/ibl.h"

#define PI_D 3.14159265358979323846

typedef void (*env_fn)(double x, double y, double z, float out[3]);

/* ibl.h's face table, written out again: unit direction of face
 * coordinates sc, tc in [-1, 1]. */
static void face_dir(int face, double sc, double tc, double d[3])
{
    double v[3];
    switch (face) {
    case 0:
        v[0] = 1, v[1] = -tc, v[2] = -sc;
        break;
    case 1:
        v[0] = -1, v[1] = -tc, v[2] = sc;
        break;
    case 2:
        v[0] = sc, v[1] = 1, v[2] = tc;
        break;
    case 3:
        v[0] = sc, v[1] = -1, v[2] = -tc;
        break;
    case 4:
        v[0] = sc, v[1] = -tc, v[2] = 1;
        break;
    default:
        v[0] = -sc, v[1] = -tc, v[2] = -1;
        break;
    }
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        d[k] = v[k] / n;
}

static void texel_dir(int face, int size, int x, int y, double d[3])
{
    face_dir(face, 2.0 * (x + 0.5) / size - 1.0, 2.0 * (y + 0.5) / size - 1.0, d);
}

/* Texel solid angle by a midpoint rule of dA / (1 + a^2 + b^2)^(3/2). */
static double texel_omega(int size, int x, int y)
{
    const int m = 8;
    double h = 2.0 / size / m, sum = 0.0;
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            double a = -1.0 + 2.0 * x / size + (i + 0.5) * h;
            double b = -1.0 + 2.0 * y / size + (j + 0.5) * h;
            sum += 1.0 / pow(1.0 + a * a + b * b, 1.5);
        }
    return sum * h * h;
}

/* texel_omega of every texel of a face, computed once per size. */
static const double *omega_table(int size)
{
    static double *table;
    static int table_size;
    if (table_size != size) {
        free(table);
        table = malloc(sizeof(double) * size * size);
        assert_non_null(table);
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++)
                table[y * size + x] = texel_omega(size, x, y);
        table_size = size;
    }
    return table;
}

static lx_cubemap make_env(int size, env_fn fn)
{
    lx_cubemap c;
    assert_int_equal(lx_cubemap_alloc(&c, size), LX_OK);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++) {
                double d[3];
                texel_dir(f, size, x, y, d);
                fn(d[0], d[1], d[2], lx_cubemap_texel(&c, f, x, y));
            }
    return c;
}

static void env_constant(double x, double y, double z, float out[3])
{
    (void)x, (void)y, (void)z;
    out[0] = 0.75f, out[1] = 1.5f, out[2] = 3.0f;
}

/* Smooth: bands 0..2 plus a broad lobe. */
static void env_smooth(double x, double y, double z, float out[3])
{
    double lobe = exp(6.0 * (0.6 * x + 0.64 * y + 0.48 * z - 1.0));
    out[0] = (float)(1.0 + 0.6 * y + 4.0 * lobe);
    out[1] = (float)(1.2 + 0.5 * x * z + 2.0 * lobe);
    out[2] = (float)(2.0 + 0.9 * y * y + 1.0 * lobe);
}

/* Bands 0..2 only: polynomials of degree <= 2 in the direction. */
static void env_band2(double x, double y, double z, float out[3])
{
    out[0] = (float)(1.0 + 0.6 * y + 0.3 * x);
    out[1] = (float)(1.2 + 0.5 * x * z - 0.4 * z);
    out[2] = (float)(2.0 + 0.9 * y * y - 0.7 * x * y + 0.2 * z);
}

/* Smooth, with detail at every scale down to ~10 degrees. */
static void env_wavy(double x, double y, double z, float out[3])
{
    double s = sin(9.0 * x) * cos(7.0 * y) + sin(5.0 * z + 1.0);
    out[0] = (float)(2.0 + s);
    out[1] = (float)(2.0 + 0.5 * s * s);
    out[2] = (float)(3.0 + sin(13.0 * y + 4.0 * x));
}

/* With a step: channel 2 jumps 10x across curved lines. */
static void env_pattern(double x, double y, double z, float out[3])
{
    double s = sin(9.0 * x) * cos(7.0 * y) + sin(5.0 * z + 1.0);
    out[0] = (float)(2.0 + s);
    out[1] = (float)(2.0 + 0.5 * s * s);
    out[2] = (float)(1.0 + (s > 0.5 ? 10.0 : 0.0));
}

static void free_levels(lx_cubemap *levels, int count)
{
    for (int i = 0; i < count; i++)
        lx_cubemap_free(&levels[i]);
}

static double flux(const lx_cubemap *c, int ch)
{
    double sum = 0.0;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < c->size; y++)
            for (int x = 0; x < c->size; x++)
                sum += lx_cube_texel_solid_angle(c->size, x, y) * lx_cubemap_texel(c, f, x, y)[ch];
    return sum;
}

/* ---- constant, identity, flux ------------------------------------------- */

static void constant_stays_constant(void **state)
{
    (void)state;
    lx_cubemap env = make_env(32, env_constant), levels[LX_MAX_CUBE_MIPS];
    const float L[3] = {0.75f, 1.5f, 3.0f};
    for (int filter = 0; filter < 2; filter++) {
        lx_prefilter_desc d = {.filter = filter, .samples = 64};
        int count;
        assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
        assert_int_equal(count, 6); /* 32, 16, 8, 4, 2, 1 */
        for (int l = 0; l < count; l++) {
            assert_int_equal(levels[l].size, 32 >> l);
            for (size_t i = 0; i < (size_t)6 * levels[l].size * levels[l].size * 3; i++)
                if (fabsf(levels[l].data[i] / L[i % 3] - 1.0f) > 1e-5f)
                    fail_msg("%s level %d value %zu: %.7f, expected %.7f", filter ? "Phong" : "GGX",
                             l, i, levels[l].data[i], L[i % 3]);
        }
        free_levels(levels, count);
    }
    lx_cubemap_free(&env);
}

static void ggx_level0_is_the_source(void **state)
{
    (void)state;
    lx_cubemap env = make_env(16, env_pattern), levels[LX_MAX_CUBE_MIPS];
    assert_float_equal(lx_ggx_level_roughness(0, 5), 0.0f, 0.0f);
    assert_float_equal(lx_ggx_level_roughness(2, 5), 0.5f, 0.0f);
    assert_float_equal(lx_ggx_level_roughness(4, 5), 1.0f, 0.0f);
    lx_prefilter_desc d = {.mips = 3, .samples = 16};
    int count;
    assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
    assert_int_equal(count, 3);
    assert_memory_equal(levels[0].data, env.data, sizeof(float) * 6 * 16 * 16 * 3);
    free_levels(levels, count);

    /* a smaller level 0: the solid-angle downsample of the source */
    d.size = 8;
    lx_cubemap half;
    assert_int_equal(lx_cubemap_downsample(&env, &half), LX_OK);
    assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
    assert_int_equal(levels[0].size, 8);
    assert_memory_equal(levels[0].data, half.data, sizeof(float) * 6 * 8 * 8 * 3);
    free_levels(levels, count);
    lx_cubemap_free(&half);
    lx_cubemap_free(&env);
}

/* A convolution with a normalised, rotationally symmetric kernel keeps the
 * integral of the environment exactly (swap the two integrals), and maps
 * bands 0..2 to bands 0..2. The flux is measured by the texel-centre rule
 * with exact solid angles, which is exact for polynomials of degree <= 3
 * on any level (the cube's texel layout has the octahedral symmetry: odd
 * terms and xy, yz, xz cancel, x^2, y^2, z^2 get equal sums), so an
 * environment of bands <= 2 isolates the filter's own error: the
 * 256-sample Hammersley estimate of a smooth integrand (~1e-3 on a single
 * texel, averaging out over the sphere), trilinear mip reads (a symmetric
 * widening of the kernel: none), float rounding. We allow 0.1%. */
static void levels_keep_the_flux(void **state)
{
    (void)state;
    lx_cubemap env = make_env(64, env_band2), levels[LX_MAX_CUBE_MIPS];
    double want[3];
    for (int c = 0; c < 3; c++)
        want[c] = flux(&env, c);
    for (int filter = 0; filter < 2; filter++) {
        lx_prefilter_desc d = {.filter = filter, .size = 32};
        int count;
        assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
        for (int l = 0; l < count; l++)
            for (int c = 0; c < 3; c++) {
                double rel = flux(&levels[l], c) / want[c] - 1.0;
                if (fabs(rel) > 1e-3)
                    fail_msg("%s level %d channel %d: flux off by %.3f%%", filter ? "Phong" : "GGX",
                             l, c, 100.0 * rel);
            }
        free_levels(levels, count);
    }
    lx_cubemap_free(&env);
}

/* ---- against brute-force convolutions -------------------------------------- */

/* Karis' estimator with N = V = R converges to
 *   sum_t L_t Omega_t D(n.h_t) (n.l_t)+ / sum_t Omega_t D(n.h_t) (n.l_t)+,
 * h_t = normalize(n + l_t), D the GGX distribution of alpha = r^2. */
static void brute_ggx(const lx_cubemap *env, double roughness, const double n[3], double out[3])
{
    double a2 = roughness * roughness * roughness * roughness, num[3] = {0, 0, 0}, den = 0.0;
    int s = env->size;
    const double *omega = omega_table(s);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < s; y++)
            for (int x = 0; x < s; x++) {
                double l[3];
                texel_dir(f, s, x, y, l);
                double nl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
                if (nl <= 0.0)
                    continue;
                double nh2 = (1.0 + nl) / 2.0; /* cos^2 of half the angle */
                double q = nh2 * (a2 - 1.0) + 1.0;
                double w = a2 / (PI_D * q * q) * nl * omega[y * s + x];
                const float *v = lx_cubemap_texel(env, f, x, y);
                for (int c = 0; c < 3; c++)
                    num[c] += w * v[c];
                den += w;
            }
    for (int c = 0; c < 3; c++)
        out[c] = num[c] / den;
}

static void brute_phong(const lx_cubemap *env, double e, const double r[3], double out[3])
{
    double num[3] = {0, 0, 0}, den = 0.0;
    int s = env->size;
    const double *omega = omega_table(s);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < s; y++)
            for (int x = 0; x < s; x++) {
                double l[3];
                texel_dir(f, s, x, y, l);
                double c = r[0] * l[0] + r[1] * l[1] + r[2] * l[2];
                if (c <= 0.0)
                    continue;
                double w = pow(c, e) * omega[y * s + x];
                const float *v = lx_cubemap_texel(env, f, x, y);
                for (int k = 0; k < 3; k++)
                    num[k] += w * v[k];
                den += w;
            }
    for (int k = 0; k < 3; k++)
        out[k] = num[k] / den;
}

/* A level against a brute-force filter: relative differences, their mean
 * and worst, and the worst on texels along the face edges and inside. */
typedef struct diff {
    double mean, worst, edge, inside;
} diff;

static diff level_vs_brute(const lx_cubemap *env, const lx_cubemap *level, int filter, double param)
{
    diff r = {0};
    int m = level->size;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < m; y++)
            for (int x = 0; x < m; x++) {
                double n[3], want[3];
                texel_dir(f, m, x, y, n);
                if (filter == LX_SPECULAR_GGX)
                    brute_ggx(env, param, n, want);
                else
                    brute_phong(env, param, n, want);
                const float *v = lx_cubemap_texel(level, f, x, y);
                bool edge = x == 0 || y == 0 || x == m - 1 || y == m - 1;
                for (int c = 0; c < 3; c++) {
                    double rel = fabs(v[c] - want[c]) / want[c];
                    r.worst = fmax(r.worst, rel);
                    if (edge)
                        r.edge = fmax(r.edge, rel);
                    else
                        r.inside = fmax(r.inside, rel);
                    r.mean += rel;
                }
            }
    r.mean /= 18.0 * m * m;
    return r;
}

/* GGX levels read a smooth environment's mips: close to the exact
 * convolution. Filtered importance sampling reads each sample from a mip
 * whose texels are about the solid angle the sample stands for, one level
 * blurrier (the bias against sparkles): that widens the lobe by about a
 * texel of the mip it reads, which moves env_smooth by 0.3-1.3% on average
 * and by up to 6% where it curves most (the lobe's peak seen through the
 * roughest levels). Bounds: mean 1.5%, worst 8%. */
static void ggx_matches_brute_force(void **state)
{
    (void)state;
    lx_cubemap env = make_env(32, env_smooth), levels[LX_MAX_CUBE_MIPS];
    lx_prefilter_desc d = {.filter = LX_SPECULAR_GGX};
    int count;
    assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
    for (int l = 1; l < count; l++) {
        double r = lx_ggx_level_roughness(l, count);
        diff e = level_vs_brute(&env, &levels[l], LX_SPECULAR_GGX, r);
        printf("GGX level %d (%dx%d, roughness %.2f): mean %.3f%%, worst %.3f%% from brute "
               "force\n",
               l, levels[l].size, levels[l].size, r, 100.0 * e.mean, 100.0 * e.worst);
        assert_true(e.mean < 0.015);
        assert_true(e.worst < 0.08);
    }
    free_levels(levels, count);
    lx_cubemap_free(&env);
}

/* Phong: exponent 64 on a 16^2 source is filtered from the full source
 * (the lobe's half-width is 2.3 texels there): the brute-force definition
 * but for the texels below 1e-4 of the peak. Those carry a share
 * delta ~ 1e-4 of the lobe's weight, so they move the result by at most
 * delta (max L - min L) / min L = 1e-3 on env_pattern (values 1 to 11).
 * Exponent 4 reads a downsampled source: a smooth environment moves by
 * well under 1%. */
static void phong_matches_brute_force(void **state)
{
    (void)state;
    lx_cubemap env = make_env(16, env_pattern), levels[LX_MAX_CUBE_MIPS];
    const float exps[2] = {64.0f, 4.0f};
    lx_prefilter_desc d = {.filter = LX_SPECULAR_PHONG, .mips = 2, .phong_exponents = exps};
    int count;
    assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
    diff e = level_vs_brute(&env, &levels[0], LX_SPECULAR_PHONG, 64.0);
    printf("Phong n = 64 from the full source: mean %.2g, worst %.2g from brute force\n", e.mean,
           e.worst);
    assert_true(e.worst < 1.2e-3);
    free_levels(levels, count);
    lx_cubemap_free(&env);

    env = make_env(32, env_smooth);
    assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
    e = level_vs_brute(&env, &levels[1], LX_SPECULAR_PHONG, 4.0);
    printf("Phong n = 4 from a downsampled source: mean %.2g, worst %.2g from brute force\n",
           e.mean, e.worst);
    assert_true(e.worst < 0.01);
    free_levels(levels, count);
    lx_cubemap_free(&env);

    /* a small light 1e4 times the sky, off the centre of the coarse texel
     * it falls in: the downsampled source keeps it where it is */
    env = make_env(32, env_constant);
    for (int k = 0; k < 3; k++)
        lx_cubemap_texel(&env, LX_FACE_PY, 21, 10)[k] = 1e4f;
    const float exps8[1] = {8.0f};
    lx_prefilter_desc d8 = {
        .filter = LX_SPECULAR_PHONG, .size = 8, .mips = 1, .phong_exponents = exps8};
    assert_int_equal(lx_prefilter(&env, &d8, levels, &count), LX_OK);
    e = level_vs_brute(&env, &levels[0], LX_SPECULAR_PHONG, 8.0);
    printf("Phong n = 8, a small bright light: mean %.2g, worst %.2g from brute force\n", e.mean,
           e.worst);
    assert_true(e.mean < 0.015);
    assert_true(e.worst < 0.08);
    free_levels(levels, count);
    lx_cubemap_free(&env);

    assert_float_equal(lx_phong_level_exponent(0), 2048.0f, 0.0f);
    assert_float_equal(lx_phong_level_exponent(3), 32.0f, 0.0f);
    assert_float_equal(lx_phong_level_exponent(9), 1.0f, 0.0f);
}

/* A seam is an error that lives on the face edges: against the exact
 * convolution, texels along the edges are no worse than those inside
 * (levels of 4x4 and more, where faces have an inside), on an environment
 * with detail at every scale. */
static void no_seams(void **state)
{
    (void)state;
    lx_cubemap env = make_env(32, env_wavy), levels[LX_MAX_CUBE_MIPS];
    for (int filter = 0; filter < 2; filter++) {
        lx_prefilter_desc d = {.filter = filter, .size = 32, .mips = 4};
        int count;
        assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
        for (int l = 1; l < count; l++) {
            double param = filter == LX_SPECULAR_GGX ? lx_ggx_level_roughness(l, count)
                                                     : lx_phong_level_exponent(l);
            diff e = level_vs_brute(&env, &levels[l], filter, param);
            printf("%s level %d (%dx%d): worst %.3f%% on the edges, %.3f%% inside\n",
                   filter ? "Phong" : "GGX", l, levels[l].size, levels[l].size, 100.0 * e.edge,
                   100.0 * e.inside);
            if (e.edge > 1.5 * e.inside + 1e-3)
                fail_msg("%s level %d: a seam", filter ? "Phong" : "GGX", l);
        }
        free_levels(levels, count);
    }
    lx_cubemap_free(&env);
}

/* ---- threads, progress, cancellation, bad input ----------------------------- */

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    lx_cubemap env = make_env(32, env_pattern);
    for (int filter = 0; filter < 2; filter++) {
        lx_cubemap levels[3][LX_MAX_CUBE_MIPS];
        int count[3];
        for (int t = 0; t < 3; t++) {
            lx_prefilter_desc d = {.filter = filter, .samples = 64, .threads = t + 1};
            assert_int_equal(lx_prefilter(&env, &d, levels[t], &count[t]), LX_OK);
        }
        assert_int_equal(count[0], count[1]);
        assert_int_equal(count[0], count[2]);
        for (int l = 0; l < count[0]; l++) {
            size_t bytes = sizeof(float) * 6 * 3 * (size_t)levels[0][l].size * levels[0][l].size;
            assert_memory_equal(levels[0][l].data, levels[1][l].data, bytes);
            assert_memory_equal(levels[0][l].data, levels[2][l].data, bytes);
        }
        for (int t = 0; t < 3; t++)
            free_levels(levels[t], count[t]);
    }
    lx_cubemap_free(&env);
}

static bool stop_at_second(void *user, float f)
{
    (void)f;
    return ++*(int *)user < 2;
}

static void cancel_returns_nothing(void **state)
{
    (void)state;
    lx_cubemap env = make_env(32, env_pattern), levels[LX_MAX_CUBE_MIPS];
    for (int filter = 0; filter < 2; filter++) {
        int calls = 0, count = 99;
        lx_prefilter_desc d = {.filter = filter,
                               .samples = 64,
                               .threads = 2,
                               .progress = stop_at_second,
                               .progress_user = &calls};
        assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_ERR_CANCELLED);
        assert_int_equal(count, 0);
        for (int l = 0; l < LX_MAX_CUBE_MIPS; l++)
            assert_null(levels[l].data);
        assert_non_null(strstr(lx_last_error(), "cancelled"));
    }
    lx_cubemap_free(&env);
}

static void expect_invalid(const lx_cubemap *env, const lx_prefilter_desc *d, const char *msg)
{
    lx_cubemap levels[LX_MAX_CUBE_MIPS];
    int count = 7;
    assert_int_equal(lx_prefilter(env, d, levels, &count), LX_ERR_INVALID);
    assert_int_equal(count, 0);
    if (!strstr(lx_last_error(), msg))
        fail_msg("message \"%s\" lacks \"%s\"", lx_last_error(), msg);
}

static void bad_input(void **state)
{
    (void)state;
    lx_cubemap env = make_env(16, env_pattern);
    expect_invalid(&env, &(lx_prefilter_desc){.mips = 6},
                   "6 mip levels asked; a 16 x 16 face has 1..5");
    expect_invalid(&env, &(lx_prefilter_desc){.mips = -1}, "-1 mip levels");
    expect_invalid(&env, &(lx_prefilter_desc){.size = -3}, "face size -3");
    expect_invalid(&env, &(lx_prefilter_desc){.samples = -1}, "-1 samples");
    expect_invalid(&env, &(lx_prefilter_desc){.samples = 70000}, "70000 samples");
    expect_invalid(&env, &(lx_prefilter_desc){.filter = 7}, "unknown filter 7");
    expect_invalid(&env, &(lx_prefilter_desc){.threads = 2000}, "thread count 2000");
    const float bad[3] = {16.0f, 0.0f, 1.0f};
    expect_invalid(
        &env, &(lx_prefilter_desc){.filter = LX_SPECULAR_PHONG, .mips = 3, .phong_exponents = bad},
        "Phong exponent 0 of level 1");
    const float nan[1] = {NAN};
    expect_invalid(
        &env, &(lx_prefilter_desc){.filter = LX_SPECULAR_PHONG, .mips = 1, .phong_exponents = nan},
        "Phong exponent nan of level 0");
    expect_invalid(NULL, NULL, "missing");
    lx_cubemap_texel(&env, 1, 3, 3)[0] = INFINITY;
    expect_invalid(&env, NULL, "1 of 4608 values are NaN or infinite");
    lx_cubemap levels[LX_MAX_CUBE_MIPS];
    assert_int_equal(lx_prefilter(&env, NULL, levels, NULL), LX_ERR_INVALID);
    lx_cubemap_free(&env);
}

int main(void)
{
    lx_test_watchdog(120);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(constant_stays_constant),
        cmocka_unit_test(ggx_level0_is_the_source),
        cmocka_unit_test(levels_keep_the_flux),
        cmocka_unit_test(ggx_matches_brute_force),
        cmocka_unit_test(phong_matches_brute_force),
        cmocka_unit_test(no_seams),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(cancel_returns_nothing),
        cmocka_unit_test(bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
