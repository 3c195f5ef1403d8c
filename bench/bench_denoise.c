/* bench_denoise - the lightmap denoiser (lx_denoise, src/bake/denoise.c):
 * its speed at 1024^2 and how much it brings a noisy lightmap closer to
 * a noise-free one.
 *
 * 1. Speed. A 1024 x 1024 atlas of 64 charts (128^2 cells, 2 empty texels
 *    between charts: 94.5% of the texels valid), each a flat patch of a
 *    10 m room's walls, floor or ceiling in its own place and
 *    orientation, 1 cm texels. Baselines in the same run: a plain memory
 *    pass (out = in * 0.5 + 0.25 over the RGB floats) and a 3x3 box
 *    filter over the valid texels; the ratio of each to them.
 * 2. Quality on that atlas with known truth: a point light at the room's
 *    centre plus 2 lux of ambient (E = I cos / d^2 + 2: smooth, "indirect
 *    like"), and the same with a hard shadow edge across every chart
 *    (light blocked on one side of a plane). Monte Carlo-like noise at S
 *    samples a texel: the mean of S draws of E X, X exponential with mean
 *    1 (relative sd 1/sqrt S), the same draw for R, G and B (as rays
 *    are). RMS error over the valid texels against the truth, relative to
 *    the truth's mean: noisy, 3x3 box, denoised.
 * 3. A real bake: bench's spheres scene (a 10 m ground under 16 floating
 *    spheres) lit by a constant sky with shadows (rays: noise everywhere,
 *    soft shadows under the spheres), the ground's 256^2 lightmap at 16,
 *    64, 256, 512 and 1024 samples a texel, raw and denoised, against a
 *    reference at --ref-samples (2048). The reference has noise of its
 *    own, so the fair figure is the sample count of a raw bake that comes
 *    as close to the reference as the denoised 16-sample one.
 *
 * Usage: bench_denoise [--threads N] [--size S] [--reps R] [--ref-samples K]
 *                      [--skip-bake] [--write DIR] [--sigma-l S] [--no-luminance]
 *                      [--iterations N]
 * The last three set lx_denoise_desc fields (defaults otherwise).
 * --write DIR writes PNG pictures of the noisy, denoised and reference
 * bakes (exposed, sRGB) into DIR. The last line is a one-line summary. */
#define _POSIX_C_SOURCE 200809L
#include "core/internal.h"
#include "cube_reference.h"
#include "scenes.h"

#include "luxel/luxel.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define CELL 128

/* CPU seconds of every thread of the process: on a machine shared with
 * other work, wall time overstates what the run needs; CPU time /
 * threads is what an idle machine would take. */
static double cpu(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}
#define GAP 2

typedef struct atlas {
    int w, h;
    uint8_t *valid;
    lx_vec3 *pos, *nrm;
    uint32_t *chart;
} atlas;

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) {
        fprintf(stderr, "bench_denoise: out of memory\n");
        exit(1);
    }
    return p;
}

/* Chart k: a patch on one of the room's six faces (a 10 m cube centred
 * at the origin), at a place and in a direction drawn from lx_random. */
static void build_atlas(atlas *a, int size)
{
    a->w = a->h = size;
    size_t n = (size_t)size * size;
    a->valid = xmalloc(n);
    a->pos = xmalloc(n * sizeof(lx_vec3));
    a->nrm = xmalloc(n * sizeof(lx_vec3));
    a->chart = xmalloc(n * sizeof(uint32_t));
    memset(a->valid, 0, n);
    memset(a->pos, 0, n * sizeof(lx_vec3));
    memset(a->nrm, 0, n * sizeof(lx_vec3));
    memset(a->chart, 0, n * sizeof(uint32_t));
    const float t = 0.01f;
    int cells = size / CELL;
    for (int cy = 0; cy < cells; cy++)
        for (int cx = 0; cx < cells; cx++) {
            uint32_t k = (uint32_t)(cy * cells + cx);
            int face = (int)(lx_random(99u, k, 0, 0) * 6.0f);
            int axis = face / 2;
            float side = face % 2 ? 1.0f : -1.0f;
            /* the face's normal points into the room */
            lx_vec3 nrm = {0, 0, 0}, u = {0, 0, 0}, v = {0, 0, 0};
            float *pn = &nrm.x, *pu = &u.x, *pv = &v.x;
            pn[axis] = -side;
            pu[(axis + 1) % 3] = 1.0f;
            pv[(axis + 2) % 3] = 1.0f;
            float ou = -4.0f + 6.5f * lx_random(99u, k, 1, 0);
            float ov = -4.0f + 6.5f * lx_random(99u, k, 2, 0);
            lx_vec3 origin = lx_add(lx_scale(nrm, -5.0f), lx_add(lx_scale(u, ou), lx_scale(v, ov)));
            for (int y = GAP; y < CELL - GAP; y++)
                for (int x = GAP; x < CELL - GAP; x++) {
                    size_t p = (size_t)(cy * CELL + y) * size + (size_t)(cx * CELL + x);
                    a->valid[p] = 1;
                    a->pos[p] = lx_add(origin, lx_add(lx_scale(u, (float)x * t),
                                                      lx_scale(v, (float)y * t)));
                    a->nrm[p] = nrm;
                    a->chart[p] = k;
                }
        }
}

static lx_denoise_guides guides_of(const atlas *a)
{
    lx_denoise_guides g = {.width = a->w,
                           .height = a->h,
                           .valid = a->valid,
                           .position = a->pos,
                           .normal = a->nrm,
                           .chart = a->chart};
    return g;
}

/* The truth: a 400 cd point light at (0.5, 1, -0.3) plus 2 lux ambient;
 * with `edge`, the light is blocked where x + 0.3 z < 0.7 (a hard
 * shadow line across the room). */
static void truth(const atlas *a, bool edge, float *out)
{
    static const float tint[3] = {1.0f, 0.9f, 0.8f};
    lx_vec3 light = lx_v3(0.5f, 1.0f, -0.3f);
    for (size_t p = 0; p < (size_t)a->w * a->h; p++) {
        float e = 0.0f;
        if (a->valid[p]) {
            lx_vec3 d = lx_sub(light, a->pos[p]);
            float d2 = lx_dot(d, d);
            float c = lx_dot(a->nrm[p], d) / sqrtf(d2);
            e = 2.0f + (c > 0.0f ? 400.0f * c / d2 : 0.0f);
            if (edge && a->pos[p].x + 0.3f * a->pos[p].z < 0.7f)
                e = 2.0f;
        }
        for (int ch = 0; ch < 3; ch++)
            out[3 * p + ch] = e * tint[ch];
    }
}

/* The mean of S exponential draws of mean 1, times the truth. */
static void add_noise(const atlas *a, const float *clean, int samples, uint32_t seed, float *out)
{
#pragma omp parallel for schedule(static)
    for (int y = 0; y < a->h; y++)
        for (int x = 0; x < a->w; x++) {
            size_t p = (size_t)y * a->w + x;
            double s = 0.0;
            for (int k = 0; k < samples; k++)
                s += -log(1.0 - (double)lx_random(seed, (uint32_t)p, (uint32_t)k, 0));
            float m = (float)(s / samples);
            for (int ch = 0; ch < 3; ch++)
                out[3 * p + ch] = clean[3 * p + ch] * m;
        }
}

/* 3x3 mean of the valid texels (channels 3). */
static void box3(const uint8_t *valid, int w, int h, const float *in, float *out, int threads)
{
#pragma omp parallel for schedule(static) num_threads(threads)
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t p = (size_t)y * w + x;
            if (!valid[p]) {
                out[3 * p] = in[3 * p];
                out[3 * p + 1] = in[3 * p + 1];
                out[3 * p + 2] = in[3 * p + 2];
                continue;
            }
            float s[3] = {0, 0, 0};
            int n = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int qx = x + dx, qy = y + dy;
                    if (qx < 0 || qy < 0 || qx >= w || qy >= h)
                        continue;
                    size_t q = (size_t)qy * w + qx;
                    if (!valid[q])
                        continue;
                    for (int c = 0; c < 3; c++)
                        s[c] += in[3 * q + c];
                    n++;
                }
            for (int c = 0; c < 3; c++)
                out[3 * p + c] = s[c] / (float)n;
        }
}

/* RMS of (got - want) over valid texels, all channels, relative to the
 * mean of want. */
static double rel_rms(const uint8_t *valid, size_t n, const float *got, const float *want)
{
    double e2 = 0.0, m = 0.0;
    size_t count = 0;
    for (size_t p = 0; p < n; p++) {
        if (!valid[p])
            continue;
        for (int c = 0; c < 3; c++) {
            double d = (double)got[3 * p + c] - want[3 * p + c];
            e2 += d * d;
            m += want[3 * p + c];
        }
        count += 3;
    }
    return sqrt(e2 / count) / (m / count);
}

static lx_denoise_desc options; /* --sigma-l, --no-luminance, --iterations */

static void denoise_or_die(const lx_denoise_guides *g, const float *in, float *out, int threads)
{
    lx_denoise_desc d = options;
    d.threads = threads;
    if (lx_denoise(g, in, out, &d) != LX_OK)
        lx_bench_die("lx_denoise");
}

/* ---- 3: a real bake ----------------------------------------------------------- */

static void constant_sky(double x, double y, double z, float out[3])
{
    (void)x, (void)y, (void)z;
    out[0] = out[1] = out[2] = 1000.0f; /* nits: 3142 lux unshadowed */
}

static void bake_ground(int samples, int threads, lx_image *out, lx_denoise_guides *g)
{
    lx_test_scene_info info;
    lx_scene *scene = lx_test_spheres_scene("denoise", 10.0f, 8, 4, 24, 12, false, &info);
    scene->light_count = 0; /* the sky alone */
    lx_cubemap env = lx_test_make_env(16, constant_sky);
    lx_bake_desc d = {.resolution = 256, .threads = threads};
    d.sky.environment = &env;
    d.sky.shadows = true;
    d.sky.samples = (uint32_t)samples;
    lx_baker *b;
    if (lx_baker_create(scene, &d, &b) != LX_OK)
        lx_bench_die("lx_baker_create");
    lx_scene_destroy(scene);
    lx_cubemap_free(&env);
    uint32_t map;
    float so[4];
    if (!lx_baker_node_lightmap(b, 0, &map, so))
        lx_bench_die("the ground has no lightmap");
    if (lx_baker_bake(b) != LX_OK || lx_baker_apply_alloc(b, map, out) != LX_OK)
        lx_bench_die("bake");
    if (g && lx_baker_denoise_guides(b, map, g) != LX_OK)
        lx_bench_die("lx_baker_denoise_guides");
    lx_baker_destroy(b);
}

static void write_png(const char *dir, const char *name, const lx_image *img, float exposure)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    lx_image_write_desc wd = {.exposure = exposure};
    if (lx_image_write(path, img, &wd) != LX_OK)
        lx_bench_die("lx_image_write");
}

int main(int argc, char **argv)
{
    int threads = 2, size = 1024, reps = 3, ref_samples = 2048;
    bool skip_bake = false;
    const char *write_dir = NULL;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            threads = atoi(argv[++i]);
        else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc)
            size = atoi(argv[++i]);
        else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc)
            reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--ref-samples") == 0 && i + 1 < argc)
            ref_samples = atoi(argv[++i]);
        else if (strcmp(argv[i], "--sigma-l") == 0 && i + 1 < argc)
            options.luminance_sigma = (float)atof(argv[++i]);
        else if (strcmp(argv[i], "--iterations") == 0 && i + 1 < argc)
            options.iterations = atoi(argv[++i]);
        else if (strcmp(argv[i], "--no-luminance") == 0)
            options.ignore_luminance = true;
        else if (strcmp(argv[i], "--skip-bake") == 0)
            skip_bake = true;
        else if (strcmp(argv[i], "--write") == 0 && i + 1 < argc)
            write_dir = argv[++i];
        else {
            fprintf(stderr, "usage: bench_denoise [--threads N] [--size S] [--reps R] "
                            "[--ref-samples K] [--skip-bake] [--write DIR] [--sigma-l S] "
                            "[--no-luminance] [--iterations N]\n");
            return 2;
        }
    }
    if (threads < 1 || size < CELL || size % CELL || reps < 1 || ref_samples < 16) {
        fprintf(stderr, "bench_denoise: bad arguments (size a multiple of %d)\n", CELL);
        return 2;
    }
    lx_bench_header("bench_denoise", threads);
    atlas a;
    build_atlas(&a, size);
    size_t n = (size_t)size * size;
    size_t valid = 0;
    for (size_t p = 0; p < n; p++)
        valid += a.valid[p] != 0;
    lx_denoise_guides g = guides_of(&a);
    float *clean = xmalloc(3 * n * sizeof(float)), *noisy = xmalloc(3 * n * sizeof(float));
    float *out = xmalloc(3 * n * sizeof(float)), *box = xmalloc(3 * n * sizeof(float));

    /* 1. speed */
    truth(&a, false, clean);
    add_noise(&a, clean, 16, 1u, noisy);
    /* best of the runs, wall and CPU seconds */
    double t_mem = 1e30, t_box = 1e30, t_dn = 1e30, c_mem = 1e30, c_box = 1e30, c_dn = 1e30;
    for (int r = 0; r < reps * 5; r++) {
        double t0 = lx_bench_now(), c0 = cpu();
#pragma omp parallel for schedule(static) num_threads(threads)
        for (long i = 0; i < (long)(3 * n); i++)
            out[i] = noisy[i] * 0.5f + 0.25f;
        double t = lx_bench_now() - t0, c = cpu() - c0;
        t_mem = t < t_mem ? t : t_mem;
        c_mem = c < c_mem ? c : c_mem;
        t0 = lx_bench_now(), c0 = cpu();
        box3(a.valid, size, size, noisy, box, threads);
        t = lx_bench_now() - t0, c = cpu() - c0;
        t_box = t < t_box ? t : t_box;
        c_box = c < c_box ? c : c_box;
    }
    for (int r = 0; r < reps; r++) {
        double t0 = lx_bench_now(), c0 = cpu();
        denoise_or_die(&g, noisy, out, threads);
        double t = lx_bench_now() - t0, c = cpu() - c0;
        t_dn = t < t_dn ? t : t_dn;
        c_dn = c < c_dn ? c : c_dn;
    }
    double mt = (double)n / 1e6;
    printf("speed: %dx%d atlas, 64 charts, %.1f%% valid, 5 passes, %d threads (best of %d)\n",
           size, size, 100.0 * (double)valid / (double)n, threads, reps);
    printf("                          wall        CPU  CPU/thread  Mtexel/s (by CPU/thread)\n");
    printf("  memory pass (baseline)  %8.4f s %8.4f s %8.4f s %8.1f\n", t_mem, c_mem,
           c_mem / threads, mt * threads / c_mem);
    printf("  3x3 box (baseline)      %8.4f s %8.4f s %8.4f s %8.1f\n", t_box, c_box,
           c_box / threads, mt * threads / c_box);
    printf("  lx_denoise              %8.4f s %8.4f s %8.4f s %8.1f\n", t_dn, c_dn,
           c_dn / threads, mt * threads / c_dn);
    printf("  lx_denoise / memory pass %.0fx (CPU %.0fx), / 3x3 box %.1fx (CPU %.1fx)\n",
           t_dn / t_mem, c_dn / c_mem, t_dn / t_box, c_dn / c_box);

    /* 2. quality against the truth */
    printf("quality: relative RMS error against the truth (valid texels)\n");
    printf("  %-12s %7s %9s %9s %9s %8s %8s\n", "signal", "samples", "noisy", "3x3 box",
           "denoised", "gain", "box gain");
    double gain16 = 0.0;
    for (int edge = 0; edge < 2; edge++) {
        truth(&a, edge, clean);
        static const int spp[3] = {4, 16, 64};
        for (int s = 0; s < 3; s++) {
            add_noise(&a, clean, spp[s], 2u + (uint32_t)s, noisy);
            box3(a.valid, size, size, noisy, box, threads);
            denoise_or_die(&g, noisy, out, threads);
            double e_n = rel_rms(a.valid, n, noisy, clean), e_b = rel_rms(a.valid, n, box, clean),
                   e_d = rel_rms(a.valid, n, out, clean);
            printf("  %-12s %7d %8.2f%% %8.2f%% %8.2f%% %7.1fx %7.1fx\n",
                   edge ? "shadow edge" : "smooth", spp[s], 100.0 * e_n, 100.0 * e_b,
                   100.0 * e_d, e_n / e_d, e_n / e_b);
            if (!edge && spp[s] == 16)
                gain16 = e_n / e_d;
        }
    }

    /* 3. a real bake: raw bakes at several sample counts and denoised
     * ones, each against the reference */
    double bake_gain = 0.0, equivalent = 0.0;
    if (!skip_bake) {
        lx_image ref;
        double t0 = lx_bench_now();
        bake_ground(ref_samples, threads, &ref, NULL);
        double t_ref = lx_bench_now() - t0;
        size_t bn = (size_t)ref.width * ref.height;
        printf("real bake: ground %dx%d under 16 spheres, constant sky with shadows; reference "
               "%d samples (%.1f s)\n",
               ref.width, ref.height, ref_samples, t_ref);
        printf("  %7s %9s %9s %9s %8s\n", "samples", "bake", "raw", "denoised", "gain");
        static const int spp[5] = {16, 64, 256, 512, 1024};
        double raw[5] = {0}, den[5] = {0};
        for (int s = 0; s < 5 && spp[s] < ref_samples; s++) {
            lx_image lo, dn;
            lx_denoise_guides bg;
            t0 = lx_bench_now();
            bake_ground(spp[s], threads, &lo, &bg);
            double t_lo = lx_bench_now() - t0;
            if (lx_image_alloc(&dn, lo.width, lo.height, 3) != LX_OK)
                lx_bench_die("lx_image_alloc");
            denoise_or_die(&bg, lo.data, dn.data, threads);
            raw[s] = rel_rms(bg.valid, bn, lo.data, ref.data);
            den[s] = rel_rms(bg.valid, bn, dn.data, ref.data);
            printf("  %7d %7.2f s %8.2f%% %8.2f%% %7.1fx\n", spp[s], t_lo, 100.0 * raw[s],
                   100.0 * den[s], raw[s] / den[s]);
            if (s == 0 && write_dir) {
                /* exposure: the reference's mean to 0.4 */
                double m = 0.0;
                for (size_t i = 0; i < 3 * bn; i++)
                    m += ref.data[i];
                float ex = (float)(0.4 / (m / (3.0 * (double)bn)));
                write_png(write_dir, "bake_16spp.png", &lo, ex);
                write_png(write_dir, "bake_16spp_denoised.png", &dn, ex);
                write_png(write_dir, "bake_reference.png", &ref, ex);
            }
            lx_image_free(&lo);
            lx_image_free(&dn);
            lx_denoise_guides_free(&bg);
        }
        bake_gain = raw[0] / den[0];
        /* the raw sample count as close to the reference as 16 denoised */
        for (int s = 0; s < 5 && raw[s] > 0.0; s++)
            if (raw[s] >= den[0])
                equivalent = spp[s];
        printf("  16 samples denoised are as close to the reference as %s%.0f raw samples\n",
               equivalent == spp[4] ? "more than " : "", equivalent);
        lx_image_free(&ref);
    }
    printf("summary: denoise %dx%d %.3f s wall, %.3f s CPU / %d threads, %.0fx a memory pass, "
           "%.1fx a 3x3 box (CPU); RMS error /%.1f (smooth, 16 samples)",
           size, size, t_dn, c_dn / threads, threads, c_dn / c_mem, c_dn / c_box, gain16);
    if (!skip_bake)
        printf(", real bake at 16 samples /%.1f (closer than %.0f raw samples)", bake_gain,
               equivalent);
    printf("\n");
    free(clean);
    free(noisy);
    free(out);
    free(box);
    free(a.valid);
    free(a.pos);
    free(a.nrm);
    free(a.chart);
    return 0;
}
