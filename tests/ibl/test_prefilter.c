/* Tests of the specular prefilter (src/ibl/prefilter*.c): a constant
 * environment stays constant at every GGX and Phong level; GGX level 0 at
 * roughness 0 is the source; each level keeps the environment's flux
 * (sum of L * Omega); GGX (direct convolution and importance sampling) and
 * Phong levels against brute-force convolutions written here over every
 * source texel (the GGX lobe D(n.h) (n.l) of Karis' N = V = R estimator,
 * the Phong lobe pow(max(0, r.l), n)), on smooth environments and with a
 * small bright light; no seams across cube edges; byte-identical results
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

#include "cube_reference.h"
#include "helpers.h"
#include "luxel/ibl.h"

#define PI_D 3.14159265358979323846

/* Texel solid angles (8 x 8 midpoint rule) of every texel of a face,
 * computed once per size. */
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
                table[y * size + x] = lx_test_texel_omega(size, x, y, 8);
        table_size = size;
    }
    return table;
}

/* lx_test_texel_dir of every texel of a cube of that size (face-major,
 * rows, columns), computed once per size. */
static const double *dir_table(int size)
{
    static double *table;
    static int table_size;
    if (table_size != size) {
        free(table);
        table = malloc(sizeof(double) * 18 * size * size);
        assert_non_null(table);
        for (int f = 0; f < 6; f++)
            for (int y = 0; y < size; y++)
                for (int x = 0; x < size; x++)
                    lx_test_texel_dir(f, size, x, y, table + 3 * ((f * size + y) * size + x));
        table_size = size;
    }
    return table;
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

/* The three ways lx_prefilter filters: GGX by direct convolution (with the
 * default 256 samples every GGX level of these tests' 16^2 to 64^2 sources
 * costs less to convolve than to sample, prefilter_ggx.c), GGX with 32
 * samples (the sharpest levels then cost more to convolve than 32 samples
 * would and are importance sampled), and Phong. */
typedef struct named_filter {
    const char *name;
    lx_prefilter_desc desc;
} named_filter;

static const named_filter g_filters[3] = {
    {"GGX", {.filter = LX_SPECULAR_GGX}},
    {"GGX 32 samples", {.filter = LX_SPECULAR_GGX, .samples = 32}},
    {"Phong", {.filter = LX_SPECULAR_PHONG}},
};

/* The roughness or exponent of level l of count. */
static double level_param(const lx_prefilter_desc *d, int l, int count)
{
    return d->filter == LX_SPECULAR_GGX ? lx_ggx_level_roughness(l, count)
                                        : lx_phong_level_exponent(l);
}

static double flux(const lx_cubemap *c, int ch)
{
    double sum = 0.0;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < c->size; y++)
            for (int x = 0; x < c->size; x++)
                sum +=
                    lx_test_texel_solid_angle(c->size, x, y) * lx_test_cube_texel(c, f, x, y)[ch];
    return sum;
}

/* ---- constant, identity, flux ------------------------------------------- */

static void constant_stays_constant(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, env_constant), levels[LX_MAX_CUBE_MIPS];
    const float L[3] = {0.75f, 1.5f, 3.0f};
    for (int filter = 0; filter < 2; filter++) {
        lx_prefilter_desc d = {.filter = filter, .samples = 32};
        int count;
        assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
        assert_int_equal(count, 6); /* 32, 16, 8, 4, 2, 1 */
        for (int l = 0; l < count; l++) {
            assert_int_equal(levels[l].size, 32 >> l);
            /* measured: exactly L on every level of both filters; bound one
             * float ulp (L's mantissas are all 1.5: 2^-23 / 1.5 = 8e-8) */
            for (size_t i = 0; i < (size_t)6 * levels[l].size * levels[l].size * 3; i++)
                if (fabs(levels[l].data[i] / (double)L[i % 3] - 1.0) > 1.2e-7)
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
    lx_cubemap env = lx_test_make_env(16, env_pattern), levels[LX_MAX_CUBE_MIPS];
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
    assert_int_equal(lx_cubemap_downsample(&env, 0, NULL, &half), LX_OK);
    assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
    assert_int_equal(levels[0].size, 8);
    assert_memory_equal(levels[0].data, half.data, sizeof(float) * 6 * 8 * 8 * 3);
    free_levels(levels, count);
    lx_cubemap_free(&half);
    lx_cubemap_free(&env);

    /* the size lx_prefilter picks, told before: the source's up to 256
     * (the header's default), else the one asked */
    assert_int_equal(LX_PREFILTER_DEFAULT_SIZE, 256);
    assert_int_equal(lx_prefilter_size(16, NULL), 16);
    assert_int_equal(lx_prefilter_size(1024, NULL), 256);
    assert_int_equal(lx_prefilter_size(1024, &d), 8);
    d.size = 0;
    assert_int_equal(lx_prefilter_size(300, &d), 256);
}

/* A convolution with a normalised, rotationally symmetric kernel keeps the
 * integral of the environment exactly (swap the two integrals), and maps
 * bands 0..2 to bands 0..2. The flux is measured by the texel-centre rule
 * with exact solid angles, which is exact for polynomials of degree <= 3
 * on any level (the cube's texel layout has the octahedral symmetry: odd
 * terms and xy, yz, xz cancel, x^2, y^2, z^2 get equal sums), so an
 * environment of bands <= 2 isolates the filter's own error: for the
 * direct convolutions, the coarse mip texels and far nodes taken as single
 * lights (second order in their size, ~1e-4 here); for importance
 * sampling, the 64-sample Hammersley estimate of a smooth integrand (~1e-3
 * on a single texel, averaging out over the sphere) and trilinear mip
 * reads (a symmetric widening of the kernel: none); float rounding. */
static void levels_keep_the_flux(void **state)
{
    (void)state;
    /* Measured, worst over levels and channels: 1.2e-4 (GGX, convolved),
     * 7.3e-4 (GGX with 32 samples: levels 1-3 importance sampled) and
     * 3.2e-4 (Phong). Bounds about 3x each. */
    const double bounds[3] = {4e-4, 2e-3, 1e-3};
    lx_cubemap env = lx_test_make_env(64, env_band2), levels[LX_MAX_CUBE_MIPS];
    double want[3];
    for (int c = 0; c < 3; c++)
        want[c] = flux(&env, c);
    for (int k = 0; k < 3; k++) {
        lx_prefilter_desc d = g_filters[k].desc;
        d.size = 32;
        int count;
        assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
        for (int l = 0; l < count; l++)
            for (int c = 0; c < 3; c++) {
                double rel = flux(&levels[l], c) / want[c] - 1.0;
                if (fabs(rel) > bounds[k])
                    fail_msg("%s level %d channel %d: flux off by %.3f%%", g_filters[k].name, l, c,
                             100.0 * rel);
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
    const double *omega = omega_table(s), *dirs = dir_table(s);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < s; y++)
            for (int x = 0; x < s; x++) {
                const double *l = dirs + 3 * ((f * s + y) * s + x);
                double nl = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
                if (nl <= 0.0)
                    continue;
                double nh2 = (1.0 + nl) / 2.0; /* cos^2 of half the angle */
                double q = nh2 * (a2 - 1.0) + 1.0;
                double w = a2 / (PI_D * q * q) * nl * omega[y * s + x];
                const float *v = lx_test_cube_texel(env, f, x, y);
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
    const double *omega = omega_table(s), *dirs = dir_table(s);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < s; y++)
            for (int x = 0; x < s; x++) {
                const double *l = dirs + 3 * ((f * s + y) * s + x);
                double c = r[0] * l[0] + r[1] * l[1] + r[2] * l[2];
                if (c <= 0.0)
                    continue;
                double w = pow(c, e) * omega[y * s + x];
                const float *v = lx_test_cube_texel(env, f, x, y);
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
                lx_test_texel_dir(f, m, x, y, n);
                if (filter == LX_SPECULAR_GGX)
                    brute_ggx(env, param, n, want);
                else
                    brute_phong(env, param, n, want);
                const float *v = lx_test_cube_texel(level, f, x, y);
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

/* Every GGX level l > 0 of env filtered with samples, against brute_ggx:
 * mean and worst relative differences below the bounds. */
static void check_ggx_levels(const lx_cubemap *env, int samples, const char *what,
                             double mean_bound, double worst_bound)
{
    lx_cubemap levels[LX_MAX_CUBE_MIPS];
    lx_prefilter_desc d = {.filter = LX_SPECULAR_GGX, .samples = samples};
    int count;
    assert_int_equal(lx_prefilter(env, &d, levels, &count), LX_OK);
    for (int l = 1; l < count; l++) {
        double r = lx_ggx_level_roughness(l, count);
        diff e = level_vs_brute(env, &levels[l], LX_SPECULAR_GGX, r);
        printf("GGX %d samples, %s, level %d (%dx%d, roughness %.2f): mean %.3f%%, worst %.3f%% "
               "from brute force\n",
               samples, what, l, levels[l].size, levels[l].size, r, 100.0 * e.mean,
               100.0 * e.worst);
        if (e.mean >= mean_bound || e.worst >= worst_bound)
            fail_msg("GGX level %d, %s: beyond mean %g%%, worst %g%%", l, what, 100.0 * mean_bound,
                     100.0 * worst_bound);
    }
    free_levels(levels, count);
}

/* GGX levels of a smooth environment against the exact convolution. With
 * the default 256 samples every level here is a direct convolution: the
 * brute force's sum but for the texels of a coarser mip and the far
 * nodes of the tree taken as single lights at their flux centroids (both
 * second order in their size over the lobe's width or their distance),
 * and, where the horizon cuts a coarse texel, the kink of the lobe's n.l
 * there (the 1x1 level reads an 8x8 mip). Measured mean 0.002-0.11%,
 * worst 0.51%; bounds mean 0.3%, worst 1.5%.
 * With 48 samples the two sharpest levels cost more to convolve (1300 and
 * 1500 lights a texel) than 48 samples would (~24 lights each) and are
 * importance sampled. Filtered importance sampling reads each sample from
 * a mip whose texels are about the solid angle the sample stands for, one
 * level blurrier (the bias against sparkles): that widens the lobe by
 * about a texel of the mip it reads, and 48 samples leave their pattern.
 * Measured: levels 1 and 2 mean 0.9% and 1.8%, worst 4.7% and 9.7% (the
 * others convolved as above). Bounds: mean 5%, worst 25%. */
static void ggx_matches_brute_force(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, env_smooth);
    check_ggx_levels(&env, 256, "a smooth sky", 0.003, 0.015);
    check_ggx_levels(&env, 48, "a smooth sky", 0.05, 0.25);
    lx_cubemap_free(&env);
}

/* A small bright light: 2x2 texels of a 32^2 source at 5e3 nits over
 * env_smooth's sky of 1-6, off the centre of every mip texel it falls in,
 * more than half of the environment's flux. GGX's tail falls only as the inverse
 * fourth power of the angle, so the light shows through the whole
 * hemisphere of the low levels; importance sampling (256 samples, the
 * method before the direct convolution) misses the exact convolution by
 * 4-9% on average and 26-65% at worst on levels 1-5 here. The direct
 * convolution takes the light's texels as lights (levels 1-2 read the
 * source itself) or as part of a mip texel or far node whose light sits
 * at its flux centroid, so the light is placed right to first order; what
 * is left is second order, plus the normalisation's share of a coarse
 * texel holding the light (its whole solid angle weighted at the light's
 * direction, not the texel's centre: at most solid angle x slope of the
 * lobe x offset / sum of the lobe = 0.033 sr x 1 x 0.13 / pi = 0.14% on
 * the 1x1 level's 8x8 mip) and the kink of n.l at the horizon (~0.4% on
 * that level). Measured mean 0.004-0.23%, worst 0.51%; bounds mean 0.5%,
 * worst 1.5%. */
static void ggx_small_bright_light_matches_brute_force(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, env_smooth);
    for (int k = 0; k < 4; k++) {
        float *t = lx_test_cube_texel(&env, LX_FACE_PY, 19 + k % 2, 11 + k / 2);
        t[0] = t[1] = t[2] = 5e3f;
    }
    check_ggx_levels(&env, 256, "a small bright light", 0.005, 0.015);
    lx_cubemap_free(&env);
}

/* Phong: exponent 64 on a 16^2 source is filtered from the full source
 * (the lobe's half-width is 2.3 texels there): the brute-force definition
 * but for the texels below 1e-4 of the peak. Those carry a share
 * delta ~ 1e-4 of the lobe's weight, so they move the result by at most
 * delta (max L - min L) / min L = 1e-3 on env_pattern (values 1 to 11);
 * measured worst 5.6e-4, bound 1.2e-3. Exponent 4 reads a downsampled
 * source: measured worst 0.70% on a smooth environment, bound 2%. A small
 * light in a downsampled source: measured mean 0.084%, worst 1.2%; bounds
 * 0.3% and 4%. */
static void phong_matches_brute_force(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(16, env_pattern), levels[LX_MAX_CUBE_MIPS];
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

    env = lx_test_make_env(32, env_smooth);
    assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
    e = level_vs_brute(&env, &levels[1], LX_SPECULAR_PHONG, 4.0);
    printf("Phong n = 4 from a downsampled source: mean %.2g, worst %.2g from brute force\n",
           e.mean, e.worst);
    assert_true(e.worst < 0.02);
    free_levels(levels, count);
    lx_cubemap_free(&env);

    /* a small light 1e4 times the sky, off the centre of the coarse texel
     * it falls in: the downsampled source keeps it where it is */
    env = lx_test_make_env(32, env_constant);
    for (int k = 0; k < 3; k++)
        lx_test_cube_texel(&env, LX_FACE_PY, 21, 10)[k] = 1e4f;
    const float exps8[1] = {8.0f};
    lx_prefilter_desc d8 = {
        .filter = LX_SPECULAR_PHONG, .size = 8, .mips = 1, .phong_exponents = exps8};
    assert_int_equal(lx_prefilter(&env, &d8, levels, &count), LX_OK);
    e = level_vs_brute(&env, &levels[0], LX_SPECULAR_PHONG, 8.0);
    printf("Phong n = 8, a small bright light: mean %.2g, worst %.2g from brute force\n", e.mean,
           e.worst);
    assert_true(e.mean < 0.003);
    assert_true(e.worst < 0.04);
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
    lx_cubemap env = lx_test_make_env(32, env_wavy), levels[LX_MAX_CUBE_MIPS];
    for (int k = 0; k < 3; k++) {
        lx_prefilter_desc d = g_filters[k].desc;
        d.size = 32, d.mips = 4;
        int count;
        assert_int_equal(lx_prefilter(&env, &d, levels, &count), LX_OK);
        for (int l = 1; l < count; l++) {
            diff e = level_vs_brute(&env, &levels[l], d.filter, level_param(&d, l, count));
            printf("%s level %d (%dx%d): worst %.3f%% on the edges, %.3f%% inside\n",
                   g_filters[k].name, l, levels[l].size, levels[l].size, 100.0 * e.edge,
                   100.0 * e.inside);
            if (e.edge > 1.5 * e.inside + 1e-3)
                fail_msg("%s level %d: a seam", g_filters[k].name, l);
        }
        free_levels(levels, count);
    }
    lx_cubemap_free(&env);
}

/* ---- threads, progress, cancellation, bad input ----------------------------- */

static void same_bytes_for_any_thread_count(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, env_pattern);
    for (int k = 0; k < 3; k++) {
        lx_cubemap levels[3][LX_MAX_CUBE_MIPS];
        int count[3];
        for (int t = 0; t < 3; t++) {
            lx_prefilter_desc d = g_filters[k].desc;
            d.threads = t + 1;
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

/* Stops at call number *user (counting down). */
static bool stop_at(void *user, float f)
{
    (void)f;
    return --*(int *)user > 0;
}

/* Only the thread that started the loop reports progress, and it may get
 * no tile at all when the others take them first (a busy machine, fast
 * levels); then the one call at the end is the first. So with 2 threads
 * the callback stops at the first call; stopping partway, at the second,
 * is tested with 1 thread. */
static void cancel_returns_nothing(void **state)
{
    (void)state;
    lx_cubemap env = lx_test_make_env(32, env_pattern), levels[LX_MAX_CUBE_MIPS];
    for (int filter = 0; filter < 2; filter++)
        for (int threads = 1; threads <= 2; threads++) {
            int countdown = threads == 1 ? 2 : 1, count = 99;
            lx_prefilter_desc d = {.filter = filter,
                                   .samples = 32,
                                   .threads = threads,
                                   .progress = stop_at,
                                   .progress_user = &countdown};
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
    lx_cubemap env = lx_test_make_env(16, env_pattern);
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
    lx_test_cube_texel(&env, 1, 3, 3)[0] = INFINITY;
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
        cmocka_unit_test(ggx_small_bright_light_matches_brute_force),
        cmocka_unit_test(phong_matches_brute_force),
        cmocka_unit_test(no_seams),
        cmocka_unit_test(same_bytes_for_any_thread_count),
        cmocka_unit_test(cancel_returns_nothing),
        cmocka_unit_test(bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
