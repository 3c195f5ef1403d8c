/* Environments out of cube maps: a cube map and its mip levels written in
 * the layouts engines read - six face images per level, a horizontal or
 * vertical cross, an equirect, or one KTX 1.1 file with the levels as its
 * mips (ktx.c) - each file atomically (lx_image_write, lx_out_*), named
 * from a stem so a caller can tell, and track, every file before it is
 * made. */
#include "ibl_internal.h"
#include "core/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define MAX_FILES (6 * LX_MAX_CUBE_MIPS)
#define MAX_NAME 256

lx_env_write_desc lx_env_write_desc_defaults(const lx_env_write_desc *desc)
{
    lx_env_write_desc d = {0};
    if (desc)
        d = *desc;
    if (d.layout == LX_ENV_AUTO)
        d.layout = LX_ENV_FACES;
    if (d.format == LX_IMAGE_AUTO)
        d.format = LX_IMAGE_EXR;
    if (d.exposure == 0.0f)
        d.exposure = 1.0f;
    return d;
}

static const char *layout_name(lx_env_layout layout)
{
    switch (layout) {
    case LX_ENV_FACES:
        return "six faces";
    case LX_ENV_CROSS:
        return "a cross";
    case LX_ENV_CROSS_VERTICAL:
        return "a vertical cross";
    case LX_ENV_EQUIRECT:
        return "an equirect";
    default:
        return "KTX";
    }
}

/* Checks the desc (defaults filled) and the stem. */
static lx_status check_desc(const char *stem, int count, const lx_env_write_desc *d)
{
    if (!stem || !stem[0] || strchr(stem, '/') || strlen(stem) > 200)
        return lx_fail(LX_ERR_INVALID,
                       "environment output: the stem '%s' must be a file name of 1..200 "
                       "characters without '/'",
                       stem ? stem : "(NULL)");
    if (count < 1 || count > LX_MAX_CUBE_MIPS)
        return lx_fail(LX_ERR_INVALID, "%s: %d levels to write (expected 1..%d)", stem, count,
                       LX_MAX_CUBE_MIPS);
    if (d->layout != LX_ENV_FACES && d->layout != LX_ENV_CROSS &&
        d->layout != LX_ENV_CROSS_VERTICAL && d->layout != LX_ENV_EQUIRECT &&
        d->layout != LX_ENV_KTX)
        return lx_fail(LX_ERR_INVALID, "%s: unknown output layout %d", stem, (int)d->layout);
    if (d->layout != LX_ENV_KTX && !lx_image_format_extension(d->format))
        return lx_fail(LX_ERR_INVALID, "%s: unknown image format %d", stem, (int)d->format);
    if (d->half && d->layout != LX_ENV_KTX && d->format != LX_IMAGE_EXR)
        return lx_fail(LX_ERR_INVALID,
                       "%s: half floats are for EXR images and KTX files, not %s images", stem,
                       lx_image_format_extension(d->format));
    if (!isfinite(d->exposure) || d->exposure < 0.0f)
        return lx_fail(LX_ERR_INVALID, "%s: exposure %g must be a finite value >= 0", stem,
                       (double)d->exposure);
    if (!lx_tonemap_name(d->tonemap))
        return lx_fail(LX_ERR_INVALID, "%s: unknown tone curve %d", stem, (int)d->tonemap);
    return lx_ibl_check_threads(d->threads);
}

/* Bytes of the image one level of size is written from, besides the
 * levels: the converted image and what the encoder copies of it. */
static uint64_t level_work(int size, const lx_env_write_desc *d)
{
    uint64_t n2 = (uint64_t)size * (uint64_t)size;
    switch (d->layout) {
    case LX_ENV_FACES:
        return 12 * n2;
    case LX_ENV_CROSS:
    case LX_ENV_CROSS_VERTICAL:
        return 2 * 144 * n2;
    case LX_ENV_EQUIRECT:
        return 2 * 96 * n2;
    default:
        return 16ull * (uint64_t)size;
    }
}

static lx_status check_memory(const char *stem, const int *sizes, int count,
                              const lx_env_write_desc *d)
{
    uint64_t held = 0, work = 0;
    for (int l = 0; l < count; l++) {
        held += lx_ibl_cube_bytes(sizes[l]);
        uint64_t w = level_work(sizes[l], d);
        work = w > work ? w : work;
    }
    char what[320];
    snprintf(what, sizeof what, "%s: writing %d level%s of %d x %d faces as %s", stem, count,
             count == 1 ? "" : "s", sizes[0], sizes[0], layout_name(d->layout));
    return lx_check_memory(held + work, what);
}

lx_status lx_env_write_check(int size, int count, const lx_env_write_desc *desc)
{
    lx_env_write_desc d = lx_env_write_desc_defaults(desc);
    lx_status st = check_desc("environment", count, &d);
    if (st != LX_OK)
        return st;
    if (size < 1 || size > LX_MAX_CUBE_SIZE)
        return lx_fail(LX_ERR_INVALID, "environment: face size %d is outside 1..%d", size,
                       LX_MAX_CUBE_SIZE);
    int sizes[LX_MAX_CUBE_MIPS] = {0};
    for (int l = 0; l < count; l++)
        sizes[l] = size >> l > 0 ? size >> l : 1;
    return check_memory("environment", sizes, count, &d);
}

/* The name of file `face` (ignored but for FACES) of `level` of count
 * levels: <stem>.ktx, else <stem>[_m<L>][_<face>].<ext>. */
static void file_name(char *name, size_t size, const char *stem, int level, int count, int face,
                      const lx_env_write_desc *d)
{
    if (d->layout == LX_ENV_KTX) {
        snprintf(name, size, "%s.ktx", stem);
        return;
    }
    char base[MAX_NAME - 16];
    if (count > 1 || d->mip_names)
        snprintf(base, sizeof base, "%s_m%d", stem, level);
    else
        snprintf(base, sizeof base, "%s", stem);
    const char *ext = lx_image_format_extension(d->format);
    if (d->layout == LX_ENV_FACES)
        snprintf(name, size, "%s_%s.%s", base, lx_cube_face_name(face), ext);
    else
        snprintf(name, size, "%s.%s", base, ext);
}

lx_status lx_env_write_names(const char *stem, int count, const lx_env_write_desc *desc)
{
    lx_env_write_desc d = lx_env_write_desc_defaults(desc);
    lx_status st = check_desc(stem, count, &d);
    if (st != LX_OK || !d.on_file)
        return st;
    int per_level = d.layout == LX_ENV_FACES ? 6 : 1;
    int files = d.layout == LX_ENV_KTX ? 1 : count * per_level;
    for (int i = 0; i < files; i++) {
        char name[MAX_NAME];
        file_name(name, sizeof name, stem, i / per_level, count, i % per_level, &d);
        if (!d.on_file(d.on_file_user, name))
            return lx_fail(LX_ERR_CANCELLED, "%s: cancelled", name);
    }
    return LX_OK;
}

/* What one call has written so far: the paths, to remove them again. */
typedef struct written {
    int count;
    char *path[MAX_FILES];
} written;

static void remove_written(written *w)
{
    for (int i = 0; i < w->count; i++) {
        unlink(w->path[i]);
        free(w->path[i]);
    }
    w->count = 0;
}

/* The path of file `name` in folder (malloc'd) after telling the caller:
 * fails when the caller stops the write or memory runs out. */
static lx_status file_path(const char *folder, const char *name, const lx_env_write_desc *d,
                           char **path)
{
    *path = lx_path_join(folder, name);
    if (!*path)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", name);
    if (d->on_file && !d->on_file(d->on_file_user, name)) {
        lx_status st = lx_fail(LX_ERR_CANCELLED, "%s: writing cancelled", *path);
        free(*path);
        *path = NULL;
        return st;
    }
    return LX_OK;
}

/* The caller's callback, never told a smaller fraction than before: the
 * parts of the run are computed in float, and where one ends and the
 * next begins may differ by a rounding. Calls come one at a time. */
typedef struct monotonic {
    lx_progress_fn fn;
    void *user;
    float last;
} monotonic;

static bool monotonic_progress(void *user, float fraction)
{
    monotonic *m = user;
    m->last = fraction > m->last ? fraction : m->last;
    return m->fn(m->user, m->last);
}

/* An image's writing as the part [run->base, run->base + run->span] of
 * the whole. */
static bool image_progress(void *user, float fraction)
{
    const lx_ibl_run *run = user;
    return run->progress(run->user, run->base + run->span * fraction);
}

/* Writes one image file, reporting on `part` of the run, and records it. */
static lx_status put_image(const char *folder, const char *name, const lx_image *img,
                           const lx_env_write_desc *d, const lx_ibl_run *part, written *w)
{
    char *path;
    lx_status st = file_path(folder, name, d, &path);
    if (st != LX_OK)
        return st;
    bool eight =
        d->format != LX_IMAGE_EXR && d->format != LX_IMAGE_HDR && d->format != LX_IMAGE_PFM;
    lx_image_write_desc wd = {.format = d->format,
                              .exposure = eight ? d->exposure : 1.0f,
                              .tonemap = d->tonemap,
                              .half = d->half,
                              .threads = d->threads,
                              .progress = part->progress ? image_progress : NULL,
                              .progress_user = (void *)part};
    st = lx_image_write(path, img, &wd);
    if (st != LX_OK) {
        free(path);
        return st;
    }
    w->path[w->count++] = path;
    return LX_OK;
}

lx_status lx_env_write(const char *folder, const char *stem, const lx_cubemap *levels, int count,
                       const lx_env_write_desc *desc)
{
    lx_env_write_desc d = lx_env_write_desc_defaults(desc);
    if (!stem) /* a NULL stem is named first, as check_desc names it */
        return check_desc(stem, count, &d);
    if (!levels)
        return lx_fail(LX_ERR_INVALID, "%s: no levels (NULL)", stem);
    if (!folder || !folder[0])
        return lx_fail(LX_ERR_INVALID, "environment output: no folder given");
    lx_status st = check_desc(stem, count, &d);
    if (st != LX_OK)
        return st;
    int sizes[LX_MAX_CUBE_MIPS] = {0};
    for (int l = 0; l < count; l++) {
        char what[240];
        snprintf(what, sizeof what, "%s: level %d", stem, l);
        if ((st = lx_ibl_check_cubemap(&levels[l], what, false)) != LX_OK)
            return st;
        sizes[l] = levels[l].size;
    }
    if ((st = check_memory(stem, sizes, count, &d)) != LX_OK)
        return st;
    monotonic mono = {d.progress, d.progress_user, 0.0f};
    lx_ibl_run run = lx_ibl_run_make(d.threads, d.progress ? monotonic_progress : NULL, &mono);
    char name[MAX_NAME];
    if (d.layout == LX_ENV_KTX) {
        file_name(name, sizeof name, stem, 0, count, 0, &d);
        char *path;
        if ((st = file_path(folder, name, &d, &path)) != LX_OK)
            return st;
        st = lx_ibl_ktx_write(path, levels, count, d.half, &run);
        free(path);
        return st;
    }
    written w = {0};
    /* progress by texels, a level's conversion and writing each half of it */
    double total = 0.0, done = 0.0;
    for (int l = 0; l < count; l++)
        total += (double)sizes[l] * sizes[l];
    for (int l = 0; l < count && st == LX_OK; l++) {
        const lx_cubemap *c = &levels[l];
        double part = (double)c->size * c->size;
        if (d.layout == LX_ENV_FACES) {
            for (int f = 0; f < 6 && st == LX_OK; f++) {
                file_name(name, sizeof name, stem, l, count, f, &d);
                lx_image face = lx_cubemap_face_image(c, f);
                lx_ibl_run file = lx_ibl_run_part(&run, (done + part * f / 6.0) / total,
                                                  (done + part * (f + 1) / 6.0) / total);
                st = put_image(folder, name, &face, &d, &file, &w);
                if (st == LX_OK && run.progress &&
                    !run.progress(run.user, (float)((done + part * (f + 1) / 6.0) / total)))
                    st = lx_fail(LX_ERR_CANCELLED, "%s: writing cancelled", stem);
            }
        } else {
            lx_image img;
            lx_ibl_run conv = lx_ibl_run_part(&run, done / total, (done + 0.5 * part) / total);
            st = d.layout == LX_ENV_EQUIRECT
                     ? lx_ibl_cube_to_equirect(c, 4 * c->size, &conv, &img)
                     : lx_ibl_cube_to_cross(c, d.layout == LX_ENV_CROSS_VERTICAL, &conv, &img);
            if (st == LX_OK) {
                file_name(name, sizeof name, stem, l, count, 0, &d);
                lx_ibl_run file =
                    lx_ibl_run_part(&run, (done + 0.5 * part) / total, (done + part) / total);
                st = put_image(folder, name, &img, &d, &file, &w);
                lx_image_free(&img);
            }
            if (st == LX_OK && run.progress &&
                !run.progress(run.user, (float)((done + part) / total)))
                st = lx_fail(LX_ERR_CANCELLED, "%s: writing cancelled", stem);
        }
        done += part;
    }
    if (st != LX_OK)
        remove_written(&w);
    for (int i = 0; i < w.count; i++)
        free(w.path[i]);
    return st;
}
