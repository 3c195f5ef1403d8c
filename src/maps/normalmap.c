/* Normal maps from height fields (Lengyel, FGED vol. 2 sec. 7.5,
 * ConstructNormalMap; seed 002): slopes by central differences (or the
 * Sobel and Scharr operators, normalised to the same slope on a ramp),
 * n = normalize(-S dh/dx, -S dh/dy, 1) with y up the image. Unlike the
 * seed's listing, texels outside the image are addressed by a wrap mode
 * at any size (not `& (size - 1)`), and nothing is clamped: the vector is
 * normalized as a whole. Also the texture encoding rgb = n/2 + 1/2 and
 * its inverse. */
#include "normal_internal.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static const char *const filter_names[] = {"central", "sobel", "scharr"};

const char *lx_normal_filter_name(lx_normal_filter filter)
{
    return (unsigned)filter < 3 ? filter_names[filter] : NULL;
}

bool lx_normal_filter_parse(const char *name, lx_normal_filter *out)
{
    for (int k = 0; name && k < 3; k++)
        if (strcmp(name, filter_names[k]) == 0) {
            *out = (lx_normal_filter)k;
            return true;
        }
    return false;
}

lx_normalmap_desc lx_normalmap_desc_defaults(const lx_normalmap_desc *desc)
{
    lx_normalmap_desc d = {0};
    if (desc)
        d = *desc;
    if (d.strength == 0.0f)
        d.strength = LX_DEFAULT_HEIGHT_STRENGTH;
    return d;
}

lx_status lx_nm_check(const lx_image *height, const lx_normalmap_desc *d, const char *what)
{
    if (!height || !height->data || height->width < 1 || height->height < 1)
        return lx_fail(LX_ERR_INVALID, "%s: the height field has no texels", what);
    if (height->channels != 1)
        return lx_fail(LX_ERR_INVALID, "%s: the height field has %d channels, not 1", what,
                       height->channels);
    if (!isfinite(d->strength) || d->strength <= 0.0f)
        return lx_fail(LX_ERR_INVALID, "%s: strength %g must be finite and > 0", what,
                       (double)d->strength);
    if (!lx_normal_filter_name(d->filter))
        return lx_fail(LX_ERR_INVALID, "%s: unknown slope filter %d", what, (int)d->filter);
    if (!lx_wrap_name(d->wrap))
        return lx_fail(LX_ERR_INVALID, "%s: unknown wrap mode %d", what, (int)d->wrap);
    if (d->threads < 0)
        return lx_fail(LX_ERR_INVALID, "%s: thread count %d is negative", what, d->threads);
    return LX_OK;
}

/* ---- slopes ------------------------------------------------------------------ */

/* Central differences of one row r along x: out[x] = (r[x+1] - r[x-1]),
 * undivided; the two ends through wrap. */
static void diff_x(const float *r, int w, lx_wrap wrap, float *out)
{
    for (int x = 1; x < w - 1; x++)
        out[x] = r[x + 1] - r[x - 1];
    int ends[2] = {0, w - 1};
    for (int k = 0; k < (w > 1 ? 2 : 1); k++) {
        int x = ends[k];
        out[x] = r[lx_wrap_index(wrap, x + 1, w)] - r[lx_wrap_index(wrap, x - 1, w)];
    }
}

/* A row's value at x with the one on either side, weighted side-centre-
 * side: out[x] = side (r[x-1] + r[x+1]) + centre r[x]. */
static void smooth_x(const float *r, int w, lx_wrap wrap, float side, float centre, float *out)
{
    for (int x = 1; x < w - 1; x++)
        out[x] = side * (r[x - 1] + r[x + 1]) + centre * r[x];
    int ends[2] = {0, w - 1};
    for (int k = 0; k < (w > 1 ? 2 : 1); k++) {
        int x = ends[k];
        out[x] = side * (r[lx_wrap_index(wrap, x - 1, w)] + r[lx_wrap_index(wrap, x + 1, w)]) +
                 centre * r[x];
    }
}

void lx_nm_slopes_row(const lx_image *height, lx_normal_filter filter, lx_wrap wrap, int y,
                      float *dx, float *dy)
{
    int w = height->width, h = height->height;
    const float *above = height->data + (size_t)lx_wrap_index(wrap, y - 1, h) * (size_t)w;
    const float *row = height->data + (size_t)y * (size_t)w;
    const float *below = height->data + (size_t)lx_wrap_index(wrap, y + 1, h) * (size_t)w;
    if (filter == LX_NORMAL_CENTRAL) {
        diff_x(row, w, wrap, dx);
        for (int x = 0; x < w; x++) {
            dx[x] *= 0.5f;
            dy[x] = 0.5f * (above[x] - below[x]);
        }
        return;
    }
    /* Sobel 1-2-1 / 8, Scharr 3-10-3 / 32: a ramp of slope a gives a */
    float side = filter == LX_NORMAL_SOBEL ? 1.0f : 3.0f;
    float centre = filter == LX_NORMAL_SOBEL ? 2.0f : 10.0f;
    float norm = 1.0f / (2.0f * (2.0f * side + centre));
    /* dx: side (d above + d below) + centre d row, d the central difference;
     * dy: the row above smoothed less the row below smoothed */
    float *t = dy; /* scratch until dy is written */
    diff_x(above, w, wrap, dx);
    diff_x(below, w, wrap, t);
    for (int x = 0; x < w; x++)
        dx[x] += t[x];
    diff_x(row, w, wrap, t);
    for (int x = 0; x < w; x++)
        dx[x] = (side * dx[x] + centre * t[x]) * norm;
    /* dx is done; dy from the smoothed rows, the lower one kept in dy */
    smooth_x(below, w, wrap, side, centre, dy);
    for (int x = 0; x < w; x++)
        dy[x] = -dy[x];
    /* add the upper row's smoothed value, one texel at a time (no more
     * scratch): the interior in one loop, the ends through wrap */
    for (int x = 1; x < w - 1; x++)
        dy[x] = (dy[x] + side * (above[x - 1] + above[x + 1]) + centre * above[x]) * norm;
    int ends[2] = {0, w - 1};
    for (int k = 0; k < (w > 1 ? 2 : 1); k++) {
        int x = ends[k];
        float up = side * (above[lx_wrap_index(wrap, x - 1, w)] +
                           above[lx_wrap_index(wrap, x + 1, w)]) +
                   centre * above[x];
        dy[x] = (dy[x] + up) * norm;
    }
}

/* ---- rows in parallel ------------------------------------------------------------ */

/* Rows per band: small enough for progress and balance, large enough that
 * the bookkeeping is nothing (2048 rows: 64 bands). */
#define NM_BAND 32

lx_status lx_nm_run_rows(int height, size_t scratch, int threads, lx_progress_fn progress,
                         void *user, lx_nm_rows_fn fn, void *ctx, const char *what, bool *bad)
{
    int bands = (height + NM_BAND - 1) / NM_BAND;
    int n = lx_thread_count(threads);
    n = n < bands ? n : bands;
    volatile int stop = 0, nomem = 0, invalid = 0;
    int done = 0, reported = 0;
    omp_lock_t lock;
    omp_init_lock(&lock);
#pragma omp parallel num_threads(n)
    {
        float *buf = malloc(scratch * sizeof(float) + 1);
        if (!buf)
            nomem = 1;
#pragma omp for schedule(dynamic, 1)
        for (int b = 0; b < bands; b++) {
            if (stop || nomem || !buf)
                continue;
            int y0 = b * NM_BAND, y1 = y0 + NM_BAND < height ? y0 + NM_BAND : height;
            if (!fn(ctx, y0, y1, buf))
                invalid = 1;
            if (!progress)
                continue;
            int now;
#pragma omp atomic capture
            now = ++done;
            /* one report at a time, never going back */
            if (!omp_test_lock(&lock))
                continue;
            reported = now > reported ? now : reported;
            if (!stop && !progress(user, (float)reported / (float)bands))
                stop = 1;
            omp_unset_lock(&lock);
        }
        free(buf);
    }
    omp_destroy_lock(&lock);
    *bad = invalid != 0;
    if (nomem)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", what);
    if (!stop && progress && reported < bands && !progress(user, 1.0f))
        stop = 1;
    if (stop)
        return lx_fail(LX_ERR_CANCELLED, "%s cancelled", what);
    if (invalid)
        return LX_ERR_INVALID; /* the caller names the texel */
    return LX_OK;
}

/* ---- the normal map ------------------------------------------------------------- */

typedef struct nm_job {
    const lx_image *height;
    const lx_normalmap_desc *d;
    lx_image *out;
} nm_job;

static bool normal_rows(void *ctx, int y0, int y1, float *scratch)
{
    const nm_job *j = ctx;
    int w = j->height->width;
    float *dx = scratch, *dy = scratch + w;
    float s = j->d->strength;
    float sy = j->d->green_down ? s : -s;
    bool ok = true;
    for (int y = y0; y < y1; y++) {
        lx_nm_slopes_row(j->height, j->d->filter, j->d->wrap, y, dx, dy);
        float *o = j->out->data + (size_t)y * (size_t)w * 3;
        for (int x = 0; x < w; x++) {
            float nx = -s * dx[x], ny = sy * dy[x];
            float nz = 1.0f / sqrtf(nx * nx + ny * ny + 1.0f);
            o[3 * x] = nx * nz;
            o[3 * x + 1] = ny * nz;
            o[3 * x + 2] = nz;
            ok &= nz > 0.0f; /* false for NaN and for slopes that overflow */
        }
    }
    return ok;
}

/* After a row came out bad: the first height that is not finite, or the
 * strength that makes slopes overflow. */
static lx_status name_bad_height(const lx_image *height, float strength, const char *what)
{
    size_t n = (size_t)height->width * (size_t)height->height;
    for (size_t i = 0; i < n; i++)
        if (!isfinite(height->data[i]))
            return lx_fail(LX_ERR_INVALID, "%s: height texel (%zu, %zu) is %s", what,
                           i % (size_t)height->width, i / (size_t)height->width,
                           isnan(height->data[i]) ? "NaN" : "infinite");
    return lx_fail(LX_ERR_INVALID, "%s: slopes overflow a float at strength %g", what,
                   (double)strength);
}

lx_status lx_normal_map(const lx_image *height, const lx_normalmap_desc *desc, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_normal_map: out must not be NULL");
    memset(out, 0, sizeof *out);
    lx_normalmap_desc d = lx_normalmap_desc_defaults(desc);
    lx_status s = lx_nm_check(height, &d, "normal map");
    if (s != LX_OK)
        return s;
    s = lx_image_alloc(out, height->width, height->height, 3);
    if (s != LX_OK)
        return s;
    nm_job job = {height, &d, out};
    bool bad = false;
    s = lx_nm_run_rows(height->height, 2 * (size_t)height->width, d.threads, d.progress,
                       d.progress_user, normal_rows, &job, "normal map", &bad);
    if (s == LX_ERR_INVALID && bad)
        s = name_bad_height(height, d.strength, "normal map");
    if (s != LX_OK)
        lx_image_free(out);
    return s;
}

/* ---- encoding --------------------------------------------------------------------- */

lx_status lx_normal_encode(const lx_image *normals, lx_image *out)
{
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_normal_encode: out must not be NULL");
    memset(out, 0, sizeof *out);
    if (!normals || !normals->data || normals->channels < 3)
        return lx_fail(LX_ERR_INVALID, "lx_normal_encode: normals need 3 channels");
    lx_status s = lx_image_alloc(out, normals->width, normals->height, 3);
    if (s != LX_OK)
        return s;
    size_t n = (size_t)normals->width * (size_t)normals->height;
    int c = normals->channels;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            out->data[3 * i + k] = 0.5f * normals->data[i * (size_t)c + (size_t)k] + 0.5f;
    return LX_OK;
}

lx_status lx_normal_decode(const lx_image *encoded, const char *name, lx_image *out)
{
    if (!encoded)
        return lx_fail_null(__func__, "encoded");
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_normal_decode: out must not be NULL");
    memset(out, 0, sizeof *out);
    name = name ? name : "normal map";
    if (!encoded || !encoded->data || encoded->width < 1 || encoded->height < 1)
        return lx_fail(LX_ERR_FORMAT, "%s: the image has no pixels", name);
    if (encoded->channels < 3)
        return lx_fail(LX_ERR_FORMAT, "%s: %d channel%s; a normal map needs RGB or RGBA", name,
                       encoded->channels, encoded->channels == 1 ? "" : "s");
    lx_status s = lx_image_alloc(out, encoded->width, encoded->height, 3);
    if (s != LX_OK)
        return s;
    size_t n = (size_t)encoded->width * (size_t)encoded->height;
    int c = encoded->channels;
    for (size_t i = 0; i < n; i++) {
        const float *e = encoded->data + i * (size_t)c;
        double v[3], len2 = 0.0;
        for (int k = 0; k < 3; k++) {
            v[k] = 2.0 * (double)e[k] - 1.0;
            len2 += v[k] * v[k];
        }
        if (!(len2 > 0.0) || !isfinite(len2)) {
            size_t x = i % (size_t)encoded->width, y = i / (size_t)encoded->width;
            lx_image_free(out);
            return lx_fail(LX_ERR_FORMAT, "%s: pixel (%zu, %zu) is not a direction (%s)", name, x,
                           y, isfinite(len2) ? "zero length" : "not finite");
        }
        double inv = 1.0 / sqrt(len2);
        for (int k = 0; k < 3; k++)
            out->data[3 * i + k] = (float)(v[k] * inv);
    }
    return LX_OK;
}
