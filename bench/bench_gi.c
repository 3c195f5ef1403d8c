/* bench_gi - the indirect light of lx_baker_bake (lx_bake_desc.bounces)
 * on the room demo scene (examples/gen_scenes.c) at --res texels a node,
 * against its baseline measured in the same run: as many incoherent rays
 * as the gathers cast (a validity pass of min(samples, 64) rays and
 * `bounces` passes of --samples rays a texel, half from the second bounce
 * on (lx_gi_bounce_samples), cosine-weighted about each
 * texel's normal), straight through Embree's rtcIntersect1 on one flat BVH
 * built here, over the same 8x8 tiles, OpenMP schedule and threads, with
 * no lookups. The GI time is the bake with bounces less the same bake
 * without; the ratio says what finding the hit's lightmap texels and
 * summing costs on top of the rays. Best and median of --reps runs each.
 *
 * Then the noise, at --noise-density texels a metre (or --noise-res a
 * node): bakes at --noise-samples S gather rays a texel, cosine-weighted
 * and guided (the default), raw (--denoise off) and denoised (indirect,
 * the CLI's default), adaptive, and a raw cosine bake at the sample count
 * that takes as long as the default (equal time), each against a
 * reference of --ref-samples (64 S) cosine-weighted rays a texel: RMS
 * error over every seen texel and channel, relative to the reference's
 * mean, and the share of texels off by more than 5% (texels inside
 * geometry, the floor under a box, left out: nobody sees them); times are
 * the best of --reps. The reference's own noise (about 1/8 of the raw
 * cosine bake's) is in every figure.
 *
 * Usage: bench_gi [--threads N] [--reps N] [--res N] [--samples N]
 *                 [--bounces N] [--scene FILE.glb] [--noise-res N]
 *                 [--noise-density D] [--noise-samples S] [--ref-samples R]
 *                 [--skip-noise]
 * (--noise-density: texels per metre, default 20, 0 for --noise-res;
 * --ref-samples: the reference's rays, default 64 S) */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include "helpers.h"
#include "core/internal.h"
#include "bake/bake_internal.h"
#include "scenes.h"
#include "bench_cli.h"
#include "luxel/denoise.h"

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
 * map order, and a fourth float: 1 where the texel is seen, 0 where it
 * sits inside geometry (its gathers mostly hit back faces: the floor
 * under a box; nobody sees it, and its light is its neighbours');
 * *seconds the best time of `reps` bakes. */
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
        lx_denoise_guides guides;
        if (lx_baker_denoise_guides(b, m, &guides) != LX_OK)
            lx_bench_die("guides");
        const uint8_t *mask = lx_baker_mask(b, m);
        size_t pixels = (size_t)img.width * (size_t)img.height;
        if (n + pixels > cap) {
            cap = (n + pixels) * 2;
            out = realloc(out, sizeof(float) * 4 * cap);
            if (!out)
                lx_bench_die("memory");
        }
        for (size_t i = 0; i < pixels; i++) {
            if (!mask[i])
                continue;
            for (size_t c = 0; c < 3; c++)
                out[4 * n + c] = img.data[i * (size_t)img.channels + c];
            out[4 * n + 3] = guides.valid[i] ? 1.0f : 0.0f;
            n++;
        }
        lx_image_free(&img);
        lx_denoise_guides_free(&guides);
    }
    lx_baker_destroy(b);
    *count = n;
    return out;
}

/* RMS of (x - ref) over the n texels' channels that ref says are seen,
 * relative to ref's mean. */
static double relative_rms(const float *x, const float *ref, size_t n)
{
    double se = 0.0, sum = 0.0;
    size_t k = 0;
    for (size_t i = 0; i < n; i++) {
        if (ref[4 * i + 3] == 0.0f)
            continue;
        for (size_t c = 0; c < 3; c++) {
            double e = (double)x[4 * i + c] - (double)ref[4 * i + c];
            se += e * e;
            sum += ref[4 * i + c];
            k++;
        }
    }
    return sum > 0.0 ? sqrt(se / (double)k) / (sum / (double)k) : 0.0;
}

/* The share of the n texels ref says are seen whose luminance is off
 * ref's by more than `tolerance` of ref's (texels where ref is dark, below
 * 1/100 of its mean, left out): the blotch measure, what a viewer
 * sees as patches. */
static double share_off(const float *x, const float *ref, size_t n, double tolerance)
{
    double mean = 0.0;
    size_t seen = 0;
    for (size_t i = 0; i < n; i++)
        if (ref[4 * i + 3] != 0.0f) {
            mean += lx_luminance(ref + 4 * i);
            seen++;
        }
    mean /= seen ? (double)seen : 1.0;
    size_t off = 0, judged = 0;
    for (size_t i = 0; i < n; i++) {
        double want = lx_luminance(ref + 4 * i), got = lx_luminance(x + 4 * i);
        if (ref[4 * i + 3] == 0.0f || want < 0.01 * mean)
            continue;
        judged++;
        off += fabs(got - want) > tolerance * want;
    }
    return judged ? (double)off / (double)judged : 0.0;
}

/* One row of the noise table: time, RMS error and the share of texels
 * off by more than 5%, against ref. */
static void noise_row(const char *what, double seconds, const float *x, const float *ref, size_t n)
{
    printf("  %-44s %8.3fs %13.2f%% %13.2f%%\n", what, seconds, 100.0 * relative_rms(x, ref, n),
           100.0 * share_off(x, ref, n, 0.05));
}

/* The noise section (see the top). */
static void noise_at_equal_time(const lx_scene *scene, const char *scene_path, int res,
                                float density, int samples, int ref_samples, int bounces,
                                int threads, int reps)
{
    lx_bake_desc d = lx_bake_desc_defaults(NULL);
    d.resolution = res;
    d.texel_density = density;
    d.threads = threads;
    size_t n_ref, n;
    double t_direct, t_ref, t_raw, t_den, t_eq, t_graw, t_gden, t_ada;
    float *direct = baked_texels(scene, &d, reps, &n, &t_direct);
    free(direct);
    d.bounces = bounces;
    d.gi_sampling = LX_GI_SAMPLING_COSINE;
    d.gi_samples = (uint32_t)ref_samples;
    float *ref = baked_texels(scene, &d, 1, &n_ref, &t_ref);
    d.gi_samples = (uint32_t)samples;
    float *raw = baked_texels(scene, &d, reps, &n, &t_raw);
    d.denoise = LX_DENOISE_INDIRECT;
    float *den = baked_texels(scene, &d, reps, &n, &t_den);
    /* guided gathers (the default), raw and denoised; adaptive on top */
    d.gi_sampling = LX_GI_SAMPLING_GUIDED;
    d.denoise = LX_DENOISE_OFF;
    float *graw = baked_texels(scene, &d, reps, &n, &t_graw);
    d.denoise = LX_DENOISE_INDIRECT;
    float *gden = baked_texels(scene, &d, reps, &n, &t_gden);
    d.gi_adaptive = true;
    float *ada = baked_texels(scene, &d, reps, &n, &t_ada);
    d.gi_adaptive = false;
    /* the GI's time grows with its rays: the raw cosine count that takes
     * as long as the default (guided, denoised) bake */
    double gi_raw = t_raw - t_direct, gi_den = t_gden - t_direct;
    int equal = (int)lround((double)samples * gi_den / (gi_raw > 1e-6 ? gi_raw : 1e-6));
    if (equal < samples)
        equal = samples;
    d.denoise = LX_DENOISE_OFF;
    d.gi_sampling = LX_GI_SAMPLING_COSINE;
    d.gi_samples = (uint32_t)equal;
    float *eq = baked_texels(scene, &d, reps, &n, &t_eq);
    if (n != n_ref)
        lx_bench_die("texel counts differ");
    double e_raw = relative_rms(raw, ref, n), e_gden = relative_rms(gden, ref, n),
           e_eq = relative_rms(eq, ref, n);
    char size[64];
    if (density > 0.0f)
        snprintf(size, sizeof size, "%g texels/m", (double)density);
    else
        snprintf(size, sizeof size, "%dx%d a node", res, res);
    printf("\nnoise  %s, %s, %zu texels, %d bounces, against %d cosine rays a texel (%.1f s)\n",
           scene_path, size, n, bounces, ref_samples, t_ref);
    printf("  %-44s %9s %14s %14s\n", "", "time", "RMS error", "texels off 5%");
    noise_row("cosine, raw, gi-samples S", t_raw, raw, ref, n);
    noise_row("cosine, denoised (--denoise indirect), S", t_den, den, ref, n);
    noise_row("guided, raw, S", t_graw, graw, ref, n);
    noise_row("guided, denoised, S (the default)", t_gden, gden, ref, n);
    noise_row("guided, adaptive (--gi-adaptive), denoised", t_ada, ada, ref, n);
    char eqs[64];
    snprintf(eqs, sizeof eqs, "cosine, raw at equal time, %d", equal);
    noise_row(eqs, t_eq, eq, ref, n);
    printf("noise: at %d rays a texel the default (guided, denoised) cuts the RMS error against "
           "the reference %.1fx (%.2f%% -> %.2f%%) from raw cosine gathers; %.1fx against the "
           "raw bake of equal time (%d rays); a raw bake would need about %.0f rays (1/sqrt "
           "law) to match\n",
           samples, e_raw / e_gden, 100.0 * e_raw, 100.0 * e_gden, e_eq / e_gden, equal,
           (double)samples * (e_raw / e_gden) * (e_raw / e_gden));
    free(ref);
    free(raw);
    free(den);
    free(graw);
    free(gden);
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
    /* the noise at the CLI's defaults: 128 rays a texel (guided), against
     * 64 times the rays, at 20 texels a metre (a quarter of the CLI's
     * texels, so the reference takes a minute) */
    int noise_res = 128, noise_samples = 128;
    float noise_density = 20.0f;
    int ref_samples = 0;
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
        else if (!strcmp(argv[i], "--ref-samples") && i + 1 < argc)
            ref_samples = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--noise-density") && i + 1 < argc)
            noise_density = (float)atof(argv[++i]);
        else if (!strcmp(argv[i], "--noise-samples") && i + 1 < argc)
            noise_samples = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--skip-noise"))
            skip_noise = true;
        else {
            fprintf(stderr,
                    "usage: %s [--threads N] [--reps N] [--res N] [--samples N] [--bounces N] "
                    "[--scene FILE.glb] [--noise-res N] [--noise-density D] [--noise-samples S] "
                    "[--ref-samples R] [--skip-noise]\n",
                    argv[0]);
            return 2;
        }
    }
    if (reps < 1 || reps > 100 || res < 4 || res > 4096 || samples < 1 || samples > 4096 ||
        bounces < 1 || bounces > 16 || noise_res < 4 || noise_res > 4096 ||
        !(noise_density >= 0.0f && noise_density <= 1000.0f) || ref_samples < 0 ||
        ref_samples > 65536 || noise_samples < 1 ||
        noise_samples > 1024) {
        fprintf(stderr, "bench_gi: --reps 1..100, --res 4..4096, --samples 1..4096, --bounces "
                        "1..16, --noise-res 4..4096, --noise-density 0..1000, --noise-samples "
                        "1..1024, --ref-samples 0..65536\n");
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
        counts[k] = lx_gi_bounce_samples((uint32_t)samples, k);
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
        noise_at_equal_time(scene, scene_path, noise_res, noise_density, noise_samples,
                            ref_samples ? ref_samples : 64 * noise_samples, bounces, threads,
                            reps);
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
