/* PNG writing: stb_image_write's PNG encoder (row filters, chunks, CRCs)
 * compiled here with zlib as its deflate (stb's STBIW_ZLIB_COMPRESS hook)
 * and zlib's CRC-32. The filtered rows are deflated in fixed strips on
 * several threads and the strips joined into one zlib stream, each strip
 * primed with the 32 KiB of data before it (the method of Mark Adler's
 * pigz): the stream decodes as one, compresses almost as well as a serial
 * deflate, and its bytes do not depend on the number of threads. */
#include "image_internal.h"

#include <zlib.h>

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
