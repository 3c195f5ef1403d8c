/* Benchmark of 2D shadowed lights (issue 11): a 1280x720 caster image
 * with a normal map, 16 dynamic soft point lights of radius 400 px moving
 * every frame, rendered through the per-frame API (lx_light2d_set_lights +
 * lx_light2d_render), against the exact reference measured in the same run:
 * every lit pixel marches the segment to every light through the caster
 * mask (the visibility the tests check against), timed on a slice of rows
 * and scaled to a frame.
 *
 * usage: bench_light2d [--threads N] [--seconds S] [--frames N]
 * (at least N frames, default 10, and at least S seconds, default 3) */
#include "luxel/light2d.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define W 1280
#define H 720
#define LIGHTS 16

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static uint32_t seed = 2024u;
static uint32_t rnd(void)
{
    seed = seed * 1664525u + 1013904223u;
    return seed >> 8;
}

/* crates and pillars over a floor, as a 2D game level has */
static void make_scene(lx_image *casters, lx_image *normals)
{
    lx_image_alloc(casters, W, H, 4);
    lx_image_alloc(normals, W, H, 3);
    for (int i = 0; i < W * H; i++) {
        normals->data[3 * i] = 0.5f;
        normals->data[3 * i + 1] = 0.5f;
        normals->data[3 * i + 2] = 1.0f;
    }
    for (int k = 0; k < 140; k++) {
        int cx = (int)(rnd() % W), cy = (int)(rnd() % H), s = 8 + (int)(rnd() % 28);
        bool round = rnd() % 2;
        for (int y = cy - s; y <= cy + s; y++)
            for (int x = cx - s; x <= cx + s; x++) {
                if (x < 0 || y < 0 || x >= W || y >= H)
                    continue;
                float dx = (float)(x - cx) / s, dy = (float)(y - cy) / s;
                if (round && dx * dx + dy * dy > 1.0f)
                    continue;
                casters->data[(y * W + x) * 4 + 3] = 1.0f;
                if (round) {
                    float nz = sqrtf(fmaxf(0.0f, 1.0f - dx * dx - dy * dy));
                    normals->data[3 * (y * W + x)] = 0.5f + 0.5f * dx;
                    normals->data[3 * (y * W + x) + 1] = 0.5f - 0.5f * dy;
                    normals->data[3 * (y * W + x) + 2] = 0.5f + 0.5f * nz;
                }
            }
    }
}

static void place_lights(lx_light2d_light *ls, int frame)
{
    for (int i = 0; i < LIGHTS; i++) {
        lx_light2d_light l = lx_light2d_light_defaults(LX_LIGHT2D_POINT);
        float t = 0.02f * frame + i;
        l.x = W * (0.5f + 0.42f * sinf(1.3f * t + i));
        l.y = H * (0.5f + 0.42f * cosf(0.7f * t + 2.0f * i));
        l.radius = 400.0f;
        l.softness = getenv("L2_SOFT") ? (float)atof(getenv("L2_SOFT")) : 6.0f;
        l.height = 60.0f;
        l.dynamic = true;
        l.color = lx_v3(0.3f + 0.05f * (i % 4), 0.3f, 0.35f - 0.05f * (i % 3));
        ls[i] = l;
    }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

static bool caster(const lx_image *c, int x, int y)
{
    return x >= 0 && y >= 0 && x < W && y < H && c->data[(y * W + x) * 4 + 3] >= 0.5f;
}

/* The reference: march each pixel-to-light segment in half-pixel steps. */
static double reference_rows(const lx_image *c, const lx_light2d_light *ls, int y0, int step)
{
    double sum = 0.0;
    for (int y = y0; y < H; y += step)
        for (int x = 0; x < W; x++)
            for (int i = 0; i < LIGHTS; i++) {
                double dx = x + 0.5 - ls[i].x, dy = y + 0.5 - ls[i].y;
                double d = sqrt(dx * dx + dy * dy);
                if (d >= ls[i].radius)
                    continue;
                int n = (int)(d * 2.0) + 1;
                bool lit = true;
                for (int k = 1; k < n && lit; k++) {
                    double t = (double)k / n;
                    lit = !caster(c, (int)floor(ls[i].x + t * dx), (int)floor(ls[i].y + t * dy));
                }
                double q = 1.0 - d * d / (ls[i].radius * ls[i].radius);
                sum += lit ? q * q : 0.0;
            }
    return sum;
}

int main(int argc, char **argv)
{
    int threads = 2;
    double seconds = 3.0;
    int min_frames = 10;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--threads") == 0)
            threads = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--seconds") == 0)
            seconds = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--frames") == 0)
            min_frames = atoi(argv[i + 1]);
    }
    lx_image casters, normals;
    make_scene(&casters, &normals);
    lx_light2d_desc d = {.threads = threads};
    lx_light2d *ctx = NULL;
    if (lx_light2d_create(&casters, &d, &ctx) != LX_OK ||
        lx_light2d_set_normals(ctx, &normals, false) != LX_OK) {
        fprintf(stderr, "bench_light2d: %s\n", lx_last_error());
        return 1;
    }
    float *out = malloc((size_t)W * H * 3 * sizeof *out);
    lx_light2d_light ls[LIGHTS];
    int frames = 0, cap = 1 << 16;
    /* each frame's time: on a shared machine the fastest frames and the
     * median say more than the mean */
    double *ft = malloc((size_t)cap * sizeof *ft);
    double t0 = now(), t = t0;
    while ((t - t0 < seconds || frames < min_frames) && frames < cap) {
        place_lights(ls, frames);
        if (lx_light2d_set_lights(ctx, ls, LIGHTS) != LX_OK ||
            lx_light2d_render(ctx, lx_v3(0.02f, 0.02f, 0.03f), NULL, out, NULL) != LX_OK) {
            fprintf(stderr, "bench_light2d: %s\n", lx_last_error());
            return 1;
        }
        double t1 = now();
        ft[frames++] = t1 - t;
        t = t1;
    }
    qsort(ft, (size_t)frames, sizeof *ft, cmp_double);
    double fps = frames / (t - t0);
    /* the reference on every 24th row (one thread), scaled to a frame */
    place_lights(ls, 0);
    int step = 24;
    double r0 = now();
    volatile double sink = getenv("L2_NOREF") ? 0.0 : reference_rows(&casters, ls, 0, step);
    (void)sink;
    double ref_frame = (now() - r0) * step;
    double ref_fps = 1.0 / ref_frame;
    printf("bench_light2d: %dx%d, %d dynamic soft point lights (radius 400 px, softness 6, "
           "normal map), %d threads\n",
           W, H, LIGHTS, threads);
    printf("  per-frame API:             %8.1f frames/s (%.2f ms a frame, %d frames)\n", fps,
           1000.0 / fps, frames);
    printf("  frame times:               fastest %.2f ms (%.1f frames/s), median %.2f ms\n",
           1000.0 * ft[0], 1.0 / ft[0], 1000.0 * ft[frames / 2]);
    printf("  ray-marching reference:    %8.3f frames/s (%.0f ms a frame, 1 thread, hard "
           "shadows)\n",
           ref_fps, 1000.0 * ref_frame);
    printf("  ratio:                     %8.0fx (per thread: %.0fx)\n", fps / ref_fps,
           fps / ref_fps / threads);
    printf("  target: >= 60 frames/s (aim 240): %s\n", fps >= 60.0 ? "met" : "NOT met");
    free(out);
    free(ft);
    lx_light2d_destroy(ctx);
    lx_image_free(&casters);
    lx_image_free(&normals);
    return 0;
}
