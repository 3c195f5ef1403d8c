/* Sizes and memory checks, thread counts, atomic output files, counter-based
 * hashing, whole-file reads and path helpers. */
#define _POSIX_C_SOURCE 200809L
#include "luxel/core.h"

#include <errno.h>
#include <omp.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

bool lx_size_mul(size_t a, size_t b, size_t c, size_t *out)
{
    size_t ab, abc;
    if (__builtin_mul_overflow(a, b, &ab) || __builtin_mul_overflow(ab, c, &abc))
        return false;
    *out = abc;
    return true;
}

uint64_t lx_physical_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES);
    long page_size = sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page_size <= 0)
        return 0;
    return (uint64_t)pages * (uint64_t)page_size;
}

static void format_bytes(uint64_t bytes, char *buf, size_t size)
{
    const double gib = 1024.0 * 1024.0 * 1024.0;
    if (bytes >= (uint64_t)gib / 4)
        snprintf(buf, size, "%.1f GiB", (double)bytes / gib);
    else
        snprintf(buf, size, "%.1f MiB", (double)bytes / (1024.0 * 1024.0));
}

lx_status lx_check_memory(uint64_t bytes, const char *what)
{
    uint64_t have = lx_physical_memory();
    if (have == 0 || bytes <= have)
        return LX_OK;
    char need_s[32], have_s[32];
    format_bytes(bytes, need_s, sizeof need_s);
    format_bytes(have, have_s, sizeof have_s);
    return lx_fail(LX_ERR_NOMEM, "%s needs %s of memory, the machine has %s", what, need_s, have_s);
}

int lx_thread_count(int requested)
{
    if (requested > 0)
        return requested;
    int n = omp_get_num_procs();
    return n > 0 ? n : 1;
}

/* ---- atomic output files ------------------------------------------------ */

/* Temp files still open, so a signal handler can remove them. */
#define LX_MAX_OPEN_OUT 64
static char *volatile open_tmp_paths[LX_MAX_OPEN_OUT];
static pthread_mutex_t open_tmp_lock = PTHREAD_MUTEX_INITIALIZER;

static void register_tmp(char *path)
{
    pthread_mutex_lock(&open_tmp_lock);
    for (int i = 0; i < LX_MAX_OPEN_OUT; i++)
        if (!open_tmp_paths[i]) {
            open_tmp_paths[i] = path;
            break;
        }
    pthread_mutex_unlock(&open_tmp_lock);
}

static void unregister_tmp(char *path)
{
    pthread_mutex_lock(&open_tmp_lock);
    for (int i = 0; i < LX_MAX_OPEN_OUT; i++)
        if (open_tmp_paths[i] == path)
            open_tmp_paths[i] = NULL;
    pthread_mutex_unlock(&open_tmp_lock);
}

void lx_out_abort_all_signal_safe(void)
{
    for (int i = 0; i < LX_MAX_OPEN_OUT; i++) {
        char *p = open_tmp_paths[i];
        if (p)
            unlink(p);
    }
}

lx_status lx_out_open(lx_out_file *f, const char *path)
{
    memset(f, 0, sizeof *f);
    size_t len = strlen(path);
    f->path = lx_strdup(path);
    f->tmp_path = malloc(len + 16);
    if (!f->path || !f->tmp_path) {
        free(f->path);
        free(f->tmp_path);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    }
    memcpy(f->tmp_path, path, len);
    /* mkstemp's template: ".tmp." then six X that it replaces */
    memcpy(f->tmp_path + len, ".tmp.", 5);
    memset(f->tmp_path + len + 5, 'X', 6);
    f->tmp_path[len + 11] = '\0';
    /* SIGINT/SIGTERM wait until the file is registered, so an interrupt
     * handler calling lx_out_abort_all_signal_safe always knows it */
    sigset_t block, old;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &block, &old);
    int fd = mkstemp(f->tmp_path);
    if (fd >= 0)
        register_tmp(f->tmp_path);
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    if (fd < 0) {
        int err = errno;
        free(f->path);
        free(f->tmp_path);
        memset(f, 0, sizeof *f);
        return lx_fail(LX_ERR_IO, "%s: cannot create: %s", path, strerror(err));
    }
    /* mkstemp makes 0600; outputs are ordinary files */
    mode_t mask = umask(0);
    umask(mask);
    fchmod(fd, 0666 & ~mask);
    f->fp = fdopen(fd, "wb");
    if (!f->fp) {
        int err = errno;
        close(fd);
        lx_out_abort(f);
        return lx_fail(LX_ERR_IO, "%s: cannot open: %s", path, strerror(err));
    }
    return LX_OK;
}

lx_status lx_out_commit(lx_out_file *f)
{
    FILE *fp = f->fp;
    f->fp = NULL;
    /* on disk before the rename, so a crash never leaves an empty target */
    int failed = fflush(fp) != 0 || ferror(fp) || fsync(fileno(fp)) != 0;
    if (fclose(fp) != 0)
        failed = 1;
    if (failed) {
        int err = errno;
        char *path = lx_strdup(f->path);
        lx_out_abort(f);
        lx_status s = lx_fail(LX_ERR_IO, "%s: write failed: %s", path ? path : "?", strerror(err));
        free(path);
        return s;
    }
    if (rename(f->tmp_path, f->path) != 0) {
        int err = errno;
        char *path = lx_strdup(f->path);
        lx_out_abort(f);
        lx_status s = lx_fail(LX_ERR_IO, "%s: cannot rename temporary file: %s", path ? path : "?",
                              strerror(err));
        free(path);
        return s;
    }
    unregister_tmp(f->tmp_path);
    free(f->tmp_path);
    free(f->path);
    memset(f, 0, sizeof *f);
    return LX_OK;
}

void lx_out_abort(lx_out_file *f)
{
    if (f->fp)
        fclose(f->fp);
    if (f->tmp_path) {
        unlink(f->tmp_path);
        unregister_tmp(f->tmp_path);
    }
    free(f->tmp_path);
    free(f->path);
    memset(f, 0, sizeof *f);
}

/* ---- counter-based random numbers --------------------------------------- */

/* "lowbias32" integer finalizer (C. Wellons' hash prospector). */
static uint32_t mix32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

uint32_t lx_hash4(uint32_t seed, uint32_t a, uint32_t b, uint32_t c)
{
    uint32_t h = mix32(seed ^ 0x9e3779b9U);
    h = mix32(h ^ a);
    h = mix32(h ^ (b * 0x85ebca6bU));
    h = mix32(h ^ (c * 0xc2b2ae35U));
    return h;
}

float lx_random(uint32_t seed, uint32_t a, uint32_t b, uint32_t c)
{
    return (float)(lx_hash4(seed, a, b, c) >> 8) * (1.0f / 16777216.0f);
}

/* ---- files and paths ---------------------------------------------------- */

lx_status lx_read_file(const char *path, size_t max_size, char **out, size_t *out_size)
{
    *out = NULL;
    *out_size = 0;
    FILE *fp = fopen(path, "rb");
    if (!fp)
        return lx_fail(LX_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    struct stat st;
    if (fstat(fileno(fp), &st) != 0 || !S_ISREG(st.st_mode)) {
        fclose(fp);
        return lx_fail(LX_ERR_IO, "%s: not a regular file", path);
    }
    if ((uint64_t)st.st_size > max_size) {
        fclose(fp);
        return lx_fail(LX_ERR_FORMAT, "%s: file is %lld bytes, more than the %zu allowed", path,
                       (long long)st.st_size, max_size);
    }
    size_t size = (size_t)st.st_size;
    char *buf = malloc(size + 1);
    if (!buf) {
        fclose(fp);
        return lx_fail(LX_ERR_NOMEM, "%s: cannot allocate %zu bytes", path, size);
    }
    size_t got = fread(buf, 1, size, fp);
    int err = ferror(fp);
    fclose(fp);
    if (err || got != size) {
        free(buf);
        return lx_fail(LX_ERR_IO, "%s: read failed", path);
    }
    buf[size] = '\0';
    *out = buf;
    *out_size = size;
    return LX_OK;
}

char *lx_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *r = malloc(n);
    if (r)
        memcpy(r, s, n);
    return r;
}

char *lx_path_dirname(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return lx_strdup(".");
    if (slash == path)
        return lx_strdup("/");
    size_t n = (size_t)(slash - path);
    char *r = malloc(n + 1);
    if (r) {
        memcpy(r, path, n);
        r[n] = '\0';
    }
    return r;
}

char *lx_path_join(const char *a, const char *b)
{
    if (b[0] == '/' || !a[0])
        return lx_strdup(b);
    size_t na = strlen(a), nb = strlen(b);
    int need_slash = a[na - 1] != '/';
    char *r = malloc(na + nb + 2);
    if (!r)
        return NULL;
    memcpy(r, a, na);
    if (need_slash)
        r[na++] = '/';
    memcpy(r + na, b, nb + 1);
    return r;
}
