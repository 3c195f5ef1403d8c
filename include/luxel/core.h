/* luxel/core.h - status codes, error messages, logging, progress, and
 * images with their files (PNG, JPEG, TGA, HDR, PFM, EXR).
 *
 * CONVENTIONS  Images are linear float RGB(A), row 0 at the top, interleaved
 *   channels. 8-bit files (PNG/JPEG/TGA) are sRGB-decoded on load unless the
 *   caller asks for raw data (normal maps); HDR/PFM/EXR hold linear values.
 * ERRORS  Every function that can fail returns lx_status and sets a message
 *   readable with lx_last_error() (thread-local) naming the file, the place
 *   in it and the problem: "scene.glb: accessor 7: index 912 out of range".
 *   A NULL pointer where a function needs one is LX_ERR_INVALID
 *   ("lx_scene_load: out is NULL"), never a crash; pointers that may be
 *   NULL say so (tests/usage/null_optional.txt lists them all), and
 *   *_free / *_destroy accept NULL.
 * MEMORY  lx_image_alloc/lx_image_load allocate; lx_image_free releases.
 * THREADING  Every function here is thread-safe. The log callback is
 *   process-wide: lx_set_log_callback may be called while other threads
 *   log, calls to the callback never overlap, and once
 *   lx_set_log_callback returns the previous callback is not called again.
 *
 * USAGE
 *   lx_image img;
 *   if (lx_image_load("sky.hdr", NULL, &img) != LX_OK)
 *       fprintf(stderr, "%s\n", lx_last_error());
 *   else if (lx_image_write("sky.exr", &img, NULL) != LX_OK)
 *       fprintf(stderr, "%s\n", lx_last_error());
 *   lx_image_free(&img);
 */
#ifndef LUXEL_CORE_H
#define LUXEL_CORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LX_VERSION_MAJOR 0
#define LX_VERSION_MINOR 1
#define LX_VERSION_PATCH 0
#define LX_VERSION "0.1.0"

/* The library's version string, LX_VERSION of the build that made it. */
const char *lx_version(void);

typedef enum lx_status {
    LX_OK = 0,
    LX_ERR_IO,          /* a file could not be opened, read or written */
    LX_ERR_FORMAT,      /* a file's contents are malformed */
    LX_ERR_INVALID,     /* a parameter or value is out of its domain */
    LX_ERR_NOMEM,       /* an allocation failed or would exceed memory */
    LX_ERR_UNSUPPORTED, /* valid input luxel does not handle */
    LX_ERR_CANCELLED    /* the progress callback asked to stop */
} lx_status;

/* The message of the last failure on this thread ("" when none).
 * Borrowed: valid until the next luxel call on this thread. */
const char *lx_last_error(void);

/* For callers that size their own buffers by input (a probe count, a
 * points file): LX_OK when bytes fit in the memory the process may use
 * now (the machine's, its control group's limit, RLIMIT_AS and
 * RLIMIT_DATA less what it holds), else LX_ERR_NOMEM with the message
 * "<what> needs N GiB of memory, <what bounds it>" (what NULL: "the
 * request"). Allocates nothing. */
lx_status lx_memory_check(uint64_t bytes, const char *what);

/* Short name of a status ("LX_ERR_IO"). Static storage. */
const char *lx_status_name(lx_status status);

/* Clears this thread's error message. */
void lx_clear_error(void);

/* ---- logging ------------------------------------------------------------ */

/* Ordered by severity: a callback can drop everything below a level. */
typedef enum lx_log_level {
    LX_LOG_DEBUG = 0, /* detail for luxel's developers */
    LX_LOG_INFO,      /* what a run did (phase times, choices made) */
    LX_LOG_WARN       /* something the caller should know: input repaired or ignored */
} lx_log_level;

/* Receives log lines (one line, no newline). Process-wide. Calls never
 * overlap (luxel serialises them), but they may come from any thread; the
 * callback must not call lx_log or lx_set_log_callback itself. */
typedef void (*lx_log_fn)(void *user, lx_log_level level, const char *message);
/* Installs fn (NULL, the default, discards every line). Safe while other
 * threads log: a line goes either to the old or to the new callback, and
 * after this returns the old one is not called again. */
void lx_set_log_callback(lx_log_fn fn, void *user);
/* Formats and sends one line to the callback (nothing when none is set). */
void lx_log(lx_log_level level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Progress of a long operation: fraction in [0, 1], non-decreasing. Return
 * false to stop; the operation then ends with LX_ERR_CANCELLED and writes
 * nothing. Called from one thread at a time (not always the caller's), a
 * few times a second at least while the operation runs. */
typedef bool (*lx_progress_fn)(void *user, float fraction);

/* ---- images ------------------------------------------------------------- */

typedef struct lx_image {
    int width, height;
    int channels; /* 1..4 */
    float *data;  /* width*height*channels floats, row 0 at the top */
} lx_image;

typedef enum lx_image_format {
    LX_IMAGE_AUTO = 0, /* from the file name's extension */
    LX_IMAGE_EXR,
    LX_IMAGE_HDR,
    LX_IMAGE_PFM,
    LX_IMAGE_PNG,
    LX_IMAGE_JPG,
    LX_IMAGE_TGA
} lx_image_format;

/* The format named by a path's extension, or LX_IMAGE_AUTO if unknown. */
lx_image_format lx_image_format_from_path(const char *path);
/* "exr", "hdr", "pfm", "png", ... (NULL for LX_IMAGE_AUTO). */
const char *lx_image_format_extension(lx_image_format format);

/* Allocates a zeroed image; checks the size for overflow and memory. */
lx_status lx_image_alloc(lx_image *img, int width, int height, int channels);
void lx_image_free(lx_image *img);

typedef struct lx_image_load_desc {
    bool raw_8bit;       /* 8-bit data is mapped to [0,1] without sRGB decoding */
    int channels;        /* wanted channel count, 0 = as stored */
    bool keep_nonfinite; /* keep NaN and infinite values (the caller checks
                            them, e.g. to count them); default: fail on the
                            first one */
    uint64_t max_pixels; /* refuse an image of more pixels (width * height)
                            than this, from its header, before decoding;
                            0 = no cap but the memory */
    uint64_t keep_pixels; /* reduce on load: halve both sides (rounding up)
                             while the half still holds this many pixels,
                             each pixel the area average of the file's
                             pixels under it, taken of the values loaded
                             (linear light after the sRGB decoding, raw
                             values with raw_8bit, alpha as stored); an
                             image of fewer than 4 x keep_pixels pixels
                             stays as stored; 0 = as stored */
} lx_image_load_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in. */
lx_image_load_desc lx_image_load_desc_defaults(const lx_image_load_desc *desc);

/* Loads PNG/JPEG/TGA/HDR (stb_image), PFM and EXR. desc may be NULL.
 * On failure *out is zeroed. The size in the file's header is checked
 * before anything is decoded: against desc->max_pixels
 * (LX_ERR_UNSUPPORTED) and against the memory the process may use for
 * the decoder's buffer, the image and its channel conversion together
 * (LX_ERR_NOMEM); either message names the file, its width x height and
 * (for memory) the bytes asked. With desc->keep_pixels, PNG, JPEG, TGA
 * and HDR files are reduced as their decoded samples are converted, so
 * no float image of the file's size is ever made (memory: the decoder's
 * samples and the reduced image); EXR and PFM are decoded whole, then
 * reduced. */
lx_status lx_image_load(const char *path, const lx_image_load_desc *desc, lx_image *out);
/* Same from memory; name is used in messages. */
lx_status lx_image_load_memory(const void *bytes, size_t size, const char *name,
                               const lx_image_load_desc *desc, lx_image *out);

/* Tone curves map scene-referred linear values (after exposure) to display
 * values in [0,1], still linear (the sRGB encoding comes after):
 * CLAMP cuts at 1; ACES is Stephen Hill's fit of the ACES reference
 * rendering and output transforms (sRGB primaries in and out, mid grey
 * 0.18 -> 0.14); FILMIC is John Hable's curve (shoulder A 0.15, B 0.5,
 * C 0.1, toe D 0.2, E 0.02, F 0.3) with white point 11.2 and the input
 * doubled, as it is usually shown. Both keep shadows from crushing to
 * black and highlights from clipping abruptly. */
typedef enum lx_tonemap { LX_TONEMAP_CLAMP = 0, LX_TONEMAP_ACES, LX_TONEMAP_FILMIC } lx_tonemap;

/* rgb (3 linear values) through curve, in place; the result lies in [0,1]
 * (NaN stays NaN). Thread-safe. */
void lx_tonemap_rgb(lx_tonemap curve, float rgb[3]);
/* One grey value through curve (the same as lx_tonemap_rgb on v, v, v). */
float lx_tonemap_grey(lx_tonemap curve, float v);
/* "aces", "filmic" or "clamp"; NULL for another value. */
const char *lx_tonemap_name(lx_tonemap curve);
/* The curve named name (as lx_tonemap_name writes it); false when none. */
bool lx_tonemap_parse(const char *name, lx_tonemap *out);

typedef struct lx_image_write_desc {
    lx_image_format format;  /* 0 = from the path's extension */
    float exposure;          /* multiplier applied to values, 0 = 1 */
    lx_tonemap tonemap;      /* 8-bit formats: the curve after exposure
                                (CLAMP by default); float formats ignore it */
    bool linear;             /* 8/16-bit formats: codes round(255 v) (or
                                round(65535 v)) without the
                                sRGB transfer, for data such as lookup
                                tables (default: sRGB encoded) */
    bool half;               /* EXR: 16-bit half floats instead of 32-bit */
    int bits;                /* integer formats' bits per sample: 0 = 8;
                                16 writes a 16-bit PNG (coded as the 8-bit
                                one: tone curve, sRGB or linear, alpha
                                linear; codes round(65535 v)). JPEG and TGA
                                fail with 16; float formats ignore it */
    int threads;             /* encoding threads, 0 = all cores */
    lx_progress_fn progress; /* may be NULL; returning false cancels */
    void *progress_user;
} lx_image_write_desc;

/* A copy of desc (or of zeros when NULL) with every default filled in
 * (the format stays LX_IMAGE_AUTO: the path decides it). */
lx_image_write_desc lx_image_write_desc_defaults(const lx_image_write_desc *desc);

/* Writes img to path atomically (temporary file in the same folder, renamed
 * when complete). 8-bit formats are exposed, put through desc->tonemap
 * (a clamp to [0,1] by default) and sRGB encoded (or, with desc->linear,
 * stored as linear unorm codes); float formats store linear values. NaN/Inf values are rejected.
 * desc->progress hears the encoding (between EXR chunks or scanlines, PNG
 * deflate strips, HDR and PFM rows; JPEG and TGA before and after their
 * encoder) and a last 1.0 before the file is committed; when it returns
 * false the call ends with LX_ERR_CANCELLED and no file (neither the
 * target nor a temporary one). The bytes written do not depend on
 * desc->threads. desc may be NULL. */
lx_status lx_image_write(const char *path, const lx_image *img, const lx_image_write_desc *desc);

/* Bilinear sample at UV (origin top-left, texel centres at (x+0.5)/W),
 * wrapping around the edges (glTF's default REPEAT). out gets img->channels
 * floats. */
void lx_image_sample_bilinear(const lx_image *img, float u, float v, float *out);

/* sRGB transfer function. */
float lx_srgb_to_linear(float c);
float lx_linear_to_srgb(float c);

#ifdef __cplusplus
}
#endif
#endif
