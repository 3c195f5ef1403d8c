/* Horizon and ambient-occlusion maps (src/maps/horizon.c) and the shading
 * side (src/maps/horizon_cube.c) against values from outside the code:
 * closed-form horizons of a plane, a cone pit and a peak, a wall (step);
 * an independent brute-force implementation of the method's definition
 * (every texel, every direction, atan2 and its own wrap arithmetic) on
 * random fields in every wrap mode, with a ray-marched lower bound; the
 * seed's piecewise-linear weights and eq. 7.58 evaluated by hand. */
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
#include "core/internal.h"

#define PI 3.14159265358979323846

static lx_image field(int w, int h)
{
    lx_image img;
    assert_int_equal(lx_image_alloc(&img, w, h, 1), LX_OK);
    return img;
}

static float *at(lx_image *img, int x, int y)
{
    return img->data + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)img->channels;
}

/* channel of direction d (0..7) at texel (x, y) */
static float dir_value(lx_image *l0, lx_image *l1, int d, int x, int y)
{
    return at(d < 4 ? l0 : l1, x, y)[d & 3];
}

static void run(const lx_image *hf, lx_horizon_desc d, lx_image *l0, lx_image *l1, lx_image *ao)
{
    lx_status s = lx_horizon_map(hf, &d, l0, l1, ao);
    if (s != LX_OK)
        fail_msg("lx_horizon_map: %s", lx_last_error());
}

/* ---- closed forms ---------------------------------------------------------- */

static void test_plane_has_no_horizon(void **state)
{
    (void)state;
    lx_image hf = field(37, 29), l0, l1, ao;
    for (int i = 0; i < 37 * 29; i++)
        hf.data[i] = 0.625f;
    for (int wrap = 0; wrap < 3; wrap++) {
        run(&hf, (lx_horizon_desc){.wrap = (lx_wrap)wrap, .ao_power = 3.0f}, &l0, &l1, &ao);
        for (int i = 0; i < 37 * 29; i++) {
            for (int c = 0; c < 4; c++) {
                assert_true(l0.data[4 * i + c] == 0.0f);
                assert_true(l1.data[4 * i + c] == 0.0f);
            }
            /* the mean of cos 0 over the bins is 1 (the seed's sum times
             * the bin count would be 1024) */
            assert_true(ao.data[i] == 1.0f);
        }
        lx_image_free(&l0);
        lx_image_free(&l1);
        lx_image_free(&ao);
    }
    lx_image_free(&hf);
}

/* h = k r / S around the centre of a 41 x 41 image: seen from the centre
 * every texel at distance r is k r texels higher, so every direction's
 * tangent is k: sin = k / sqrt(k^2 + 1), AO = (1 / sqrt(k^2 + 1))^p or
 * 1 / (k^2 + 1) with the cosine weighting. The apex of the opposite cone
 * (a peak) sees nothing: 0 and 1. */
static void test_cone_pit_and_peak(void **state)
{
    (void)state;
    const float S = 8.0f;
    const double k = 0.75;
    lx_image pit = field(41, 41), peak = field(41, 41), l0, l1, ao;
    for (int y = 0; y < 41; y++)
        for (int x = 0; x < 41; x++) {
            double r = sqrt((double)((x - 20) * (x - 20) + (y - 20) * (y - 20)));
            *at(&pit, x, y) = (float)(k * r / S);
            *at(&peak, x, y) = (float)(1.0 - k * r / S);
        }
    double sin_e = k / sqrt(k * k + 1), cos_e = 1 / sqrt(k * k + 1);
    for (int angles = 16; angles <= 64; angles *= 2) {
        run(&pit, (lx_horizon_desc){.strength = S, .angles = angles, .ao_power = 2.5f}, &l0, &l1,
            &ao);
        for (int d = 0; d < 8; d++)
            assert_float_equal(dir_value(&l0, &l1, d, 20, 20), sin_e, 2e-6);
        assert_float_equal(at(&ao, 20, 20)[0], pow(cos_e, 2.5), 2e-6);
        lx_image_free(&l0);
        lx_image_free(&l1);
        lx_image_free(&ao);
        run(&pit, (lx_horizon_desc){.strength = S, .angles = angles, .ao_cosine = true}, NULL,
            NULL, &ao);
        assert_float_equal(at(&ao, 20, 20)[0], cos_e * cos_e, 2e-6);
        lx_image_free(&ao);
        run(&peak, (lx_horizon_desc){.strength = S, .angles = angles}, &l0, &l1, &ao);
        for (int d = 0; d < 8; d++)
            assert_true(dir_value(&l0, &l1, d, 20, 20) == 0.0f);
        assert_true(at(&ao, 20, 20)[0] == 1.0f);
        lx_image_free(&l0);
        lx_image_free(&l1);
        lx_image_free(&ao);
    }
    lx_image_free(&pit);
    lx_image_free(&peak);
}

/* A wall H texels high filling columns x >= 30 (clamp: the rows are all
 * alike). A texel d columns before it sees, toward +x, the wall's nearest
 * texel at distance d (tan = H / d, exact for the bin along +x, and at
 * most that for the others: every wall texel is at least d away); a ray
 * at angle a from +x meets the wall at d / cos a, so the direction-0
 * channel is close to the mean of sin(atan(H cos a / d)) over its bins.
 * Toward -x (directions 3, 4, 5) nothing is higher: exactly 0. At d >=
 * radius the wall is out of reach: every channel 0, AO 1. */
static void test_step(void **state)
{
    (void)state;
    const int R = 16, N = 32;
    const float H = 4.0f;
    lx_image hf = field(48, 9), l0, l1, ao;
    for (int y = 0; y < 9; y++)
        for (int x = 0; x < 48; x++)
            *at(&hf, x, y) = x >= 30 ? 1.0f : 0.0f;
    run(&hf, (lx_horizon_desc){.strength = H, .radius = R, .angles = N, .wrap = LX_WRAP_CLAMP},
        &l0, &l1, &ao);
    double worst = 0.0;
    for (int d = 1; d <= 20; d++) {
        int x = 30 - d;
        for (int y = 0; y < 9; y++) {
            for (int dir = 3; dir <= 5; dir++)
                assert_true(dir_value(&l0, &l1, dir, x, y) == 0.0f);
            float got = dir_value(&l0, &l1, 0, x, y);
            if (d >= R) {
                for (int dir = 0; dir < 8; dir++)
                    assert_true(dir_value(&l0, &l1, dir, x, y) == 0.0f);
                assert_true(at(&ao, x, y)[0] == 1.0f);
                continue;
            }
            double upper = H / d / sqrt((double)H * H / ((double)d * d) + 1), sum = 0.0;
            assert_true(got <= upper + 1e-6);
            for (int m = -N / 16; m <= N / 16; m++) {
                double a = 2 * PI * m / N, reach = d / cos(a);
                double t = reach < R ? H / reach : 0.0;
                sum += t / sqrt(t * t + 1);
            }
            double want = sum / (N / 8 + 1), err = fabs(got - want);
            worst = err > worst ? err : worst;
        }
    }
    /* texel centres lie off the bins' rays: measured worst 0.0055 */
    if (getenv("LX_TEST_MEASURE"))
        fprintf(stderr, "step: worst %g\n", worst);
    if (worst > 0.015)
        fail_msg("step: direction 0 differs from the closed form by %g", worst);
    lx_image_free(&l0);
    lx_image_free(&l1);
    lx_image_free(&ao);
    lx_image_free(&hf);
}

/* ---- brute force -------------------------------------------------------------
 * The method's definition, done the slow way: for each texel and each
 * direction theta_m, every texel within the radius, its azimuth by atan2,
 * counted when theta_m is within atan(sqrt(1/2) / r) of it. Wrap by the
 * test's own arithmetic. Double precision throughout. */

static int bf_wrap(int mode, int i, int n)
{
    if (mode == LX_WRAP_CLAMP)
        return i < 0 ? 0 : i >= n ? n - 1 : i;
    if (mode == LX_WRAP_MIRROR) {
        int m = i;
        while (m < 0 || m >= n)
            m = m < 0 ? -m - 1 : 2 * n - 1 - m;
        return m;
    }
    return ((i % n) + n) % n;
}

static double bf_height(const lx_image *hf, int mode, int x, int y)
{
    return hf->data[(size_t)bf_wrap(mode, y, hf->height) * (size_t)hf->width +
                    (size_t)bf_wrap(mode, x, hf->width)];
}

/* tangent of each of the N directions at (x, y) into t */
static void bf_tangents(const lx_image *hf, int mode, double S, int R, int N, int x, int y,
                        double *t)
{
    double h0 = bf_height(hf, mode, x, y);
    for (int m = 0; m < N; m++) {
        double theta = 2 * PI * m / N, best = 0.0;
        for (int j = -R; j <= R; j++)
            for (int i = -R; i <= R; i++) {
                int r2 = i * i + j * j;
                if (r2 == 0 || r2 >= R * R)
                    continue;
                double r = sqrt((double)r2);
                double diff = fabs(remainder(atan2((double)j, (double)i) - theta, 2 * PI));
                if (diff > atan(sqrt(0.5) / r))
                    continue;
                /* j is up the image: row y - j */
                double dh = (bf_height(hf, mode, x + i, y - j) - h0) * S;
                best = fmax(best, dh / r);
            }
        t[m] = best;
    }
}

/* Ray-marched lower bound: along theta_m, the texels whose centre is
 * within 0.4 of a point of the ray (those the ray crosses well inside)
 * are all counted by the definition, so their largest tangent is at most
 * the map's. */
static void ray_tangents(const lx_image *hf, int mode, double S, int R, int N, int x, int y,
                         double *t)
{
    double h0 = bf_height(hf, mode, x, y);
    for (int m = 0; m < N; m++) {
        double c = cos(2 * PI * m / N), s = sin(2 * PI * m / N), best = 0.0;
        for (double u = 0.5; u < R; u += 0.01) {
            double px = u * c, py = u * s;
            int i = (int)lround(px), j = (int)lround(py);
            int r2 = i * i + j * j;
            if (r2 == 0 || r2 >= R * R || fabs(px - i) > 0.4 || fabs(py - j) > 0.4)
                continue;
            double dh = (bf_height(hf, mode, x + i, y - j) - h0) * S;
            best = fmax(best, dh / sqrt((double)r2));
        }
        t[m] = best;
    }
}

static void check_against_brute_force(const lx_image *hf, int mode, double S, int R, int N,
                                      float power, bool cosine)
{
    lx_image l0, l1, ao;
    run(hf, (lx_horizon_desc){.strength = (float)S, .radius = R, .angles = N, .wrap = (lx_wrap)mode,
                              .ao_power = power, .ao_cosine = cosine, .threads = 2},
        &l0, &l1, &ao);
    double t[1024], lo[1024], worst = 0.0;
    for (int y = 0; y < hf->height; y++)
        for (int x = 0; x < hf->width; x++) {
            bf_tangents(hf, mode, S, R, N, x, y, t);
            ray_tangents(hf, mode, S, R, N, x, y, lo);
            double aosum = 0.0;
            for (int m = 0; m < N; m++) {
                assert_true(lo[m] <= t[m] + 1e-9);
                double q = 1 / sqrt(t[m] * t[m] + 1);
                aosum += cosine ? q * q : q;
            }
            for (int d = 0; d < 8; d++) {
                double sum = 0.0, sum_lo = 0.0;
                for (int k = -N / 16; k <= N / 16; k++) {
                    int m = (d * N / 8 + k + N) % N;
                    sum += t[m] / sqrt(t[m] * t[m] + 1);
                    sum_lo += lo[m] / sqrt(lo[m] * lo[m] + 1);
                }
                double got = dir_value(&l0, &l1, d, x, y), want = sum / (N / 8 + 1);
                worst = fmax(worst, fabs(got - want));
                assert_true(got >= sum_lo / (N / 8 + 1) - 1e-5);
            }
            double want_ao = pow(aosum / N, power);
            worst = fmax(worst, fabs(at(&ao, x, y)[0] - want_ao));
        }
    /* float against double: measured worst 5.3e-7 */
    if (getenv("LX_TEST_MEASURE"))
        fprintf(stderr, "brute force %s R %d N %d: worst %g\n", lx_wrap_name(mode), R, N, worst);
    if (worst > 2e-6)
        fail_msg("wrap %s, radius %d, %d angles: off the brute force by %g", lx_wrap_name(mode),
                 R, N, worst);
    lx_image_free(&l0);
    lx_image_free(&l1);
    lx_image_free(&ao);
}

static lx_image random_field(int w, int h, uint32_t seed)
{
    lx_image hf = field(w, h);
    for (int i = 0; i < w * h; i++)
        hf.data[i] = lx_random(seed, (uint32_t)i, 0, 0);
    return hf;
}

static void test_random_field_every_wrap(void **state)
{
    (void)state;
    lx_image hf = random_field(23, 17, 11u);
    for (int mode = 0; mode < 3; mode++) {
        check_against_brute_force(&hf, mode, 3.0, 6, 16, 1.0f, false);
        check_against_brute_force(&hf, mode, 5.0, 9, 32, 2.0f, true);
    }
    lx_image_free(&hf);
    /* an image smaller than the radius: addresses wrap several times */
    hf = random_field(5, 3, 12u);
    for (int mode = 0; mode < 3; mode++)
        check_against_brute_force(&hf, mode, 2.0, 8, 64, 0.5f, false);
    lx_image_free(&hf);
}

/* h = sin(2 pi x / 15) on 45 x 37 (sizes that are not powers of two, the
 * period dividing the width so REPEAT tiles seamlessly): the brute force
 * agrees, every row is the same, the map repeats with the period, and
 * directions mirrored in y (1 and 7, 2 and 6, 3 and 5) are equal. */
static void test_sinusoid_non_power_of_two(void **state)
{
    (void)state;
    lx_image hf = field(45, 37), l0, l1, ao;
    for (int y = 0; y < 37; y++)
        for (int x = 0; x < 45; x++)
            *at(&hf, x, y) = (float)(0.5 + 0.5 * sin(2 * PI * x / 15.0));
    check_against_brute_force(&hf, LX_WRAP_REPEAT, 6.0, 16, 32, 1.0f, false);
    run(&hf, (lx_horizon_desc){.strength = 6.0f}, &l0, &l1, &ao);
    for (int y = 0; y < 37; y++)
        for (int x = 0; x < 45; x++)
            for (int d = 0; d < 8; d++) {
                float v = dir_value(&l0, &l1, d, x, y);
                assert_true(v == dir_value(&l0, &l1, d, x, 0));
                assert_true(v == dir_value(&l0, &l1, d, (x + 15) % 45, y));
                if (d != 0 && d != 4)
                    assert_float_equal(v, dir_value(&l0, &l1, 8 - d, x, y), 1e-6);
            }
    lx_image_free(&l0);
    lx_image_free(&l1);
    lx_image_free(&ao);
    lx_image_free(&hf);
}

/* One tall texel at (0, 0) of a flat 12 x 10 image, seen from the texel
 * at the other end of row 0, (11, 0), one column past the edge, with 16
 * directions (direction 0 is the mean of the bins at -22.5, 0 and 22.5
 * degrees). REPEAT: it is the neighbour at (1, 0), whose half-width
 * atan(sqrt(1/2)) = 35.3 degrees takes in all three bins: tan = H each.
 * CLAMP: the columns past the edge repeat column 11, nothing is higher.
 * MIRROR: columns 23 and 24 are column 0 and row -1 is row 0, so the tall
 * texel is at offsets (12, 0), (12, 1), (13, 0), (13, 1); only the bin
 * along +x meets one, at distance 12 (the others pass 3.4 degrees off). */
static void test_wrap_at_borders(void **state)
{
    (void)state;
    const double H = 6.0;
    lx_image hf = field(12, 10), l0, l1;
    *at(&hf, 0, 0) = 1.0f;
    const double s1 = H / sqrt(H * H + 1), s12 = (H / 12) / sqrt(H * H / 144 + 1);
    const double want[3] = {s1, 0.0, s12 / 3.0};
    for (int mode = 0; mode < 3; mode++) {
        run(&hf, (lx_horizon_desc){.strength = (float)H, .wrap = (lx_wrap)mode, .angles = 16},
            &l0, &l1, NULL);
        float got = dir_value(&l0, &l1, 0, 11, 0);
        if (fabs(got - want[mode]) > 1e-6)
            fail_msg("%s: direction 0 at (11, 0) is %g, want %g", lx_wrap_name(mode), got,
                     want[mode]);
        lx_image_free(&l0);
        lx_image_free(&l1);
    }
    lx_image_free(&hf);
}

static int progress_calls;
static bool stop_at_half(void *user, float f)
{
    (void)user;
    progress_calls++;
    return f < 0.5f;
}

static void test_threads_bad_input_and_cancel(void **state)
{
    (void)state;
    lx_image hf = random_field(64, 48, 5u), a0, a1, aa, b0, b1, ba;
    run(&hf, (lx_horizon_desc){.threads = 1}, &a0, &a1, &aa);
    run(&hf, (lx_horizon_desc){.threads = 2}, &b0, &b1, &ba);
    assert_memory_equal(a0.data, b0.data, sizeof(float) * 4 * 64 * 48);
    assert_memory_equal(a1.data, b1.data, sizeof(float) * 4 * 64 * 48);
    assert_memory_equal(aa.data, ba.data, sizeof(float) * 64 * 48);
    lx_image_free(&a0);
    lx_image_free(&a1);
    lx_image_free(&aa);
    lx_image_free(&b0);
    lx_image_free(&b1);
    lx_image_free(&ba);

    lx_image o = {.width = 99};
    const int bad_angles[] = {8, 24, 48, 2048, -16};
    for (size_t i = 0; i < sizeof bad_angles / sizeof bad_angles[0]; i++) {
        lx_horizon_desc d = {.angles = bad_angles[i]};
        assert_int_equal(lx_horizon_map(&hf, &d, NULL, NULL, &o), LX_ERR_INVALID);
        char num[16];
        snprintf(num, sizeof num, "%d", bad_angles[i]);
        assert_non_null(strstr(lx_last_error(), num));
        assert_null(o.data);
        assert_int_equal(o.width, 0);
    }
    lx_horizon_desc bad[] = {{.radius = 1}, {.radius = -3}, {.strength = -1.0f},
                             {.strength = NAN}, {.ao_power = -2.0f}, {.wrap = (lx_wrap)7}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        assert_int_equal(lx_horizon_map(&hf, &bad[i], NULL, NULL, &o), LX_ERR_INVALID);
    lx_image rgb;
    assert_int_equal(lx_image_alloc(&rgb, 8, 8, 3), LX_OK);
    assert_int_equal(lx_horizon_map(&rgb, NULL, NULL, NULL, &o), LX_ERR_INVALID);
    assert_non_null(strstr(lx_last_error(), "3 channels"));
    lx_image_free(&rgb);
    hf.data[77] = NAN;
    assert_int_equal(lx_horizon_map(&hf, NULL, NULL, NULL, &o), LX_ERR_INVALID);
    hf.data[77] = 0.5f;

    progress_calls = 0;
    lx_horizon_desc d = {.threads = 1, .progress = stop_at_half};
    assert_int_equal(lx_horizon_map(&hf, &d, &a0, &a1, &aa), LX_ERR_CANCELLED);
    assert_true(progress_calls > 1);
    assert_null(a0.data);
    assert_null(aa.data);
    lx_image_free(&hf);
}

/* ---- weights and the shading function ---------------------------------- */

static lx_vec3 azimuth(double deg, double elev_deg)
{
    double a = deg * PI / 180, e = elev_deg * PI / 180;
    return lx_v3((float)(cos(e) * cos(a)), (float)(cos(e) * sin(a)), (float)sin(e));
}

/* The seed's weights: linear between the two neighbouring directions of
 * the eight, positive for 0..3 (layer 0), negative for 4..7 (layer 1). */
static void test_weights(void **state)
{
    (void)state;
    float w[4];
    for (int k = 0; k < 8; k++) {
        lx_horizon_weights(azimuth(45.0 * k, 10.0), w);
        for (int c = 0; c < 4; c++)
            assert_float_equal(w[c], c == (k & 3) ? (k < 4 ? 1.0 : -1.0) : 0.0, 1e-6);
    }
    lx_horizon_weights(azimuth(22.5, 0.0), w);
    assert_float_equal(w[0], 0.5, 1e-6);
    assert_float_equal(w[1], 0.5, 1e-6);
    lx_horizon_weights(azimuth(200.0, 30.0), w); /* 4/9 of the way from 180 to 225 */
    assert_float_equal(w[0], -5.0 / 9.0, 1e-6);
    assert_float_equal(w[1], -4.0 / 9.0, 1e-6);
    lx_horizon_weights(azimuth(-30.0, 5.0), w); /* between 315 (7) and 360 (0) */
    assert_float_equal(w[3], -2.0 / 3.0, 1e-6);
    assert_float_equal(w[0], 1.0 / 3.0, 1e-6);
    /* a partition of unity, continuous in the azimuth */
    float prev[4];
    lx_horizon_weights(azimuth(0.0, 0.0), prev);
    for (int s = 1; s <= 3600; s++) {
        lx_horizon_weights(azimuth(s * 0.1, 20.0), w);
        double total = 0.0;
        int nonzero = 0;
        for (int c = 0; c < 4; c++) {
            total += fabs(w[c]);
            nonzero += w[c] != 0.0f;
            assert_true(fabs(w[c] - prev[c]) <= 0.1 / 45.0 + 1e-5);
            prev[c] = w[c];
        }
        assert_float_equal(total, 1.0, 1e-6);
        assert_true(nonzero <= 2);
    }
}

/* Each cube texel holds the weights of the direction through its centre,
 * in the OpenGL face order and orientation (spec table 8.19: major axis,
 * sc, tc per face, tc down the face): checked against that table. */
static void test_weight_cube(void **state)
{
    (void)state;
    const int n = 8;
    lx_image cube;
    assert_int_equal(lx_horizon_weight_cube(n, &cube), LX_OK);
    assert_int_equal(cube.width, n);
    assert_int_equal(cube.height, 6 * n);
    assert_int_equal(cube.channels, 4);
    for (int f = 0; f < 6; f++)
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                double sc = 2.0 * (i + 0.5) / n - 1, tc = 2.0 * (j + 0.5) / n - 1;
                /* direction = major axis (+-1 on its axis), sc and tc on the
                 * others, per the spec's table */
                double d[3];
                switch (f) {
                case 0: d[0] = 1; d[1] = -tc; d[2] = -sc; break;
                case 1: d[0] = -1; d[1] = -tc; d[2] = sc; break;
                case 2: d[0] = sc; d[1] = 1; d[2] = tc; break;
                case 3: d[0] = sc; d[1] = -1; d[2] = -tc; break;
                case 4: d[0] = sc; d[1] = -tc; d[2] = 1; break;
                default: d[0] = -sc; d[1] = -tc; d[2] = -1; break;
                }
                double az = atan2(d[1], d[0]) * 180 / PI;
                if (az < 0)
                    az += 360;
                int k = (int)floor(az / 45) & 7;
                double frac = az / 45 - floor(az / 45);
                double want[4] = {0, 0, 0, 0};
                want[k & 3] = (k < 4 ? 1 : -1) * (1 - frac);
                int k1 = (k + 1) & 7;
                want[k1 & 3] = (k1 < 4 ? 1 : -1) * frac;
                for (int c = 0; c < 4; c++)
                    assert_float_equal(at(&cube, i, f * n + j)[c], want[c], 1e-5);
            }
    lx_image_free(&cube);
    assert_int_equal(lx_horizon_weight_cube(0, &cube), LX_ERR_INVALID);
}

/* eq. 7.58: saturate((l.z - sin horizon) * hardness + 1), the horizon sine
 * interpolated between the two neighbouring directions. */
static void test_light(void **state)
{
    (void)state;
    const float flat[4] = {0, 0, 0, 0};
    assert_float_equal(lx_horizon_light(flat, flat, azimuth(77, 0.5), 0), 1.0, 1e-6);
    const float h0[4] = {0.2f, 0.6f, 0.5f, 0.5f}, h1[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    /* toward 22.5 degrees: sin horizon = (0.2 + 0.6) / 2 = 0.4 */
    double e = asin(0.35) * 180 / PI;
    assert_float_equal(lx_horizon_light(h0, h1, azimuth(22.5, e), 0), (0.35 - 0.4) * 8 + 1,
                       1e-5);
    assert_float_equal(lx_horizon_light(h0, h1, azimuth(22.5, e), 4), (0.35 - 0.4) * 4 + 1,
                       1e-5);
    /* toward 180: layer 1 red, 0.5; a light at 20 degrees is in shadow */
    assert_float_equal(lx_horizon_light(h0, h1, azimuth(180, 20), 0), 0.0, 1e-6);
    assert_float_equal(lx_horizon_light(h0, h1, azimuth(180, 30.1), 0), 1.0, 1e-6);
    /* toward 0: 0.2 */
    e = asin(0.15) * 180 / PI;
    assert_float_equal(lx_horizon_light(h0, h1, azimuth(0, e), 0), (0.15 - 0.2) * 8 + 1, 1e-5);
}

/* The shading function on a map: at the cone pit's centre (horizon
 * elevation atan k everywhere) a light above it is lit and one below it
 * shadowed. */
static void test_light_on_map(void **state)
{
    (void)state;
    const float S = 8.0f;
    const double k = 0.5;
    lx_image pit = field(41, 41), l0, l1;
    for (int y = 0; y < 41; y++)
        for (int x = 0; x < 41; x++)
            *at(&pit, x, y) = (float)(k * hypot(x - 20, y - 20) / S);
    run(&pit, (lx_horizon_desc){.strength = S}, &l0, &l1, NULL);
    double horizon = atan(k) * 180 / PI; /* 26.57 degrees */
    for (int a = 0; a < 360; a += 15) {
        float lit = lx_horizon_light(at(&l0, 20, 20), at(&l1, 20, 20), azimuth(a, horizon + 8), 0);
        float dark = lx_horizon_light(at(&l0, 20, 20), at(&l1, 20, 20), azimuth(a, horizon - 8), 0);
        assert_float_equal(lit, 1.0, 1e-6);
        assert_float_equal(dark, 0.0, 1e-6);
        /* 3 degrees under it: partly lit, (sin(e) - sin(atan k)) * 8 + 1 */
        double want = (sin((horizon - 3) * PI / 180) - k / sqrt(k * k + 1)) * 8 + 1;
        assert_float_equal(
            lx_horizon_light(at(&l0, 20, 20), at(&l1, 20, 20), azimuth(a, horizon - 3), 0), want,
            1e-5);
    }
    lx_image_free(&l0);
    lx_image_free(&l1);
    lx_image_free(&pit);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_plane_has_no_horizon),
        cmocka_unit_test(test_cone_pit_and_peak),
        cmocka_unit_test(test_step),
        cmocka_unit_test(test_random_field_every_wrap),
        cmocka_unit_test(test_sinusoid_non_power_of_two),
        cmocka_unit_test(test_wrap_at_borders),
        cmocka_unit_test(test_threads_bad_input_and_cancel),
        cmocka_unit_test(test_weights),
        cmocka_unit_test(test_weight_cube),
        cmocka_unit_test(test_light),
        cmocka_unit_test(test_light_on_map),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
