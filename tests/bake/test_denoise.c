/* The lightmap denoiser (lx_denoise, lx_denoise_combine) against
 * invariants and closed forms, on lightmaps built here from planes whose
 * positions and normals are written down directly:
 * - a constant comes out exactly (weights normalized), with any mask;
 * - one pass without the luminance weight on a flat plane is the
 *   normalized B3-spline convolution, computed here the plain way;
 * - a constant plus deterministic noise keeps its mean within the noise's
 *   standard error and its RMS noise drops by a stated factor;
 * - invalid texels are never read (NaN and garbage there change nothing)
 *   and receive nothing;
 * - charts adjacent in the map but far apart in space exchange nothing
 *   (B stays exactly 0), while the same charts continuing each other in
 *   space do mix;
 * - a step along a crease (90 and 30 degrees) stays exactly sharp;
 * - 1 and 2 threads give the same bytes; the modes are what they say;
 * - bad input and cancelling leave the output as it was;
 * - the baker's guides match the texels lx_baker_texel reports. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helpers.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- deterministic noise --------------------------------------------------- */

static uint64_t rng_state;

static uint64_t next_random(void)
{
    /* splitmix64 */
    uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* uniform in [0, 1) */
static double random_unit(void)
{
    return (double)(next_random() >> 11) / 9007199254740992.0;
}

/* ---- synthetic lightmaps ------------------------------------------------------ */

typedef struct map {
    int w, h;
    uint8_t *valid;
    lx_vec3 *pos, *nrm;
    uint32_t *chart;
    float *rgb;
} map;

static map map_new(int w, int h)
{
    size_t n = (size_t)w * h;
    map m = {w, h, calloc(n, 1), calloc(n, sizeof(lx_vec3)), calloc(n, sizeof(lx_vec3)),
             calloc(n, sizeof(uint32_t)), calloc(3 * n, sizeof(float))};
    assert_true(m.valid && m.pos && m.nrm && m.chart && m.rgb);
    return m;
}

static void map_free(map *m)
{
    free(m->valid);
    free(m->pos);
    free(m->nrm);
    free(m->chart);
    free(m->rgb);
}

static lx_denoise_guides guides_of(const map *m, bool charts)
{
    lx_denoise_guides g = {.width = m->w,
                           .height = m->h,
                           .valid = m->valid,
                           .position = m->pos,
                           .normal = m->nrm,
                           .chart = charts ? m->chart : NULL};
    return g;
}

/* Texels x0..x1-1 (all rows) as a flat plane y = 0 facing +Y, texel side
 * t metres, texel (x, y) at origin + (x t, 0, y t). */
static void plane(map *m, int x0, int x1, float t, lx_vec3 origin, uint32_t chart)
{
    for (int y = 0; y < m->h; y++)
        for (int x = x0; x < x1; x++) {
            size_t p = (size_t)y * m->w + x;
            m->valid[p] = 1;
            m->pos[p] = lx_v3(origin.x + x * t, origin.y, origin.z + y * t);
            m->nrm[p] = lx_v3(0.0f, 1.0f, 0.0f);
            m->chart[p] = chart;
        }
}

static void fill(map *m, int x0, int x1, float v)
{
    for (int y = 0; y < m->h; y++)
        for (int x = x0; x < x1; x++)
            for (int c = 0; c < 3; c++)
                m->rgb[3 * ((size_t)y * m->w + x) + c] = v;
}

/* Adds uniform noise in [-a, a] (grey) to texels x0..x1-1. */
static void add_noise(map *m, int x0, int x1, float a)
{
    for (int y = 0; y < m->h; y++)
        for (int x = x0; x < x1; x++) {
            float e = (float)((2.0 * random_unit() - 1.0) * a);
            for (int c = 0; c < 3; c++)
                m->rgb[3 * ((size_t)y * m->w + x) + c] += e;
        }
}

static float *run_denoise(const map *m, bool charts, const lx_denoise_desc *d)
{
    float *out = malloc(sizeof(float) * 3 * (size_t)m->w * m->h);
    assert_non_null(out);
    lx_denoise_guides g = guides_of(m, charts);
    lx_status st = lx_denoise(&g, m->rgb, out, d);
    if (st != LX_OK)
        fail_msg("lx_denoise: %s", lx_last_error());
    return out;
}

/* Mean and RMS deviation from `about` of channel 0 over texels x0..x1-1. */
static void stats(const map *m, const float *v, int x0, int x1, double about, double *mean,
                  double *rms)
{
    double s = 0.0, s2 = 0.0;
    int n = 0;
    for (int y = 0; y < m->h; y++)
        for (int x = x0; x < x1; x++) {
            double e = v[3 * ((size_t)y * m->w + x)];
            s += e;
            s2 += (e - about) * (e - about);
            n++;
        }
    *mean = s / n;
    *rms = sqrt(s2 / n);
}

/* ---- tests --------------------------------------------------------------------- */

static void test_modes_named(void **state)
{
    (void)state;
    const char *names[] = {"off", "indirect", "all"};
    for (int m = 0; m < 3; m++) {
        lx_denoise_mode got;
        assert_string_equal(lx_denoise_mode_name((lx_denoise_mode)m), names[m]);
        assert_true(lx_denoise_mode_parse(names[m], &got));
        assert_int_equal(got, m);
    }
    lx_denoise_mode got;
    assert_false(lx_denoise_mode_parse("direct", &got));
    assert_false(lx_denoise_mode_parse(NULL, &got));
    assert_null(lx_denoise_mode_name((lx_denoise_mode)3));
    lx_denoise_desc d = lx_denoise_desc_defaults(NULL);
    assert_int_equal(d.iterations, 5);
    assert_true(d.luminance_sigma == 4.0f && d.normal_sigma == 64.0f &&
                d.normal_cutoff == 25.0f && d.position_sigma == 0.25f &&
                d.albedo_sigma == 0.1f);
}

/* A constant signal on a random mask over two planes and a curved strip
 * comes out as the same bytes: every output is c_p + sum w (c - c) / W. */
static void test_constant_exact(void **state)
{
    (void)state;
    rng_state = 1;
    map m = map_new(96, 64);
    plane(&m, 0, 40, 0.05f, lx_v3(0, 0, 0), 0);
    plane(&m, 44, 96, 0.02f, lx_v3(5, 1, 0), 1);
    /* bend the second plane's right part around a cylinder */
    for (int y = 0; y < m.h; y++)
        for (int x = 70; x < 96; x++) {
            size_t p = (size_t)y * m.w + x;
            float a = (float)(x - 70) * 0.04f;
            m.pos[p] = lx_v3(5.0f + 70 * 0.02f + sinf(a), 1.0f + 1.0f - cosf(a), y * 0.02f);
            m.nrm[p] = lx_v3(-sinf(a), cosf(a), 0.0f);
        }
    for (size_t p = 0; p < (size_t)m.w * m.h; p++)
        if (random_unit() < 0.2)
            m.valid[p] = 0;
    fill(&m, 0, 96, 0.7f);
    float *out = run_denoise(&m, true, NULL);
    for (size_t p = 0; p < (size_t)m.w * m.h; p++)
        for (int c = 0; c < 3; c++)
            assert_true(out[3 * p + c] == m.rgb[3 * p + c]);
    free(out);
    map_free(&m);
}

/* One pass on a flat, fully valid plane without the luminance weight: all
 * guide weights are 1 (same normal, distances exactly texel sizes), so the
 * output is sum h_i h_j c_q / sum h_i h_j over the taps inside the map. */
static void test_one_pass_is_b3_convolution(void **state)
{
    (void)state;
    rng_state = 2;
    const int w = 23, h = 17;
    map m = map_new(w, h);
    plane(&m, 0, w, 0.125f, lx_v3(0, 0, 0), 0); /* exact binary positions */
    for (size_t i = 0; i < 3 * (size_t)w * h; i++)
        m.rgb[i] = (float)random_unit();
    lx_denoise_desc d = {.iterations = 1, .ignore_luminance = true};
    float *out = run_denoise(&m, false, &d);
    static const double hk[5] = {1.0 / 16, 1.0 / 4, 3.0 / 8, 1.0 / 4, 1.0 / 16};
    double worst = 0.0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++) {
                double s = 0.0, ws = 0.0;
                for (int j = -2; j <= 2; j++)
                    for (int i = -2; i <= 2; i++) {
                        int qx = x + i, qy = y + j;
                        if (qx < 0 || qy < 0 || qx >= w || qy >= h)
                            continue;
                        s += hk[i + 2] * hk[j + 2] * m.rgb[3 * ((size_t)qy * w + qx) + c];
                        ws += hk[i + 2] * hk[j + 2];
                    }
                double want = s / ws, got = out[3 * ((size_t)y * w + x) + c];
                worst = fmax(worst, fabs(got - want));
            }
    printf("B3 pass: worst error %.3g\n", worst);
    /* float sums of 25 terms of values in [0, 1): a few ulps of 1 */
    assert_true(worst < 4e-7);
    free(out);
    map_free(&m);
}

/* 1 + uniform noise in [-0.5, 0.5] (sd 0.5 / sqrt 3) on a 256^2 plane.
 * The output's mean is sum_q c_q x_q / N with c_q the column sums of the
 * normalized weights, so it moves from the input's mean by sd
 * rms(c_q - 1) / sqrt N: less than half a standard error (sd / sqrt N) of
 * it (measured 0.13), and it stays within 4 standard errors of 1. The RMS
 * deviation from 1 drops at least 10x (measured 16.8x; the unweighted
 * five-pass B3 kernel would give about 65x, the luminance weight keeps
 * some of the noise as it keeps edges). */
static void test_noise_mean_and_rms(void **state)
{
    (void)state;
    rng_state = 3;
    const int n = 256;
    map m = map_new(n, n);
    plane(&m, 0, n, 0.01f, lx_v3(0, 0, 0), 0);
    fill(&m, 0, n, 1.0f);
    add_noise(&m, 0, n, 0.5f);
    float *out = run_denoise(&m, true, NULL);
    double mean_in, rms_in, mean_out, rms_out;
    stats(&m, m.rgb, 0, n, 1.0, &mean_in, &rms_in);
    stats(&m, out, 0, n, 1.0, &mean_out, &rms_out);
    double sd = 0.5 / sqrt(3.0), se = sd / n;
    printf("noise: mean in %.6f out %.6f (standard error %.2g); rms in %.4f (sd %.4f) out %.5f, "
           "drop %.1fx\n",
           mean_in, mean_out, se, rms_in, sd, rms_out, rms_in / rms_out);
    assert_true(fabs(mean_out - mean_in) <= 0.5 * se);
    assert_true(fabs(mean_out - 1.0) <= 4.0 * se);
    assert_true(rms_in / rms_out >= 10.0);
    free(out);
    map_free(&m);
}

/* A random mask; invalid texels hold NaN colours and NaN guides in one
 * run, zeros in another: the valid texels' outputs are the same bytes,
 * and the invalid texels' outputs are their inputs. */
static void test_invalid_never_read(void **state)
{
    (void)state;
    rng_state = 4;
    const int w = 80, h = 60;
    map a = map_new(w, h), b = map_new(w, h);
    plane(&a, 0, w, 0.02f, lx_v3(0, 0, 0), 0);
    fill(&a, 0, w, 0.5f);
    add_noise(&a, 0, w, 0.3f);
    for (size_t p = 0; p < (size_t)w * h; p++)
        if (random_unit() < 0.3 || (p % (size_t)w > 30 && p % (size_t)w < 34))
            a.valid[p] = 0;
    size_t n = (size_t)w * h;
    memcpy(b.valid, a.valid, n);
    memcpy(b.pos, a.pos, n * sizeof(lx_vec3));
    memcpy(b.nrm, a.nrm, n * sizeof(lx_vec3));
    memcpy(b.rgb, a.rgb, 3 * n * sizeof(float));
    for (size_t p = 0; p < n; p++) {
        if (a.valid[p])
            continue;
        float bad = p % 3 == 0 ? NAN : p % 3 == 1 ? 1e30f : -INFINITY;
        a.rgb[3 * p] = a.rgb[3 * p + 1] = a.rgb[3 * p + 2] = bad;
        a.pos[p] = lx_v3(NAN, bad, 0.0f);
        a.nrm[p] = lx_v3(0.0f, 0.0f, 0.0f);
        a.chart[p] = 77;
        b.rgb[3 * p] = b.rgb[3 * p + 1] = b.rgb[3 * p + 2] = 0.0f;
    }
    float *oa = run_denoise(&a, true, NULL), *ob = run_denoise(&b, true, NULL);
    int filtered = 0;
    for (size_t p = 0; p < n; p++) {
        if (a.valid[p]) {
            assert_memory_equal(oa + 3 * p, ob + 3 * p, 3 * sizeof(float));
            filtered += oa[3 * p] != a.rgb[3 * p];
        } else {
            assert_memory_equal(oa + 3 * p, a.rgb + 3 * p, 3 * sizeof(float));
            assert_memory_equal(ob + 3 * p, b.rgb + 3 * p, 3 * sizeof(float));
        }
    }
    assert_true(filtered > 0); /* the filter did work */
    free(oa);
    free(ob);
    map_free(&a);
    map_free(&b);
}

/* Chart A (texels 0..31, value 1 plus noise) and chart B (32..63, value 0)
 * touch in the map; B lies 100 m away. B stays exactly 0, with chart ids
 * and without them (the distance alone separates them). With B moved
 * next to A in space (its plane continuing A's), light does cross. */
static void test_charts_apart_in_space(void **state)
{
    (void)state;
    rng_state = 5;
    const int w = 64, h = 40;
    const float t = 0.05f;
    for (int placement = 0; placement < 2; placement++) {
        map m = map_new(w, h);
        plane(&m, 0, 32, t, lx_v3(0, 0, 0), 0);
        /* far: 100 m along x; near: exactly where A's plane continues */
        plane(&m, 32, 64, t, placement == 0 ? lx_v3(100.0f, 0, 0) : lx_v3(0, 0, 0), 1);
        fill(&m, 0, 32, 1.0f);
        add_noise(&m, 0, 32, 0.3f);
        for (int charts = 0; charts < 2; charts++) {
            float *out = run_denoise(&m, charts, NULL);
            double sum_b = 0.0;
            for (int y = 0; y < h; y++)
                for (int x = 32; x < w; x++)
                    for (int c = 0; c < 3; c++)
                        sum_b += out[3 * ((size_t)y * w + x) + c];
            if (placement == 0 || charts)
                for (int y = 0; y < h; y++)
                    for (int x = 32; x < w; x++)
                        for (int c = 0; c < 3; c++)
                            assert_true(out[3 * ((size_t)y * w + x) + c] == 0.0f);
            else
                assert_true(sum_b > 1.0); /* neighbours in space do share */
            free(out);
        }
        map_free(&m);
    }
}

/* A floor (texels 0..31, +Y, value 1) folds into a wall (32..63) along a
 * crease; the wall's texels continue the floor's spacing in space, its
 * normal turned by `angle`. Constants: both sides keep their values
 * exactly. With noise: the columns on each side of the crease keep their
 * side's mean (within 4 standard errors of the column's input noise). */
static void crease(double angle_deg)
{
    const int w = 64, h = 128;
    const float t = 0.05f;
    double a = angle_deg * LX_PI / 180.0;
    /* the wall rises from the crease line x = 31.5 t at angle a */
    lx_vec3 dir = lx_v3((float)cos(a), (float)sin(a), 0.0f);
    lx_vec3 nw = lx_v3((float)-sin(a), (float)cos(a), 0.0f);
    for (int noisy = 0; noisy < 2; noisy++) {
        map m = map_new(w, h);
        plane(&m, 0, 32, t, lx_v3(0, 0, 0), 0);
        for (int y = 0; y < h; y++)
            for (int x = 32; x < w; x++) {
                size_t p = (size_t)y * w + x;
                float s = (float)(x - 31.5) * t;
                m.valid[p] = 1;
                m.pos[p] = lx_v3(31.5f * t + s * dir.x, s * dir.y, y * t);
                m.nrm[p] = nw;
            }
        fill(&m, 0, 32, 1.0f);
        fill(&m, 32, 64, 0.25f);
        if (noisy) {
            add_noise(&m, 0, 64, 0.2f);
        }
        float *out = run_denoise(&m, false, NULL);
        if (!noisy) {
            for (size_t p = 0; p < (size_t)w * h; p++)
                assert_true(out[3 * p] == (p % (size_t)w < 32 ? 1.0f : 0.25f));
        } else {
            double se = 0.2 / sqrt(3.0) / sqrt((double)h), mean, rms;
            stats(&m, out, 31, 32, 1.0, &mean, &rms);
            printf("crease %.0f: floor column %.5f", angle_deg, mean);
            assert_true(fabs(mean - 1.0) <= 4.0 * se);
            stats(&m, out, 32, 33, 0.25, &mean, &rms);
            printf(", wall column %.5f (standard error %.2g)\n", mean, se);
            assert_true(fabs(mean - 0.25) <= 4.0 * se);
        }
        free(out);
        map_free(&m);
    }
}

static void test_crease_90(void **state)
{
    (void)state;
    rng_state = 6;
    crease(90.0);
}

static void test_crease_30(void **state)
{
    (void)state;
    rng_state = 7;
    crease(30.0);
}

/* A noisy map with a mask, two charts, a crease, albedo and a variance
 * guide: 1 and 2 threads give the same bytes, each mode. */
static void test_threads_identical(void **state)
{
    (void)state;
    rng_state = 8;
    const int w = 150, h = 90;
    map m = map_new(w, h);
    plane(&m, 0, 70, 0.03f, lx_v3(0, 0, 0), 0);
    plane(&m, 72, 150, 0.02f, lx_v3(3, 0, 0), 1);
    for (int y = 0; y < h; y++)
        for (int x = 110; x < 150; x++)
            m.nrm[(size_t)y * w + x] = lx_v3(0.3f, 1.0f, 0.0f);
    size_t n = (size_t)w * h;
    for (size_t p = 0; p < n; p++)
        if (random_unit() < 0.1)
            m.valid[p] = 0;
    fill(&m, 0, w, 2.0f);
    add_noise(&m, 0, w, 1.5f);
    lx_vec3 *albedo = malloc(n * sizeof(lx_vec3));
    float *variance = malloc(n * sizeof(float)), *direct = malloc(3 * n * sizeof(float));
    assert_true(albedo && variance && direct);
    for (size_t p = 0; p < n; p++) {
        albedo[p] = lx_v3((float)random_unit(), 0.5f, 0.5f);
        variance[p] = (float)random_unit() * 0.5f;
        for (int c = 0; c < 3; c++)
            direct[3 * p + c] = (float)random_unit();
    }
    for (int mode = LX_DENOISE_OFF; mode <= LX_DENOISE_ALL; mode++)
        for (int guides = 0; guides < 2; guides++) {
            float *o[2];
            for (int k = 0; k < 2; k++) {
                lx_denoise_guides g = guides_of(&m, true);
                if (guides) {
                    g.albedo = albedo;
                    g.variance = variance;
                }
                lx_denoise_desc d = {.threads = k + 1};
                o[k] = malloc(3 * n * sizeof(float));
                assert_non_null(o[k]);
                assert_int_equal(
                    lx_denoise_combine((lx_denoise_mode)mode, &g, direct, m.rgb, o[k], &d), LX_OK);
            }
            assert_memory_equal(o[0], o[1], 3 * n * sizeof(float));
            free(o[0]);
            free(o[1]);
        }
    free(albedo);
    free(variance);
    free(direct);
    map_free(&m);
}

/* The modes by their definitions: off adds; indirect is direct + the
 * filtered indirect; all filters the sum (the sums formed here in the
 * same float operations). Outputs may be an input. */
static void test_modes(void **state)
{
    (void)state;
    rng_state = 9;
    const int w = 48, h = 32;
    size_t n = (size_t)w * h;
    map m = map_new(w, h);
    plane(&m, 0, w, 0.1f, lx_v3(0, 0, 0), 0);
    for (size_t p = 0; p < n; p++)
        m.valid[p] = random_unit() < 0.9;
    fill(&m, 0, w, 0.3f);
    add_noise(&m, 0, w, 0.2f);
    float *direct = malloc(3 * n * sizeof(float)), *sum = malloc(3 * n * sizeof(float));
    float *out = malloc(3 * n * sizeof(float)), *alias = malloc(3 * n * sizeof(float));
    assert_true(direct && sum && out && alias);
    for (size_t i = 0; i < 3 * n; i++) {
        direct[i] = i / 3 % (size_t)w < 24 ? 2.0f : 0.0f; /* a sharp direct edge */
        sum[i] = direct[i] + m.rgb[i];
    }
    lx_denoise_guides g = guides_of(&m, false);
    /* off */
    assert_int_equal(lx_denoise_combine(LX_DENOISE_OFF, &g, direct, m.rgb, out, NULL), LX_OK);
    assert_memory_equal(out, sum, 3 * n * sizeof(float));
    /* indirect */
    float *f_ind = run_denoise(&m, false, NULL);
    assert_int_equal(lx_denoise_combine(LX_DENOISE_INDIRECT, &g, direct, m.rgb, out, NULL), LX_OK);
    for (size_t p = 0; p < n; p++)
        for (int c = 0; c < 3; c++) {
            float want = m.valid[p] ? direct[3 * p + c] + f_ind[3 * p + c] : sum[3 * p + c];
            assert_true(out[3 * p + c] == want);
        }
    memcpy(alias, m.rgb, 3 * n * sizeof(float)); /* out = indirect */
    assert_int_equal(lx_denoise_combine(LX_DENOISE_INDIRECT, &g, direct, alias, alias, NULL), LX_OK);
    assert_memory_equal(alias, out, 3 * n * sizeof(float));
    /* all */
    float *f_sum;
    {
        map s = m;
        s.rgb = sum;
        f_sum = run_denoise(&s, false, NULL);
    }
    assert_int_equal(lx_denoise_combine(LX_DENOISE_ALL, &g, direct, m.rgb, out, NULL), LX_OK);
    assert_memory_equal(out, f_sum, 3 * n * sizeof(float));
    memcpy(alias, direct, 3 * n * sizeof(float)); /* out = direct */
    assert_int_equal(lx_denoise_combine(LX_DENOISE_ALL, &g, alias, m.rgb, alias, NULL), LX_OK);
    assert_memory_equal(alias, f_sum, 3 * n * sizeof(float));
    free(f_ind);
    free(f_sum);
    free(direct);
    free(sum);
    free(out);
    free(alias);
    map_free(&m);
}

static bool stop_at_half(void *user, float fraction)
{
    int *calls = user;
    (*calls)++;
    return fraction < 0.5f;
}

static bool stop_at_once(void *user, float fraction)
{
    (void)fraction;
    int *calls = user;
    (*calls)++;
    return false;
}

/* Bad inputs fail with a message naming the problem (and the texel) and
 * leave out as it was; so does cancelling. */
static void test_bad_input_and_cancel(void **state)
{
    (void)state;
    rng_state = 10;
    const int w = 40, h = 30;
    size_t n = (size_t)w * h;
    map m = map_new(w, h);
    plane(&m, 0, w, 0.1f, lx_v3(0, 0, 0), 0);
    fill(&m, 0, w, 1.0f);
    add_noise(&m, 0, w, 0.5f);
    float *out = malloc(3 * n * sizeof(float));
    assert_non_null(out);
    for (size_t i = 0; i < 3 * n; i++)
        out[i] = -7.0f;
    lx_denoise_guides g = guides_of(&m, false);
    struct {
        const char *what;
        size_t texel;
    } cases[] = {{"colour", 5 * w + 7}, {"position", 3 * w + 2}, {"normal", 11 * w + 30}};
    for (int k = 0; k < 3; k++) {
        map c = map_new(w, h);
        memcpy(c.valid, m.valid, n);
        memcpy(c.pos, m.pos, n * sizeof(lx_vec3));
        memcpy(c.nrm, m.nrm, n * sizeof(lx_vec3));
        memcpy(c.rgb, m.rgb, 3 * n * sizeof(float));
        size_t p = cases[k].texel;
        if (k == 0)
            c.rgb[3 * p + 1] = NAN;
        else if (k == 1)
            c.pos[p].z = INFINITY;
        else
            c.nrm[p] = lx_v3(0, 0, 0);
        lx_denoise_guides cg = guides_of(&c, false);
        assert_int_equal(lx_denoise(&cg, c.rgb, out, NULL), LX_ERR_INVALID);
        char want[64];
        snprintf(want, sizeof want, "texel (%d, %d): %s", (int)(p % w), (int)(p / w),
                 cases[k].what);
        printf("%s\n", lx_last_error());
        assert_non_null(strstr(lx_last_error(), want));
        map_free(&c);
    }
    lx_denoise_desc bad[] = {{.iterations = 13}, {.iterations = -1}, {.normal_cutoff = -5.0f},
                             {.luminance_sigma = NAN}, {.threads = -2}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++)
        assert_int_equal(lx_denoise(&g, m.rgb, out, &bad[k]), LX_ERR_INVALID);
    lx_denoise_guides none = g;
    none.normal = NULL;
    assert_int_equal(lx_denoise(&none, m.rgb, out, NULL), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "normal"));
    assert_int_equal(lx_denoise(NULL, m.rgb, out, NULL), LX_ERR_INVALID);
    assert_int_equal(lx_denoise(&g, NULL, out, NULL), LX_ERR_INVALID);
    assert_int_equal(lx_denoise_combine((lx_denoise_mode)7, &g, NULL, m.rgb, out, NULL),
                     LX_ERR_INVALID);
    int calls = 0;
    lx_denoise_desc d = {.progress = stop_at_half, .progress_user = &calls};
    assert_int_equal(lx_denoise(&g, m.rgb, out, &d), LX_ERR_CANCELLED);
    assert_true(calls > 0);
    for (size_t i = 0; i < 3 * n; i++)
        assert_true(out[i] == -7.0f);
    /* stopped at the first report (the surfaces, before any pass) */
    calls = 0;
    d.progress = stop_at_once;
    assert_int_equal(lx_denoise(&g, m.rgb, out, &d), LX_ERR_CANCELLED);
    assert_int_equal(calls, 1);
    for (size_t i = 0; i < 3 * n; i++)
        assert_true(out[i] == -7.0f);
    free(out);
    map_free(&m);
}

/* The baker's guides of two planes sharing an atlas-free lightmap each:
 * valid = lx_baker_mask, positions and normals = lx_baker_texel's, chart =
 * the node; and denoising the applied map keeps a uniformly lit floor's
 * values (a constant up to float rounding of the bake). */
static void test_baker_guides(void **state)
{
    (void)state;
    lx_scene *scene = lx_test_new_scene("guides");
    lx_mesh floor = lx_test_plane("floor", 2.0f, 0.0f, 0.0f, 0.0f, 2);
    lx_test_add(scene, &floor);
    lx_test_mesh_free(&floor);
    scene->ambient = lx_v3(3.0f, 3.0f, 3.0f);
    lx_bake_desc desc = {.resolution = 16, .threads = 2};
    lx_baker *baker;
    assert_int_equal(lx_baker_create(scene, &desc, &baker), LX_OK);
    lx_scene_destroy(scene);
    uint32_t lm = lx_test_map_of(baker, 0);
    lx_denoise_guides g;
    assert_int_equal(lx_baker_denoise_guides(baker, lm, &g), LX_OK);
    const lx_lightmap_info *info = lx_baker_lightmap_info(baker, lm);
    assert_int_equal(g.width, info->width);
    assert_int_equal(g.height, info->height);
    const uint8_t *mask = lx_baker_mask(baker, lm);
    int covered = 0;
    for (int y = 0; y < g.height; y++)
        for (int x = 0; x < g.width; x++) {
            size_t p = (size_t)y * g.width + x;
            lx_texel_sample s;
            bool has = lx_baker_texel(baker, lm, x, y, &s);
            assert_int_equal(!!g.valid[p], has);
            assert_int_equal(!!g.valid[p], !!mask[p]);
            if (!has)
                continue;
            covered++;
            assert_memory_equal(&g.position[p], &s.position, sizeof(lx_vec3));
            assert_memory_equal(&g.normal[p], &s.normal, sizeof(lx_vec3));
            assert_int_equal(g.chart[p], s.node);
        }
    assert_int_equal(covered, 16 * 16);
    assert_null(g.albedo);
    assert_null(g.texel_size);
    assert_null(g.variance);
    assert_int_equal(lx_baker_bake(baker), LX_OK);
    lx_image img;
    assert_int_equal(lx_baker_apply_alloc(baker, lm, &img), LX_OK);
    float *before = malloc(sizeof(float) * 3 * 16 * 16);
    assert_non_null(before);
    memcpy(before, img.data, sizeof(float) * 3 * 16 * 16);
    assert_int_equal(lx_denoise(&g, img.data, img.data, NULL), LX_OK);
    /* ambient 3 lux everywhere: a constant in, the same constant out */
    for (int i = 0; i < 3 * 16 * 16; i++) {
        assert_true(before[i] == 3.0f);
        assert_true(img.data[i] == 3.0f);
    }
    free(before);
    lx_image_free(&img);
    lx_denoise_guides_free(&g);
    assert_null(g.valid);
    lx_denoise_guides_free(NULL);
    lx_baker_destroy(baker);
}

int main(void)
{
    lx_test_watchdog(300);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_modes_named),
        cmocka_unit_test(test_constant_exact),
        cmocka_unit_test(test_one_pass_is_b3_convolution),
        cmocka_unit_test(test_noise_mean_and_rms),
        cmocka_unit_test(test_invalid_never_read),
        cmocka_unit_test(test_charts_apart_in_space),
        cmocka_unit_test(test_crease_90),
        cmocka_unit_test(test_crease_30),
        cmocka_unit_test(test_threads_identical),
        cmocka_unit_test(test_modes),
        cmocka_unit_test(test_bad_input_and_cancel),
        cmocka_unit_test(test_baker_guides),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
