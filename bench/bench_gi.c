/* bench_gi - the indirect light of lx_baker_bake (lx_bake_desc.bounces)
 * on the room demo scene (examples/gen_scenes.c) at --res texels a node,
 * against its baseline measured in the same run: as many incoherent rays
 * as the gathers cast (a validity pass of min(samples, 64) rays and
 * `bounces` passes of --samples rays a texel, cosine-weighted about each
 * texel's normal), straight through Embree's rtcIntersect1 on one flat BVH
 * built here, over the same 8x8 tiles, OpenMP schedule and threads, with
 * no lookups. The GI time is the bake with bounces less the same bake
 * without; the ratio says what finding the hit's lightmap texels and
 * summing costs on top of the rays. Best and median of --reps runs each.
 *
 * Then the noise, at --noise-res texels a node: the bake at
 * --noise-samples S gather rays a texel raw (--denoise off) and denoised
 * (indirect, the CLI's default), and a raw bake at the sample count that
 * takes as long as the denoised one (equal time), each against a
 * reference of 64 S rays a texel: RMS error over every covered texel and
 * channel, relative to the reference's mean; times are the best of --reps. The reference's own noise
 * (about 1/8 of the raw S bake's) is in every figure.
 *
 * Usage: bench_gi [--threads N] [--reps N] [--res N] [--samples N]
 *                 [--bounces N] [--scene FILE.glb] [--noise-res N]
 *                 [--noise-samples S] [--skip-noise] */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include "helpers.h"
#include "core/internal.h"
#include "scenes.h"
#include "bench_cli.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>


/* Seconds of lx_baker_bake with `bounces`. */
static double bake_time(lx_baker *b)
{
    double t0 = lx_bench_now();
    if (lx_baker_bake(b) != LX_OK)
        lx_bench_die("bake");
    return lx_bench_now() - t0;
}

/* Every covered texel's RGB of every lightmap of a bake with desc, in
 * map order; *seconds the best time of `reps` bakes. */
static float *baked_texels(const lx_scene *scene, const lx_bake_desc *desc, int reps,
                           size_t *count, double *seconds)
{
    lx_baker *b;
    if (lx_baker_create(scene, desc, &b) != LX_OK)
        lx_bench_die("baker");
    *seconds = bake_time(b);
    for (int k = 1; k < reps; k++) {
        double t = bake_time(b);
        if (t < *seconds)
            *seconds = t;
    }
    size_t n = 0, cap = 0;
    float *out = NULL;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(b); m++) {
        lx_image img;
        if (lx_baker_apply_alloc(b, m, &img) != LX_OK)
            lx_bench_die("apply");
        const uint8_t *mask = lx_baker_mask(b, m);
        size_t pixels = (size_t)img.width * (size_t)img.height;
        if (n + pixels > cap) {
            cap = (n + pixels) * 2;
            out = realloc(out, sizeof(float) * 3 * cap);
            if (!out)
                lx_bench_die("memory");
        }
        for (size_t i = 0; i < pixels; i++) {
            if (!mask[i])
                continue;
            for (size_t c = 0; c < 3; c++)
                out[3 * n + c] = img.data[i * (size_t)img.channels + c];
            n++;
        }
        lx_image_free(&img);
    }
    lx_baker_destroy(b);
    *count = n;
    return out;
}

/* RMS of (x - ref) over n texels' channels, relative to ref's mean. */
static double relative_rms(const float *x, const float *ref, size_t n)
{
    double se = 0.0, sum = 0.0;
    for (size_t i = 0; i < 3 * n; i++) {
        double e = (double)x[i] - (double)ref[i];
        se += e * e;
        sum += ref[i];
    }
    return sum > 0.0 ? sqrt(se / (double)(3 * n)) / (sum / (double)(3 * n)) : 0.0;
}

/* The share of n texels whose luminance is off ref's by more than
 * `tolerance` of ref's (texels where ref is dark, below 1/100 of its mean,
 * left out): the blotch measure, what a viewer sees as patches. */
static double share_off(const float *x, const float *ref, size_t n, double tolerance)
{
    double mean = 0.0;
    for (size_t i = 0; i < n; i++)
        mean += lx_luminance(ref + 3 * i);
    mean /= n ? (double)n : 1.0;
    size_t off = 0, judged = 0;
    for (size_t i = 0; i < n; i++) {
        double want = lx_luminance(ref + 3 * i), got = lx_luminance(x + 3 * i);
        if (want < 0.01 * mean)
            continue;
        judged++;
        off += fabs(got - want) > tolerance * want;
    }
    return judged ? (double)off / (double)judged : 0.0;
}

/* The noise section (see the top). */
static void noise_at_equal_time(const lx_scene *scene, const char *scene_path, int res,
                                int samples, int bounces, int threads, int reps)
{
    lx_bake_desc d = lx_bake_desc_defaults(NULL);
    d.resolution = res;
    d.threads = threads;
    size_t n_ref, n;
    double t_direct, t_ref, t_raw, t_den, t_eq;
    float *direct = baked_texels(scene, &d, reps, &n, &t_direct);
    free(direct);
    d.bounces = bounces;
    d.gi_samples = (uint32_t)samples * 64u;
    float *ref = baked_texels(scene, &d, 1, &n_ref, &t_ref);
    d.gi_samples = (uint32_t)samples;
    float *raw = baked_texels(scene, &d, reps, &n, &t_raw);
    d.denoise = LX_DENOISE_INDIRECT;
    float *den = baked_texels(scene, &d, reps, &n, &t_den);
    /* adaptive gathers (--gi-adaptive), denoised */
    double t_ada;
    d.gi_adaptive = true;
    float *ada = baked_texels(scene, &d, reps, &n, &t_ada);
    d.gi_adaptive = false;
    /* the GI's time grows with its rays: the raw count that takes as long
     * as the denoised bake */
    double gi_raw = t_raw - t_direct, gi_den = t_den - t_direct;
    int equal = (int)lround((double)samples * gi_den / (gi_raw > 1e-6 ? gi_raw : 1e-6));
    if (equal < samples)
        equal = samples;
    d.denoise = LX_DENOISE_OFF;
    d.gi_samples = (uint32_t)equal;
    float *eq = baked_texels(scene, &d, reps, &n, &t_eq);
    if (n != n_ref)
        lx_bench_die("texel counts differ");
    double e_raw = relative_rms(raw, ref, n), e_den = relative_rms(den, ref, n),
           e_eq = relative_rms(eq, ref, n);
    printf("\nnoise  %s, %dx%d a node, %zu texels, %d bounces, against %d rays a texel (%.1f s)\n",
           scene_path, res, res, n, bounces, samples * 64, t_ref);
    printf("  %-44s %9s %14s %14s\n", "", "time", "RMS error", "texels off 5%");
    printf("  %-44s %8.3fs %13.2f%% %13.2f%%\n", "raw, gi-samples S", t_raw, 100.0 * e_raw,
           100.0 * share_off(raw, ref, n, 0.05));
    printf("  %-44s %8.3fs %13.2f%% %13.2f%%\n", "denoised (--denoise indirect), S", t_den,
           100.0 * e_den, 100.0 * share_off(den, ref, n, 0.05));
    printf("  raw at equal time, %-25d %8.3fs %13.2f%% %13.2f%%\n", equal, t_eq, 100.0 * e_eq,
           100.0 * share_off(eq, ref, n, 0.05));
    printf("  %-44s %8.3fs %13.2f%% %13.2f%%\n", "adaptive (--gi-adaptive), denoised", t_ada,
           100.0 * relative_rms(ada, ref, n), 100.0 * share_off(ada, ref, n, 0.05));
    printf("noise: at %d rays a texel the denoiser cuts the RMS error against a 64x reference "
           "%.1fx (%.2f%% -> %.2f%%); %.1fx against the raw bake of equal time (%d rays); "
           "a raw bake would need about %.0f rays (1/sqrt law) to match\n",
           samples, e_raw / e_den, 100.0 * e_raw, 100.0 * e_den, e_eq / e_den, equal,
           (double)samples * (e_raw / e_den) * (e_raw / e_den));
    free(ref);
    free(raw);
    free(den);
    free(ada);
    free(eq);
}

typedef struct texel {
    lx_vec3 p, n, ng;
    uint32_t pixel;
} texel;

/* The gathers' rays through rtcIntersect1: per texel `passes` rounds of
 * rays (counts[pass] each), cosine-weighted about its normal, over tiles
 * of texels; returns seconds and the rays cast in *rays. */
static double raw_gathers(RTCScene flat, const texel *tx, const uint32_t *tile_start, int tiles,
                          const uint32_t *counts, int passes, float bias, int threads,
                          uint64_t *rays)
{
    uint64_t total = 0;
    double t0 = lx_bench_now();
    for (int pass = 0; pass < passes; pass++) {
        uint32_t want = counts[pass];
        uint32_t sx = (uint32_t)sqrtf((float)want), sy = (want + sx - 1) / sx;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : total)
        for (int t = 0; t < tiles; t++)
            for (uint32_t i = tile_start[t]; i < tile_start[t + 1]; i++) {
                lx_vec3 n = tx[i].n, tt = lx_perpendicular(n), bt = lx_cross(n, tt);
                lx_vec3 o = lx_madd(tx[i].p, tx[i].ng, bias);
                for (uint32_t k = 0; k < sx * sy; k++) {
                    float u = ((float)(k % sx) + lx_random(0, tx[i].pixel, k, (uint32_t)pass)) / sx;
                    float v = ((float)(k / sx) + lx_random(1, tx[i].pixel, k, (uint32_t)pass)) / sy;
                    float r = sqrtf(u), phi = 2.0f * LX_PI * v;
                    lx_vec3 d = lx_add(lx_add(lx_scale(tt, r * cosf(phi)), lx_scale(bt, r * sinf(phi))),
                                       lx_scale(n, sqrtf(fmaxf(0.0f, 1.0f - u))));
                    struct RTCIntersectContext ctx;
                    rtcInitIntersectContext(&ctx);
                    struct RTCRayHit rh = {0};
                    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
                    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
                    rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.mask = 0xFFFFFFFFu;
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(flat, &ctx, &rh);
                    total++;
                }
            }
    }
    *rays = total;
    return lx_bench_now() - t0;
}

int main(int argc, char **argv)
{
    int threads = 0, reps = 3, res = 256, samples = 256, bounces = 2;
    int noise_res = 128, noise_samples = 16;
    bool skip_noise = false;
    const char *scene_path = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--reps") && i + 1 < argc)
            reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--res") && i + 1 < argc)
            res = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc)
            samples = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--bounces") && i + 1 < argc)
            bounces = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--scene") && i + 1 < argc)
            scene_path = argv[++i];
        else if (!strcmp(argv[i], "--noise-res") && i + 1 < argc)
            noise_res = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--noise-samples") && i + 1 < argc)
            noise_samples = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--skip-noise"))
            skip_noise = true;
        else {
            fprintf(stderr,
                    "usage: %s [--threads N] [--reps N] [--res N] [--samples N] [--bounces N] "
                    "[--scene FILE.glb] [--noise-res N] [--noise-samples S] [--skip-noise]\n",
                    argv[0]);
            return 2;
        }
    }
    if (reps < 1 || reps > 100 || res < 4 || res > 4096 || samples < 1 || samples > 4096 ||
        bounces < 1 || bounces > 16 || noise_res < 4 || noise_res > 4096 || noise_samples < 1 ||
        noise_samples > 1024) {
        fprintf(stderr, "bench_gi: --reps 1..100, --res 4..4096, --samples 1..4096, --bounces "
                        "1..16, --noise-res 4..4096, --noise-samples 1..1024\n");
        return 2;
    }
    threads = lx_thread_count(threads);
    lx_bench_header("bench_gi", threads);
    lx_scene *scene = lx_bench_load_room("bench_gi", &scene_path);
    lx_bake_desc d = lx_bake_desc_defaults(NULL);
    d.resolution = res;
    d.threads = threads;
    lx_baker *direct, *gi;
    if (lx_baker_create(scene, &d, &direct) != LX_OK)
        lx_bench_die("baker");
    d.bounces = bounces;
    d.gi_samples = (uint32_t)samples;
    if (lx_baker_create(scene, &d, &gi) != LX_OK)
        lx_bench_die("baker");

    /* the texels, tile by tile, as the baker orders them */
    uint64_t used = 0;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(gi); m++)
        used += lx_baker_lightmap_info(gi, m)->used_texels;
    texel *tx = malloc(sizeof *tx * (used + 1));
    int tiles_max = 0;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(gi); m++) {
        const lx_lightmap_info *info = lx_baker_lightmap_info(gi, m);
        tiles_max += ((info->width + 7) / 8) * ((info->height + 7) / 8);
    }
    uint32_t *tile_start = malloc(sizeof(uint32_t) * (size_t)(tiles_max + 1));
    int tiles = 0;
    uint32_t n = 0;
    for (uint32_t m = 0; m < lx_baker_lightmap_count(gi); m++) {
        const lx_lightmap_info *info = lx_baker_lightmap_info(gi, m);
        for (int ty = 0; ty < info->height; ty += LX_BENCH_TILE)
            for (int txx = 0; txx < info->width; txx += LX_BENCH_TILE) {
                tile_start[tiles++] = n;
                for (int y = ty; y < ty + LX_BENCH_TILE && y < info->height; y++)
                    for (int x = txx; x < txx + LX_BENCH_TILE && x < info->width; x++) {
                        lx_texel_sample s;
                        if (!lx_baker_texel(gi, m, x, y, &s))
                            continue;
                        tx[n++] = (texel){s.position, s.normal, s.geometric_normal,
                                          (uint32_t)(y * info->width + x)};
                    }
            }
    }
    tile_start[tiles] = n;
    uint32_t counts[17];
    counts[0] = samples < 64 ? (uint32_t)samples : 64u;
    for (int k = 1; k <= bounces; k++)
        counts[k] = (uint32_t)samples;
    lx_vec3 lo, hi;
    lx_scene_bounds(scene, &lo, &hi);
    float bias = 1e-5f * lx_length(lx_sub(hi, lo));
    RTCDevice dev = rtcNewDevice(NULL);
    RTCScene flat = lx_bench_flat_scene(dev, scene);

    double *tg = calloc((size_t)reps, sizeof *tg), *tr = calloc((size_t)reps, sizeof *tr);
    uint64_t rays = 0;
    /* warm up, then alternate so load changes hit both alike */
    bake_time(direct);
    bake_time(gi);
    raw_gathers(flat, tx, tile_start, tiles, counts, bounces + 1, bias, threads, &rays);
    for (int k = 0; k < reps; k++) {
        double t_direct = bake_time(direct);
        double t_gi = bake_time(gi);
        tg[k] = t_gi - t_direct;
        tr[k] = raw_gathers(flat, tx, tile_start, tiles, counts, bounces + 1, bias, threads,
                            &rays);
    }
    qsort(tg, (size_t)reps, sizeof *tg, lx_bench_cmp_double);
    qsort(tr, (size_t)reps, sizeof *tr, lx_bench_cmp_double);
    char a[32], b[32];
    printf("\nGI  %s, %dx%d a node, %u texels, %d bounces x %d rays a texel (+%u validity), %d "
           "threads, %d runs\n",
           scene_path, res, res, n, bounces, samples, counts[0], threads, reps);
    printf("  %-38s %9s %9s %12s\n", "", "best", "median", "rays/s best");
    printf("  %-38s %8.3fs %8.3fs %12s\n", "indirect light (bake - direct bake)", tg[0],
           tg[reps / 2], lx_bench_si((double)rays / tg[0], a));
    printf("  %-38s %8.3fs %8.3fs %12s\n", "raw rtcIntersect1, as many rays", tr[0], tr[reps / 2],
           lx_bench_si((double)rays / tr[0], b));
    printf("gi: %.2fx the time of raw incoherent rtcIntersect1 on as many rays (best; median "
           "%.2fx)\n",
           tg[0] / tr[0], tg[reps / 2] / tr[reps / 2]);
    if (!skip_noise)
        noise_at_equal_time(scene, scene_path, noise_res, noise_samples, bounces, threads, reps);
    free(tg);
    free(tr);
    free(tx);
    free(tile_start);
    rtcReleaseScene(flat);
    rtcReleaseDevice(dev);
    lx_baker_destroy(direct);
    lx_baker_destroy(gi);
    lx_scene_destroy(scene);
    return 0;
}
