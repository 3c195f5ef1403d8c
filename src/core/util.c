/* Sizes, thread counts, atomic output files, counter-based
 * hashing, whole-file reads and path helpers (declared in internal.h). */
#define _DEFAULT_SOURCE /* flock, DT_REG */
#include "internal.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <omp.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

bool lx_size_mul(size_t a, size_t b, size_t c, size_t *out)
{
    size_t ab, abc;
    if (__builtin_mul_overflow(a, b, &ab) || __builtin_mul_overflow(ab, c, &abc))
        return false;
    *out = abc;
    return true;
}

int lx_thread_count(int requested)
{
    if (requested > 0)
        return requested;
    int n = omp_get_num_procs();
    return n > 0 ? n : 1;
}

/* ---- atomic output files ------------------------------------------------ */

/* A name no other writer picks: the process id, a per-process counter and
 * the clock, hashed; O_EXCL catches the rare clash and we try again. */
static void temp_suffix(char out[7])
{
    static _Atomic uint32_t counter;
    static const char digits[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint32_t h = lx_hash4((uint32_t)getpid(), counter++, (uint32_t)ts.tv_nsec, (uint32_t)ts.tv_sec);
    for (int i = 0; i < 6; i++) {
        out[i] = digits[h % 36u];
        h /= 36u;
    }
    out[6] = '\0';
}

/* True for the name of a temporary file of lx_out_open for base:
 * "<base>.tmp." and six of temp_suffix's characters. */
static bool is_temp_of(const char *name, const char *base)
{
    size_t n = strlen(base);
    if (strncmp(name, base, n) != 0 || strncmp(name + n, ".tmp.", 5) != 0)
        return false;
    const char *suffix = name + n + 5;
    if (strlen(suffix) != 6)
        return false;
    for (int i = 0; i < 6; i++)
        if (!((suffix[i] >= 'a' && suffix[i] <= 'z') || (suffix[i] >= '0' && suffix[i] <= '9')))
            return false;
    return true;
}

/* A writer holds an exclusive flock on its temporary file until it is
 * renamed or removed. A temporary file of the same target that nobody
 * holds was left by a run that was killed (or crashed) before it could
 * remove it: it is reported and removed, as nothing else could finish it. */
static void remove_leftovers(const char *path, const char *mine)
{
    char *folder = lx_path_dirname(path);
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    DIR *dir = folder ? opendir(folder) : NULL;
    if (!dir) {
        free(folder);
        return;
    }
    const char *mine_base = strrchr(mine, '/') ? strrchr(mine, '/') + 1 : mine;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        if (!is_temp_of(e->d_name, base) || strcmp(e->d_name, mine_base) == 0)
            continue;
        int fd = openat(dirfd(dir), e->d_name, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
        if (fd < 0)
            continue;
        struct stat st;
        if (fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && flock(fd, LOCK_EX | LOCK_NB) == 0 &&
            unlinkat(dirfd(dir), e->d_name, 0) == 0)
            lx_log(LX_LOG_WARN, "%s/%s: removed, a partial file of %s left by a run that was "
                                "stopped",
                   folder, e->d_name, base);
        close(fd);
    }
    closedir(dir);
    free(folder);
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
        memset(f, 0, sizeof *f);
        return lx_fail(LX_ERR_NOMEM, "%s: out of memory", path);
    }
    int fd = -1, err = 0;
    for (int attempt = 0; attempt < 100 && fd < 0; attempt++) {
        char suffix[7];
        temp_suffix(suffix);
        snprintf(f->tmp_path, len + 16, "%s.tmp.%s", path, suffix);
        /* 0666 less the umask, as any new file: the kernel applies it */
        fd = open(f->tmp_path, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        err = errno;
        if (fd < 0 && err != EEXIST)
            break;
        /* held until the file is renamed or removed; a leftover sweep of
         * another writer may have taken this file between open and flock,
         * so a file no longer linked is given up for a new one */
        struct stat st;
        if (fd >= 0 && (flock(fd, LOCK_EX) != 0 || fstat(fd, &st) != 0 || st.st_nlink == 0)) {
            close(fd);
            fd = -1;
            err = EEXIST;
        }
    }
    if (fd >= 0)
        remove_leftovers(path, f->tmp_path);
    if (fd < 0) {
        free(f->path);
        free(f->tmp_path);
        memset(f, 0, sizeof *f);
        return lx_fail(LX_ERR_IO, "%s: cannot create: %s", path, strerror(err));
    }
    f->fp = fdopen(fd, "wb");
    if (!f->fp) {
        err = errno;
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
    /* on disk before the rename, so a crash never leaves an empty target;
     * renamed while still open (and locked), so no leftover sweep takes it */
    int failed = fflush(fp) != 0 || ferror(fp) || fsync(fileno(fp)) != 0;
    int err = errno;
    const char *what = "write failed";
    if (!failed && rename(f->tmp_path, f->path) != 0) {
        failed = 1;
        err = errno;
        what = "cannot rename temporary file";
    }
    if (fclose(fp) != 0 && !failed) {
        failed = 1;
        err = errno;
        unlink(f->path); /* renamed, but not all of it written */
    }
    if (failed) {
        char *path = f->path;
        f->path = NULL;
        lx_out_abort(f);
        lx_status s = lx_fail(LX_ERR_IO, "%s: %s: %s", path ? path : "?", what, strerror(err));
        free(path);
        return s;
    }
    free(f->tmp_path);
    free(f->path);
    memset(f, 0, sizeof *f);
    return LX_OK;
}

void lx_out_abort(lx_out_file *f)
{
    if (f->tmp_path)
        unlink(f->tmp_path);
    if (f->fp)
        fclose(f->fp);
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
