/* bench_horizon - horizon and ambient-occlusion maps (lx_horizon_map,
 * src/maps/horizon.c) of a 2048 x 2048 height field, 32 angular bins,
 * radius 16, the target being under 1.5 s on 2 cores.
 *
 * Height field: a sum of sinusoids plus hashed noise (every texel has
 * higher neighbours somewhere, so no direction's search ends early).
 * Baseline: a plain memory pass over the image in the same run (read the
 * heights, write the ambient map: one float in, one out per texel, the
 * least any per-texel map costs), and the ratio of each to it.
 *
 * Usage: bench_horizon [--threads N] [--size S] [--reps R]
 * The last line is a one-line summary.
 */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"

#include "luxel/maps.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}
static double now(void)
{
    return clock_s(CLOCK_MONOTONIC);
}
/* CPU seconds of every thread of the process: on a machine shared with
 * other work, wall time / threads overstates the time the run needs, and
 * CPU time / threads is what an idle machine would take. */
static double cpu(void)
{
    return clock_s(CLOCK_PROCESS_CPUTIME_ID);
}

/* Best of reps of a plain pass: out[i] = in[i] * 0.5 + 0.25 over 2 threads. */
static double memory_pass(const lx_image *in, lx_image *out, int threads, int reps)
{
    double best = 1e30;
    long n = (long)in->width * in->height;
    for (int r = 0; r < reps; r++) {
        double t0 = now();
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long i = 0; i < n; i++)
            out->data[i] = in->data[i] * 0.5f + 0.25f;
        double t = now() - t0;
        best = t < best ? t : best;
    }
    return best;
}

int main(int argc, char **argv)
{
    int threads = 2, size = 2048, reps = 3;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc)
            size = atoi(argv[++i]);
        else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc)
            reps = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: bench_horizon [--threads N] [--size S] [--reps R]\n");
            return 2;
        }
    }
    if (threads < 1 || size < 16 || reps < 1) {
        fprintf(stderr, "bench_horizon: bad arguments\n");
        return 2;
    }
    lx_image hf, base;
    if (lx_image_alloc(&hf, size, size, 1) != LX_OK || lx_image_alloc(&base, size, size, 1) != LX_OK) {
        fprintf(stderr, "bench_horizon: %s\n", lx_last_error());
        return 1;
    }
    for (int y = 0; y < size; y++)
        for (int x = 0; x < size; x++)
            hf.data[(size_t)y * size + x] =
                0.5f + 0.2f * sinf(0.05f * x) * cosf(0.037f * y) + 0.1f * sinf(0.31f * x + 0.2f * y) +
                0.1f * (lx_random(7u, (uint32_t)(y * size + x), 0, 0) - 0.5f);

    double t_mem = memory_pass(&hf, &base, threads, reps * 5);
    lx_horizon_desc d = {.angles = 32, .radius = 16, .threads = threads};
    double best = 1e30, best_cpu = 1e30;
    lx_image l0, l1, ao;
    for (int r = 0; r < reps; r++) {
        double t0 = now(), c0 = cpu();
        if (lx_horizon_map(&hf, &d, &l0, &l1, &ao) != LX_OK) {
            fprintf(stderr, "bench_horizon: %s\n", lx_last_error());
            return 1;
        }
        double t = now() - t0, c = cpu() - c0;
        best = t < best ? t : best;
        best_cpu = c < best_cpu ? c : best_cpu;
        double mean = 0.0;
        for (size_t i = 0; i < (size_t)size * size; i++)
            mean += ao.data[i];
        if (r == reps - 1)
            printf("  mean ambient factor %.4f (a check that the work was done)\n",
                   mean / ((double)size * size));
        lx_image_free(&l0);
        lx_image_free(&l1);
        lx_image_free(&ao);
    }
    double mtexels = (double)size * size / 1e6;
    printf("horizon + AO map %dx%d, 32 bins, radius 16, %d threads (best of %d):\n", size, size,
           threads, reps);
    printf("  memory pass (baseline) %10.4f s  %8.1f Mtexel/s\n", t_mem, mtexels / t_mem);
    printf("  horizon + AO           %10.4f s  %8.1f Mtexel/s\n", best, mtexels / best);
    printf("  horizon + AO CPU time  %10.4f s  (/ %d threads = %.4f s)\n", best_cpu, threads,
           best_cpu / threads);
    printf("summary: horizon+AO %dx%d %.3f s wall, %.3f s CPU / %d threads (target < 1.5 s: "
           "%s), memory pass %.4f s, ratio %.0fx\n",
           size, size, best, best_cpu / threads, threads, best < 1.5 ? "met" : "MISSED", t_mem,
           best / t_mem);
    lx_image_free(&hf);
    lx_image_free(&base);
    return 0;
}
