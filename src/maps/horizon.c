/* Horizon and ambient-occlusion maps from a height field: Lengyel's
 * ConstructHorizonMap (FGED vol. 2 sec. 7.8, eq. 7.53; seed
 * 002_26369eb9c57a642b.txt), written for any image size and wrap mode.
 *
 * The method. Around each texel, `angles` sample directions theta_m =
 * 2 pi m / angles (counter-clockwise from +x with y up the image). A texel
 * at offset (i, j) within the radius (0 < i^2 + j^2 < radius^2), seen at
 * azimuth phi = atan2(j, i) and distance r, spans the angular half-width
 * atan(sqrt(1/2) / r) (its half-diagonal seen from the centre, the seed's
 * 0.7071); it counts for the directions theta_m that lie within that
 * half-width of phi. Each direction keeps the largest tangent of the
 * elevation t = (h(i, j) - h(0, 0)) / r (heights in texels, strength * v),
 * or 0 when nothing is higher. Direction k of the eight (every 45 degrees)
 * is the mean of sin(atan t) = sqrt(t^2 / (t^2 + 1)) over the angles/8 + 1
 * directions within 22.5 degrees of it, ends included, as the seed does.
 * The ambient factor is the mean over the directions of cos(atan t) =
 * 1 / sqrt(t^2 + 1) (the seed multiplies the sum by the count where the
 * mean is meant), or of its square for the cosine-weighted visible
 * fraction, raised to ao_power.
 *
 * Two departures from the listing. The seed widens each texel's range
 * with floor/ceil to whole bins on both sides, so a texel also raises the
 * horizon of directions that pass up to a bin away from it; here a texel
 * only counts for the directions that cross it. And the work is turned
 * inside out for speed: the offsets within the radius are the same for
 * every texel, so each direction's list of offsets (with 1/r) is made
 * once, and each row is swept direction by direction over a copy of the
 * height field padded by the radius with the wrap mode applied, a loop of
 * subtract, multiply and max the compiler vectorises (no atan2 or
 * branches inside it). */
#include "luxel/maps.h"
#include "core/internal.h"

#include <math.h>

#define HZ_PI 3.14159265358979323846
#include <omp.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

/* Texels of a row swept at once: each direction's maxima for a chunk stay
 * in the first-level cache (32 directions x 256 x 4 bytes = 32 KiB). */
#define HZ_CHUNK 256
#define HZ_MAX_ANGLES 1024
#define HZ_MAX_RADIUS 256

lx_horizon_desc lx_horizon_desc_defaults(const lx_horizon_desc *desc)
{
    lx_horizon_desc d;
    if (desc)
        d = *desc;
    else
        memset(&d, 0, sizeof d);
    if (d.strength == 0.0f)
        d.strength = LX_DEFAULT_HEIGHT_STRENGTH;
    if (d.angles == 0)
        d.angles = 32;
    if (d.radius == 0)
        d.radius = 16;
    if (d.ao_power == 0.0f)
        d.ao_power = 1.0f;
    return d;
}

/* One offset of a direction's list: texel (x + dx, y - dy) seen from
 * (x, y) (dy up the image, rows down), at 1/r. */
typedef struct hz_offset {
    int dx, dy;
    float inv_r;
} hz_offset;

typedef struct hz_plan {
    int angles, radius;
    int *first;     /* angles + 1 starts into list */
    hz_offset *list;
} hz_plan;

static void plan_free(hz_plan *p)
{
    free(p->first);
    free(p->list);
}

/* The directions [lo, hi] (unwrapped indices) that offset (i, j) counts for. */
static void offset_bins(int i, int j, int angles, int *lo, int *hi)
{
    double r = sqrt((double)(i * i + j * j));
    double phi = atan2((double)j, (double)i);
    double half = atan(sqrt(0.5) / r);
    double per = (double)angles / (2.0 * HZ_PI);
    *lo = (int)ceil((phi - half) * per);
    *hi = (int)floor((phi + half) * per);
}

static lx_status plan_make(int angles, int radius, hz_plan *p)
{
    memset(p, 0, sizeof *p);
    p->angles = angles;
    p->radius = radius;
    p->first = calloc((size_t)angles + 1, sizeof *p->first);
    if (!p->first)
        return lx_fail(LX_ERR_NOMEM, "horizon map: out of memory");
    int r2max = radius * radius;
    /* count, then fill (the directions' lists in row-major offset order) */
    for (int pass = 0; pass < 2; pass++) {
        int *fill = NULL;
        if (pass == 1) {
            for (int m = 0; m < angles; m++)
                p->first[m + 1] += p->first[m];
            p->list = malloc(sizeof *p->list * (size_t)(p->first[angles] ? p->first[angles] : 1));
            fill = malloc(sizeof *fill * (size_t)angles);
            if (!p->list || !fill) {
                free(fill);
                plan_free(p);
                return lx_fail(LX_ERR_NOMEM, "horizon map: out of memory");
            }
            memcpy(fill, p->first, sizeof *fill * (size_t)angles);
        }
        for (int j = -radius + 1; j < radius; j++)
            for (int i = -radius + 1; i < radius; i++) {
                int r2 = i * i + j * j;
                if (r2 == 0 || r2 >= r2max)
                    continue;
                int lo, hi;
                offset_bins(i, j, angles, &lo, &hi);
                for (int n = lo; n <= hi; n++) {
                    int m = ((n % angles) + angles) % angles;
                    if (pass == 0)
                        p->first[m + 1]++;
                    else
                        p->list[fill[m]++] =
                            (hz_offset){i, j, (float)(1.0 / sqrt((double)r2))};
                }
            }
        free(fill);
    }
    return LX_OK;
}

/* acc[x] = max(acc[x], (s[x] - c[x]) * inv_r) for x < n: the inner loop,
 * compiled twice on x86-64 (AVX2 and the baseline) and picked at run time.
 * Both give the same bits: subtract, multiply and max are exact IEEE
 * operations in any vector width, and nothing is fused. */
#define HZ_SWEEP_BODY                                                                              \
    for (int x = 0; x < n; x++) {                                                                  \
        float v = (s[x] - c[x]) * inv_r;                                                           \
        acc[x] = acc[x] > v ? acc[x] : v;                                                          \
    }
typedef void (*hz_sweep_fn)(float *restrict acc, const float *restrict s,
                            const float *restrict c, float inv_r, int n);
static void sweep_base(float *restrict acc, const float *restrict s, const float *restrict c,
                       float inv_r, int n)
{
    HZ_SWEEP_BODY
}
#if defined(__GNUC__) && defined(__x86_64__)
#define HZ_HAVE_AVX2 1
__attribute__((target("avx2"))) static void sweep_avx2(float *restrict acc,
                                                       const float *restrict s,
                                                       const float *restrict c, float inv_r, int n)
{
    HZ_SWEEP_BODY
}
#endif

static hz_sweep_fn pick_sweep(void)
{
#ifdef HZ_HAVE_AVX2
    if (__builtin_cpu_supports("avx2"))
        return sweep_avx2;
#endif
    return sweep_base;
}

typedef struct hz_job {
    const hz_plan *plan;
    hz_sweep_fn sweep;
    const float *pad; /* (w + 2R) x (h + 2R) heights in texels */
    int w, h, pw;
    float ao_power;
    bool ao_cosine;
    float *l0, *l1, *ao; /* outputs' data, any may be NULL */
} hz_job;

/* Row y, texels [x0, x0 + n); t holds angles * HZ_CHUNK floats. */
static void hz_chunk(const hz_job *jb, int y, int x0, int n, float *t)
{
    const hz_plan *p = jb->plan;
    int R = p->radius, N = p->angles;
    const float *c = jb->pad + (size_t)(y + R) * (size_t)jb->pw + (size_t)(R + x0);
    for (int m = 0; m < N; m++) {
        float *acc = t + (size_t)m * HZ_CHUNK;
        memset(acc, 0, sizeof *acc * (size_t)n);
        for (int k = p->first[m]; k < p->first[m + 1]; k++) {
            const hz_offset *o = &p->list[k];
            const float *s = jb->pad + (size_t)(y + R - o->dy) * (size_t)jb->pw +
                             (size_t)(R + x0 + o->dx);
            jb->sweep(acc, s, c, o->inv_r, n);
        }
    }
    /* tangents -> sines in place, and the ambient sum */
    float aos[HZ_CHUNK];
    memset(aos, 0, sizeof aos);
    for (int m = 0; m < N; m++) {
        float *acc = t + (size_t)m * HZ_CHUNK;
        for (int x = 0; x < n; x++) {
            float q = 1.0f / sqrtf(acc[x] * acc[x] + 1.0f); /* cos of the elevation */
            acc[x] *= q;                                     /* its sin */
            aos[x] += jb->ao_cosine ? q * q : q;
        }
    }
    size_t row = (size_t)y * (size_t)jb->w + (size_t)x0;
    if (jb->l0 || jb->l1) {
        int half = N / 16, count = N / 8 + 1;
        float inv = 1.0f / (float)count;
        float sum[HZ_CHUNK];
        for (int d = 0; d < 8; d++) {
            float *layer = d < 4 ? jb->l0 : jb->l1;
            if (!layer)
                continue;
            memset(sum, 0, sizeof sum);
            int centre = d * (N / 8);
            for (int k = -half; k <= half; k++) {
                const float *sn = t + (size_t)((centre + k + N) % N) * HZ_CHUNK;
                for (int x = 0; x < n; x++)
                    sum[x] += sn[x];
            }
            float *out = layer + row * 4 + (size_t)(d & 3);
            for (int x = 0; x < n; x++)
                out[(size_t)x * 4] = sum[x] * inv;
        }
    }
    if (jb->ao) {
        float inv = 1.0f / (float)N;
        for (int x = 0; x < n; x++) {
            float a = aos[x] * inv;
            jb->ao[row + (size_t)x] = jb->ao_power == 1.0f ? a : powf(a, jb->ao_power);
        }
    }
}

static lx_status check_desc(const lx_image *height, const lx_horizon_desc *d)
{
    if (!height || !height->data || height->width < 1 || height->height < 1)
        return lx_fail(LX_ERR_INVALID, "horizon map: no height field");
    if (height->channels != 1)
        return lx_fail(LX_ERR_INVALID,
                       "horizon map: the height field has %d channels (one is needed)",
                       height->channels);
    if (d->angles < 16 || d->angles > HZ_MAX_ANGLES || (d->angles & (d->angles - 1)) != 0)
        return lx_fail(LX_ERR_INVALID,
                       "horizon map: angles %d is not a power of two from 16 to %d", d->angles,
                       HZ_MAX_ANGLES);
    if (d->radius < 2 || d->radius > HZ_MAX_RADIUS)
        return lx_fail(LX_ERR_INVALID, "horizon map: radius %d is not from 2 to %d texels",
                       d->radius, HZ_MAX_RADIUS);
    if (!isfinite(d->strength) || d->strength < 0.0f)
        return lx_fail(LX_ERR_INVALID, "horizon map: strength %g is not a finite number >= 0",
                       (double)d->strength);
    if (!isfinite(d->ao_power) || d->ao_power <= 0.0f)
        return lx_fail(LX_ERR_INVALID, "horizon map: ao power %g is not a finite number > 0",
                       (double)d->ao_power);
    if ((unsigned)d->wrap > LX_WRAP_MIRROR)
        return lx_fail(LX_ERR_INVALID, "horizon map: unknown wrap mode %d", (int)d->wrap);
    if (d->threads < 0)
        return lx_fail(LX_ERR_INVALID, "horizon map: threads %d is negative", d->threads);
    return LX_OK;
}

/* The height field times strength, padded by R texels on every side with
 * the wrap mode applied, into *out (row length *pw_out). */
static lx_status make_padded(const lx_image *hf, int R, lx_wrap wrap, float strength, float **out,
                             int *pw_out)
{
    int w = hf->width, h = hf->height;
    size_t pw = (size_t)w + 2 * (size_t)R, ph = (size_t)h + 2 * (size_t)R, bytes;
    if (!lx_size_mul(pw, ph, sizeof(float), &bytes))
        return lx_fail(LX_ERR_NOMEM, "horizon map: the image is too large");
    lx_status st = lx_check_memory(bytes, "horizon map: the padded height field");
    if (st != LX_OK)
        return st;
    float *pad = malloc(bytes);
    int *col = malloc(sizeof *col * pw);
    if (!pad || !col) {
        free(pad);
        free(col);
        return lx_fail(LX_ERR_NOMEM, "horizon map: out of memory");
    }
    for (size_t px = 0; px < pw; px++)
        col[px] = lx_wrap_index(wrap, (int)px - R, w);
    for (size_t py = 0; py < ph; py++) {
        const float *src = hf->data + (size_t)lx_wrap_index(wrap, (int)py - R, h) * (size_t)w;
        float *dst = pad + py * pw;
        for (size_t px = 0; px < pw; px++)
            dst[px] = src[col[px]] * strength;
    }
    free(col);
    *out = pad;
    *pw_out = (int)pw;
    return LX_OK;
}

lx_status lx_horizon_map(const lx_image *height, const lx_horizon_desc *desc, lx_image *layer0,
                         lx_image *layer1, lx_image *ao)
{
    lx_image *outs[3] = {layer0, layer1, ao};
    for (int k = 0; k < 3; k++)
        if (outs[k])
            memset(outs[k], 0, sizeof *outs[k]);
    lx_horizon_desc d = lx_horizon_desc_defaults(desc);
    lx_status st = check_desc(height, &d);
    if (st != LX_OK)
        return st;
    int w = height->width, h = height->height;
    size_t count = (size_t)w * (size_t)h;
    for (size_t i = 0; i < count; i++)
        if (!isfinite(height->data[i]))
            return lx_fail(LX_ERR_INVALID, "horizon map: height at texel (%d, %d) is not finite",
                           (int)(i % (size_t)w), (int)(i / (size_t)w));

    hz_plan plan;
    if ((st = plan_make(d.angles, d.radius, &plan)) != LX_OK)
        return st;
    hz_job jb = {.plan = &plan, .sweep = pick_sweep(), .w = w, .h = h, .ao_power = d.ao_power, .ao_cosine = d.ao_cosine};
    float *pad;
    if ((st = make_padded(height, d.radius, d.wrap, d.strength, &pad, &jb.pw)) != LX_OK) {
        plan_free(&plan);
        return st;
    }
    jb.pad = pad;
    const int chans[3] = {4, 4, 1};
    for (int k = 0; k < 3 && st == LX_OK; k++)
        if (outs[k])
            st = lx_image_alloc(outs[k], w, h, chans[k]);
    if (st != LX_OK) {
        for (int k = 0; k < 3; k++)
            if (outs[k])
                lx_image_free(outs[k]);
        free(pad);
        plan_free(&plan);
        lx_error_prefix("horizon map");
        return st;
    }
    jb.l0 = layer0 ? layer0->data : NULL;
    jb.l1 = layer1 ? layer1->data : NULL;
    jb.ao = ao ? ao->data : NULL;

    int threads = lx_thread_count(d.threads);
    atomic_int done = 0;
    atomic_bool cancel = false, nomem = false;
#pragma omp parallel num_threads(threads)
    {
        float *t = malloc(sizeof *t * (size_t)d.angles * HZ_CHUNK);
        if (!t)
            atomic_store(&nomem, true);
#pragma omp for schedule(dynamic, 1)
        for (int y = 0; y < h; y++) {
            if (!t || atomic_load_explicit(&cancel, memory_order_relaxed) ||
                atomic_load_explicit(&nomem, memory_order_relaxed))
                continue;
            for (int x0 = 0; x0 < w; x0 += HZ_CHUNK)
                hz_chunk(&jb, y, x0, w - x0 < HZ_CHUNK ? w - x0 : HZ_CHUNK, t);
            int k = atomic_fetch_add(&done, 1) + 1;
            /* only the first thread reports: calls never overlap */
            if (d.progress && omp_get_thread_num() == 0 &&
                !d.progress(d.progress_user, (float)k / (float)h))
                atomic_store(&cancel, true);
        }
        free(t);
    }
    if (!atomic_load(&cancel) && !atomic_load(&nomem) && d.progress &&
        !d.progress(d.progress_user, 1.0f))
        atomic_store(&cancel, true);
    free(pad);
    plan_free(&plan);
    if (atomic_load(&cancel) || atomic_load(&nomem)) {
        for (int k = 0; k < 3; k++)
            if (outs[k])
                lx_image_free(outs[k]);
        return atomic_load(&nomem) ? lx_fail(LX_ERR_NOMEM, "horizon map: out of memory")
                                   : lx_fail(LX_ERR_CANCELLED, "horizon map: cancelled");
    }
    return LX_OK;
}
