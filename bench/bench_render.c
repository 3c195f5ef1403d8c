/* bench_render - frames per second of lx_render_view at 1280x720 (4
 * stratified samples a pixel, bilinear lightmaps) on the room demo scene
 * (examples/gen_scenes.c, baked here at 256x256 a node), against its
 * baseline measured in the same run: the same primary rays (same jitter,
 * same 16x16 tiles, OpenMP schedule and threads) straight through Embree's
 * rtcIntersect1 on one flat BVH built here, with no shading. The ratio
 * says what the lookups, culling and lx_tracer wrapper cost on top of the
 * rays themselves; the same frames two-sided show the culling's share (a
 * ray through a back face is traced again past it). Best and median of
 * --reps frames each.
 *
 * Usage: bench_render [--threads N] [--reps N] [--samples N] [--scene FILE.glb]
 * Without --scene, gen_scenes (beside this program) writes the room to a
 * temporary folder. */
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

#define W 1280
#define H 720
#define TILE 16


/* The bake's lightmaps as lx_lightmaps, without files. */
static void bake(const lx_scene *scene, int threads, lx_lightmaps *lm)
{
    lx_bake_desc bd = lx_bake_desc_defaults(NULL);
    bd.resolution = 256;
    bd.padding = LX_PADDING_RECOMMENDED;
    bd.threads = threads;
    lx_baker *b;
    if (lx_baker_create(scene, &bd, &b) != LX_OK || lx_baker_bake(b) != LX_OK)
        lx_bench_die("bake");
    memset(lm, 0, sizeof *lm);
    lm->dir = lx_strdup("(in memory)");
    lm->pre_exposure = 1.0f;
    lm->padding = -1;
    lm->page_count = lx_baker_lightmap_count(b);
    lm->pages = calloc(lm->page_count, sizeof *lm->pages);
    lm->nodes = calloc(scene->node_count, sizeof *lm->nodes);
    for (uint32_t p = 0; p < lm->page_count; p++) {
        if (lx_baker_apply_alloc(b, p, &lm->pages[p].image) != LX_OK)
            lx_bench_die("apply");
        lm->pages[p].width = lm->pages[p].image.width;
        lm->pages[p].height = lm->pages[p].image.height;
        lm->pages[p].file = lx_strdup("page");
    }
    for (uint32_t n = 0; n < scene->node_count; n++) {
        lx_lightmap_node *ln = &lm->nodes[lm->node_count];
        if (!lx_baker_node_lightmap(b, n, &ln->page, ln->scale_offset))
            continue;
        ln->name = lx_strdup(scene->nodes[n].name);
        ln->mesh_count = scene->nodes[n].mesh_count;
        ln->uv_set = lx_bake_uv_set(scene, n, LX_UV_SET_AUTO);
        lm->node_count++;
    }
    lx_baker_destroy(b);
}

/* The renderer's primary rays through rtcIntersect1; returns seconds and
 * the hits in *hits. */
static double raw_frame(RTCScene flat, const lx_camera *cam, int samples, int threads,
                        uint64_t *hits)
{
    lx_vec3 f = lx_normalize(lx_sub(cam->target, cam->eye));
    lx_vec3 r = lx_normalize(lx_cross(f, cam->up));
    lx_vec3 u = lx_cross(r, f);
    float ty = tanf(0.5f * cam->fov), tx = ty * (float)W / (float)H;
    int sx = (int)floorf(sqrtf((float)samples));
    while (samples % sx)
        sx--;
    int sy = samples / sx;
    int tiles_x = (W + TILE - 1) / TILE, tiles = tiles_x * ((H + TILE - 1) / TILE);
    uint64_t total = 0;
    double t0 = lx_bench_now();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) reduction(+ : total)
    for (int t = 0; t < tiles; t++) {
        int x0 = (t % tiles_x) * TILE, y0 = (t / tiles_x) * TILE;
        for (int y = y0; y < y0 + TILE && y < H; y++)
            for (int x = x0; x < x0 + TILE && x < W; x++) {
                uint32_t pixel = (uint32_t)y * W + (uint32_t)x;
                for (int s = 0; s < samples; s++) {
                    float jx = ((float)(s % sx) + lx_random(0, pixel, (uint32_t)s, 0)) / (float)sx;
                    float jy = ((float)(s / sx) + lx_random(0, pixel, (uint32_t)s, 1)) / (float)sy;
                    float px = (2.0f * ((float)x + jx) / W - 1.0f) * tx;
                    float py = (1.0f - 2.0f * ((float)y + jy) / H) * ty;
                    lx_vec3 d = lx_normalize(lx_add(f, lx_add(lx_scale(r, px), lx_scale(u, py))));
                    struct RTCIntersectContext ctx;
                    rtcInitIntersectContext(&ctx);
                    struct RTCRayHit rh = {0};
                    rh.ray.org_x = cam->eye.x, rh.ray.org_y = cam->eye.y, rh.ray.org_z = cam->eye.z;
                    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
                    rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.mask = 0xFFFFFFFFu;
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(flat, &ctx, &rh);
                    total += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                }
            }
    }
    *hits = total;
    return lx_bench_now() - t0;
}

int main(int argc, char **argv)
{
    int threads = 0, reps = 5, samples = 4;
    const char *scene_path = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--reps") && i + 1 < argc)
            reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc)
            samples = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--scene") && i + 1 < argc)
            scene_path = argv[++i];
        else {
            fprintf(stderr, "usage: %s [--threads N] [--reps N] [--samples N] [--scene FILE.glb]\n",
                    argv[0]);
            return 2;
        }
    }
    if (reps < 1 || reps > 100 || samples < 1 || samples > 64) {
        fprintf(stderr, "bench_render: --reps 1..100, --samples 1..64\n");
        return 2;
    }
    threads = lx_thread_count(threads);
    lx_bench_header("bench_render", threads);
    lx_scene *scene = lx_bench_load_room("bench_render", &scene_path);
    uint32_t triangles = 0;
    for (uint32_t n = 0; n < scene->node_count; n++)
        for (uint32_t k = 0; k < scene->nodes[n].mesh_count; k++)
            triangles += scene->meshes[scene->nodes[n].meshes[k]].triangle_count;
    lx_lightmaps lm;
    bake(scene, threads, &lm);
    lx_tracer_desc td = {.threads = threads};
    lx_tracer *tracer;
    if (lx_tracer_create(scene, &td, &tracer) != LX_OK)
        lx_bench_die("tracer");
    RTCDevice dev = rtcNewDevice(NULL);
    RTCScene flat = lx_bench_flat_scene(dev, scene);
    lx_vec3 lo, hi;
    lx_scene_bounds(scene, &lo, &hi);
    lx_render_desc d = lx_render_desc_defaults(NULL);
    d.width = W, d.height = H, d.samples = samples, d.threads = threads;
    d.camera = lx_camera_frame(lo, hi, LX_VIEW_ISO, 0.0f, (float)W / H);

    double *tr = calloc((size_t)reps, sizeof *tr), *tw = calloc((size_t)reps, sizeof *tw);
    double *t2 = calloc((size_t)reps, sizeof *t2);
    lx_render_desc d2 = d;
    d2.two_sided = true;
    uint64_t hits = 0;
    lx_image img;
    /* warm both up, then alternate so load changes hit both alike */
    if (lx_render_view(scene, &lm, tracer, &d, &img) != LX_OK)
        lx_bench_die("render");
    lx_image_free(&img);
    raw_frame(flat, &d.camera, samples, threads, &hits);
    for (int k = 0; k < reps; k++) {
        double t0 = lx_bench_now();
        if (lx_render_view(scene, &lm, tracer, &d, &img) != LX_OK)
            lx_bench_die("render");
        tr[k] = lx_bench_now() - t0;
        lx_image_free(&img);
        t0 = lx_bench_now();
        if (lx_render_view(scene, &lm, tracer, &d2, &img) != LX_OK)
            lx_bench_die("render");
        t2[k] = lx_bench_now() - t0;
        lx_image_free(&img);
        tw[k] = raw_frame(flat, &d.camera, samples, threads, &hits);
    }
    qsort(tr, (size_t)reps, sizeof *tr, lx_bench_cmp_double);
    qsort(tw, (size_t)reps, sizeof *tw, lx_bench_cmp_double);
    qsort(t2, (size_t)reps, sizeof *t2, lx_bench_cmp_double);
    double rays = (double)W * H * samples;
    char a[32], b[32];
    printf("\nRENDER  %s, %dx%d, %d samples a pixel, %u triangles' scene, %d threads, %d frames\n",
           scene_path, W, H, samples, triangles, threads, reps);
    printf("  %-34s %8s %8s %12s\n", "", "best", "median", "rays/s best");
    printf("  %-34s %7.2f/s %7.2f/s %12s\n", "lx_render_view (frames/s)", 1.0 / tr[0],
           1.0 / tr[reps / 2], lx_bench_si(rays / tr[0], a));
    printf("  %-34s %7.2f/s %7.2f/s %12s\n", "  the same, two-sided (no culling)", 1.0 / t2[0],
           1.0 / t2[reps / 2], lx_bench_si(rays / t2[0], a));
    printf("  %-34s %7.2f/s %7.2f/s %12s\n", "raw rtcIntersect1, same rays", 1.0 / tw[0],
           1.0 / tw[reps / 2], lx_bench_si(rays / tw[0], b));
    printf("  %.1f%% of the primary rays hit the scene\n", 100.0 * (double)hits / rays);
    printf("render: %.2f frames/s at %dx%d (%d spp), %.2fx the time of raw rtcIntersect1 on the "
           "same rays (best; median %.2fx)\n",
           1.0 / tr[0], W, H, samples, tr[0] / tw[0], tr[reps / 2] / tw[reps / 2]);
    printf("  (two-sided %.2fx: culled back faces cost a second ray each)\n", t2[0] / tw[0]);
    free(tr);
    free(tw);
    free(t2);
    rtcReleaseScene(flat);
    rtcReleaseDevice(dev);
    lx_tracer_destroy(tracer);
    lx_lightmaps_free(&lm);
    lx_scene_destroy(scene);
    return 0;
}
