/* luxel/core.h - status codes, error messages, logging, progress, images and
 * their files, counter-based random numbers, atomic file output.
 *
 * CONVENTIONS  Images are linear float RGB(A), row 0 at the top, interleaved
 *   channels. 8-bit files (PNG/JPEG/TGA) are sRGB-decoded on load unless the
 *   caller asks for raw data (normal maps); HDR/PFM/EXR hold linear values.
 * ERRORS  Every function that can fail returns lx_status and sets a message
 *   readable with lx_last_error() (thread-local) naming the file, the place
 *   in it and the problem: "scene.glb: accessor 7: index 912 out of range".
 * MEMORY  lx_image_alloc/lx_image_load allocate; lx_image_free releases.
 * THREADING  Everything here is reentrant; the log callback is process-wide
 *   and may be called from several threads at once.
 *
 * USAGE
 *   lx_image img;
 *   if (lx_image_load("sky.hdr", NULL, &img) != LX_OK)
 *       fprintf(stderr, "%s\n", lx_last_error());
 *   lx_image_write("sky.exr", &img, NULL);
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

/* Short name of a status ("LX_ERR_IO"). Static storage. */
const char *lx_status_name(lx_status status);

/* Sets this thread's error message (printf format) and returns status.
 * For luxel's own modules and for code extending them. */
lx_status lx_fail(lx_status status, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Prefixes this thread's current error message with "prefix: ". */
void lx_error_prefix(const char *prefix);

/* Clears this thread's error message. */
void lx_clear_error(void);

/* ---- logging ------------------------------------------------------------ */

typedef enum lx_log_level { LX_LOG_INFO = 0, LX_LOG_WARN, LX_LOG_DEBUG } lx_log_level;

/* Receives warnings and notes (one line, no newline). Process-wide; may be
 * called from several threads. NULL (the default) discards them. */
typedef void (*lx_log_fn)(void *user, lx_log_level level, const char *message);
void lx_set_log_callback(lx_log_fn fn, void *user);
void lx_log(lx_log_level level, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Progress of a long operation: fraction in [0, 1]. Return false to stop;
 * the operation then ends with LX_ERR_CANCELLED and writes nothing.
 * Called from one thread at a time. */
typedef bool (*lx_progress_fn)(void *user, float fraction);

/* ---- sizes and memory --------------------------------------------------- */

/* a*b*c in *out, false on overflow of size_t. */
bool lx_size_mul(size_t a, size_t b, size_t c, size_t *out);

/* Physical memory of the machine in bytes (0 when unknown). */
uint64_t lx_physical_memory(void);

/* Fails with LX_ERR_NOMEM and a message "<what> needs N GiB, the machine
 * has M GiB" when bytes exceed the machine's physical memory. */
lx_status lx_check_memory(uint64_t bytes, const char *what);

/* Number of threads to use: requested when > 0, else all cores. */
int lx_thread_count(int requested);

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
    bool raw_8bit; /* 8-bit data is mapped to [0,1] without sRGB decoding */
    int channels;  /* wanted channel count, 0 = as stored */
    bool keep_nonfinite; /* keep NaN and infinite values (the caller checks
                            them, e.g. to count them); default: fail on the
                            first one */
} lx_image_load_desc;

/* Loads PNG/JPEG/TGA/HDR (stb_image), PFM and EXR. desc may be NULL.
 * On failure *out is zeroed. */
lx_status lx_image_load(const char *path, const lx_image_load_desc *desc, lx_image *out);
/* Same from memory; name is used in messages. */
lx_status lx_image_load_memory(const void *bytes, size_t size, const char *name,
                               const lx_image_load_desc *desc, lx_image *out);

typedef struct lx_image_write_desc {
    lx_image_format format; /* 0 = from the path's extension */
    float exposure;         /* multiplier applied to values, 0 = 1 */
    bool half;              /* EXR: 16-bit half floats instead of 32-bit */
} lx_image_write_desc;

/* Writes img to path atomically (temporary file in the same folder, renamed
 * when complete). 8-bit formats are exposed, clamped to [0,1] and sRGB
 * encoded; float formats store linear values. NaN/Inf values are rejected.
 * desc may be NULL. */
lx_status lx_image_write(const char *path, const lx_image *img, const lx_image_write_desc *desc);

/* Bilinear sample at UV (origin top-left, texel centres at (x+0.5)/W),
 * wrapping around the edges (glTF's default REPEAT). out gets img->channels
 * floats. */
void lx_image_sample_bilinear(const lx_image *img, float u, float v, float *out);

/* sRGB transfer function. */
float lx_srgb_to_linear(float c);
float lx_linear_to_srgb(float c);

/* ---- atomic output files ----------------------------------------------- */

/* A file written under a temporary name in the target folder and renamed
 * over the target by lx_out_commit; lx_out_abort removes it. */
typedef struct lx_out_file {
    void *fp; /* FILE* */
    char *tmp_path;
    char *path;
} lx_out_file;

lx_status lx_out_open(lx_out_file *f, const char *path);
lx_status lx_out_commit(lx_out_file *f);
void lx_out_abort(lx_out_file *f);

/* Removes every temporary file still open (for signal handlers: only calls
 * async-signal-safe unlink). */
void lx_out_abort_all_signal_safe(void);

/* ---- random numbers ----------------------------------------------------- */

/* A counter-based hash: the same (seed, a, b, c) always gives the same bits,
 * whatever thread asks. Use a = texel or pixel index, b = sample index,
 * c = dimension. */
uint32_t lx_hash4(uint32_t seed, uint32_t a, uint32_t b, uint32_t c);
/* Uniform float in [0, 1) from lx_hash4. */
float lx_random(uint32_t seed, uint32_t a, uint32_t b, uint32_t c);

/* ---- misc --------------------------------------------------------------- */

/* Reads a whole file into a malloc'd buffer (NUL-terminated, size excludes
 * the NUL). Fails with LX_ERR_IO naming the path. max_size bounds the read. */
lx_status lx_read_file(const char *path, size_t max_size, char **out, size_t *out_size);

/* The folder part of a path (malloc'd; "." when none). */
char *lx_path_dirname(const char *path);
/* a/b joined (malloc'd); b returned as-is when absolute. */
char *lx_path_join(const char *a, const char *b);
/* strdup that reports LX_ERR_NOMEM via NULL. */
char *lx_strdup(const char *s);

#ifdef __cplusplus
}
#endif
#endif
