/* bench_realtime - the real-time lightmap update rate
 * with its baseline measured in the same run.
 *
 * Scene: a generated ~10k-triangle scene (tests/common/scenes.h: a
 * lightmapped ground under 49 floating spheres), one 256x256 lightmap,
 * 4 dynamic point lights with hard shadows that move every update.
 * Figure: updates per second of lx_baker_set_light x4 + lx_baker_update +
 * lx_baker_apply, looped for ~2 s after one full bake; target >= 60/s.
 * Baseline: the rays of one update alone (regenerated with
 * lx_bench_rays_build: same 8x8 tiles, same OpenMP schedule and threads)
 * through lx_tracer_occluded_batch, coherent, and lx_tracer_occluded, one
 * ray per call - the ceiling an update could reach if shading were free.
 *
 * Usage: bench_realtime [--res N] [--reps N] [--threads N] [--skip-raw]
 * --res sets the lightmap resolution; --reps the baseline's repetitions
 * (x5); --skip-raw leaves the baseline out. The last line is a one-line
 * summary.
 */
#define _POSIX_C_SOURCE 200809L
#include "helpers.h"
#include "core/internal.h"
#include "scenes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int g_threads, g_reps = 3, g_res = 256;
static bool g_skip_raw;

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--res") && i + 1 < argc)
            g_res = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--reps") && i + 1 < argc)
            g_reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            g_threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--skip-raw"))
            g_skip_raw = true;
        else {
            fprintf(stderr, "usage: %s [--res N] [--reps N] [--threads N] [--skip-raw]\n", argv[0]);
            return 2;
        }
    }
    if (g_reps < 1)
        g_reps = 1;
    g_threads = lx_thread_count(g_threads);
    lx_bench_header("bench_realtime", g_threads);

    lx_test_scene_info info;
    /* 512-triangle ground + 49 spheres x 192 = 9,920 triangles */
    const float size = 16.0f;
    lx_scene *scene = lx_test_spheres_scene("bench-10k", size, 16, 7, 16, 7, true, &info);
    printf("\nREAL-TIME  %u triangles (ground %u + %u spheres), %dx%d lightmap, "
           "%u dynamic point lights, hard shadows, %d threads\n",
           info.triangles, info.ground_triangles, info.spheres, g_res, g_res, scene->light_count,
           g_threads);
    lx_bake_desc desc = {.resolution = g_res, .threads = g_threads};
    lx_baker *b;
    double t0 = lx_bench_now();
    if (lx_baker_create(scene, &desc, &b) != LX_OK)
        lx_bench_die("lx_baker_create");
    double t1 = lx_bench_now();
    if (lx_baker_bake(b) != LX_OK)
        lx_bench_die("lx_baker_bake");
    double t2 = lx_bench_now();
    printf("  setup: lx_baker_create %.3f s, first lx_baker_bake %.3f s\n", t1 - t0, t2 - t1);
    lx_image img;
    if (lx_image_alloc(&img, g_res, g_res, 3) != LX_OK)
        lx_bench_die("lx_image_alloc");
    lx_light base[LX_BENCH_LIGHTS];
    uint32_t L = lx_baker_light_count(b);
    for (uint32_t l = 0; l < L && l < LX_BENCH_LIGHTS; l++)
        base[l] = *lx_baker_light(b, l);

    /* the lights circle their start positions, each a different phase */
    double t_set = 0, t_update = 0, t_apply = 0, min_update = INFINITY;
    int frames = 0;
    double start = lx_bench_now(), busy = 0;
    while (busy < 2.0) {
        t0 = lx_bench_now();
        for (uint32_t l = 0; l < L && l < LX_BENCH_LIGHTS; l++) {
            lx_light m = base[l];
            float ph = 0.05f * (float)frames + 1.57f * (float)l;
            m.position =
                lx_add(m.position, lx_v3(0.15f * size * cosf(ph), 0.0f, 0.15f * size * sinf(ph)));
            if (lx_baker_set_light(b, l, &m) != LX_OK)
                lx_bench_die("lx_baker_set_light");
        }
        t1 = lx_bench_now();
        if (lx_baker_update(b) != LX_OK)
            lx_bench_die("lx_baker_update");
        t2 = lx_bench_now();
        if (lx_baker_apply(b, 0, &img) != LX_OK)
            lx_bench_die("lx_baker_apply");
        double t3 = lx_bench_now();
        t_set += t1 - t0, t_update += t2 - t1, t_apply += t3 - t2;
        min_update = fmin(min_update, t2 - t1);
        frames++;
        busy = t3 - start;
    }
    double per_update = busy / frames, ups = frames / busy;
    uint32_t used = lx_baker_lightmap_info(b, 0)->used_texels;
    printf("  %d updates in %.2f s; per update: set_light x%u %.3f ms + update %.3f ms + "
           "apply %.3f ms\n",
           frames, busy, L, 1e3 * t_set / frames, 1e3 * t_update / frames, 1e3 * t_apply / frames);

    /* baseline: the last update's rays alone, same tiles and schedule */
    double best_batch = NAN, best_single = NAN;
    lx_bench_rays rs = {0};
    if (!g_skip_raw) {
        lx_bench_rays_build(b, scene, &rs);
        lx_tracer *tr;
        if (lx_tracer_create(scene, NULL, &tr) != LX_OK)
            lx_bench_die("lx_tracer_create");
        uint8_t *occ = malloc(rs.count + 1);
        if (!occ)
            lx_bench_die("malloc");
        best_batch = best_single = INFINITY;
        for (int rep = 0; rep < 5 * g_reps; rep++) {
            best_batch = fmin(best_batch, lx_bench_trace(tr, &rs, LX_BENCH_BATCH, g_threads, occ));
            best_single =
                fmin(best_single, lx_bench_trace(tr, &rs, LX_BENCH_SINGLE, g_threads, occ));
        }
        free(occ);
        lx_tracer_destroy(tr);
        printf("  one update: %u used texels x %u lights = %llu samples, %llu shadow rays\n", used,
               L, (unsigned long long)rs.samples, (unsigned long long)rs.count);
    }

    char a[32], c[32];
    printf("\n  %-42s %12s %16s %14s\n", "figure (per update)", "time", "per second",
           "update / this");
    printf("  %-42s %9.3f ms %10s updates/s\n", "set_light x4 + update + apply (mean)",
           1e3 * per_update, lx_bench_si(ups, a));
    printf("  %-42s %9.3f ms %10s updates/s  (%ssamples/s)\n", "lx_baker_update alone (best)",
           1e3 * min_update, lx_bench_si(1.0 / min_update, a),
           lx_bench_si((double)used * L / min_update, c));
    if (!g_skip_raw) {
        printf("  %-42s %9.3f ms %10s updates/s %13.2fx\n",
               "its rays: lx_tracer_occluded_batch coherent", 1e3 * best_batch,
               lx_bench_si(1.0 / best_batch, a), best_batch / min_update);
        printf("  %-42s %9.3f ms %10s updates/s %13.2fx\n",
               "its rays: lx_tracer_occluded, 1 ray/call", 1e3 * best_single,
               lx_bench_si(1.0 / best_single, a), best_single / min_update);
    }
    const char *met = ups >= 60.0 ? "MET" : "NOT MET";
    printf("\n  => %.0f updates/s against the 60/s target (%.2fx: %s)", ups, ups / 60.0, met);
    if (!g_skip_raw)
        printf("; best update at %.2fx its rays' coherent-batch throughput",
               best_batch / min_update);
    printf("\n");

    char load[32];
    printf("\nbench_realtime: %dx%d, %u triangles, %u dynamic lights: %.0f updates/s "
           "(target >= 60/s: %s)",
           g_res, g_res, info.triangles, L, ups, met);
    if (!g_skip_raw)
        printf("; best update %.3f ms = %.2fx its rays as coherent batches (%.3f ms), %.2fx as "
               "1 ray/call",
               1e3 * min_update, best_batch / min_update, 1e3 * best_batch,
               best_single / min_update);
    printf("; %d threads, load %s\n", g_threads, lx_bench_load(load, sizeof load));
    lx_bench_rays_free(&rs);
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
    return 0;
}
