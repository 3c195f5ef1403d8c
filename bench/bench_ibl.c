/* bench_ibl - the IBL filters' speed, each figure with
 * a baseline measured in the same run on the same synthetic environment (a
 * sky gradient, a textured ground, a sun of 0.5 degrees radius at 2e4
 * nits):
 *
 *  1. lx_sh_project of a 6x512^2 cube map (target < 20 ms), against the
 *     memory-bandwidth floor: one pass summing the cube in double with the
 *     same threads.
 *  2. lx_irradiance_brute of a 6x32^2 source into 6x32^2 (threads), against
 *     the seed's loop as written (every output texel x every source texel,
 *     centre directions, approximate solid angle x cosine, float sums),
 *     single thread; and their agreement.
 *  3. lx_prefilter GGX of a 6x256^2 cube with its full mip chain (9 levels,
 *     the default 256 samples' budget; target < 1 s), against a
 *     straightforward single-thread brute-force convolution of one low
 *     level (8x8 faces, roughness 5/8) over every source texel; their
 *     agreement on that level. Then every GGX level against the same brute
 *     force (all texels of levels up to 16x16, a 16x16 grid per face
 *     above, and the 9x9 texels around the sun's), on all threads. The
 *     Phong chain is timed the same way against a brute-force Phong
 *     level.
 *  4. The whole `luxel ibl sky.pfm --layout ktx` process on gen_scenes'
 *     1024x512 HDR sky (256^2 faces, 9 GGX levels, brute irradiance, SH,
 *     the 128^2 DFG table; target < 0.7 s wall on 2 cores), against the
 *     same library calls made in this process (load, SH, irradiance,
 *     prefilter, seam fix, DFG table, the KTX and EXR files): the ratio is
 *     what the process adds (start-up, staging, publishing). With
 *     --threads 1 its CPU use must be ~100%.
 *
 * Usage: bench_ibl [--reps N] [--threads N] [--only-cli] (--only-cli: section 4 alone)
 * The last line is a one-line summary.
 */
#define _POSIX_C_SOURCE 200809L
#include "helpers.h"
#include "core/internal.h"
#include "scenes.h"

#include "luxel/ibl.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

static int g_threads, g_reps = 3;

static lx_vec3 sun_dir(void)
{
    return lx_normalize(lx_v3(0.35f, 0.6f, -0.72f));
}

/* The synthetic environment, radiance in nits at unit direction d. */
static void sky(lx_vec3 d, float out[3])
{
    float up = d.y > 0.0f ? d.y : 0.0f;
    float r = 0.3f + 0.5f * (1.0f - up), g = 0.5f + 0.4f * (1.0f - up), b = 1.2f - 0.3f * up;
    if (d.y < 0.0f) { /* a checkered ground */
        float u = d.x / (0.05f - d.y), v = d.z / (0.05f - d.y);
        float c = ((int)floorf(4.0f * u) + (int)floorf(4.0f * v)) & 1 ? 0.35f : 0.15f;
        r = c, g = 0.8f * c, b = 0.6f * c;
    }
    if (lx_dot(d, sun_dir()) > cosf(0.5f * (float)LX_PI / 180.0f))
        r = g = b = 2e4f;
    out[0] = r, out[1] = g, out[2] = b;
}

static lx_cubemap make_env(int size)
{
    lx_cubemap c;
    if (lx_cubemap_alloc(&c, size) != LX_OK)
        lx_bench_die("lx_cubemap_alloc");
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < size; y++)
            for (int x = 0; x < size; x++)
                sky(lx_cube_direction(f, (x + 0.5f) / size, (y + 0.5f) / size),
                    lx_cubemap_texel(&c, f, x, y));
    return c;
}

/* Best time of fn over at least min_reps runs and min_seconds. */
typedef void (*bench_fn)(void *);
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
    if (runs)
        *runs = n;
    return best;
}

/* ---- [1] SH projection ------------------------------------------------- */

typedef struct sh_job {
    const lx_cubemap *env;
    lx_sh9 sh;
    double sum;
} sh_job;

static void run_sh(void *p)
{
    sh_job *j = p;
    if (lx_sh_project(j->env, NULL, &j->sh) != LX_OK)
        lx_bench_die("lx_sh_project");
}

/* The floor: read every float once, rows summed in double by the same
 * threads (what any projection must at least do). */
static void run_sum(void *p)
{
    sh_job *j = p;
    int n = j->env->size, rows = 6 * n;
    double total = 0.0;
#pragma omp parallel for schedule(static) num_threads(g_threads) reduction(+ : total)
    for (int r = 0; r < rows; r++) {
        const float *q = j->env->data + (size_t)r * n * 3;
        double s = 0.0;
        for (int i = 0; i < 3 * n; i++)
            s += q[i];
        total += s;
    }
    j->sum = total;
}

/* ---- [2] brute-force irradiance ------------------------------------------ */

typedef struct irr_job {
    const lx_cubemap *env;
    lx_cubemap out;
    float *seed_out;
} irr_job;

static void run_irr(void *p)
{
    irr_job *j = p;
    lx_cubemap_free(&j->out);
    lx_ibl_desc d = {.threads = g_threads};
    if (lx_irradiance_brute(j->env, 32, 32, &d, &j->out) != LX_OK)
        lx_bench_die("lx_irradiance_brute");
}

/* Wikibooks' computeFilteredCubemap (Cg Programming/Unity/Many Light
 * Sources) as written, one thread: for every
 * output texel, every source texel as a directional light along its
 * centre d (on the cube of half-size 0.5), weighted by
 * (1 / |d|^2) (face normal . d^) max(0, n . d^), the sum divided by the
 * sum of the weights ("normalize to the potential max illumination");
 * times pi here to give lux like lx_irradiance_brute. */
static void seed_direction(int face, int i, int j, int size, lx_vec3 *d)
{
    float a = (i + 0.5f) / size - 0.5f, b = (j + 0.5f) / size - 0.5f;
    switch (face) {
    case 0:
        *d = lx_v3(0.5f, -b, -a);
        break;
    case 1:
        *d = lx_v3(-0.5f, -b, a);
        break;
    case 2:
        *d = lx_v3(a, 0.5f, b);
        break;
    case 3:
        *d = lx_v3(a, -0.5f, -b);
        break;
    case 4:
        *d = lx_v3(a, -b, 0.5f);
        break;
    default:
        *d = lx_v3(-a, -b, -0.5f);
        break;
    }
}

static void run_seed_irr(void *p)
{
    irr_job *j = p;
    const lx_cubemap *e = j->env;
    int n = e->size, m = 32;
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < m; y++)
            for (int x = 0; x < m; x++) {
                lx_vec3 nrm;
                seed_direction(f, x, y, m, &nrm);
                nrm = lx_normalize(nrm);
                float total = 0.0f, s[3] = {0, 0, 0};
                for (int g = 0; g < 6; g++) {
                    lx_vec3 fn;
                    seed_direction(g, 1, 1, 3, &fn);
                    fn = lx_normalize(fn);
                    for (int u = 0; u < n; u++)
                        for (int v = 0; v < n; v++) {
                            lx_vec3 d;
                            seed_direction(g, u, v, n, &d);
                            float w = 1.0f / lx_dot(d, d);
                            d = lx_normalize(d);
                            w *= lx_dot(fn, d);
                            w *= fmaxf(0.0f, lx_dot(nrm, d));
                            total += w;
                            const float *t = lx_cubemap_texel(e, g, u, v);
                            s[0] += w * t[0], s[1] += w * t[1], s[2] += w * t[2];
                        }
                }
                float *o = j->seed_out + 3 * (((size_t)f * m + y) * m + x);
                for (int k = 0; k < 3; k++)
                    o[k] = (float)LX_PI * s[k] / total;
            }
}

/* ---- [3] specular prefilter ---------------------------------------------- */

typedef struct pre_job {
    const lx_cubemap *env;
    lx_specular_filter filter;
    lx_cubemap levels[LX_MAX_CUBE_MIPS];
    int count;
} pre_job;

static void run_prefilter(void *p)
{
    pre_job *j = p;
    for (int i = 0; i < j->count; i++)
        lx_cubemap_free(&j->levels[i]);
    lx_prefilter_desc d = {.filter = j->filter, .threads = g_threads};
    if (lx_prefilter(j->env, &d, j->levels, &j->count) != LX_OK)
        lx_bench_die("lx_prefilter");
}

/* One level by brute force over every source texel, one thread: GGX
 * (Karis' N = V = R lobe D(n.h) (n.l)) of roughness param, or Phong
 * pow(max(0, r.l), param); each normalised by its own sum. */
typedef struct brute_job {
    const lx_cubemap *env;
    lx_specular_filter filter;
    double param;
    int size;
    float *out;
    double *omega;
} brute_job;

static void run_brute_level(void *p)
{
    brute_job *j = p;
    const lx_cubemap *e = j->env;
    int n = e->size, m = j->size;
    double a2 = pow(j->param, 4.0);
    for (int f = 0; f < 6; f++)
        for (int y = 0; y < m; y++)
            for (int x = 0; x < m; x++) {
                lx_vec3 r = lx_cube_direction(f, (x + 0.5f) / m, (y + 0.5f) / m);
                double s[3] = {0, 0, 0}, den = 0.0;
                for (int g = 0; g < 6; g++)
                    for (int v = 0; v < n; v++)
                        for (int u = 0; u < n; u++) {
                            lx_vec3 l = lx_cube_direction(g, (u + 0.5f) / n, (v + 0.5f) / n);
                            double c = lx_dot(r, l);
                            if (c <= 0.0)
                                continue;
                            double w;
                            if (j->filter == LX_SPECULAR_GGX) {
                                double q = 0.5 * (1.0 + c) * (a2 - 1.0) + 1.0;
                                w = a2 / (q * q) * c;
                            } else {
                                w = pow(c, j->param);
                            }
                            w *= j->omega[v * n + u];
                            const float *t = lx_cubemap_texel(e, g, u, v);
                            s[0] += w * t[0], s[1] += w * t[1], s[2] += w * t[2];
                            den += w;
                        }
                float *o = j->out + 3 * (((size_t)f * m + y) * m + x);
                for (int k = 0; k < 3; k++)
                    o[k] = (float)(s[k] / den);
            }
}

/* The same GGX brute force at selected texels of a level, on every
 * thread: the source as flat arrays (texel direction, solid angle, value),
 * the lobe's normalisation summed in double. Texel k of the list is
 * (face, x, y) = pick[3k..3k+2]; out gets 3 floats per texel. */
typedef struct flat_env {
    size_t count;
    float *dir; /* 3 per texel */
    double *omega;
    float *value; /* 3 per texel */
} flat_env;

static flat_env flatten(const lx_cubemap *e, const double *omega)
{
    int n = e->size;
    flat_env f = {.count = (size_t)6 * n * n};
    f.dir = malloc(sizeof(float) * 3 * f.count);
    f.omega = malloc(sizeof(double) * f.count);
    f.value = malloc(sizeof(float) * 3 * f.count);
    if (!f.dir || !f.omega || !f.value)
        lx_bench_die("malloc");
    size_t i = 0;
    for (int g = 0; g < 6; g++)
        for (int v = 0; v < n; v++)
            for (int u = 0; u < n; u++, i++) {
                lx_vec3 l = lx_cube_direction(g, (u + 0.5f) / n, (v + 0.5f) / n);
                f.dir[3 * i] = l.x, f.dir[3 * i + 1] = l.y, f.dir[3 * i + 2] = l.z;
                f.omega[i] = omega[v * n + u];
                memcpy(f.value + 3 * i, lx_cubemap_texel(e, g, u, v), sizeof(float) * 3);
            }
    return f;
}

static void flat_free(flat_env *f)
{
    free(f->dir);
    free(f->omega);
    free(f->value);
}

static void brute_ggx_at(const flat_env *e, double roughness, int size, const int *pick, int count,
                         float *out)
{
    double a2 = pow(roughness, 4.0);
#pragma omp parallel for schedule(dynamic, 4) num_threads(g_threads)
    for (int k = 0; k < count; k++) {
        lx_vec3 r = lx_cube_direction(pick[3 * k], (pick[3 * k + 1] + 0.5f) / size,
                                      (pick[3 * k + 2] + 0.5f) / size);
        double s[3] = {0, 0, 0}, den = 0.0;
        for (size_t i = 0; i < e->count; i++) {
            const float *l = e->dir + 3 * i;
            double c = (double)r.x * l[0] + (double)r.y * l[1] + (double)r.z * l[2];
            if (c <= 0.0)
                continue;
            double q = 0.5 * (1.0 + c) * (a2 - 1.0) + 1.0;
            double w = a2 / (q * q) * c * e->omega[i];
            const float *t = e->value + 3 * i;
            s[0] += w * t[0], s[1] += w * t[1], s[2] += w * t[2];
            den += w;
        }
        for (int j = 0; j < 3; j++)
            out[3 * k + j] = (float)(s[j] / den);
    }
}

/* Mean and worst relative difference of count values. */
static void compare(const float *a, const float *b, size_t count, double *mean, double *worst)
{
    *mean = *worst = 0.0;
    for (size_t i = 0; i < count; i++) {
        double rel = fabs(a[i] - b[i]) / fmax(fabs(b[i]), 1e-6);
        *mean += rel;
        *worst = fmax(*worst, rel);
    }
    *mean /= (double)count;
}

/* Every GGX level of the chain against the brute force: on all texels of
 * levels up to 16x16, on a regular 16x16 subset of each face above (the
 * texel at the middle of every size/16-th row and column); and on the 9x9
 * texels around the sun's (on its face). */
static double ggx_levels_vs_brute(const lx_cubemap *env, const double *omega, const pre_job *pj)
{
    flat_env flat = flatten(env, omega);
    int *pick = malloc(sizeof(int) * 3 * 6 * 16 * 16);
    float *got = malloc(sizeof(float) * 3 * 6 * 16 * 16),
          *want = malloc(sizeof(float) * 3 * 6 * 16 * 16);
    if (!pick || !got || !want)
        lx_bench_die("malloc");
    int sun_face;
    float sun_s, sun_t;
    lx_cube_face_coords(sun_dir(), &sun_face, &sun_s, &sun_t);
    printf("  per GGX level against the brute force (relative, all channels):\n");
    printf("  %5s %9s %9s %20s %26s %9s\n", "level", "size", "roughness", "grid: mean  worst",
           "9x9 around the sun: mean  worst", "texels");
    double t0 = lx_bench_now(), worst_mean = 0.0;
    for (int l = 1; l < pj->count; l++) {
        const lx_cubemap *lev = &pj->levels[l];
        int m = lev->size, step = m > 16 ? m / 16 : 1, side = m > 16 ? 16 : m;
        double r = lx_ggx_level_roughness(l, pj->count);
        double mean[2], worst[2];
        int counts[2];
        for (int pass = 0; pass < 2; pass++) {
            int k = 0;
            if (pass == 0) {
                for (int f = 0; f < 6; f++)
                    for (int y = 0; y < side; y++)
                        for (int x = 0; x < side; x++, k++)
                            pick[3 * k] = f, pick[3 * k + 1] = x * step + step / 2,
                                     pick[3 * k + 2] = y * step + step / 2;
            } else {
                int cx = (int)(sun_s * m), cy = (int)(sun_t * m);
                for (int y = cy - 4; y <= cy + 4; y++)
                    for (int x = cx - 4; x <= cx + 4; x++)
                        if (x >= 0 && y >= 0 && x < m && y < m)
                            pick[3 * k] = sun_face, pick[3 * k + 1] = x, pick[3 * k + 2] = y, k++;
            }
            for (int i = 0; i < k; i++)
                memcpy(got + 3 * i,
                       lx_cubemap_texel(lev, pick[3 * i], pick[3 * i + 1], pick[3 * i + 2]),
                       sizeof(float) * 3);
            brute_ggx_at(&flat, r, m, pick, k, want);
            compare(got, want, 3 * (size_t)k, &mean[pass], &worst[pass]);
            counts[pass] = k;
        }
        worst_mean = fmax(worst_mean, mean[0]);
        printf("  %5d %4dx%-4d %9.3f %9.2f%% %8.1f%% %15.2f%% %8.1f%% %9d\n", l, m, m, r,
               100.0 * mean[0], 100.0 * worst[0], 100.0 * mean[1], 100.0 * worst[1],
               counts[0] + counts[1]);
    }
    printf("  (brute force at those texels: %.1f s, %d threads)\n", lx_bench_now() - t0, g_threads);
    free(pick);
    free(got);
    free(want);
    flat_free(&flat);
    return worst_mean;
}

/* ---- [4] the whole luxel ibl run ------------------------------------------ */

/* bin/<name> beside this program (make bench runs it from build/bin). */
static char *sibling(const char *name)
{
    char self[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n <= 0)
        return NULL;
    self[n] = '\0';
    char *slash = strrchr(self, '/');
    if (!slash)
        return NULL;
    *slash = '\0';
    size_t len = strlen(self) + strlen(name) + 2;
    char *path = malloc(len);
    if (path)
        snprintf(path, len, "%s/%s", self, name);
    if (path && access(path, X_OK) != 0) {
        free(path);
        return NULL;
    }
    return path;
}

/* Runs argv to its end: wall seconds, and the child's CPU seconds in *cpu;
 * negative when it fails. */
static double run_process(char *const argv[], double *cpu)
{
    double t0 = lx_bench_now();
    pid_t pid = fork();
    if (pid < 0)
        return -1.0;
    if (pid == 0) {
        execv(argv[0], argv);
        _exit(127);
    }
    int status;
    struct rusage before, after;
    getrusage(RUSAGE_CHILDREN, &before);
    if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
        return -1.0;
    double wall = lx_bench_now() - t0;
    getrusage(RUSAGE_CHILDREN, &after);
    *cpu = (double)(after.ru_utime.tv_sec - before.ru_utime.tv_sec) +
           1e-6 * (double)(after.ru_utime.tv_usec - before.ru_utime.tv_usec) +
           (double)(after.ru_stime.tv_sec - before.ru_stime.tv_sec) +
           1e-6 * (double)(after.ru_stime.tv_usec - before.ru_stime.tv_usec);
    return wall;
}

/* The library calls of `luxel ibl ENV --layout ktx` in this process. */
typedef struct cli_job {
    const char *sky, *out;
} cli_job;

static void run_library(void *p)
{
    const cli_job *j = p;
    lx_cubemap env, irr, spec[LX_MAX_CUBE_MIPS];
    lx_sh9 sh;
    int count;
    lx_image lut;
    lx_env_load_desc ld = {.threads = g_threads};
    lx_ibl_desc d = {.threads = g_threads};
    lx_prefilter_desc pd = {.threads = g_threads};
    if (lx_env_load(j->sky, &ld, &env) != LX_OK || lx_sh_project(&env, &d, &sh) != LX_OK ||
        lx_irradiance_brute(&env, 32, 0, &d, &irr) != LX_OK ||
        lx_prefilter(&env, &pd, spec, &count) != LX_OK || lx_dfg_lut(128, 0, &d, &lut) != LX_OK)
        lx_bench_die("the library's ibl calls");
    lx_cubemap_fix_seams(&irr);
    for (int i = 0; i < count; i++)
        lx_cubemap_fix_seams(&spec[i]);
    lx_image rgb;
    if (lx_image_alloc(&rgb, lut.width, lut.height, 3) != LX_OK)
        lx_bench_die("lx_image_alloc");
    for (int i = 0; i < lut.width * lut.height; i++)
        rgb.data[3 * i] = lut.data[2 * i], rgb.data[3 * i + 1] = lut.data[2 * i + 1];
    lx_env_write_desc wd = {.layout = LX_ENV_KTX, .threads = g_threads};
    lx_image_write_desc id = {.format = LX_IMAGE_EXR, .threads = g_threads};
    char *lut_path = lx_path_join(j->out, "dfg_lut.exr");
    if (!lut_path || lx_env_write(j->out, "irradiance", &irr, 1, &wd) != LX_OK ||
        lx_env_write(j->out, "specular", spec, count, &wd) != LX_OK ||
        lx_image_write(lut_path, &rgb, &id) != LX_OK)
        lx_bench_die("writing the ibl files");
    free(lut_path);
    lx_image_free(&rgb);
    lx_image_free(&lut);
    for (int i = 0; i < count; i++)
        lx_cubemap_free(&spec[i]);
    lx_cubemap_free(&irr);
    lx_cubemap_free(&env);
}

/* Section [4]; returns the CLI's best wall time (0 when it cannot run). */
static double bench_cli(double *cpu_share_one, double *ratio)
{
    printf("\n[4] THE WHOLE `luxel ibl sky.pfm --layout ktx` RUN  gen_scenes' 1024x512 sky, 256^2 "
           "faces, 9 GGX levels, irradiance, SH, DFG table; baseline: the same library calls in "
           "this process\n");
    char *luxel = sibling("luxel"), *gen = sibling("gen_scenes");
    char dir[] = "/tmp/bench_ibl.XXXXXX";
    if (!luxel || !gen || !mkdtemp(dir)) {
        printf("  skipped: luxel and gen_scenes must be beside bench_ibl (build/bin)\n");
        free(luxel);
        free(gen);
        return 0.0;
    }
    char scenes[64], sky[96], out[64], lib_out[64], threads_arg[16];
    snprintf(scenes, sizeof scenes, "%s/scenes", dir);
    snprintf(sky, sizeof sky, "%s/sky.pfm", scenes);
    snprintf(out, sizeof out, "%s/out", dir);
    snprintf(lib_out, sizeof lib_out, "%s/lib", dir);
    snprintf(threads_arg, sizeof threads_arg, "%d", g_threads);
    double cpu = 0.0;
    char *gen_argv[] = {gen, scenes, NULL};
    if (run_process(gen_argv, &cpu) < 0.0 || mkdir(lib_out, 0777) != 0)
        lx_bench_die("gen_scenes");
    char *argv_n[] = {luxel,       "ibl",       sky,  "--layout", "ktx", "-q",
                      "--threads", threads_arg, "-o", out,        NULL};
    char *argv_1[] = {luxel,       "ibl", sky,  "--layout", "ktx", "-q",
                      "--threads", "1",   "-o", out,        NULL};
    double best = INFINITY, best_cpu = 0.0, best1 = INFINITY, best1_cpu = 0.0;
    int runs = 5 * g_reps;
    for (int i = 0; i < runs; i++) {
        double t = run_process(argv_n, &cpu);
        if (t < 0.0)
            lx_bench_die("luxel ibl");
        if (t < best)
            best = t, best_cpu = cpu;
        t = run_process(argv_1, &cpu);
        if (t < 0.0)
            lx_bench_die("luxel ibl --threads 1");
        if (t < best1)
            best1 = t, best1_cpu = cpu;
    }
    cli_job job = {sky, lib_out};
    int lib_runs;
    double t_lib = best_of(run_library, &job, runs, 0.0, &lib_runs);
    printf("  %-44s %10s %10s %10s\n", "figure (best of runs)", "wall", "CPU", "ratio");
    printf("  %-44s %8.3f s %8.0f %% %9.2fx  (%d runs)\n", "luxel ibl, all threads", best,
           100.0 * best_cpu / best, best / t_lib, runs);
    printf("  %-44s %8.3f s %8.0f %% %9.2fx  (%d runs)\n", "luxel ibl --threads 1", best1,
           100.0 * best1_cpu / best1, best1 / t_lib, runs);
    printf("  %-44s %8.3f s %10s %9.2fx  (%d runs)\n", "baseline: the library calls, all threads",
           t_lib, "", 1.0, lib_runs);
    printf("  => %.3f s wall (target < 0.7 s: %s), %.2fx the library calls alone; --threads 1 "
           "uses %.0f%% CPU\n",
           best, best < 0.7 ? "MET" : "NOT MET", best / t_lib, 100.0 * best1_cpu / best1);
    *cpu_share_one = best1_cpu / best1;
    *ratio = best / t_lib;
    char rm[160];
    snprintf(rm, sizeof rm, "rm -rf '%s'", dir);
    if (system(rm) != 0)
        fprintf(stderr, "bench_ibl: could not remove %s\n", dir);
    free(luxel);
    free(gen);
    return best;
}

int main(int argc, char **argv)
{
    bool only_cli = false;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--reps") && i + 1 < argc)
            g_reps = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc)
            g_threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--only-cli"))
            only_cli = true;
        else {
            fprintf(stderr, "usage: %s [--reps N] [--threads N] [--only-cli]\n", argv[0]);
            return 2;
        }
    }
    if (g_reps < 1)
        g_reps = 1;
    g_threads = lx_thread_count(g_threads);
    lx_bench_header("bench_ibl", g_threads);
    double t_start = lx_bench_now();
    char a[32], b[32], load[32];
    if (only_cli) {
        double cpu_one, ratio, t = bench_cli(&cpu_one, &ratio);
        printf("bench_ibl: luxel ibl of a 1024x512 sky %.3f s (target < 0.7 s: %s, %.2fx its "
               "library calls, %.0f%% CPU with --threads 1); %d threads, load %s\n",
               t, t > 0.0 && t < 0.7 ? "MET" : "NOT MET", ratio, 100.0 * cpu_one, g_threads,
               lx_bench_load(load, sizeof load));
        return 0;
    }

    /* [1] */
    lx_cubemap env512 = make_env(512);
    sh_job sj = {.env = &env512};
    int runs_sh, runs_sum;
    double t_sh = best_of(run_sh, &sj, 5 * g_reps, 0.5, &runs_sh);
    double t_sum = best_of(run_sum, &sj, 5 * g_reps, 0.5, &runs_sum);
    double texels = 6.0 * 512 * 512;
    printf("\n[1] SH PROJECTION  6x512^2 cube map (%.1f MB of floats), %d threads\n",
           texels * 12 / 1e6, g_threads);
    printf("  %-44s %10s %16s %10s\n", "figure (best of runs)", "time", "per second", "ratio");
    printf("  %-44s %8.2f ms %12stexels/s %9.2fx  (%d runs)\n", "lx_sh_project", 1e3 * t_sh,
           lx_bench_si(texels / t_sh, a), t_sh / t_sum, runs_sh);
    printf("  %-44s %8.2f ms %12stexels/s %9.2fx  (%d runs)\n", "baseline: sum the cube once",
           1e3 * t_sum, lx_bench_si(texels / t_sum, b), 1.0, runs_sum);
    printf("  => %.2f ms (target < 20 ms: %s), %.2fx the memory-bandwidth floor\n", 1e3 * t_sh,
           t_sh < 0.020 ? "MET" : "NOT MET", t_sh / t_sum);
    lx_cubemap_free(&env512);

    /* [2] */
    lx_cubemap env32 = make_env(32);
    irr_job ij = {.env = &env32};
    ij.seed_out = malloc(sizeof(float) * 6 * 32 * 32 * 3);
    if (!ij.seed_out)
        lx_bench_die("malloc");
    int runs_irr, runs_seed;
    double t_irr = best_of(run_irr, &ij, 3 * g_reps, 0.5, &runs_irr);
    double t_seed = best_of(run_seed_irr, &ij, 1, 0.0, &runs_seed);
    double mean, worst;
    compare(ij.out.data, ij.seed_out, 6 * 32 * 32 * 3, &mean, &worst);
    double pairs = 6.0 * 32 * 32 * 6.0 * 32 * 32;
    printf("\n[2] BRUTE-FORCE IRRADIANCE  6x32^2 source -> 6x32^2, %d threads vs 1\n", g_threads);
    printf("  %-44s %10s %16s %10s\n", "figure (best of runs)", "time", "per second", "speed-up");
    printf("  %-44s %8.2f ms %12spairs/s %10.1fx  (%d runs)\n", "lx_irradiance_brute", 1e3 * t_irr,
           lx_bench_si(pairs / t_irr, a), t_seed / t_irr, runs_irr);
    printf("  %-44s %8.2f ms %12spairs/s %10.1fx\n", "baseline: the seed's loop, 1 thread",
           1e3 * t_seed, lx_bench_si(pairs / t_seed, b), 1.0);
    printf("  agreement: mean %.3g, worst %.3g relative (the seed: centre directions, "
           "approximate solid angles, float sums)\n",
           mean, worst);
    printf("  => %.1fx faster than the seed's loop\n", t_seed / t_irr);
    double irr_speedup = t_seed / t_irr;
    lx_cubemap_free(&ij.out);
    free(ij.seed_out);
    lx_cubemap_free(&env32);

    /* [3] */
    lx_cubemap env256 = make_env(256);
    double *omega = malloc(sizeof(double) * 256 * 256);
    float *brute = malloc(sizeof(float) * 6 * 8 * 8 * 3);
    if (!omega || !brute)
        lx_bench_die("malloc");
    for (int y = 0; y < 256; y++)
        for (int x = 0; x < 256; x++)
            omega[y * 256 + x] = lx_cube_texel_solid_angle(256, x, y);
    printf("\n[3] SPECULAR PREFILTER  6x256^2 source, full chain 256..1 (9 levels), %d threads; "
           "baseline: one 8x8 level by brute force over all 393,216 source texels, 1 thread\n",
           g_threads);
    printf("  %-44s %10s %10s %22s\n", "figure (best of runs)", "time", "ratio",
           "8x8 level vs brute");
    double t_pre[2] = {0, 0}, t_brute[2] = {0, 0}, ggx_mean = 0.0;
    for (int filter = 0; filter < 2; filter++) {
        pre_job pj = {.env = &env256, .filter = (lx_specular_filter)filter};
        int runs;
        t_pre[filter] = best_of(run_prefilter, &pj, g_reps, 0.0, &runs);
        /* level 5 of 9: 8x8 faces */
        double param = filter == LX_SPECULAR_GGX ? lx_ggx_level_roughness(5, pj.count)
                                                 : lx_phong_level_exponent(5);
        brute_job bj = {.env = &env256,
                        .filter = pj.filter,
                        .param = param,
                        .size = 8,
                        .out = brute,
                        .omega = omega};
        t_brute[filter] = best_of(run_brute_level, &bj, 1, 0.0, NULL);
        compare(pj.levels[5].data, brute, 6 * 8 * 8 * 3, &mean, &worst);
        char name[64];
        snprintf(name, sizeof name, "lx_prefilter %s, 9 levels",
                 filter == LX_SPECULAR_GGX ? "GGX" : "Phong");
        printf("  %-44s %8.3f s %9.2fx   mean %.2f%% worst %.1f%%  (%d runs)\n", name,
               t_pre[filter], t_pre[filter] / t_brute[filter], 100.0 * mean, 100.0 * worst, runs);
        snprintf(name, sizeof name, "baseline: brute %s 8x8 level (%s %g)",
                 filter == LX_SPECULAR_GGX ? "GGX" : "Phong",
                 filter == LX_SPECULAR_GGX ? "roughness" : "n", param);
        printf("  %-44s %8.3f s %9.2fx\n", name, t_brute[filter], 1.0);
        if (filter == LX_SPECULAR_GGX)
            ggx_mean = ggx_levels_vs_brute(&env256, omega, &pj);
        for (int i = 0; i < pj.count; i++)
            lx_cubemap_free(&pj.levels[i]);
    }
    printf("  => GGX chain %.3f s (target < 1 s: %s) = %.2fx one brute-force 8x8 level, every "
           "level within %.2f%% of the brute force on average; Phong chain %.3f s\n",
           t_pre[0], t_pre[0] < 1.0 ? "MET" : "NOT MET", t_pre[0] / t_brute[0], 100.0 * ggx_mean,
           t_pre[1]);
    free(omega);
    free(brute);
    lx_cubemap_free(&env256);

    /* [4] */
    double cpu_one = 0.0, cli_ratio = 0.0;
    double t_cli = bench_cli(&cpu_one, &cli_ratio);

    printf("\ntotal bench time %.1f s\n", lx_bench_now() - t_start);
    printf(
        "bench_ibl: SH 6x512^2 %.2f ms (target < 20 ms: %s, %.2fx a plain sum); brute "
        "irradiance 6x32^2 %.1f ms (%.0fx the seed's loop); GGX chain 6x256^2 %.3f s (target "
        "< 1 s: %s, %.2fx one brute 8x8 level, levels' mean error <= %.2f%%); Phong chain %.3f s; "
        "luxel ibl of a 1024x512 sky %.3f s (target < 0.7 s: %s, %.2fx its library calls, "
        "%.0f%% CPU with --threads 1); %d threads, load %s\n",
        1e3 * t_sh, t_sh < 0.020 ? "MET" : "NOT MET", t_sh / t_sum, 1e3 * t_irr, irr_speedup,
        t_pre[0], t_pre[0] < 1.0 ? "MET" : "NOT MET", t_pre[0] / t_brute[0], 100.0 * ggx_mean,
        t_pre[1], t_cli, t_cli > 0.0 && t_cli < 0.7 ? "MET" : "NOT MET", cli_ratio, 100.0 * cpu_one,
        g_threads, lx_bench_load(load, sizeof load));
    return 0;
}
