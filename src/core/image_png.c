/* PNG writing: stb_image_write's PNG encoder (row filters, chunks, CRCs)
 * compiled here with zlib as its deflate (stb's STBIW_ZLIB_COMPRESS hook)
 * and zlib's CRC-32; 16-bit PNGs (which stb cannot write) are assembled
 * here from the same deflate (PNG specification, ISO/IEC 15948: IHDR bit
 * depth 16, samples big-endian, the Up filter on bytes). The filtered rows are deflated in fixed strips on
 * several threads and the strips joined into one zlib stream, each strip
 * primed with the 32 KiB of data before it (the method of Mark Adler's
 * pigz): the stream decodes as one, compresses almost as well as a serial
 * deflate, and its bytes do not depend on the number of threads. */
#include "image_internal.h"

#include <zlib.h>

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

static unsigned char *lx_png_deflate(unsigned char *data, int data_len, int *out_len, int quality);
static unsigned int lx_png_crc32(unsigned char *buffer, int len);

/* stb_image_write's implementation, private to this file: its other
 * writers stay unused here (image_io.c calls Debian's libstb for them) */
#define STB_IMAGE_WRITE_STATIC
#define STBIW_ZLIB_COMPRESS lx_png_deflate
#define STBIW_CRC32 lx_png_crc32
#define STB_IMAGE_WRITE_IMPLEMENTATION
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

/* Bytes of filtered rows per strip: fixed, so the stream's bytes depend on
 * the image alone. 128 KiB keeps the threads busy on a 256x256 preview's
 * worth of strips and costs under 0.1% of compression against one serial
 * stream (each strip restarts its block and sees the 32 KiB before it). */
#define LX_PNG_STRIP (128 * 1024)
/* zlib's run-length strategy (matches at distance 1 only) at level 1: after
 * the PNG row filters a lightmap is mostly runs, and on bench_bake's
 * preview this is 18% smaller than stb's own deflate at its level 8 and
 * faster than zlib's default strategy at level 1, which is 12% larger. */
#define LX_PNG_LEVEL 1
#define LX_PNG_STRATEGY Z_RLE

/* Threads and progress for the encoder running on this thread (stb's
 * hook has no context argument). */
static _Thread_local int png_threads = 1;
static _Thread_local lx_img_progress *png_progress;

typedef struct png_strip {
    unsigned char *out;
    size_t size;
    uLong adler;
    bool failed;
} png_strip;

/* Raw deflate of data[at, at + len); not the last strip: ends with a sync
 * flush on a byte boundary, so the next strip's blocks follow it. */
static void deflate_strip(const unsigned char *data, size_t at, size_t len, bool last, int level,
                          png_strip *s)
{
    z_stream zs;
    memset(&zs, 0, sizeof zs);
    if (deflateInit2(&zs, level, Z_DEFLATED, -15, 8, LX_PNG_STRATEGY) != Z_OK) {
        s->failed = true;
        return;
    }
    size_t window = at < 32768 ? at : 32768;
    if (window && deflateSetDictionary(&zs, data + at - window, (uInt)window) != Z_OK)
        s->failed = true;
    size_t cap = deflateBound(&zs, (uLong)len) + 16;
    s->out = malloc(cap);
    if (!s->out || s->failed) {
        s->failed = true;
        deflateEnd(&zs);
        return;
    }
    zs.next_in = (Bytef *)(data + at);
    zs.avail_in = (uInt)len;
    zs.next_out = s->out;
    zs.avail_out = (uInt)cap;
    int rc = deflate(&zs, last ? Z_FINISH : Z_SYNC_FLUSH);
    if (last ? rc != Z_STREAM_END : (rc != Z_OK || zs.avail_in != 0))
        s->failed = true;
    s->size = cap - zs.avail_out;
    deflateEnd(&zs);
    s->adler = adler32(1L, data + at, (uInt)len);
}

/* stb's zlib hook: a zlib stream (header, deflate data, Adler-32) of data
 * in memory from malloc, which stb frees. quality (stb's level) is not
 * used: the level is LX_PNG_LEVEL. */
static unsigned char *lx_png_deflate(unsigned char *data, int data_len, int *out_len, int quality)
{
    (void)quality;
    size_t n = data_len > 0 ? (size_t)data_len : 0;
    size_t count = n ? (n + LX_PNG_STRIP - 1) / LX_PNG_STRIP : 1;
    png_strip *strips = calloc(count, sizeof *strips);
    if (!strips)
        return NULL;
    int level = LX_PNG_LEVEL;
    int threads = png_threads < (int)count ? png_threads : (int)count;
    /* the strips are the current phase's units */
    lx_img_progress *progress = png_progress;
    if (progress)
        lx_img_progress_phase(progress, progress->base, progress->span, count);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (long k = 0; k < (long)count; k++) {
        if (progress && lx_img_progress_stopped(progress))
            continue;
        size_t at = (size_t)k * LX_PNG_STRIP;
        size_t len = n - at < LX_PNG_STRIP ? n - at : LX_PNG_STRIP;
        deflate_strip(data, at, len, k == (long)count - 1, level, &strips[k]);
        if (progress)
            lx_img_progress_add(progress, 1);
    }
    size_t total = 2 + 4;
    bool failed = progress && lx_img_progress_stopped(progress);
    for (size_t k = 0; k < count; k++) {
        total += strips[k].size;
        failed |= strips[k].failed;
    }
    unsigned char *out = failed || total > INT_MAX ? NULL : malloc(total);
    if (out) {
        /* CMF: deflate, 32 KiB window; FLG: fastest level, no dictionary,
         * check bits making CMF * 256 + FLG a multiple of 31 */
        out[0] = 0x78;
        out[1] = 0x01;
        size_t o = 2;
        uLong adler = 1L;
        for (size_t k = 0; k < count; k++) {
            memcpy(out + o, strips[k].out, strips[k].size);
            o += strips[k].size;
            size_t len = n - k * LX_PNG_STRIP < LX_PNG_STRIP ? n - k * LX_PNG_STRIP : LX_PNG_STRIP;
            adler = adler32_combine(adler, strips[k].adler, (z_off_t)len);
        }
        out[o++] = (unsigned char)(adler >> 24);
        out[o++] = (unsigned char)(adler >> 16);
        out[o++] = (unsigned char)(adler >> 8);
        out[o++] = (unsigned char)adler;
        *out_len = (int)o;
    }
    for (size_t k = 0; k < count; k++)
        free(strips[k].out);
    free(strips);
    return out;
}

static unsigned int lx_png_crc32(unsigned char *buffer, int len)
{
    return (unsigned int)crc32(0L, buffer, (uInt)len);
}

/* Every row gets the Up filter (the difference from the row above) instead
 * of stb's per-row trial of all five filters: on lightmaps it is as small
 * (bench_bake's preview: 0.7% smaller) and costs one pass, not six. */
#define LX_PNG_FILTER 2

unsigned char *lx_img_png_encode(const unsigned char *pixels, int width, int height, int channels,
                                 int threads, lx_img_progress *progress, int *out_len)
{
    png_threads = lx_thread_count(threads);
    png_progress = progress;
    stbi_write_force_png_filter = LX_PNG_FILTER;
    unsigned char *png =
        stbi_write_png_to_mem(pixels, width * channels, width, height, channels, out_len);
    png_threads = 1;
    png_progress = NULL;
    return png;
}

/* ---- 16-bit PNG -------------------------------------------------------------- */

/* The 16-bit code of a display value in [0,1] (after the tone curve):
 * round(65535 v), or of its sRGB encoding, computed in double so each code
 * decodes (lx_srgb_to_linear(code / 65535)) to a value that encodes back
 * to it. */
static uint16_t encode16(double v, bool linear)
{
    if (!(v > 0.0))
        return 0; /* also NaN, which the caller has rejected */
    if (v >= 1.0)
        return 65535;
    if (!linear)
        v = v <= 0.0031308 ? v * 12.92 : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (uint16_t)floor(v * 65535.0 + 0.5);
}

static void put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* One chunk: length, type, data, CRC-32 of type and data. */
static void write_chunk(FILE *fp, const char type[4], const unsigned char *data, size_t len)
{
    unsigned char head[8];
    put32(head, (uint32_t)len);
    memcpy(head + 4, type, 4);
    uLong crc = crc32(0L, (const Bytef *)type, 4);
    if (len)
        crc = crc32(crc, data, (uInt)len);
    unsigned char tail[4];
    put32(tail, (uint32_t)crc);
    fwrite(head, 1, 8, fp);
    if (len)
        fwrite(data, 1, len, fp);
    fwrite(tail, 1, 4, fp);
}

/* Shares of the 16-bit writer's progress: the codes and row filters, then
 * the deflate strips, then the file's bytes. */
#define LX_PNG16_CODES 0.3f
#define LX_PNG16_DEFLATE_TO 0.9f

lx_status lx_img_write_png16(FILE *fp, const char *path, const lx_image *img, float exposure,
                             lx_tonemap tonemap, bool linear, int threads,
                             lx_img_progress *progress)
{
    int c = img->channels;
    size_t row = 1 + 2 * (size_t)img->width * (size_t)c; /* filter byte + samples */
    /* the deflate hook takes an int length */
    if ((double)row * (double)img->height > (double)(INT_MAX / 2))
        return lx_fail(LX_ERR_UNSUPPORTED, "%s: %dx%d is too large for the 16-bit png writer",
                       path, img->width, img->height);
    size_t n = row * (size_t)img->height;
    unsigned char *raw = malloc(n), *filtered = malloc(n);
    if (!raw || !filtered) {
        free(raw);
        free(filtered);
        return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, 2 * n);
    }
    int colour = c == 2 || c == 4 ? c - 1 : c; /* channels before alpha */
    int nthreads = lx_thread_count(threads);
    lx_img_progress_phase(progress, 0.0f, LX_PNG16_CODES, (uint64_t)img->height);
#pragma omp parallel for schedule(static) num_threads(nthreads)
    for (int y = 0; y < img->height; y++) {
        if (lx_img_progress_stopped(progress))
            continue;
        unsigned char *out = raw + (size_t)y * row;
        out[0] = 0;
        out++;
        for (int x = 0; x < img->width; x++) {
            const float *v = img->data + ((size_t)y * (size_t)img->width + (size_t)x) * (size_t)c;
            uint16_t code[4];
            if (colour == 3) {
                float rgb[3] = {v[0] * exposure, v[1] * exposure, v[2] * exposure};
                lx_tonemap_rgb(tonemap, rgb);
                for (int k = 0; k < 3; k++)
                    code[k] = encode16(rgb[k], linear);
            } else {
                code[0] = encode16(lx_tonemap_grey(tonemap, v[0] * exposure), linear);
            }
            if (colour < c)
                code[colour] = encode16(v[colour], true);
            for (int k = 0; k < c; k++) {
                *out++ = (unsigned char)(code[k] >> 8);
                *out++ = (unsigned char)code[k];
            }
        }
        lx_img_progress_add(progress, 1);
    }
    /* the Up filter: each byte less the byte above it (row 0: itself) */
#pragma omp parallel for schedule(static) num_threads(nthreads)
    for (int y = 0; y < img->height; y++) {
        const unsigned char *cur = raw + (size_t)y * row;
        unsigned char *f = filtered + (size_t)y * row;
        f[0] = (unsigned char)LX_PNG_FILTER;
        for (size_t i = 1; i < row; i++)
            f[i] = (unsigned char)(cur[i] - (y ? cur[i - row] : 0));
    }
    free(raw);
    if (lx_img_progress_stopped(progress)) {
        free(filtered);
        return lx_img_cancelled(path);
    }
    lx_img_progress_phase(progress, LX_PNG16_CODES, LX_PNG16_DEFLATE_TO - LX_PNG16_CODES, 1);
    png_threads = nthreads;
    png_progress = progress;
    int len = 0;
    unsigned char *z = lx_png_deflate(filtered, (int)n, &len, 0);
    png_threads = 1;
    png_progress = NULL;
    free(filtered);
    if (!z && lx_img_progress_stopped(progress))
        return lx_img_cancelled(path);
    if (!z)
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory encoding png", path);
    static const unsigned char colour_type[5] = {0, 0, 4, 2, 6};
    unsigned char ihdr[13];
    put32(ihdr, (uint32_t)img->width);
    put32(ihdr + 4, (uint32_t)img->height);
    ihdr[8] = 16;
    ihdr[9] = colour_type[c];
    ihdr[10] = ihdr[11] = ihdr[12] = 0; /* deflate, adaptive filters, no interlace */
    fwrite("\x89PNG\r\n\x1a\n", 1, 8, fp);
    write_chunk(fp, "IHDR", ihdr, sizeof ihdr);
    write_chunk(fp, "IDAT", z, (size_t)len);
    write_chunk(fp, "IEND", NULL, 0);
    free(z);
    return LX_OK;
}
