/* Private to libluxel: the plumbing every module shares - error messages,
 * size arithmetic and memory checks, thread counts, atomic output files,
 * whole-file reads, paths, counter-based random numbers and half floats.
 * Not installed and not for users; tests and benchmarks may include it.
 * (The one private header modules share, docs/ARCHITECTURE.md.) */
#ifndef LX_CORE_INTERNAL_H
#define LX_CORE_INTERNAL_H

#include "luxel/core.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__)
#define LX_PRINTF(fmt_index, args_index) __attribute__((format(printf, fmt_index, args_index)))
#else
#define LX_PRINTF(fmt_index, args_index)
#endif

/* ---- errors -------------------------------------------------------------- */

/* Sets this thread's error message (printf format) and returns status. */
lx_status lx_fail(lx_status status, const char *fmt, ...) LX_PRINTF(2, 3);

/* Prefixes this thread's current error message with "prefix: ". */
void lx_error_prefix(const char *prefix);

/* ---- sizes, memory, threads ---------------------------------------------- */

/* a*b*c in *out, false on overflow of size_t. */
bool lx_size_mul(size_t a, size_t b, size_t c, size_t *out);

/* Physical memory of the machine in bytes (0 when unknown). */
uint64_t lx_physical_memory(void);

/* Fails with LX_ERR_NOMEM and a message "<what> needs N GiB of memory, the
 * machine has M GiB" when bytes exceed the machine's physical memory. */
lx_status lx_check_memory(uint64_t bytes, const char *what);

/* "1.5 GiB" or "12.0 MiB" into buf. */
void lx_format_bytes(uint64_t bytes, char *buf, size_t size);

/* Number of threads to use: requested when > 0, else all cores. */
int lx_thread_count(int requested);

/* ---- atomic output files -------------------------------------------------- */

/* A file written under a temporary name in the target folder
 * (<path>.tmp.<random>, created with O_EXCL and mode 0666 less the umask)
 * and renamed over the target by lx_out_commit; lx_out_abort removes it.
 * Nothing process-wide is touched: no signal masks, no umask calls, no
 * registry. */
typedef struct lx_out_file {
    void *fp; /* FILE* */
    char *tmp_path;
    char *path;
} lx_out_file;

lx_status lx_out_open(lx_out_file *f, const char *path);
lx_status lx_out_commit(lx_out_file *f);
void lx_out_abort(lx_out_file *f);

/* ---- files and paths ------------------------------------------------------ */

/* Reads a whole file into a malloc'd buffer (NUL-terminated, size excludes
 * the NUL). Fails with LX_ERR_IO naming the path. max_size bounds the read. */
lx_status lx_read_file(const char *path, size_t max_size, char **out, size_t *out_size);

/* The folder part of a path (malloc'd; "." when none). */
char *lx_path_dirname(const char *path);
/* a/b joined (malloc'd); b returned as-is when absolute. */
char *lx_path_join(const char *a, const char *b);
/* strdup that reports running out of memory by NULL. */
char *lx_strdup(const char *s);

/* ---- counter-based random numbers ----------------------------------------- */

/* The same (seed, a, b, c) always gives the same bits, whatever thread asks.
 * a = texel or pixel index, b = sample index, c = dimension. */
uint32_t lx_hash4(uint32_t seed, uint32_t a, uint32_t b, uint32_t c);
/* Uniform float in [0, 1) from lx_hash4. */
float lx_random(uint32_t seed, uint32_t a, uint32_t b, uint32_t c);

/* ---- half floats ---------------------------------------------------------- */

/* Largest finite IEEE binary16 value. */
#define LX_HALF_MAX 65504.0f

/* binary32 -> binary16, rounded to nearest, ties to even, subnormals
 * included. Values beyond LX_HALF_MAX give infinity and NaN gives NaN;
 * writers reject them before converting. */
uint16_t lx_float_to_half(float f);

#endif
