/* Heights from a normal map: the least-squares integration of its slope
 * field, solved exactly with fast transforms (the Poisson approach of
 * Simchony, Chellappa and Shao, "Direct analytical methods for solving
 * Poisson equations in computer vision problems", IEEE PAMI 12(5), 1990;
 * Frankot and Chellappa 1988 for the periodic case).
 *
 * Each normal n gives the slopes g = (-n.x / n.z, -n.y / n.z) in texels of
 * height per texel, x along the columns and y up the image (the inverse of
 * normalmap.c's n ~ (-dh/dx, -dh/dy, 1)). Every pair of neighbouring texels
 * p, q asks h(q) - h(p) to be the mean of their slopes along the step
 * (down a column, one row lower is -g.y). Heights minimising the sum of the
 * squared misfits solve the normal equations -L h = b: L the 5-point graph
 * Laplacian, b the divergence of the step slopes. With wrap REPEAT the
 * steps wrap around the edges (a torus) and the discrete Fourier transform
 * diagonalises L (eigenvalues -4 sin^2(pi k / W) - 4 sin^2(pi l / H));
 * with CLAMP or MIRROR there are no steps across the edges (Neumann
 * boundaries) and the cosine transform DCT-II diagonalises it
 * (-4 sin^2(pi k / 2W) - 4 sin^2(pi l / 2H)). The constant, the one thing
 * the slopes leave free, is chosen so the lowest height is 0.
 *
 * A step of the mean slope recovers central-difference normals (the
 * normal map's own) exactly below a quarter of the sampling rate and
 * attenuates finer detail by cos^2(pi f) (f in cycles per texel); a smooth
 * field's heights come back to within about (pi f)^2 / 3 of themselves. */
#include "fft_internal.h"
#include "luxel/maps.h"
#include "core/internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HN_PI 3.14159265358979323846
/* Columns gathered and transformed together: a block's part of a row
 * spans whole cache lines and the gather touches each page once a block. */
#define HN_BLOCK 32
/* A normal's z below this counts as this: slopes at most 16. */
#define HN_MIN_Z (1.0 / 16.0)

lx_height_from_normals_desc
lx_height_from_normals_desc_defaults(const lx_height_from_normals_desc *desc)
{
    lx_height_from_normals_desc d;
    if (desc)
        d = *desc;
    else
        memset(&d, 0, sizeof d);
    return d;
}

typedef struct hn_job {
    int w, h;
    bool periodic; /* complex values (2 doubles) per texel, else 1 */
    double *v;     /* the right-hand side, its transform, then the heights */
    lx_fft_plan row, col;
    int threads;
} hn_job;

/* One pass of 1-D transforms along rows (along_rows) or columns, forward
 * or inverse. LX_ERR_NOMEM when a thread's scratch cannot be had. */
static lx_status pass(hn_job *j, bool along_rows, bool inverse)
{
    const lx_fft_plan *p = along_rows ? &j->row : &j->col;
    int len = p->n, lines = along_rows ? j->h : j->w;
    /* real data: the spectrum's columns k and W - k are conjugate, so
     * columns 0..W/2 are all the solve needs (real_rows fills the rest) */
    if (!along_rows && j->periodic)
        lines = j->w / 2 + 1;
    int per = j->periodic ? 2 : 1; /* doubles per value */
    int block = along_rows ? 1 : HN_BLOCK;
    int tasks = (lines + block - 1) / block;
    size_t rowlen = (size_t)j->w * (size_t)per;
    volatile int nomem = 0;
#pragma omp parallel num_threads(lx_thread_count(j->threads))
    {
        size_t line_doubles = (size_t)len * (size_t)(j->periodic ? 2 : 1);
        double *scratch = malloc(sizeof(double) * (lx_fft_scratch(p) + line_doubles * block));
        if (!scratch)
            nomem = 1;
#pragma omp for schedule(dynamic, 4)
        for (int t = 0; t < tasks; t++) {
            if (!scratch)
                continue;
            double *buf = scratch + lx_fft_scratch(p);
            int first = t * block, count = first + block <= lines ? block : lines - first;
            for (int c = 0; c < count; c++) {
                double *line;
                if (along_rows) {
                    line = j->v + (size_t)(first + c) * rowlen;
                } else {
                    line = buf + (size_t)c * line_doubles;
                    size_t x = (size_t)(first + c) * (size_t)per;
                    for (int y = 0; y < len; y++)
                        for (int k = 0; k < per; k++)
                            line[(size_t)y * per + k] = j->v[(size_t)y * rowlen + x + k];
                }
                if (j->periodic)
                    lx_fft(p, line, inverse, scratch);
                else if (inverse)
                    lx_idct(p, line, scratch);
                else
                    lx_dct(p, line, scratch);
                if (!along_rows) {
                    size_t x = (size_t)(first + c) * (size_t)per;
                    for (int y = 0; y < len; y++)
                        for (int k = 0; k < per; k++)
                            j->v[(size_t)y * rowlen + x + k] = line[(size_t)y * per + k];
                }
            }
        }
        free(scratch);
    }
    return nomem ? lx_fail(LX_ERR_NOMEM, "heights from normals: out of memory") : LX_OK;
}

/* The periodic case's row transforms of real data, two rows in one complex
 * transform (rows 2q and 2q + 1, the same pairs for any thread count).
 * Forward: z = a + i b, Z = F(z), A_k = (Z_k + conj Z_-k) / 2,
 * B_k = (Z_k - conj Z_-k) / 2i. Inverse: rows whose spectra are only valid
 * for k <= W/2 (conjugate above), z = A + i B, F^-1(z) = a + i b, the real
 * results in the real parts. */
static lx_status real_rows(hn_job *j, bool inverse)
{
    const lx_fft_plan *p = &j->row;
    int w = j->w, pairs = (j->h + 1) / 2;
    size_t rowlen = 2 * (size_t)w;
    volatile int nomem = 0;
#pragma omp parallel num_threads(lx_thread_count(j->threads))
    {
        double *scratch = malloc(sizeof(double) * (lx_fft_scratch(p) + rowlen));
        if (!scratch)
            nomem = 1;
#pragma omp for schedule(dynamic, 4)
        for (int q = 0; q < pairs; q++) {
            if (!scratch)
                continue;
            double *z = scratch + lx_fft_scratch(p);
            double *a = j->v + (size_t)(2 * q) * rowlen;
            double *b = 2 * q + 1 < j->h ? a + rowlen : NULL; /* none: the last of odd H */
            if (!inverse) {
                for (int k = 0; k < w; k++) {
                    z[2 * k] = a[2 * k];
                    z[2 * k + 1] = b ? b[2 * k] : 0.0;
                }
                lx_fft(p, z, false, scratch);
                for (int k = 0; k < w; k++) {
                    int m = k ? w - k : 0;
                    double zr = z[2 * k], zi = z[2 * k + 1], mr = z[2 * m], mi = z[2 * m + 1];
                    a[2 * k] = 0.5 * (zr + mr);
                    a[2 * k + 1] = 0.5 * (zi - mi);
                    if (b) {
                        b[2 * k] = 0.5 * (zi + mi);
                        b[2 * k + 1] = -0.5 * (zr - mr);
                    }
                }
            } else {
                for (int k = 0; k < w; k++) {
                    /* above W/2 the conjugate of W - k */
                    int m = k <= w / 2 ? k : w - k;
                    double sg = k <= w / 2 ? 1.0 : -1.0;
                    double ar = a[2 * m], ai = sg * a[2 * m + 1];
                    double br = b ? b[2 * m] : 0.0, bi = b ? sg * b[2 * m + 1] : 0.0;
                    z[2 * k] = ar - bi;
                    z[2 * k + 1] = ai + br;
                }
                lx_fft(p, z, true, scratch);
                for (int k = 0; k < w; k++) {
                    a[2 * k] = z[2 * k];
                    if (b)
                        b[2 * k] = z[2 * k + 1];
                }
            }
        }
        free(scratch);
    }
    return nomem ? lx_fail(LX_ERR_NOMEM, "heights from normals: out of memory") : LX_OK;
}

/* Slopes of every texel into gx, gy (x along columns, y up the image);
 * false with *bad the first texel (in row order) whose normal is not a
 * finite non-zero vector. */
static bool slopes(const lx_image *n, bool green_down, int threads, float *gx, float *gy,
                   size_t *bad)
{
    size_t count = (size_t)n->width * (size_t)n->height;
    size_t first_bad = count;
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(threads)) \
    reduction(min : first_bad)
    for (int64_t ii = 0; ii < (int64_t)count; ii++) {
        size_t i = (size_t)ii;
        const float *t = n->data + i * (size_t)n->channels;
        double x = t[0], y = green_down ? -(double)t[1] : t[1], z = t[2];
        double len = sqrt(x * x + y * y + z * z);
        if (!isfinite(len) || !(len > 0.0)) {
            first_bad = i < first_bad ? i : first_bad;
            gx[i] = gy[i] = 0.0f;
            continue;
        }
        z /= len;
        z = z < HN_MIN_Z ? HN_MIN_Z : z;
        gx[i] = (float)(-(x / len) / z);
        gy[i] = (float)(-(y / len) / z);
    }
    *bad = first_bad;
    return first_bad == count;
}

/* The right-hand side b = -(divergence of the step slopes) into j->v. */
static void divergence(hn_job *j, const float *gx, const float *gy)
{
    int w = j->w, h = j->h, per = j->periodic ? 2 : 1;
    bool wrap = j->periodic;
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(j->threads))
    for (int r = 0; r < h; r++) {
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)r * (size_t)w + (size_t)x;
            double b = 0.0;
            /* step x -> x + 1 wants h(x+1) - h(x) = (gx(x) + gx(x+1)) / 2 */
            if (x + 1 < w || wrap) {
                size_t q = (size_t)r * (size_t)w + (size_t)((x + 1) % w);
                b -= 0.5 * ((double)gx[i] + gx[q]);
            }
            if (x > 0 || wrap) {
                size_t q = (size_t)r * (size_t)w + (size_t)((x + w - 1) % w);
                b += 0.5 * ((double)gx[i] + gx[q]);
            }
            /* step r -> r + 1 (down) wants h(r+1) - h(r) = -(gy(r) + gy(r+1)) / 2 */
            if (r + 1 < h || wrap) {
                size_t q = (size_t)((r + 1) % h) * (size_t)w + (size_t)x;
                b += 0.5 * ((double)gy[i] + gy[q]);
            }
            if (r > 0 || wrap) {
                size_t q = (size_t)((r + h - 1) % h) * (size_t)w + (size_t)x;
                b -= 0.5 * ((double)gy[i] + gy[q]);
            }
            j->v[i * (size_t)per] = b;
            if (per == 2)
                j->v[i * 2 + 1] = 0.0;
        }
    }
}

/* Divides each transformed value by the eigenvalue of -L (the constant
 * mode, eigenvalue 0, set to 0). */
static lx_status solve_spectrum(hn_job *j)
{
    int w = j->w, h = j->h, per = j->periodic ? 2 : 1;
    double ax = j->periodic ? HN_PI / w : HN_PI / (2.0 * w);
    double ay = j->periodic ? HN_PI / h : HN_PI / (2.0 * h);
    /* 4 sin^2 along each axis, once */
    double *ex = malloc(sizeof(double) * ((size_t)w + (size_t)h));
    if (!ex)
        return lx_fail(LX_ERR_NOMEM, "heights from normals: out of memory");
    double *ey = ex + w;
    for (int k = 0; k < w; k++)
        ex[k] = 4.0 * sin(ax * k) * sin(ax * k);
    for (int l = 0; l < h; l++)
        ey[l] = 4.0 * sin(ay * l) * sin(ay * l);
#pragma omp parallel for schedule(static) num_threads(lx_thread_count(j->threads))
    for (int l = 0; l < h; l++) {
        double *row = j->v + (size_t)l * (size_t)w * (size_t)per;
        for (int k = 0; k < w; k++) {
            double lambda = ex[k] + ey[l];
            double f = lambda > 0.0 ? 1.0 / lambda : 0.0;
            for (int c = 0; c < per; c++)
                row[(size_t)k * per + c] *= f;
        }
    }
    free(ex);
    return LX_OK;
}

static bool report(const lx_height_from_normals_desc *d, float f)
{
    return !d->progress || d->progress(d->progress_user, f);
}

lx_status lx_height_from_normals(const lx_image *normals, const lx_height_from_normals_desc *desc,
                                 lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "heights from normals: out must not be NULL");
    memset(out, 0, sizeof *out);
    lx_height_from_normals_desc d = lx_height_from_normals_desc_defaults(desc);
    if (!normals || !normals->data || normals->width < 1 || normals->height < 1)
        return lx_fail(LX_ERR_INVALID, "heights from normals: the normal map has no texels");
    if (normals->channels < 3)
        return lx_fail(LX_ERR_INVALID, "heights from normals: the normal map has %d channels, not 3",
                       normals->channels);
    if (!lx_wrap_name(d.wrap))
        return lx_fail(LX_ERR_INVALID, "heights from normals: unknown wrap mode %d", (int)d.wrap);
    if (d.threads < 0)
        return lx_fail(LX_ERR_INVALID, "heights from normals: thread count %d is negative",
                       d.threads);
    int w = normals->width, h = normals->height;
    hn_job j = {.w = w, .h = h, .periodic = d.wrap == LX_WRAP_REPEAT, .threads = d.threads};
    size_t count = (size_t)w * (size_t)h;
    /* values, slopes and the output at once */
    uint64_t bytes = (uint64_t)count * ((j.periodic ? 16u : 8u) + 8u + 4u);
    char what[96];
    snprintf(what, sizeof what, "heights from a %dx%d normal map", w, h);
    lx_status st = lx_check_memory(bytes, what);
    if (st != LX_OK)
        return st;
    float *gx = malloc(sizeof(float) * count), *gy = malloc(sizeof(float) * count);
    j.v = malloc(sizeof(double) * count * (j.periodic ? 2 : 1));
    if (!gx || !gy || !j.v) {
        st = lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
        goto done;
    }
    if ((st = lx_fft_plan_make(w, &j.row)) != LX_OK || (st = lx_fft_plan_make(h, &j.col)) != LX_OK)
        goto done;
    size_t bad;
    if (!slopes(normals, d.green_down, d.threads, gx, gy, &bad)) {
        st = lx_fail(LX_ERR_INVALID,
                     "heights from normals: the normal at texel (%zu, %zu) is not a finite, "
                     "non-zero vector",
                     bad % (size_t)w, bad / (size_t)w);
        goto done;
    }
    divergence(&j, gx, gy);
    free(gx);
    free(gy);
    gx = gy = NULL;
    /* forward along rows and columns, solve, back along columns and rows */
    static const struct {
        bool rows, inverse;
    } steps[4] = {{true, false}, {false, false}, {false, true}, {true, true}};
    float f = 0.1f;
    for (int s = 0; s < 4 && st == LX_OK; s++) {
        if (!report(&d, f)) {
            st = lx_fail(LX_ERR_CANCELLED, "heights from normals cancelled");
            break;
        }
        st = steps[s].rows && j.periodic ? real_rows(&j, steps[s].inverse)
                                         : pass(&j, steps[s].rows, steps[s].inverse);
        if (s == 1 && st == LX_OK)
            st = solve_spectrum(&j);
        f += 0.2f;
    }
    if (st != LX_OK)
        goto done;
    if ((st = lx_image_alloc(out, w, h, 1)) != LX_OK)
        goto done;
    /* the real part, scaled (the inverse Fourier transform is unscaled);
     * the lowest height at 0 */
    int per = j.periodic ? 2 : 1;
    double scale = j.periodic ? 1.0 / ((double)w * (double)h) : 1.0;
    double lo = INFINITY;
    for (size_t i = 0; i < count; i++)
        lo = j.v[i * (size_t)per] < lo ? j.v[i * (size_t)per] : lo;
    for (size_t i = 0; i < count; i++)
        out->data[i] = (float)((j.v[i * (size_t)per] - lo) * scale);
    if (!report(&d, 1.0f)) {
        lx_image_free(out);
        st = lx_fail(LX_ERR_CANCELLED, "heights from normals cancelled");
    }
done:
    free(gx);
    free(gy);
    free(j.v);
    lx_fft_plan_free(&j.row);
    lx_fft_plan_free(&j.col);
    if (st != LX_OK)
        lx_image_free(out);
    return st;
}
