/* Private to src/core: the per-format image readers and writers behind
 * lx_image_load_memory and lx_image_write (image.c). */
#ifndef LX_CORE_IMAGE_INTERNAL_H
#define LX_CORE_IMAGE_INTERNAL_H

#include "internal.h"

#include <stdatomic.h>
#include <stdio.h>

#if defined(__GNUC__)
#define LX_IMG_HIDDEN __attribute__((visibility("hidden")))
#else
#define LX_IMG_HIDDEN
#endif

/* Progress of one lx_image_write: work is counted in units (rows, chunks,
 * strips) of the phase under way, which maps them onto [base, base +
 * span] of the frame, itself [frame_base, frame_base + frame_span] of the
 * whole (the writers' [0, 1] after the values are checked). Any thread
 * may add units; the one that does calls
 * the callback unless another is in it, so calls come one at a time and
 * never go back. Once the callback returns false every later call of
 * lx_img_progress_add returns false too (the writer stops and its caller
 * returns LX_ERR_CANCELLED). */
typedef struct lx_img_progress {
    lx_progress_fn fn; /* NULL: nothing reported, never stopped */
    void *user;
    _Atomic bool stop;
    _Atomic bool busy;
    _Atomic uint64_t done;
    uint64_t total;
    float base, span;
    float frame_base, frame_span;
    float last; /* the last fraction reported (under busy) */
} lx_img_progress;

/* Starts a phase of `total` units covering [base, base + span]. Call
 * between parallel loops, not inside one. */
LX_IMG_HIDDEN void lx_img_progress_phase(lx_img_progress *p, float base, float span,
                                         uint64_t total);
/* Adds units done in the current phase and reports; false once stopped. */
LX_IMG_HIDDEN bool lx_img_progress_add(lx_img_progress *p, uint64_t units);
/* Whether the callback has asked to stop. */
LX_IMG_HIDDEN bool lx_img_progress_stopped(lx_img_progress *p);

/* What a load may take: the caller's pixel cap (0: none), the channels
 * the image is converted to afterwards (0: as stored) and the pixels a
 * reduction keeps (lx_image_load_desc.keep_pixels, 0: as stored). */
typedef struct lx_img_budget {
    uint64_t max_pixels;
    int want_channels;
    uint64_t keep_pixels;
    int *halvings; /* where the reader that reduces says how often (may be NULL) */
} lx_img_budget;

/* Checked by every reader once it has the header's size and before it
 * decodes: width * height against the cap, then the memory of the whole
 * load (decoder_bytes, the reader's own buffers, beside the float image of
 * stored_channels at the size budget->keep_pixels leaves, then the
 * converted image beside that) against what the process may use; a
 * reader that makes the float image at the file's size before reducing
 * it says so with floats_first. The message names the file, its size and
 * the bytes asked. */
LX_IMG_HIDDEN lx_status lx_img_check_size(const lx_img_budget *budget, const char *name, int64_t w,
                                          int64_t h, int stored_channels, uint64_t decoder_bytes,
                                          bool floats_first);

/* The size an image of width x height is reduced to for keep_pixels
 * (image_reduce.c): halved (sides rounded up) while the half still holds
 * keep_pixels pixels; keep_pixels 0 leaves it as it is. *halvings (may be
 * NULL) gets the number of halvings. */
LX_IMG_HIDDEN void lx_img_reduced_size(int width, int height, uint64_t keep_pixels, int *out_w,
                                       int *out_h, int *halvings);
/* Source row y (0..height-1) of `channels` floats a pixel into row (width
 * x channels floats): the values the load returns. */
typedef void (*lx_img_row_fn)(void *ctx, int y, float *row);
/* Fills out (allocated at its reduced size, `channels` channels) with the
 * area average of the width x height source read through row, a row at
 * a time. */
LX_IMG_HIDDEN lx_status lx_img_reduce(int width, int height, int channels, lx_img_row_fn row,
                                      void *ctx, lx_image *out);

/* Readers. name is used in messages only; data holds size bytes; is_tga
 * says the stb reader got a TGA (which has no signature). Each checks the
 * header's size with lx_img_check_size before decoding, fills *out with
 * the values as stored (no channel conversion, no NaN check) and leaves it
 * zeroed on failure. */
LX_IMG_HIDDEN lx_status lx_img_load_stb(const unsigned char *data, size_t size, const char *name,
                                        bool is_tga, bool raw_8bit, const lx_img_budget *budget,
                                        lx_image *out);
LX_IMG_HIDDEN lx_status lx_img_load_pfm(const unsigned char *data, size_t size, const char *name,
                                        const lx_img_budget *budget, lx_image *out);
LX_IMG_HIDDEN lx_status lx_img_load_exr(const unsigned char *data, size_t size, const char *name,
                                        const lx_img_budget *budget, lx_image *out);

/* Writers to an open temporary file. The caller has checked img (1..4
 * channels, finite values, exposed values in the format's range) and
 * commits or aborts the file. exposure is the multiplier (never 0);
 * tonemap the curve of the 8-bit formats, linear their codes without
 * the sRGB transfer;
 * threads bounds the encoding threads (0 = all cores). Each reports on
 * progress over [0, 1] and returns LX_ERR_CANCELLED ("<path>: writing
 * cancelled") when it stops. */
LX_IMG_HIDDEN lx_status lx_img_write_stb(FILE *fp, const char *path, const lx_image *img,
                                         lx_image_format format, float exposure,
                                         lx_tonemap tonemap, bool linear, int threads,
                                         lx_img_progress *progress);
LX_IMG_HIDDEN lx_status lx_img_write_pfm(FILE *fp, const char *path, const lx_image *img,
                                         float exposure, lx_img_progress *progress);
LX_IMG_HIDDEN lx_status lx_img_write_exr(FILE *fp, const char *path, const lx_image *img,
                                         float exposure, bool half, int threads,
                                         lx_img_progress *progress);

/* The LX_ERR_CANCELLED of a writer that stopped. */
LX_IMG_HIDDEN lx_status lx_img_cancelled(const char *path);

/* A PNG file of 8-bit pixels (channels 1..4, rows top to bottom) in memory
 * from malloc, *out_len bytes; NULL when out of memory or stopped by
 * progress (whose current phase it reports on, by deflate strip).
 * Deflates on up to `threads` threads (0 = all cores); the bytes do not
 * depend on it (image_png.c). */
LX_IMG_HIDDEN unsigned char *lx_img_png_encode(const unsigned char *pixels, int width, int height,
                                               int channels, int threads, lx_img_progress *progress,
                                               int *out_len);

/* A 16-bit PNG of img (1..4 channels): colour values exposed, put through
 * tonemap and stored as round(65535 v) of their sRGB encoding (or of v
 * itself with linear); alpha as round(65535 a). As lx_img_write_stb
 * otherwise (progress, cancel, threads, checked input). */
LX_IMG_HIDDEN lx_status lx_img_write_png16(FILE *fp, const char *path, const lx_image *img,
                                           float exposure, lx_tonemap tonemap, bool linear,
                                           int threads, lx_img_progress *progress);

/* The bound below which stb's RGBE encoder keeps its exponent byte in
 * range (2^127). */
#define LX_RGBE_LIMIT 0x1p127f

#endif
