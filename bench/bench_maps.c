/* bench_maps - the texture-space map tools' speed on a 2048^2 height field
 * (a sum of sinusoids and a hash noise), each against a baseline measured
 * in the same run with the same threads:
 *
 *  baseline  a plain memory pass with the normal map's traffic: a fresh
 *            3-channel float image allocated (lx_image_alloc, as the
 *            tools do) and every texel's three floats written from the
 *            height read once (what any normal map must at least do);
 *            and the same pass into memory already touched, to show
 *            what the fresh pages cost;
 *  1. lx_normal_map, central differences (target < 30 ms on 2 cores),
 *     then Sobel and Scharr;
 *  2. lx_parallax_map (one channel out);
 *  3. lx_normal_encode and the 16-bit PNG of the encoded map
 *     (lx_image_write, for scale: deflate dominates);
 *  4. lx_height_from_normals of the central normal map: repeat (complex
 *     transforms), clamp (cosine transforms), and repeat at the prime size
 *     N - 9 when that is prime (2039: Bluestein's transforms), against the
 *     baseline and the normal map that made them.
 *
 * Usage: bench_maps [--threads N] [--size N] (default 2 threads, 2048)
 * The last line is a one-line summary.
 */
#define _POSIX_C_SOURCE 200809L
#include "helpers.h"
#include "core/internal.h"
#include "scenes.h"

#include "luxel/maps.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_threads = 2, g_size = 2048;

typedef void (*bench_fn)(void *);

/* Best time of at least min_reps runs and min_seconds. */
static double best_of(bench_fn fn, void *arg, int min_reps, double min_seconds, int *runs)
{
    double best = INFINITY, start = lx_bench_now();
    int n = 0;
    while (n < min_reps || lx_bench_now() - start < min_seconds) {
        double t0 = lx_bench_now();
        fn(arg);
        best = fmin(best, lx_bench_now() - t0);
        n++;
    }
    *runs = n;
    return best;
}

typedef struct job {
    lx_image height;
    lx_image out;
    lx_normal_filter filter;
    const char *path;
} job;

static void run_copy(void *p)
{
    job *j = p;
    lx_image_free(&j->out);
    if (lx_image_alloc(&j->out, j->height.width, j->height.height, 3) != LX_OK)
        lx_bench_die("lx_image_alloc");
    long n = (long)j->height.width * j->height.height;
    const float *h = j->height.data;
    float *o = j->out.data;
#pragma omp parallel for schedule(static) num_threads(g_threads)
    for (long i = 0; i < n; i++) {
        float v = h[i];
        o[3 * i] = v;
        o[3 * i + 1] = v;
        o[3 * i + 2] = 1.0f;
    }
}

/* The same pass into the image the last run left (no allocation): the
 * share of the baseline that is fresh pages rather than writing. */
static void run_fill(void *p)
{
    job *j = p;
    long n = (long)j->height.width * j->height.height;
    const float *h = j->height.data;
    float *o = j->out.data;
#pragma omp parallel for schedule(static) num_threads(g_threads)
    for (long i = 0; i < n; i++) {
        float v = h[i];
        o[3 * i] = v;
        o[3 * i + 1] = v;
        o[3 * i + 2] = 1.0f;
    }
}

static void run_normal(void *p)
{
    job *j = p;
    lx_image_free(&j->out);
    lx_normalmap_desc d = {.filter = j->filter, .threads = g_threads};
    if (lx_normal_map(&j->height, &d, &j->out) != LX_OK)
        lx_bench_die("lx_normal_map");
}

static void run_parallax(void *p)
{
    job *j = p;
    lx_image_free(&j->out);
    lx_normalmap_desc d = {.threads = g_threads};
    if (lx_parallax_map(&j->height, &d, &j->out) != LX_OK)
        lx_bench_die("lx_parallax_map");
}

static void run_encode(void *p)
{
    job *j = p;
    lx_image_free(&j->out);
    if (lx_normal_encode(&j->height, &j->out) != LX_OK) /* height: the normals here */
        lx_bench_die("lx_normal_encode");
}

static lx_wrap g_wrap;

static void run_heights(void *p)
{
    job *j = p;
    lx_image_free(&j->out);
    lx_height_from_normals_desc d = {.wrap = g_wrap, .threads = g_threads};
    if (lx_height_from_normals(&j->height, &d, &j->out) != LX_OK)
        lx_bench_die("lx_height_from_normals");
}

static bool is_prime(int n)
{
    for (int k = 2; k * k <= n; k++)
        if (n % k == 0)
            return false;
    return n > 1;
}

static void run_png16(void *p)
{
    job *j = p;
    lx_image_write_desc d = {.linear = true, .bits = 16, .threads = g_threads};
    if (lx_image_write(j->path, &j->height, &d) != LX_OK)
        lx_bench_die("lx_image_write");
}

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            g_threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc)
            g_size = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: bench_maps [--threads N] [--size N]\n");
            return 2;
        }
    }
    if (g_threads < 1 || g_size < 16) {
        fprintf(stderr, "bench_maps: bad --threads or --size\n");
        return 2;
    }
    lx_bench_header("bench_maps", g_threads);
    int N = g_size;
    job j = {0};
    if (lx_image_alloc(&j.height, N, N, 1) != LX_OK)
        lx_bench_die("lx_image_alloc");
    for (int y = 0; y < N; y++)
        for (int x = 0; x < N; x++) {
            double u = (double)x / N, v = (double)y / N;
            double h = 0.5 + 0.2 * sin(2 * LX_PI * 7 * u) * cos(2 * LX_PI * 5 * v) +
                       0.1 * sin(2 * LX_PI * 41 * (u + v));
            h += 0.05 * ((double)(lx_hash4(1, (uint32_t)x, (uint32_t)y, 0) >> 8) / 16777216.0);
            j.height.data[(size_t)y * N + x] = (float)h;
        }
    printf("height field %dx%d (%.1f MB), normal map %.1f MB, %d threads\n", N, N,
           N * (double)N * 4 / 1e6, N * (double)N * 12 / 1e6, g_threads);

    int runs;
    double t_base = best_of(run_copy, &j, 10, 1.0, &runs);
    printf("  %-40s %8.2f ms  (%d runs)\n", "baseline: alloc + 3 floats a texel", 1e3 * t_base,
           runs);
    double t_fill = best_of(run_fill, &j, 10, 1.0, &runs);
    printf("  %-40s %8.2f ms  (%d runs; the rest of the baseline is fresh pages)\n",
           "  the same pass into a touched image", 1e3 * t_fill, runs);
    double t_filter[3];
    for (int f = 0; f < 3; f++) {
        j.filter = (lx_normal_filter)f;
        t_filter[f] = best_of(run_normal, &j, 10, 1.0, &runs);
        char what[64];
        snprintf(what, sizeof what, "lx_normal_map (%s)", lx_normal_filter_name(j.filter));
        printf("  %-40s %8.2f ms  %6.2fx baseline  (%d runs)\n", what, 1e3 * t_filter[f],
               t_filter[f] / t_base, runs);
    }
    double t_par = best_of(run_parallax, &j, 10, 1.0, &runs);
    printf("  %-40s %8.2f ms  %6.2fx baseline  (%d runs)\n", "lx_parallax_map", 1e3 * t_par,
           t_par / t_base, runs);

    /* encoding and the 16-bit file, from the central normal map */
    j.filter = LX_NORMAL_CENTRAL;
    run_normal(&j);
    lx_image normals = j.out;
    j.out = (lx_image){0};
    lx_image keep = j.height;
    j.height = normals;
    double t_enc = best_of(run_encode, &j, 5, 0.5, &runs);
    printf("  %-40s %8.2f ms  %6.2fx baseline  (%d runs)\n", "lx_normal_encode", 1e3 * t_enc,
           t_enc / t_base, runs);
    lx_image encoded = j.out;
    j.out = (lx_image){0};
    j.height = encoded;
    char path[4096];
    snprintf(path, sizeof path, "%s/normal16.png", lx_test_dir("bench_maps"));
    j.path = path;
    double t_png = best_of(run_png16, &j, 3, 1.0, &runs);
    printf("  %-40s %8.2f ms  %6.2fx baseline  (%d runs)\n", "16-bit PNG write of the map",
           1e3 * t_png, t_png / t_base, runs);
    lx_image_free(&encoded);

    /* heights integrated back from the normals */
    j.height = normals;
    double t_heights[2];
    for (int w = 0; w < 2; w++) {
        g_wrap = w == 0 ? LX_WRAP_REPEAT : LX_WRAP_CLAMP;
        t_heights[w] = best_of(run_heights, &j, 3, 1.0, &runs);
        char what[64];
        snprintf(what, sizeof what, "lx_height_from_normals (%s)", lx_wrap_name(g_wrap));
        printf("  %-40s %8.2f ms  %6.2fx baseline  %5.1fx normal map  (%d runs)\n", what,
               1e3 * t_heights[w], t_heights[w] / t_base, t_heights[w] / t_filter[0], runs);
    }
    if (is_prime(N - 9)) {
        lx_image odd;
        if (lx_image_alloc(&odd, N - 9, N - 9, 3) != LX_OK)
            lx_bench_die("lx_image_alloc");
        for (int y = 0; y < N - 9; y++)
            memcpy(odd.data + (size_t)y * (N - 9) * 3, normals.data + (size_t)y * N * 3,
                   sizeof(float) * 3 * (size_t)(N - 9));
        j.height = odd;
        g_wrap = LX_WRAP_REPEAT;
        double t_odd = best_of(run_heights, &j, 3, 1.0, &runs);
        char what[64];
        snprintf(what, sizeof what, "  the same at %dx%d (prime)", N - 9, N - 9);
        printf("  %-40s %8.2f ms  %6.2fx baseline  %5.1fx normal map  (%d runs)\n", what,
               1e3 * t_odd, t_odd / t_base, t_odd / t_filter[0], runs);
        lx_image_free(&odd);
    }
    lx_image_free(&normals);
    j.height = keep;

    printf("bench_maps: normal map %dx%d in %.2f ms on %d threads (target < 30 ms: %s), %.2fx the "
           "memory pass (%.2f ms)\n",
           N, N, 1e3 * t_filter[0], g_threads, t_filter[0] < 0.030 ? "MET" : "NOT MET",
           t_filter[0] / t_base, 1e3 * t_base);
    lx_image_free(&j.height);
    lx_image_free(&j.out);
    return 0;
}
