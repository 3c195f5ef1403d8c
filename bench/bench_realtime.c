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
 * Dynamic bounce (lx_bake_desc.dynamic_bounce_samples): a closed box room
 * (16 x 4 x 16 m, walls of albedo 0.6, one lightmap of the same
 * resolution, every gather ray landing on it) with the same 4 dynamic
 * lights; two bakers, without and with the bounce at --bounce-samples
 * (default 16), updated alternately frame by frame for ~2 s: the mean and
 * best update of each and their ratio, the cache's build (the first
 * update) and its bytes per texel.
 *
 * Usage: bench_realtime [--res N] [--reps N] [--threads N] [--skip-raw]
 *                       [--bounce-samples N]
 * --res sets the lightmap resolution; --reps the baseline's repetitions
 * (x5); --skip-raw leaves the baseline out; --bounce-samples 0 leaves the
 * bounce section out. The last line is a one-line summary.
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
static int g_bounce_samples = 16;

typedef struct bounce_figures {
    double without_mean, with_mean, without_best, with_best, build, bytes_per_texel;
} bounce_figures;

/* A closed box room of side `size` with the 4 dynamic lights; one baker
 * with `samples` of dynamic bounce (0: none). */
static lx_baker *room_baker(float size, int samples, lx_scene **scene_out)
{
    lx_scene *scene;
    if (lx_scene_create("room", &scene) != LX_OK)
        lx_bench_die("lx_scene_create");
    lx_material mat = {.name = "walls", .base_color = {0.6f, 0.6f, 0.6f, 1.0f},
                       .normal_scale = 1.0f};
    if (lx_scene_add_material(scene, &mat, NULL) != LX_OK)
        lx_bench_die("lx_scene_add_material");
    lx_mesh box = lx_test_box("room", lx_v3(-0.5f * size, 0.0f, -0.5f * size),
                              lx_v3(0.5f * size, 0.25f * size, 0.5f * size), true);
    lx_test_add(scene, &box);
    lx_test_mesh_free(&box);
    for (int k = 0; k < LX_BENCH_LIGHTS; k++) {
        lx_light l = lx_test_point_light(k, size, 0.15f * size, true);
        if (lx_scene_add_light(scene, &l) != LX_OK)
            lx_bench_die("lx_scene_add_light");
    }
    lx_bake_desc desc = {.resolution = g_res,
                         .threads = g_threads,
                         .dynamic_bounce_samples = (uint32_t)samples};
    lx_baker *b;
    if (lx_baker_create(scene, &desc, &b) != LX_OK || lx_baker_bake(b) != LX_OK)
        lx_bench_die("room baker");
    *scene_out = scene;
    return b;
}

static void move_lights(lx_baker *b, const lx_light *base, uint32_t count, int frame, float size)
{
    for (uint32_t l = 0; l < count; l++) {
        lx_light m = base[l];
        float ph = 0.05f * (float)frame + 1.57f * (float)l;
        m.position =
            lx_add(m.position, lx_v3(0.15f * size * cosf(ph), 0.0f, 0.15f * size * sinf(ph)));
        if (lx_baker_set_light(b, l, &m) != LX_OK)
            lx_bench_die("lx_baker_set_light");
    }
}

static bounce_figures bounce_section(float size)
{
    bounce_figures f = {0};
    lx_scene *s0, *s1;
    lx_baker *b0 = room_baker(size, 0, &s0), *b1 = room_baker(size, g_bounce_samples, &s1);
    uint32_t used = lx_baker_lightmap_info(b1, 0)->used_texels;
    printf("\nDYNAMIC BOUNCE  closed room %gx%gx%g m, one %dx%d lightmap (%u texels), %u dynamic "
           "point lights, %d gather samples a texel, %d threads\n",
           size, 0.25f * size, size, g_res, g_res, used, lx_baker_light_count(b1),
           g_bounce_samples, g_threads);
    lx_light base[LX_BENCH_LIGHTS];
    uint32_t L = lx_baker_light_count(b1);
    for (uint32_t l = 0; l < L && l < LX_BENCH_LIGHTS; l++)
        base[l] = *lx_baker_light(b1, l);
    /* the first update of each: b1 builds its cache of hits */
    double t0 = lx_bench_now();
    if (lx_baker_update(b0) != LX_OK)
        lx_bench_die("lx_baker_update");
    double t1 = lx_bench_now();
    if (lx_baker_update(b1) != LX_OK)
        lx_bench_die("lx_baker_update");
    double t2 = lx_bench_now();
    f.build = (t2 - t1) - (t1 - t0);
    /* the cache: 12 bytes a sample (cells of the strata), 1 a texel, 13 a pixel */
    uint32_t sx = (uint32_t)sqrt((double)g_bounce_samples);
    sx = sx ? sx : 1;
    uint32_t cells = sx * ((g_bounce_samples + sx - 1) / sx);
    f.bytes_per_texel = 12.0 * cells + 1.0 + 13.0 * (double)g_res * g_res / used;
    double sum0 = 0, sum1 = 0;
    f.without_best = f.with_best = INFINITY;
    int frames = 0;
    double start = lx_bench_now();
    while (lx_bench_now() - start < 2.0) {
        move_lights(b0, base, L, frames, size);
        move_lights(b1, base, L, frames, size);
        double a = lx_bench_now();
        if (lx_baker_update(b0) != LX_OK)
            lx_bench_die("lx_baker_update");
        double m = lx_bench_now();
        if (lx_baker_update(b1) != LX_OK)
            lx_bench_die("lx_baker_update");
        double e = lx_bench_now();
        sum0 += m - a, sum1 += e - m;
        f.without_best = fmin(f.without_best, m - a);
        f.with_best = fmin(f.with_best, e - m);
        frames++;
    }
    f.without_mean = sum0 / frames, f.with_mean = sum1 / frames;
    printf("  first update with the bounce (traces and caches %u rays a texel): %.3f s more than "
           "without\n",
           cells, f.build);
    printf("  cache: %.0f bytes a texel (12 x %u samples + 1, and 13 a pixel)\n", f.bytes_per_texel,
           cells);
    printf("\n  %-42s %12s %12s\n", "figure (per update, interleaved)", "mean", "best");
    printf("  %-42s %9.3f ms %9.3f ms\n", "lx_baker_update, direct only", 1e3 * f.without_mean,
           1e3 * f.without_best);
    printf("  %-42s %9.3f ms %9.3f ms\n", "lx_baker_update with the bounce", 1e3 * f.with_mean,
           1e3 * f.with_best);
    printf("  %-42s %9.2fx %10.2fx\n", "ratio (with / without)", f.with_mean / f.without_mean,
           f.with_best / f.without_best);
    printf("  the bounce's own part: %.3f ms an update, %.1f ns a texel (%d frames)\n",
           1e3 * (f.with_best - f.without_best), 1e9 * (f.with_best - f.without_best) / used,
           frames);
    lx_baker_destroy(b0);
    lx_baker_destroy(b1);
    lx_scene_destroy(s0);
    lx_scene_destroy(s1);
    return f;
}

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
        else if (!strcmp(argv[i], "--bounce-samples") && i + 1 < argc)
            g_bounce_samples = atoi(argv[++i]);
        else {
            fprintf(stderr,
                    "usage: %s [--res N] [--reps N] [--threads N] [--skip-raw] "
                    "[--bounce-samples N]\n",
                    argv[0]);
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

    bounce_figures bf = {0};
    if (g_bounce_samples > 0)
        bf = bounce_section(size);

    char load[32];
    printf("\nbench_realtime: %dx%d, %u triangles, %u dynamic lights: %.0f updates/s "
           "(target >= 60/s: %s)",
           g_res, g_res, info.triangles, L, ups, met);
    if (g_bounce_samples > 0)
        printf("; room with the dynamic bounce at %d samples: update %.3f ms against %.3f ms "
               "without (%.2fx), cache %.0f bytes/texel built in %.3f s",
               g_bounce_samples, 1e3 * bf.with_mean, 1e3 * bf.without_mean,
               bf.with_mean / bf.without_mean, bf.bytes_per_texel, bf.build);
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
