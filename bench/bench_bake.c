/* bench_bake - the static bake's speed, each figure
 * with its baseline measured in the same run:
 *
 *  1. Full bake of a generated ~100k-triangle scene (tests/common/scenes.h),
 *     one 1024x1024 lightmap, 4 point lights with hard shadows: texel-light
 *     samples per second of lx_baker_bake, against raw occlusion throughput
 *     for exactly the rays the bake casts (regenerated with
 *     lx_bench_rays_build: same 8x8 tiles, same OpenMP schedule and threads):
 *       - lx_tracer_occluded, one ray per call   (the baseline of the target:
 *                                                 bake >= 0.80x of it)
 *       - lx_tracer_occluded_batch, 64-ray coherent and incoherent batches
 *       - Embree directly on one flat world-space BVH built here:
 *         rtcOccluded1 and coherent rtcOccluded1M (no luxel wrapper)
 *     Check: summing the lights over the rays lx_tracer_occluded finds
 *     unoccluded must rebuild the bake's lightmap exactly.
 *  2. Brute-force reference: tests/common/reference.h, the tests' oracle
 *     (the per-texel lighting article's every-texel x every-triangle UV search, then every light x
 *     every triangle in double precision), on a ~2k-triangle scene at
 *     128x128 with the bake's OpenMP threads, against lx_baker_create +
 *     lx_baker_bake: the speed-up, and their agreement (texels within 1%,
 *     near-tie texels the oracle flags left out).
 *
 *  3. The whole `luxel bake` process on the hard case: the same ~100k
 *     triangles written as a .glb (tests/common/scenes.h), 16 point lights
 *     without range in a --lights JSON (every texel sees every light: 16.8M
 *     shadow rays at 1024x1024), the real CLI run as a child process and
 *     timed from fork to exit (import to every file written). Its
 *     texel-light samples per second against raw single-ray Embree
 *     (rtcOccluded1 on a flat BVH built here, same tiles, schedule and
 *     threads) on the same rays, traced right after each CLI run (target
 *     >= 2x, issue 28; best against best, and the median of the pairs), plus the
 *     other ways to cast them (rtcOccluded1M, 4-, 8- and 16-wide packets).
 *     Phases (import, texel maps, BVH, bake, dynamic lights, apply, each
 *     file's encoding) come from the CLI's library calls in a fresh process
 *     (this program re-run with --phases-child), each the best of the
 *     repetitions. The writers against the ones luxel had (OpenEXRCore's ZIP
 *     at its default level on one thread; stb_image_write's own deflate),
 *     and the EXR + PNG time as a share of the bake (target <= 25%). Check:
 *     the CLI's EXR equals this process's lightmap bit for bit.
 *
 * The real-time update rate is bench_realtime's.
 *
 * Usage: bench_bake [--res N] [--cli-res N] [--reps N] [--threads N]
 *                   [--only bake|brute|cli] [--skip-raw]
 * --res sets [1]'s resolution, --cli-res [3]'s (4096 shows the phases of a
 * large lightmap; with --skip-raw, which leaves out the raw figures and
 * their 48 bytes of stored ray per sample). [3] repeats 5 times unless
 * --reps is given. The last line is a one-line summary.
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* sync() */
#include "helpers.h"
#include "core/internal.h"
#include "reference.h"
#include "scenes.h"
#include "bench_cli.h"

#include <embree3/rtcore.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define TILE LX_BENCH_TILE

static int g_threads, g_reps = 3, g_res = 1024, g_cli_res = 1024;
static bool g_reps_set; /* --reps given: [3] uses it instead of its 5 */
static bool g_skip_raw;

/* ---- raw throughput: the lx_tracer modes, then Embree on a flat BVH ------ */

typedef enum raw_mode {
    RAW_SINGLE,      /* lx_tracer_occluded */
    RAW_BATCH,       /* lx_tracer_occluded_batch coherent */
    RAW_BATCH_INCOH, /* lx_tracer_occluded_batch incoherent */
    RAW_FLAT_1,      /* rtcOccluded1 on a flat BVH */
    RAW_FLAT_1M,     /* rtcOccluded1M coherent on a flat BVH */
    RAW_MODES
} raw_mode;

static const char *raw_names[RAW_MODES] = {
    "lx_tracer_occluded, 1 ray/call",      "lx_tracer_occluded_batch coherent",
    "lx_tracer_occluded_batch incoherent", "Embree flat BVH, rtcOccluded1",
    "Embree flat BVH, rtcOccluded1M coh.",
};

static double raw_run(raw_mode mode, const lx_tracer *tr, RTCScene flat, const lx_bench_rays *rs,
                      uint8_t *occluded)
{
    switch (mode) {
    case RAW_SINGLE:
        return lx_bench_trace(tr, rs, LX_BENCH_SINGLE, g_threads, occluded);
    case RAW_BATCH:
        return lx_bench_trace(tr, rs, LX_BENCH_BATCH, g_threads, occluded);
    case RAW_BATCH_INCOH:
        return lx_bench_trace(tr, rs, LX_BENCH_BATCH_INCOHERENT, g_threads, occluded);
    case RAW_FLAT_1:
        return lx_bench_flat_trace(LX_FLAT_1, flat, rs, g_threads, occluded);
    default:
        return lx_bench_flat_trace(LX_FLAT_1M, flat, rs, g_threads, occluded);
    }
}

/* The bake's per-sample work without the rays: lx_light_evaluate and the
 * shadow ray for every texel and light, over the same tiles and schedule. */
static double eval_run(const lx_baker *b, const lx_bench_rays *rs)
{
    const int L = rs->lights;
    double sink = 0;
    double t0 = lx_bench_now();
#pragma omp parallel for schedule(dynamic, 4) num_threads(g_threads) reduction(+ : sink)
    for (int tile = 0; tile < rs->tiles; tile++) {
        lx_ray rays[TILE * TILE];
        lx_vec3 accum[TILE * TILE] = {{0}};
        for (int l = 0; l < L; l++) {
            const lx_light *light = lx_baker_light(b, (uint32_t)l);
            uint32_t n = 0;
            for (uint32_t i = rs->tile_texel[tile]; i < rs->tile_texel[tile + 1]; i++) {
                const lx_texel_sample *t = &rs->texel[i];
                lx_light_eval e;
                bool direct = lx_light_evaluate(light, t->position, t->normal, &e);
                accum[i - rs->tile_texel[tile]] =
                    lx_add(accum[i - rs->tile_texel[tile]], e.illuminance);
                if (direct)
                    rays[n++] = lx_bench_shadow_ray(rs->bias, t->position, t->geometric_normal, &e);
            }
            for (uint32_t j = 0; j < n; j++)
                sink += rays[j].tmax;
        }
        for (int k = 0; k < TILE * TILE; k++)
            sink += accum[k].y;
    }
    double dt = lx_bench_now() - t0;
    if (sink == 42.0)
        printf(" ");
    return dt;
}

/* The lightmap rebuilt from the rays lx_tracer_occluded left unoccluded,
 * summed in the bake's order; returns the channels that differ from the
 * bake's. *blocked counts the occluded rays. */
static uint64_t rebuild_differs(const lx_baker *b, const lx_bench_rays *rs, const uint8_t *occ,
                                uint64_t *blocked)
{
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, 0);
    size_t pixels = (size_t)info->width * info->height;
    float *mine = calloc(pixels * 3, sizeof(float));
    if (!mine)
        lx_bench_die("calloc");
    *blocked = 0;
    for (int tile = 0; tile < rs->tiles; tile++)
        for (int l = 0; l < rs->lights; l++)
            for (uint32_t j = rs->batch[(size_t)tile * rs->lights + l];
                 j < rs->batch[(size_t)tile * rs->lights + l + 1]; j++) {
                if (occ[j]) {
                    (*blocked)++;
                    continue;
                }
                float *o = mine + 3 * (size_t)rs->pixel[j];
                o[0] += rs->illuminance[j].x, o[1] += rs->illuminance[j].y,
                    o[2] += rs->illuminance[j].z;
            }
    lx_image img;
    if (lx_baker_apply_alloc(b, 0, &img) != LX_OK)
        lx_bench_die("lx_baker_apply_alloc");
    const uint8_t *mask = lx_baker_mask(b, 0);
    uint64_t differ = 0;
    for (size_t p = 0; p < pixels; p++)
        if (mask[p])
            for (int c = 0; c < 3; c++)
                differ += img.data[3 * p + c] != mine[3 * p + c];
    lx_image_free(&img);
    free(mine);
    return differ;
}

/* ---- [1] the full bake ---------------------------------------------------- */

typedef struct bake_result {
    bool ran, raw;
    double samples_s, vs_single, vs_batch, vs_flat1;
} bake_result;

static bake_result bench_full_bake(void)
{
    bake_result res = {.ran = true, .raw = !g_skip_raw};
    lx_test_scene_info si_;
    /* 441 spheres x 224 triangles + a 2,048-triangle ground = 100,832 */
    lx_scene *scene = lx_test_spheres_scene("bench-100k", 40.0f, 32, 21, 16, 8, false, &si_);
    printf("\n[1] FULL BAKE  %u triangles (ground %u + %u spheres = %u, %u nodes), "
           "%dx%d lightmap, %u point lights, hard shadows, %d threads\n",
           si_.triangles, si_.ground_triangles, si_.spheres, si_.sphere_triangles, si_.nodes, g_res,
           g_res, scene->light_count, g_threads);

    lx_bake_desc desc = {.resolution = g_res, .threads = g_threads};
    lx_baker *b;
    double t0 = lx_bench_now();
    if (lx_baker_create(scene, &desc, &b) != LX_OK)
        lx_bench_die("lx_baker_create");
    double t_create = lx_bench_now() - t0;
    if (lx_baker_lightmap_count(b) != 1) {
        fprintf(stderr, "bench_bake: expected 1 lightmap, got %u\n", lx_baker_lightmap_count(b));
        exit(1);
    }
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, 0);

    t0 = lx_bench_now();
    lx_bench_rays rs;
    lx_bench_rays_build(b, scene, &rs);
    double t_rays = lx_bench_now() - t0;

    lx_tracer *tr = NULL;
    RTCDevice dev = NULL;
    RTCScene flat = NULL;
    double t_tracer = 0, t_flat = 0;
    uint8_t *occ[RAW_MODES] = {0};
    if (!g_skip_raw) {
        t0 = lx_bench_now();
        if (lx_tracer_create(scene, NULL, &tr) != LX_OK)
            lx_bench_die("lx_tracer_create");
        t_tracer = lx_bench_now() - t0;
        dev = rtcNewDevice(NULL);
        t0 = lx_bench_now();
        flat = lx_bench_flat_scene(dev, scene);
        t_flat = lx_bench_now() - t0;
        for (int m = 0; m < RAW_MODES; m++)
            if (!(occ[m] = malloc(rs.count + 1)))
                lx_bench_die("malloc");
    }

    double best_bake = INFINITY, best_eval = INFINITY, best_raw[RAW_MODES];
    for (int m = 0; m < RAW_MODES; m++)
        best_raw[m] = INFINITY;
    /* interleaved repetitions so machine noise hits every figure alike */
    for (int rep = 0; rep < g_reps; rep++) {
        t0 = lx_bench_now();
        if (lx_baker_bake(b) != LX_OK)
            lx_bench_die("lx_baker_bake");
        best_bake = fmin(best_bake, lx_bench_now() - t0);
        if (g_skip_raw)
            continue;
        best_eval = fmin(best_eval, eval_run(b, &rs));
        for (int m = 0; m < RAW_MODES; m++)
            best_raw[m] = fmin(best_raw[m], raw_run((raw_mode)m, tr, flat, &rs, occ[m]));
    }

    printf("  setup: lx_baker_create %.2f s, ray regeneration %.2f s", t_create, t_rays);
    if (!g_skip_raw)
        printf(", extra lx_tracer %.2f s, flat Embree BVH %.2f s", t_tracer, t_flat);
    printf("\n  used texels %u of %d; texel-light samples %llu; shadow rays %llu "
           "(%llu samples with the light behind/out of range: no ray)\n",
           info->used_texels, info->width * info->height, (unsigned long long)rs.samples,
           (unsigned long long)rs.count, (unsigned long long)rs.behind);
    uint64_t disagree[RAW_MODES] = {0};
    if (!g_skip_raw) {
        uint64_t blocked;
        uint64_t differ = rebuild_differs(b, &rs, occ[RAW_SINGLE], &blocked);
        for (int m = 0; m < RAW_MODES; m++)
            for (uint64_t j = 0; j < rs.count; j++)
                disagree[m] += occ[m][j] != occ[RAW_SINGLE][j];
        printf("  %.1f%% of rays blocked; check: the lightmap rebuilt from the regenerated rays "
               "%s the bake's (%llu differing channels)\n",
               100.0 * (double)blocked / (double)(rs.count ? rs.count : 1),
               differ == 0 ? "equals" : "DIFFERS FROM", (unsigned long long)differ);
    }

    char a[32], c[32];
    res.samples_s = (double)rs.samples / best_bake;
    printf("\n  %-40s %12s %14s %12s\n", "figure (best of reps)", "time", "per second",
           "bake / this");
    printf("  %-40s %10.3f s %12ssamples/s\n", "lx_baker_bake (samples)", best_bake,
           lx_bench_si(res.samples_s, a));
    printf("  %-40s %12s %12srays/s\n", "lx_baker_bake (rays cast)", "",
           lx_bench_si((double)rs.count / best_bake, c));
    if (g_skip_raw) {
        printf("\n  => %ssamples/s (raw throughput skipped: --skip-raw)\n",
               lx_bench_si(res.samples_s, a));
    } else {
        for (int m = 0; m < RAW_MODES; m++) {
            double rays_s = (double)rs.count / best_raw[m];
            printf("  %-40s %10.3f s %12srays/s %11.2fx%s\n", raw_names[m], best_raw[m],
                   lx_bench_si(rays_s, a), res.samples_s / rays_s,
                   disagree[m] ? "  (occlusion differs!)" : "");
        }
        printf("  %-40s %10.3f s  (lx_light_evaluate + shadow ray, no tracing)\n",
               "bake's per-sample work alone", best_eval);
        printf("  %-40s %10.3f s  (bake - its rays as coherent batches; overlaps the line "
               "above)\n",
               "bake's time beyond its rays", best_bake - best_raw[RAW_BATCH]);
        res.vs_single = res.samples_s / ((double)rs.count / best_raw[RAW_SINGLE]);
        res.vs_batch = res.samples_s / ((double)rs.count / best_raw[RAW_BATCH]);
        res.vs_flat1 = res.samples_s / ((double)rs.count / best_raw[RAW_FLAT_1]);
        printf("\n  => bake at %.2fx single-ray lx_tracer_occluded (target >= 0.80x: %s), "
               "%.2fx the coherent batch, %.2fx flat rtcOccluded1\n",
               res.vs_single, res.vs_single >= 0.8 ? "MET" : "NOT MET", res.vs_batch, res.vs_flat1);
    }
    for (int m = 0; m < RAW_MODES; m++)
        free(occ[m]);
    if (flat)
        rtcReleaseScene(flat);
    if (dev)
        rtcReleaseDevice(dev);
    lx_tracer_destroy(tr);
    lx_bench_rays_free(&rs);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
    return res;
}

/* ---- [3] the whole luxel bake process ------------------------------------ */

typedef struct cli_result {
    bool ran, raw;
    int res;
    double wall, samples_s, flat1_rays_s, ratio, median_ratio, writes_share;
} cli_result;

/* luxel's writers and the old ones on the same lightmap, best of reps;
 * prints the figures. */
static void bench_writers(const lx_image *img, float exposure, const char *dir)
{
    char p[6][1100];
    const char *names[6] = {"luxel.exr", "luxel-half.exr", "luxel.png",
                            "old.exr",   "old.png",        "luxel-1thread.png"};
    for (int k = 0; k < 6; k++)
        snprintf(p[k], sizeof p[k], "%s/%s", dir, names[k]);
    double best[6] = {INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY};
    for (int rep = 0; rep < g_reps; rep++) {
        sync(); /* earlier files' write-back is not this figure's */
        double t0 = lx_bench_now();
        lx_image_write_desc wd = {.format = LX_IMAGE_EXR, .threads = g_threads};
        if (lx_image_write(p[0], img, &wd) != LX_OK)
            lx_bench_die("lx_image_write");
        best[0] = fmin(best[0], lx_bench_now() - t0);
        sync();
        t0 = lx_bench_now();
        wd.half = true;
        if (lx_image_write(p[1], img, &wd) != LX_OK)
            lx_bench_die("lx_image_write");
        best[1] = fmin(best[1], lx_bench_now() - t0);
        sync();
        t0 = lx_bench_now();
        lx_image_write_desc pd = {
            .format = LX_IMAGE_PNG, .exposure = exposure, .threads = g_threads};
        if (lx_image_write(p[2], img, &pd) != LX_OK)
            lx_bench_die("lx_image_write");
        best[2] = fmin(best[2], lx_bench_now() - t0);
        sync();
        best[3] = fmin(best[3], lx_bench_old_exr(img, p[3]));
        sync();
        best[4] = fmin(best[4], lx_bench_old_png(img, exposure, p[4]));
        sync();
        t0 = lx_bench_now();
        pd.threads = 1;
        if (lx_image_write(p[5], img, &pd) != LX_OK)
            lx_bench_die("lx_image_write");
        best[5] = fmin(best[5], lx_bench_now() - t0);
    }
    printf("\n  %-44s %7s %12s  %s\n", "writing this lightmap (best of reps)", "time", "bytes",
           "vs the old writer");
    const char *what[6] = {"luxel EXR, 32-bit float (uncompressed)",
                           "luxel EXR, half (ZIP 1)",
                           "luxel PNG preview",
                           "old: EXR float, ZIP, 1 thread",
                           "old: PNG, stb's deflate",
                           "luxel PNG preview, 1 thread"};
    const int order[6] = {3, 0, 1, 4, 2, 5};
    for (int i = 0; i < 6; i++) {
        int k = order[i];
        printf("  %-44s %7.3f s %12ld", what[k], best[k], lx_bench_file_size(p[k]));
        if (k == 0 || k == 1)
            printf("  %5.1fx faster", best[3] / best[k]);
        if (k == 2 || k == 5)
            printf("  %5.1fx faster", best[4] / best[k]);
        printf("\n");
    }
}

static cli_result bench_cli(void)
{
    cli_result res = {.ran = true, .raw = !g_skip_raw, .res = g_cli_res};
    lx_test_scene_info si_;
    lx_scene *gen = lx_test_spheres_scene("bench-cli", 40.0f, 32, 21, 16, 8, false, &si_);
    enum { GRID = 4, LIGHTS = GRID * GRID };
    lx_light lights[LIGHTS];
    lx_test_grid_lights(GRID, 40.0f, 8.0f, lights);
    char tag[64], dir[1024], glb[1100], json[1100], out[1100], exr[1200], luxel[4200], errlog[1100];
    snprintf(tag, sizeof tag, "bench-cli-%ld", (long)getpid());
    snprintf(dir, sizeof dir, "%s", lx_test_dir(tag));
    snprintf(glb, sizeof glb, "%s/scene.glb", dir);
    snprintf(json, sizeof json, "%s/lights.json", dir);
    snprintf(out, sizeof out, "%s/out", dir);
    snprintf(errlog, sizeof errlog, "%s/luxel-stderr.txt", dir);
    lx_test_write_glb(gen, glb);
    lx_test_write_lights_json(lights, LIGHTS, json);
    lx_scene_destroy(gen);
    lx_bench_sibling("luxel", luxel, sizeof luxel);
    printf("\n[3] WHOLE luxel bake PROCESS  %u triangles (ground %u + %u spheres), %dx%d "
           "lightmap, %d point lights without range (every texel sees every light), hard "
           "shadows, %d threads\n",
           si_.triangles, si_.ground_triangles, si_.spheres, g_cli_res, g_cli_res, LIGHTS,
           g_threads);
    printf("  the CLI, timed as a child process from fork to exit: %s bake scene.glb --lights "
           "lights.json -o out --resolution %d --threads %d -q --bounces 0 --unwrap never "
           "--edge-supersample 0  (direct light; "
           "writes an EXR, a PNG preview and the manifest)\n",
           luxel, g_cli_res, g_threads);

    char res_s[16], thr_s[16];
    snprintf(res_s, sizeof res_s, "%d", g_cli_res);
    snprintf(thr_s, sizeof thr_s, "%d", g_threads);
    /* --unwrap never: the spheres, without UVs, stay occluders (auto would
     * give them lightmaps and pack an atlas); --edge-supersample 0: the
     * same rays as this process's bake (edge supersampling adds its own) */
    char *argv[] = {luxel,       "bake",      glb,     "--lights", json,  "-o",
                    out,         "--resolution", res_s, "--threads", thr_s, "-q",
                    "--bounces", "0",         "--unwrap", "never", "--edge-supersample", "0",
                    NULL};

    lx_bench_phases best = {INFINITY, INFINITY, INFINITY, INFINITY,
                            INFINITY, INFINITY, INFINITY, INFINITY};
    double best_wall = INFINITY, best_raw[LX_FLAT_MODES];
    for (int m = 0; m < LX_FLAT_MODES; m++)
        best_raw[m] = INFINITY;
    /* this process's own bake of the scene: the rays, and the check */
    lx_scene *scene;
    if (lx_scene_load(glb, NULL, &scene) != LX_OK || lx_lights_json_apply(scene, json) != LX_OK)
        lx_bench_die("load");
    lx_bake_desc desc = lx_bake_desc_defaults(NULL);
    desc.resolution = g_cli_res;
    desc.threads = g_threads;
    desc.padding = LX_PADDING_RECOMMENDED;
    lx_baker *b;
    lx_image img;
    if (lx_baker_create(scene, &desc, &b) != LX_OK || lx_baker_bake(b) != LX_OK ||
        lx_baker_update(b) != LX_OK || lx_baker_apply_alloc(b, 0, &img) != LX_OK)
        lx_bench_die("bake");
    lx_bench_rays rs = {0};
    RTCDevice dev = NULL;
    RTCScene flat = NULL;
    uint8_t *occ[LX_FLAT_MODES] = {0};
    if (!g_skip_raw) {
        lx_bench_rays_build(b, scene, &rs);
        dev = rtcNewDevice(NULL);
        flat = lx_bench_flat_scene(dev, scene);
        for (int m = 0; m < LX_FLAT_MODES; m++)
            if (!(occ[m] = malloc(rs.count + 1)))
                lx_bench_die("malloc");
    }
    /* interleaved repetitions, the process and its baseline side by side:
     * machine noise hits them alike; the ratio of each pair is kept too */
    int reps = g_reps_set ? g_reps : 5;
    double ratios[64];
    int nratios = 0;
    for (int rep = 0; rep < reps; rep++) {
        sync(); /* the last run's write-back is not this one's */
        double wall = lx_bench_run_child(argv, errlog);
        best_wall = fmin(best_wall, wall);
        for (int m = 0; m < LX_FLAT_MODES && !g_skip_raw; m++) {
            double t = lx_bench_flat_trace((lx_bench_flat_mode)m, flat, &rs, g_threads, occ[m]);
            best_raw[m] = fmin(best_raw[m], t);
            if (m == 0 && nratios < 64)
                ratios[nratios++] = t / wall; /* samples = rays: throughputs' ratio */
        }
        sync();
        lx_bench_phases ph;
        lx_bench_phases_run(glb, json, dir, g_cli_res, g_threads, &ph);
        lx_bench_phases_min(&best, &ph);
    }
    for (int i = 1; i < nratios; i++) /* insertion sort for the median */
        for (int j = i; j > 0 && ratios[j] < ratios[j - 1]; j--) {
            double x = ratios[j];
            ratios[j] = ratios[j - 1], ratios[j - 1] = x;
        }
    res.median_ratio = nratios ? ratios[nratios / 2] : 0.0;
    const lx_lightmap_info *info = lx_baker_lightmap_info(b, 0);
    uint64_t samples = (uint64_t)info->used_texels * scene->light_count;

    /* the CLI's lightmap is this process's, bit for bit */
    snprintf(exr, sizeof exr, "%s/%s.exr", out, info->name);
    lx_image got;
    if (lx_image_load(exr, NULL, &got) != LX_OK)
        lx_bench_die("lx_image_load");
    size_t n = (size_t)img.width * img.height * 3, differ = 0;
    for (size_t i = 0; i < n; i++)
        differ += got.width != img.width || memcmp(&got.data[i], &img.data[i], 4) != 0;
    lx_image_free(&got);

    res.wall = best_wall;
    res.samples_s = (double)samples / best_wall;
    double sum = best.import + best.texel_maps + best.bvh + best.bake + best.dynamic + best.apply +
                 best.exr + best.png;
    printf("  used texels %u; texel-light samples %llu; check: the CLI's EXR %s this "
           "process's lightmap (%zu differing values)\n",
           info->used_texels, (unsigned long long)samples, differ ? "DIFFERS FROM" : "equals",
           differ);
    if (!g_skip_raw) {
        uint64_t blocked = 0;
        for (uint64_t j = 0; j < rs.count; j++)
            blocked += occ[0][j];
        printf("  %.1f%% of the %llu rays blocked\n", 100.0 * (double)blocked / (double)rs.count,
               (unsigned long long)rs.count);
    }
    printf("\n  %-40s %7s  %6s   (best of %d, interleaved)\n",
           "phase (the CLI's calls, fresh process)", "time", "share", reps);
    const double *vals = &best.import;
    for (int k = 0; k < LX_BENCH_PHASES; k++)
        printf("  %-40s %7.3f s %5.1f%%\n", lx_bench_phase_names[k], vals[k],
               100.0 * vals[k] / best_wall);
    printf("  %-40s %7.3f s %5.1f%%\n", "sum of the phases", sum, 100.0 * sum / best_wall);
    printf("  %-40s %7.3f s  (process start and exit, staging, manifest, freeing;\n"
           "  %-40s            each figure is its own best, so this takes the noise)\n",
           "rest of the CLI process", best_wall - sum, "");
    char a[32], c[32];
    printf("  %-40s %7.3f s  %ssamples/s\n", "WHOLE luxel bake process", best_wall,
           lx_bench_si(res.samples_s, a));
    /* the CLI's default edge supersampling on top: its cost with 16 lights
     * (only the lights whose shadows differ around a texel are shaded
     * again) */
    char *argv_edge[sizeof argv / sizeof argv[0]];
    memcpy(argv_edge, argv, sizeof argv);
    char edge_n[16];
    snprintf(edge_n, sizeof edge_n, "%d", LX_EDGE_SUPERSAMPLE_RECOMMENDED);
    argv_edge[17] = edge_n;
    double best_edge = INFINITY;
    for (int rep = 0; rep < reps; rep++) {
        sync();
        best_edge = fmin(best_edge, lx_bench_run_child(argv_edge, errlog));
    }
    printf("  %-40s %7.3f s  (+%.0f%% for the edges, --edge-supersample %s)\n",
           "the same with the default edges", best_edge, 100.0 * (best_edge / best_wall - 1.0),
           edge_n);
    float ev;
    bool lit;
    lx_baker_meter_ev100(b, &ev, &lit);
    bench_writers(&img, lx_exposure_from_ev100(ev) / LX_PI, dir);
    /* the share from the phases: written as the CLI writes, fresh process */
    res.writes_share = (best.exr + best.png) / best.bake;
    printf("  => the EXR and the PNG take %.0f%% of the bake's time in the phases above (target "
           "<= 25%%: %s)\n",
           100.0 * res.writes_share, res.writes_share <= 0.25 ? "MET" : "NOT MET");
    if (!g_skip_raw) {
        double best1 = best_raw[0];
        res.flat1_rays_s = (double)rs.count / best1;
        res.ratio = res.samples_s / res.flat1_rays_s;
        printf("\n  %-40s %7s  %14s %s\n", "raw Embree, the same rays", "time", "per second",
               "process / this");
        for (int m = 0; m < LX_FLAT_MODES; m++) {
            uint64_t dis = 0;
            for (uint64_t j = 0; j < rs.count; j++)
                dis += occ[m][j] != occ[0][j];
            double rays_s = (double)rs.count / best_raw[m];
            printf("  %-40s %7.3f s %12srays/s %6.2fx%s\n", lx_bench_flat_names[m], best_raw[m],
                   lx_bench_si(rays_s, c), res.samples_s / rays_s,
                   dis ? "  (occlusion differs!)" : "");
        }
        printf("\n  => whole process at %.2fx raw single-ray Embree rtcOccluded1, best against "
               "best (target >= 2x: %s); the median of the %d side-by-side pairs: "
               "%.2fx\n",
               res.ratio, res.ratio >= 2.0 ? "MET" : "NOT MET", nratios, res.median_ratio);
        for (int m = 0; m < LX_FLAT_MODES; m++)
            free(occ[m]);
        rtcReleaseScene(flat);
        rtcReleaseDevice(dev);
        lx_bench_rays_free(&rs);
    }
    lx_image_free(&img);
    lx_baker_destroy(b);
    lx_scene_destroy(scene);
    rmdir(lx_test_dir(tag)); /* emptied (a 4096^2 run leaves 0.5 GB) */
    return res;
}

/* ---- [2] the brute-force reference ---------------------------------------- */

/* tests/common/reference.h on every texel of node 0's lightmap: the
 * oracle's own serial texel map, then its shading on the bake's OpenMP
 * threads. Returns seconds; ambiguous[p] marks texels with a near-tie ray. */
static double brute_reference(const lx_scene *scene, int w, int h, float *out, uint8_t *ambiguous,
                              uint32_t *used_out)
{
    double t0 = lx_bench_now();
    lx_ref_scene rs;
    lx_ref_scene_build(scene, &rs);
    lx_ref_map map;
    lx_ref_texel_map(scene, 0, w, h, &map);
    uint32_t used = 0;
#pragma omp parallel for schedule(dynamic, 1) num_threads(g_threads) reduction(+ : used)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            const lx_ref_texel *t = &map.texels[p];
            if (!t->used)
                continue;
            used++;
            bool amb = false;
            lx_vec3 e = lx_ref_shade(&rs, scene->lights, scene->light_count, scene->ambient,
                                     t->position, t->normal, t->geometric_normal, 1e-5, &amb);
            out[3 * p] = e.x, out[3 * p + 1] = e.y, out[3 * p + 2] = e.z;
            ambiguous[p] = amb;
        }
    double dt = lx_bench_now() - t0;
    lx_ref_map_free(&map);
    lx_ref_scene_free(&rs);
    *used_out = used;
    return dt;
}

/* Texels whose irradiance (green) differs from ref by more than 1%, near
 * ties (skip) counted apart. */
static uint32_t count_differ(const float *ref, const float *img, const uint8_t *skip, size_t n,
                             uint32_t *skipped_differ, double *max_rel)
{
    uint32_t bad = 0;
    *skipped_differ = 0;
    *max_rel = 0;
    for (size_t p = 0; p < n; p++) {
        double r = ref[3 * p + 1], v = img[3 * p + 1];
        double rel = fabs(r - v) / fmax(fabs(r), 1e-3);
        if (rel <= 0.01)
            continue;
        if (skip[p]) {
            (*skipped_differ)++;
            continue;
        }
        bad++;
        if (rel > *max_rel)
            *max_rel = rel;
    }
    return bad;
}

typedef struct brute_result {
    bool ran;
    double speedup;
    uint32_t bad, used;
} brute_result;

static brute_result bench_brute_force(void)
{
    lx_test_scene_info si_;
    /* 1,152-triangle ground + 9 spheres x 96 = 2,016 triangles */
    lx_scene *scene = lx_test_spheres_scene("bench-2k", 10.0f, 24, 3, 12, 5, false, &si_);
    const int res = 128;
    const size_t pixels = (size_t)res * res;
    printf("\n[2] BRUTE-FORCE REFERENCE  %u triangles (ground %u + %u spheres), %dx%d, "
           "%u point lights, hard shadows, %d threads for both\n",
           si_.triangles, si_.ground_triangles, si_.spheres, res, res, scene->light_count,
           g_threads);

    double best = INFINITY, best_create = 0, best_bake = 0;
    lx_image img = {0};
    /* ms-scale on shared cores: best of at least 4 x reps and 1 s of tries */
    int tries = 0;
    for (double start = lx_bench_now(); tries < 4 * g_reps || lx_bench_now() - start < 1.0;
         tries++) {
        lx_bake_desc desc = {.resolution = res, .threads = g_threads, .padding = LX_PADDING_NONE};
        lx_baker *b;
        double t0 = lx_bench_now();
        if (lx_baker_create(scene, &desc, &b) != LX_OK)
            lx_bench_die("lx_baker_create");
        double t1 = lx_bench_now();
        if (lx_baker_bake(b) != LX_OK)
            lx_bench_die("lx_baker_bake");
        double t2 = lx_bench_now();
        if (t2 - t0 < best)
            best = t2 - t0, best_create = t1 - t0, best_bake = t2 - t1;
        if (tries == 0 && lx_baker_apply_alloc(b, 0, &img) != LX_OK)
            lx_bench_die("lx_baker_apply_alloc");
        lx_baker_destroy(b);
    }

    float *ref = calloc(pixels * 3, sizeof(float));
    uint8_t *amb = calloc(pixels, 1);
    if (!ref || !amb)
        lx_bench_die("calloc");
    brute_result r = {.ran = true};
    double t_ref = brute_reference(scene, res, res, ref, amb, &r.used);
    uint32_t skipped, n_amb = 0;
    double max_rel;
    r.bad = count_differ(ref, img.data, amb, pixels, &skipped, &max_rel);
    for (size_t p = 0; p < pixels; p++)
        n_amb += amb[p];
    r.speedup = t_ref / best;

    char a[32], c[32];
    printf("\n  %-40s %12s %14s %12s\n", "figure", "time", "per second", "this / bake");
    printf("  %-40s %10.4f s %12stexels/s %11s  (create %.2f ms + bake %.2f ms, best of %d)\n",
           "lx_baker_create + lx_baker_bake", best, lx_bench_si(r.used / best, a), "",
           1e3 * best_create, 1e3 * best_bake, tries);
    printf("  %-40s %10.3f s %12stexels/s %11.0fx\n", "tests/common/reference.h oracle", t_ref,
           lx_bench_si(r.used / t_ref, c), r.speedup);
    printf("  agreement: %u of %u texels differ by > 1%% (max %.2g) %s; %u near-tie texels "
           "left out (%u of them differ)\n",
           r.bad, r.used, max_rel, r.bad ? "(DIFFERS)" : "(agrees)", n_amb, skipped);
    printf("\n  => bake %.0fx faster than the brute-force reference\n", r.speedup);
    free(amb);
    free(ref);
    lx_image_free(&img);
    lx_scene_destroy(scene);
    return r;
}

int main(int argc, char **argv)
{
    lx_bench_phases_child(argc, argv); /* returns unless this is the phase-timing child */
    const char *only = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--res") && i + 1 < argc)
            g_res = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--reps") && i + 1 < argc)
            g_reps = atoi(argv[++i]), g_reps_set = true;
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            g_threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--cli-res") && i + 1 < argc)
            g_cli_res = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--only") && i + 1 < argc &&
                 (!strcmp(argv[i + 1], "bake") || !strcmp(argv[i + 1], "brute") ||
                  !strcmp(argv[i + 1], "cli")))
            only = argv[++i];
        else if (!strcmp(argv[i], "--skip-raw"))
            g_skip_raw = true;
        else {
            fprintf(stderr,
                    "usage: %s [--res N] [--cli-res N] [--reps N] [--threads N] "
                    "[--only bake|brute|cli] [--skip-raw]\n",
                    argv[0]);
            return 2;
        }
    }
    if (g_reps < 1)
        g_reps = 1;
    g_threads = lx_thread_count(g_threads);
    lx_bench_header("bench_bake", g_threads);
    double t0 = lx_bench_now();
    bake_result bake = {0};
    brute_result brute = {0};
    if (!only || !strcmp(only, "bake"))
        bake = bench_full_bake();
    if (!only || !strcmp(only, "brute"))
        brute = bench_brute_force();
    cli_result cli = {0};
    if (!only || !strcmp(only, "cli"))
        cli = bench_cli();

    char a[32], load[32];
    printf("\ntotal bench time %.1f s\n", lx_bench_now() - t0);
    printf("bench_bake:");
    if (bake.ran && bake.raw)
        printf(" %dx%d bake %ssamples/s = %.2fx lx_tracer_occluded 1 ray/call (target >= 0.80x: "
               "%s), %.2fx coherent batch, %.2fx flat rtcOccluded1;",
               g_res, g_res, lx_bench_si(bake.samples_s, a), bake.vs_single,
               bake.vs_single >= 0.8 ? "MET" : "NOT MET", bake.vs_batch, bake.vs_flat1);
    else if (bake.ran)
        printf(" %dx%d bake %ssamples/s;", g_res, g_res, lx_bench_si(bake.samples_s, a));
    if (brute.ran)
        printf(" %.0fx faster than the brute-force reference (%u of %u texels differ);",
               brute.speedup, brute.bad, brute.used);
    if (cli.ran && cli.raw)
        printf(" whole luxel bake %dx%d x16 lights %ssamples/s in %.2f s = %.2fx raw "
               "rtcOccluded1 %srays/s (target >= 2x: %s; median pair %.2fx);",
               cli.res, cli.res, lx_bench_si(cli.samples_s, a), cli.wall, cli.ratio,
               lx_bench_si(cli.flat1_rays_s, load), cli.ratio >= 2.0 ? "MET" : "NOT MET",
               cli.median_ratio);
    if (cli.ran)
        printf(" EXR + PNG = %.0f%% of the bake (target <= 25%%: %s);", 100.0 * cli.writes_share,
               cli.writes_share <= 0.25 ? "MET" : "NOT MET");
    else if (cli.ran)
        printf(" whole luxel bake %dx%d x16 lights %ssamples/s in %.2f s;", cli.res, cli.res,
               lx_bench_si(cli.samples_s, a), cli.wall);
    printf(" %d threads, load %s\n", g_threads, lx_bench_load(load, sizeof load));
    return 0;
}
