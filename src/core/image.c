/* Images: allocation, the sRGB transfer function (IEC 61966-2-1:1999),
 * format detection, channel conversion and the checks shared by every
 * reader and writer. The codecs live in image_io.c (stb), image_pfm.c and
 * image_exr.c. */
#include "image_internal.h"
#include "luxel/math.h"

#include <ctype.h>
#include <float.h>
#include <inttypes.h>
#include <limits.h>
#include <stdio.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef __linux__
#include <sys/mman.h>
#endif

/* ---- allocation ----------------------------------------------------------- */

/* Large images live in fresh pages (calloc maps them untouched), and the
 * first write to each 4 KiB page faults: for a 2048^2 RGB image that is
 * 12k faults, most of the cost of filling it. Asking for transparent huge
 * pages over the 2 MiB-aligned interior makes that 24 faults. Advice only:
 * where the kernel declines, nothing changes. */
static void advise_huge_pages(void *data, size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const uintptr_t huge = (uintptr_t)2 << 20;
    if (bytes < 4 * huge)
        return;
    uintptr_t begin = ((uintptr_t)data + huge - 1) & ~(huge - 1);
    uintptr_t end = ((uintptr_t)data + bytes) & ~(huge - 1);
    if (end > begin)
        (void)madvise((void *)begin, end - begin, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

lx_status lx_image_alloc(lx_image *img, int width, int height, int channels)
{
    if (!img)
        return lx_fail_null(__func__, "img");
    memset(img, 0, sizeof *img);
    if (width < 1 || height < 1 || channels < 1 || channels > 4)
        return lx_fail(LX_ERR_INVALID,
                       "image %dx%d with %d channels: width and height must be "
                       ">= 1 and channels 1..4",
                       width, height, channels);
    size_t count, bytes;
    if (!lx_size_mul((size_t)width, (size_t)height, (size_t)channels, &count) ||
        !lx_size_mul(count, sizeof(float), 1, &bytes))
        return lx_fail(LX_ERR_NOMEM, "image %dx%d with %d channels: size overflows memory", width,
                       height, channels);
    char what[96];
    snprintf(what, sizeof what, "image %dx%d (%d channels)", width, height, channels);
    lx_status s = lx_check_memory(bytes, what);
    if (s != LX_OK)
        return s;
    float *data = calloc(count, sizeof(float));
    if (!data)
        return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", what, bytes);
    advise_huge_pages(data, bytes);
    img->width = width;
    img->height = height;
    img->channels = channels;
    img->data = data;
    return LX_OK;
}

void lx_image_free(lx_image *img)
{
    if (!img)
        return;
    free(img->data);
    memset(img, 0, sizeof *img);
}

/* ---- sRGB ------------------------------------------------------------------ */

/* Computed in double so 8-bit code values round the same way as the
 * published formula; the segments meet at 0.04045 / 0.0031308. */
float lx_srgb_to_linear(float c)
{
    double v = c;
    if (v <= 0.04045)
        return (float)(v / 12.92);
    return (float)pow((v + 0.055) / 1.055, 2.4);
}

float lx_linear_to_srgb(float c)
{
    double v = c;
    if (v <= 0.0031308)
        return (float)(v * 12.92);
    return (float)(1.055 * pow(v, 1.0 / 2.4) - 0.055);
}

/* ---- formats ------------------------------------------------------------- */

static const struct {
    const char *ext;
    lx_image_format format;
} format_exts[] = {
    {"exr", LX_IMAGE_EXR}, {"hdr", LX_IMAGE_HDR},  {"pfm", LX_IMAGE_PFM}, {"png", LX_IMAGE_PNG},
    {"jpg", LX_IMAGE_JPG}, {"jpeg", LX_IMAGE_JPG}, {"tga", LX_IMAGE_TGA},
};

lx_image_format lx_image_format_from_path(const char *path)
{
    if (!path)
        return LX_IMAGE_AUTO;
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    if (!dot || dot == base)
        return LX_IMAGE_AUTO;
    const char *ext = dot + 1;
    for (size_t i = 0; i < sizeof format_exts / sizeof format_exts[0]; i++) {
        const char *a = ext, *b = format_exts[i].ext;
        while (*a && *b && tolower((unsigned char)*a) == *b) {
            a++;
            b++;
        }
        if (!*a && !*b)
            return format_exts[i].format;
    }
    return LX_IMAGE_AUTO;
}

const char *lx_image_format_extension(lx_image_format format)
{
    switch (format) {
    case LX_IMAGE_EXR:
        return "exr";
    case LX_IMAGE_HDR:
        return "hdr";
    case LX_IMAGE_PFM:
        return "pfm";
    case LX_IMAGE_PNG:
        return "png";
    case LX_IMAGE_JPG:
        return "jpg";
    case LX_IMAGE_TGA:
        return "tga";
    case LX_IMAGE_AUTO:
        break;
    }
    return NULL;
}

/* The format named by the file's first bytes (AUTO when none matches).
 * Content wins over the extension so a JPEG saved as .png still loads. */
static lx_image_format sniff_format(const unsigned char *d, size_t n)
{
    if (n >= 4 && d[0] == 0x76 && d[1] == 0x2f && d[2] == 0x31 && d[3] == 0x01)
        return LX_IMAGE_EXR;
    if (n >= 8 && memcmp(d, "\x89PNG\r\n\x1a\n", 8) == 0)
        return LX_IMAGE_PNG;
    if (n >= 3 && d[0] == 0xff && d[1] == 0xd8 && d[2] == 0xff)
        return LX_IMAGE_JPG;
    if (n >= 2 && d[0] == '#' && d[1] == '?')
        return LX_IMAGE_HDR;
    if (n >= 3 && d[0] == 'P' && (d[1] == 'F' || d[1] == 'f') && isspace(d[2]))
        return LX_IMAGE_PFM;
    return LX_IMAGE_AUTO;
}

/* TGA has no signature. Only a plausible header goes to stb, so stb's other
 * decoders (GIF, PSD, PIC, ...) never see luxel's input: all of their
 * signatures fail this test. */
static bool plausible_tga(const unsigned char *d, size_t n)
{
    if (n < 18 || d[1] > 1)
        return false;
    switch (d[2]) {
    case 1:
    case 2:
    case 3:
    case 9:
    case 10:
    case 11:
        return true;
    default:
        return false;
    }
}

static const char *format_title(lx_image_format f)
{
    switch (f) {
    case LX_IMAGE_EXR:
        return "an OpenEXR file (bad magic number)";
    case LX_IMAGE_HDR:
        return "a Radiance HDR file (no \"#?\" header)";
    case LX_IMAGE_PFM:
        return "a PFM file (header must start with \"PF\" or \"Pf\")";
    case LX_IMAGE_PNG:
        return "a PNG file (no PNG signature)";
    case LX_IMAGE_JPG:
        return "a JPEG file (no JPEG marker)";
    case LX_IMAGE_TGA:
        return "a TGA file (implausible header)";
    case LX_IMAGE_AUTO:
        break;
    }
    return "an image";
}

/* ---- loading ----------------------------------------------------------------- */

lx_status lx_img_check_size(const lx_img_budget *budget, const char *name, int64_t w, int64_t h,
                            int stored_channels, uint64_t decoder_bytes, bool floats_first)
{
    if (w < 1 || h < 1 || w > INT_MAX || h > INT_MAX)
        return lx_fail(LX_ERR_FORMAT, "%s: invalid image size %lldx%lld", name, (long long)w,
                       (long long)h);
    uint64_t pixels = (uint64_t)w * (uint64_t)h; /* < 2^62 */
    if (budget->max_pixels && pixels > budget->max_pixels)
        return lx_fail(LX_ERR_UNSUPPORTED,
                       "%s: image %lldx%lld (%" PRIu64 " pixels) is larger than the %" PRIu64
                       " pixels allowed",
                       name, (long long)w, (long long)h, pixels, budget->max_pixels);
    /* the reader's buffers and the stored image live together, then the
     * stored image and its conversion; each term < 2^62 * 16 would
     * overflow, so the sum is taken in double and clamped */
    int want = budget->want_channels;
    int kw, kh;
    lx_img_reduced_size((int)w, (int)h, budget->keep_pixels, &kw, &kh, NULL);
    double kept = (double)kw * (double)kh;
    double stored = kept * stored_channels * sizeof(float);
    double converted = want && want != stored_channels ? kept * want * sizeof(float) : 0;
    double decoder = (double)decoder_bytes;
    if (floats_first && kept < (double)pixels) /* the file's size in floats, then reduced */
        decoder += (double)pixels * stored_channels * sizeof(float);
    double after = converted > decoder ? converted : decoder;
    double total = stored + after;
    char what[96];
    snprintf(what, sizeof what, "image %lldx%lld (%d channels)", (long long)w, (long long)h,
             stored_channels);
    lx_status s = lx_check_memory(total >= 1.8e19 ? UINT64_MAX : (uint64_t)total, what);
    if (s != LX_OK)
        lx_error_prefix(name);
    return s;
}

static lx_status check_finite(const lx_image *img, const char *name)
{
    size_t n = (size_t)img->width * (size_t)img->height * (size_t)img->channels;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(img->data[i])) {
            size_t px = i / (size_t)img->channels;
            return lx_fail(LX_ERR_FORMAT, "%s: pixel (%zu, %zu) channel %zu is not finite (%s)",
                           name, px % (size_t)img->width, px / (size_t)img->width,
                           i % (size_t)img->channels, isnan(img->data[i]) ? "NaN" : "infinity");
        }
    }
    return LX_OK;
}

/* Rewrites img with `want` channels: 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA.
 * Grey from colour is Rec.709 luminance; missing alpha is 1. */
static lx_status convert_channels(lx_image *img, int want, const char *name)
{
    int have = img->channels;
    if (want == 0 || want == have)
        return LX_OK;
    lx_image out;
    lx_status s = lx_image_alloc(&out, img->width, img->height, want);
    if (s != LX_OK) {
        lx_error_prefix(name);
        return s;
    }
    size_t n = (size_t)img->width * (size_t)img->height;
    bool have_alpha = have == 2 || have == 4;
    for (size_t i = 0; i < n; i++) {
        const float *p = img->data + i * (size_t)have;
        float *q = out.data + i * (size_t)want;
        float r, g, b;
        if (have >= 3) {
            r = p[0];
            g = p[1];
            b = p[2];
        } else {
            r = g = b = p[0];
        }
        float a = have_alpha ? p[have - 1] : 1.0f;
        if (want <= 2) {
            q[0] = have >= 3 ? (float)lx_luminance((const float[3]){r, g, b}) : r;
            if (want == 2)
                q[1] = a;
        } else {
            q[0] = r;
            q[1] = g;
            q[2] = b;
            if (want == 4)
                q[3] = a;
        }
    }
    lx_image_free(img);
    *img = out;
    return LX_OK;
}

/* EXR and PFM decode to floats at the file's size: reduced afterwards
 * (the stb formats are reduced by their reader, before any float image
 * of the file's size exists). */
typedef struct float_rows {
    const lx_image *img;
} float_rows;

static void float_row(void *ctx, int y, float *row)
{
    const lx_image *img = ((const float_rows *)ctx)->img;
    size_t n = (size_t)img->width * (size_t)img->channels;
    memcpy(row, img->data + (size_t)y * n, sizeof(float) * n);
}

static lx_status reduce_floats(lx_image *img, uint64_t keep_pixels, const char *name,
                               int *halvings)
{
    int w, h;
    lx_img_reduced_size(img->width, img->height, keep_pixels, &w, &h, halvings);
    if (w == img->width && h == img->height)
        return LX_OK;
    lx_image out;
    lx_status s = lx_image_alloc(&out, w, h, img->channels);
    float_rows rows = {img};
    if (s == LX_OK)
        s = lx_img_reduce(img->width, img->height, img->channels, float_row, &rows, &out);
    if (s != LX_OK) {
        lx_image_free(&out);
        lx_error_prefix(name);
        return s;
    }
    lx_image_free(img);
    *img = out;
    return LX_OK;
}

lx_image_load_desc lx_image_load_desc_defaults(const lx_image_load_desc *desc)
{
    lx_image_load_desc d = {0};
    if (desc)
        d = *desc;
    return d; /* every field's zero is its default: as stored, sRGB-decoded, finite */
}

static lx_status load_memory(const void *bytes, size_t size, const char *name,
                             const lx_image_load_desc *desc, lx_image *out, int *halvings)
{
    if (!bytes)
        return lx_fail_null("lx_image_load_memory", "bytes");
    if (!out)
        return lx_fail(LX_ERR_INVALID, "lx_image_load_memory: out is NULL");
    memset(out, 0, sizeof *out);
    if (!name)
        name = "<memory>";
    lx_image_load_desc d = lx_image_load_desc_defaults(desc);
    if (d.channels < 0 || d.channels > 4)
        return lx_fail(LX_ERR_INVALID, "%s: requested %d channels (expected 0..4)", name,
                       d.channels);
    if (!bytes && size > 0)
        return lx_fail(LX_ERR_INVALID, "%s: no data", name);
    if (size == 0)
        return lx_fail(LX_ERR_FORMAT, "%s: empty file", name);

    const unsigned char *data = bytes;
    lx_image_format format = sniff_format(data, size);
    if (format == LX_IMAGE_AUTO) {
        lx_image_format named = lx_image_format_from_path(name);
        if (named == LX_IMAGE_AUTO)
            return lx_fail(LX_ERR_UNSUPPORTED,
                           "%s: unknown image format (expected EXR, HDR, PFM, PNG, JPEG or "
                           "TGA)",
                           name);
        if (named != LX_IMAGE_TGA || !plausible_tga(data, size))
            return lx_fail(LX_ERR_FORMAT, "%s: not %s", name, format_title(named));
        format = LX_IMAGE_TGA;
    }

    lx_img_budget budget = {.max_pixels = d.max_pixels,
                            .want_channels = d.channels,
                            .keep_pixels = d.keep_pixels,
                            .halvings = halvings};
    lx_status s;
    switch (format) {
    case LX_IMAGE_EXR:
        s = lx_img_load_exr(data, size, name, &budget, out);
        break;
    case LX_IMAGE_PFM:
        s = lx_img_load_pfm(data, size, name, &budget, out);
        break;
    default:
        s = lx_img_load_stb(data, size, name, format == LX_IMAGE_TGA, d.raw_8bit, &budget, out);
        break;
    }
    if (s == LX_OK && !d.keep_nonfinite)
        s = check_finite(out, name);
    if (s == LX_OK && (format == LX_IMAGE_EXR || format == LX_IMAGE_PFM))
        s = reduce_floats(out, d.keep_pixels, name, halvings);
    if (s == LX_OK)
        s = convert_channels(out, d.channels, name);
    if (s != LX_OK)
        lx_image_free(out);
    return s;
}

lx_status lx_image_load_memory(const void *bytes, size_t size, const char *name,
                               const lx_image_load_desc *desc, lx_image *out)
{
    return load_memory(bytes, size, name, desc, out, NULL);
}

lx_status lx_image_load_halved(const char *path, const void *bytes, size_t size, const char *name,
                               const lx_image_load_desc *desc, lx_image *out, int *halvings)
{
    if (halvings)
        *halvings = 0;
    if (bytes)
        return load_memory(bytes, size, name, desc, out, halvings);
    if (out)
        memset(out, 0, sizeof *out);
    if (!path || !out)
        return lx_fail(LX_ERR_INVALID, "lx_image_load: path and out must not be NULL");
    uint64_t limit = (uint64_t)1 << 36; /* 64 GiB */
    size_t max_size = limit > SIZE_MAX ? SIZE_MAX : (size_t)limit;
    char *buf;
    size_t got;
    lx_status s = lx_read_file(path, max_size, &buf, &got);
    if (s != LX_OK)
        return s;
    s = load_memory(buf, got, name ? name : path, desc, out, halvings);
    free(buf);
    if (s != LX_OK && halvings)
        *halvings = 0;
    return s;
}

lx_status lx_image_load(const char *path, const lx_image_load_desc *desc, lx_image *out)
{
    /* Files are read whole: every decoder here works from memory. */
    return lx_image_load_halved(path, NULL, 0, path, desc, out, NULL);
}

/* ---- writing ------------------------------------------------------------- */

/* What is wrong with value v of channel c on its way into the file, or
 * NULL: finite, finite after exposure, and inside the format's range (half
 * floats, RGBE). */
static inline const char *value_problem(float v, int c, int channels, lx_image_format format,
                                        float exposure, bool half)
{
    /* exposure scales light, never alpha */
    bool alpha = (channels == 2 || channels == 4) && c == channels - 1;
    float e = alpha ? v : v * exposure;
    if (!isfinite(v))
        return isnan(v) ? "is NaN" : "is infinite";
    if (!isfinite(e))
        return "overflows when multiplied by the exposure";
    if (format == LX_IMAGE_EXR && half && fabsf(e) > LX_HALF_MAX)
        return "exceeds the half-float range (65504); write a 32-bit float EXR instead";
    if (format == LX_IMAGE_HDR && e >= LX_RGBE_LIMIT)
        return "exceeds the Radiance HDR range (2^127)";
    return NULL;
}

/* Every value must survive the trip into the file. Runs before the output
 * is opened so a bad image leaves nothing behind: rows are checked on
 * `threads` threads (reporting on progress), and only when one fails does
 * a serial scan find the first bad value to name. */
static lx_status check_writable(const char *path, const lx_image *img, lx_image_format format,
                                float exposure, bool half, int threads, lx_img_progress *progress)
{
    int nc = img->channels;
    size_t row = (size_t)img->width * (size_t)nc;
    int bad = 0;
    /* value_problem's tests as one branch-free test a value: |e| within
     * the format's magnitude (false for NaN and infinities, so a
     * non-finite value or product is caught) and e under the RGBE top */
    float scale[4], most = FLT_MAX, top = INFINITY;
    for (int c = 0; c < nc && c < 4; c++)
        scale[c] = (nc == 2 || nc == 4) && c == nc - 1 ? 1.0f : exposure;
    if (format == LX_IMAGE_EXR && half)
        most = LX_HALF_MAX;
    if (format == LX_IMAGE_HDR)
        top = LX_RGBE_LIMIT;
    lx_img_progress_phase(progress, 0.0f, 1.0f, (uint64_t)img->height);
#pragma omp parallel for schedule(static) reduction(| : bad) num_threads(lx_thread_count(threads))
    for (int y = 0; y < img->height; y++) {
        if (lx_img_progress_stopped(progress))
            continue;
        const float *v = img->data + (size_t)y * row;
        int row_bad = 0;
        for (size_t i = 0; i < row; i += (size_t)nc)
            for (int c = 0; c < nc; c++) {
                float e = v[i + (size_t)c] * scale[c];
                row_bad |= !(fabsf(e) <= most) | (e >= top);
            }
        bad |= row_bad;
        lx_img_progress_add(progress, 1);
    }
    if (lx_img_progress_stopped(progress))
        return lx_img_cancelled(path);
    if (!bad)
        return LX_OK;
    size_t n = row * (size_t)img->height;
    for (size_t i = 0; i < n; i++) {
        int c = (int)(i % (size_t)nc);
        const char *problem = value_problem(img->data[i], c, nc, format, exposure, half);
        if (problem) {
            float v = img->data[i];
            bool alpha = (nc == 2 || nc == 4) && c == nc - 1;
            float e = alpha ? v : v * exposure;
            size_t px = i / (size_t)nc;
            char value[48] = "";
            if (isfinite(v))
                snprintf(value, sizeof value, ": value %g", (double)e);
            return lx_fail(LX_ERR_INVALID, "%s: pixel (%zu, %zu) channel %d%s %s", path,
                           px % (size_t)img->width, px / (size_t)img->width, c, value, problem);
        }
    }
    return LX_OK;
}

/* ---- writing progress -------------------------------------------------------- */

void lx_img_progress_phase(lx_img_progress *p, float base, float span, uint64_t total)
{
    p->base = base;
    p->span = span;
    p->total = total ? total : 1;
    atomic_store(&p->done, 0);
}

bool lx_img_progress_add(lx_img_progress *p, uint64_t units)
{
    if (!p->fn)
        return true;
    uint64_t done = atomic_fetch_add(&p->done, units) + units;
    if (atomic_load(&p->stop))
        return false;
    if (atomic_exchange(&p->busy, true))
        return true; /* another thread is reporting */
    /* the latest count, at most the phase's end */
    done = atomic_load(&p->done);
    double part = done >= p->total ? 1.0 : (double)done / (double)p->total;
    float f = p->frame_base + p->frame_span * (p->base + p->span * (float)part);
    f = f > 1.0f ? 1.0f : f;
    /* a report every 0.1% at most, and the end of each phase */
    if ((f - p->last >= 0.001f || (done >= p->total && f > p->last)) && !atomic_load(&p->stop)) {
        p->last = f;
        if (!p->fn(p->user, f))
            atomic_store(&p->stop, true);
    }
    atomic_store(&p->busy, false);
    return !atomic_load(&p->stop);
}

bool lx_img_progress_stopped(lx_img_progress *p)
{
    return atomic_load(&p->stop);
}

lx_status lx_img_cancelled(const char *path)
{
    return lx_fail(LX_ERR_CANCELLED, "%s: writing cancelled", path);
}

lx_image_write_desc lx_image_write_desc_defaults(const lx_image_write_desc *desc)
{
    lx_image_write_desc d = {0};
    if (desc)
        d = *desc;
    if (d.exposure == 0.0f)
        d.exposure = 1.0f;
    if (d.bits == 0)
        d.bits = 8;
    return d;
}

lx_status lx_image_write(const char *path, const lx_image *img, const lx_image_write_desc *desc)
{
    if (!path || !img)
        return lx_fail(LX_ERR_INVALID, "lx_image_write: path and img must not be NULL");
    lx_image_write_desc d = lx_image_write_desc_defaults(desc);
    if (!lx_tonemap_name(d.tonemap))
        return lx_fail(LX_ERR_INVALID, "%s: unknown tone curve %d", path, (int)d.tonemap);
    size_t count;
    if (!img->data || img->width < 1 || img->height < 1 || img->channels < 1 || img->channels > 4 ||
        !lx_size_mul((size_t)img->width, (size_t)img->height, (size_t)img->channels, &count))
        return lx_fail(LX_ERR_INVALID, "%s: invalid image (%dx%d, %d channels, data %s)", path,
                       img->width, img->height, img->channels, img->data ? "set" : "NULL");
    if (d.threads < 0)
        return lx_fail(LX_ERR_INVALID, "%s: thread count %d is negative", path, d.threads);
    if (d.format != LX_IMAGE_AUTO && !lx_image_format_extension(d.format))
        return lx_fail(LX_ERR_INVALID, "%s: unknown image format %d in lx_image_write_desc", path,
                       (int)d.format);
    lx_image_format format = d.format != LX_IMAGE_AUTO ? d.format : lx_image_format_from_path(path);
    if (!lx_image_format_extension(format))
        return lx_fail(LX_ERR_INVALID,
                       "%s: cannot tell the image format from the name (use .exr, .hdr, .pfm, "
                       ".png, .jpg or .tga)",
                       path);
    if (d.bits != 8 && d.bits != 16)
        return lx_fail(LX_ERR_INVALID, "%s: %d bits per sample: use 8 or 16", path, d.bits);
    if (d.bits == 16 && (format == LX_IMAGE_JPG || format == LX_IMAGE_TGA))
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %s has no 16-bit samples (write png)", path,
                       lx_image_format_extension(format));
    float exposure = d.exposure;
    if (!isfinite(exposure) || exposure < 0.0f)
        return lx_fail(LX_ERR_INVALID, "%s: exposure %g must be a finite value >= 0", path,
                       (double)d.exposure);
    /* the values' check takes about a tenth of a write (8192 x 8192, PNG,
     * EXR half and HDR: 7-20%) */
    lx_img_progress progress = {
        .fn = d.progress, .user = d.progress_user, .frame_base = 0.0f, .frame_span = 0.1f};
    lx_status s = check_writable(path, img, format, exposure, d.half, d.threads, &progress);
    if (s != LX_OK)
        return s;
    progress.frame_base = 0.1f;
    progress.frame_span = 0.9f;
    lx_img_progress_phase(&progress, 0.0f, 1.0f, 1);
    lx_out_file f;
    s = lx_out_open(&f, path);
    if (s != LX_OK)
        return s;
    switch (format) {
    case LX_IMAGE_PFM:
        s = lx_img_write_pfm(f.fp, path, img, exposure, &progress);
        break;
    case LX_IMAGE_EXR:
        s = lx_img_write_exr(f.fp, path, img, exposure, d.half, d.threads, &progress);
        break;
    case LX_IMAGE_PNG:
        if (d.bits == 16) {
            s = lx_img_write_png16(f.fp, path, img, exposure, d.tonemap, d.linear, d.threads,
                                   &progress);
            break;
        }
        /* fall through */
    default:
        s = lx_img_write_stb(f.fp, path, img, format, exposure, d.tonemap, d.linear, d.threads,
                                 &progress);
        break;
    }
    /* the last word before the file is committed: 1.0, which may still
     * stop it */
    if (s == LX_OK && progress.fn && !lx_img_progress_stopped(&progress) && progress.last < 1.0f &&
        !progress.fn(progress.user, 1.0f))
        atomic_store(&progress.stop, true);
    if (s == LX_OK && lx_img_progress_stopped(&progress))
        s = lx_img_cancelled(path);
    if (s != LX_OK) {
        lx_out_abort(&f);
        return s;
    }
    return lx_out_commit(&f);
}
