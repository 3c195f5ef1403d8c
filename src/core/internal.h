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

/* LX_ERR_INVALID with "function: param is NULL" for a required pointer
 * the caller left NULL (public entry points call it first of all). */
lx_status lx_fail_null(const char *function, const char *param);

/* Prefixes this thread's current error message with "prefix: ". */
void lx_error_prefix(const char *prefix);

/* ---- sizes, memory, threads ---------------------------------------------- */

/* a*b*c in *out, false on overflow of size_t. */
bool lx_size_mul(size_t a, size_t b, size_t c, size_t *out);

/* Physical memory of the machine in bytes (0 when unknown). */
uint64_t lx_physical_memory(void);

/* What bounds the memory a request may take (memory.c). */
typedef enum lx_memory_bound {
    LX_MEMORY_UNKNOWN = 0,   /* nothing known: no bound */
    LX_MEMORY_PHYSICAL,      /* the machine's physical memory */
    LX_MEMORY_CGROUP,        /* the memory limit of the process's control group */
    LX_MEMORY_ADDRESS_SPACE, /* RLIMIT_AS less the address space in use */
    LX_MEMORY_DATA           /* RLIMIT_DATA less the data in use */
} lx_memory_bound;

typedef struct lx_memory_limit {
    uint64_t available; /* what a new request may take (UINT64_MAX: unbounded) */
    uint64_t limit;     /* the bound's limit */
    uint64_t used;      /* of it already in use (the rlimits; 0 for the others) */
    lx_memory_bound bound;
} lx_memory_limit;

/* The memory a new request may take: the smallest of the machine's
 * physical memory, its control group's limit (cgroup v2 and v1, the
 * group and the groups above it), and RLIMIT_AS and RLIMIT_DATA less what
 * the process has of them. Fills *out (may be NULL) with the bound that
 * decided. Reads /proc on every call: limits may change. */
uint64_t lx_memory_available(lx_memory_limit *out);

/* "the machine has 23.5 GiB", "the address-space limit (RLIMIT_AS, ulimit
 * -v) is 8.0 GiB, 1.2 GiB of it in use", ... into buf. */
void lx_memory_limit_describe(const lx_memory_limit *m, char *buf, size_t size);

/* The smallest memory limit of the control groups a /proc/<pid>/cgroup
 * file names, found through a /proc/<pid>/mountinfo file (paths, for
 * tests); UINT64_MAX when there is none. */
uint64_t lx_cgroup_memory_limit(const char *cgroup_file, const char *mountinfo_file);

/* Fails with LX_ERR_NOMEM and a message "<what> needs N GiB of memory,
 * <the bound>" ("the machine has M GiB", "the address-space limit ...")
 * when bytes exceed lx_memory_available. */
lx_status lx_check_memory(uint64_t bytes, const char *what);

/* "1.5 GiB" or "12.0 MiB" into buf. */
void lx_format_bytes(uint64_t bytes, char *buf, size_t size);

/* Number of threads to use: requested when > 0, else all cores. */
int lx_thread_count(int requested);

/* ---- atomic output files -------------------------------------------------- */

/* A file written under a temporary name in the target folder
 * (<path>.tmp.<random>, created with O_EXCL and mode 0666 less the umask)
 * and renamed over the target by lx_out_commit; lx_out_abort removes it.
 * The writer holds an flock on it throughout, so lx_out_open can tell a
 * temporary file of the same target left by a killed run (nobody holds
 * it): it removes such files with one warning each. Nothing process-wide
 * is touched: no signal masks, no umask calls, no registry. */
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

/* lx_image_load / lx_image_load_memory that also tell how many times
 * desc->keep_pixels halved the image (*halvings, may be NULL; 0 on
 * failure): the scene's textures record it (image.c). path is read when
 * bytes is NULL. */
lx_status lx_image_load_halved(const char *path, const void *bytes, size_t size, const char *name,
                               const lx_image_load_desc *desc, lx_image *out, int *halvings);

/* The folder part of a path (malloc'd; "." when none). */
char *lx_path_dirname(const char *path);
/* False when path resolves (symbolic links followed; with backslashes
 * as slashes when it does not as written) to an existing file outside
 * folder and below it; a path naming nothing is not judged (its reader
 * reports it missing). path_policy.c */
bool lx_path_within(const char *folder, const char *path);
/* LX_OK when allow_any or path lies within folder; else LX_ERR_INVALID
 * with "file: what 'named' lies outside folder ...". */
lx_status lx_path_confine(const char *file, const char *what, const char *named, const char *folder,
                          const char *path, bool allow_any);
/* a/b joined (malloc'd); b returned as-is when absolute. */
char *lx_path_join(const char *a, const char *b);
/* Mutes lx_log on the calling thread while true (nested calls count):
 * the baker rebuilding a texel map it built before says nothing twice. */
void lx_log_mute(bool mute);
/* True while lx_log is muted on the calling thread (a worker it starts
 * mutes itself alike). */
bool lx_log_muted(void);

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
