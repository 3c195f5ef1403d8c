/* Staged output for the commands that write several files (bake, ibl):
 * every file goes to DIR/.luxel-<random> first and is moved into DIR only
 * when all of them are written, so a failure or an interrupt leaves DIR as
 * it was. Publishing keeps what it replaces until the last rename is done
 * and restores it if one fails.
 * Locks (flock, released by the kernel when a run dies): every run holds
 * its staging folder's, so a staging folder whose lock can be taken was
 * left by a run that was killed or crashed; a command whose files belong
 * together (bake, ibl) holds the output folder's too, so two such runs
 * never mix their files in one folder. */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* flock */
#include "cli.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

/* The folder inside the staging folder that holds the replaced outputs
 * while publishing (staged names never start with a dot). */
#define PREVIOUS ".previous"

/* A staging folder is STAGE_PREFIX and mkdtemp's six characters. */
#define STAGE_PREFIX ".luxel-"
#define STAGE_NAME_LENGTH (sizeof STAGE_PREFIX - 1 + 6)

/* How often a staging folder is made again when another run's --clean
 * took it for a leftover between its creation and its lock. */
#define STAGE_ATTEMPTS 8

bool cli_make_dirs(const char *dir)
{
    if (!dir[0]) {
        errno = ENOENT;
        return false;
    }
    char *p = cli_strdup(dir);
    if (!p)
        return false;
    for (char *s = p + 1; *s; s++)
        if (*s == '/') {
            *s = '\0';
            if (mkdir(p, 0777) != 0 && errno != EEXIST) {
                free(p);
                return false;
            }
            *s = '/';
        }
    bool ok = mkdir(p, 0777) == 0 || errno == EEXIST;
    struct stat st;
    if (ok && (stat(p, &st) != 0 || !S_ISDIR(st.st_mode))) {
        ok = false;
        errno = ENOTDIR;
    }
    free(p);
    return ok;
}

/* The folders among path and its parents that do not exist yet, deepest
 * first: the ones cli_make_dirs will create. false when out of memory. */
static bool find_missing_dirs(cli_stage *st, const char *path)
{
    char *p = cli_strdup(path);
    if (!p)
        return false;
    struct stat sb;
    bool ok = true;
    while (p[0] && lstat(p, &sb) != 0) {
        char **grown = realloc(st->made, sizeof(char *) * (st->made_count + 1));
        char *copy = grown ? cli_strdup(p) : NULL;
        if (grown)
            st->made = grown;
        if (!copy) {
            ok = false;
            break;
        }
        st->made[st->made_count++] = copy;
        char *slash = strrchr(p, '/');
        if (!slash || slash == p)
            break;
        *slash = '\0';
    }
    free(p);
    return ok;
}

/* Removes the folders the run made, deepest first (only empty ones go). */
static void remove_made(const cli_stage *st)
{
    for (uint32_t i = 0; i < st->made_count; i++)
        rmdir(st->made[i]);
}

static void stage_free(cli_stage *st)
{
    for (uint32_t i = 0; i < st->made_count; i++)
        free(st->made[i]);
    for (uint32_t i = 0; i < st->count; i++)
        free(st->names[i]);
    free(st->made);
    free(st->names);
    free(st->dir);
    free(st->output);
    /* closing a folder's descriptor releases its lock: the staging folder
     * is gone by now, the output folder's lock goes last */
    if (st->dir_locked)
        close(st->dir_fd);
    if (st->output_locked)
        close(st->output_fd);
    memset(st, 0, sizeof *st);
}

/* Takes the output folder's lock: an exclusive flock on the folder itself
 * (a lock file would stay behind), held until cli_stage_clear. Fails at
 * once when another run holds it: waiting would hide a mistake (two
 * bakes into one folder) behind a run that seems to hang. */
static bool lock_output(cli_stage *st)
{
    int fd = open(st->output, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd < 0) {
        cli_error("%s: cannot open the output folder: %s", st->output, strerror(errno));
        return false;
    }
    if (flock(fd, LOCK_EX | LOCK_NB) == 0) {
        st->output_fd = fd;
        st->output_locked = true;
        return true;
    }
    int err = errno;
    close(fd);
    if (err == EWOULDBLOCK) {
        cli_error("another luxel run is writing %s: wait for it to end, or give another -o",
                  st->output);
        return false;
    }
    /* a file system without flock (some network mounts): no guard */
    lx_log(LX_LOG_INFO,
           "%s: cannot lock the output folder (%s): a second run into it would not "
           "be noticed",
           st->output, strerror(err));
    return true;
}

/* Makes the staging folder and takes its lock, which tells other runs it
 * is in use. Another run's --clean may take a just-made folder for a
 * leftover before its lock is taken, and remove it: then it is made
 * again. */
static bool make_staging(cli_stage *st)
{
    /* mkdtemp replaces the template's last six characters, which must be
     * 'X'; they are written in below so the name reads as .luxel-<random> */
    st->dir = cli_path_join(st->output, STAGE_PREFIX "123456");
    if (!st->dir) {
        cli_error("out of memory");
        return false;
    }
    for (int attempt = 0; attempt < STAGE_ATTEMPTS; attempt++) {
        memset(st->dir + strlen(st->dir) - 6, 'X', 6);
        if (!mkdtemp(st->dir)) {
            cli_error("%s: cannot write into the output folder: %s", st->output, strerror(errno));
            return false;
        }
        int fd = open(st->dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        if (fd < 0)
            continue; /* removed already */
        if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
            int err = errno;
            close(fd);
            if (err == EWOULDBLOCK)
                continue; /* being removed: that run's --clean rmdirs it */
            return true;  /* no flock here: the folder is used unlocked */
        }
        /* still the folder at that name, not one removed under the lock */
        struct stat held, named;
        if (fstat(fd, &held) == 0 && lstat(st->dir, &named) == 0 && held.st_dev == named.st_dev &&
            held.st_ino == named.st_ino) {
            st->dir_fd = fd;
            st->dir_locked = true;
            return true;
        }
        close(fd);
    }
    cli_error("%s: cannot make a staging folder: it was removed %d times while being made",
              st->output, STAGE_ATTEMPTS);
    return false;
}

/* The names of folder fd's entries (without . and ..), malloc'd; *count
 * of them. NULL with *count 0 when there are none or the folder cannot
 * be read. */
static char **folder_entries(int fd, uint32_t *count)
{
    *count = 0;
    int copy = dup(fd);
    DIR *d = copy >= 0 ? fdopendir(copy) : NULL;
    if (!d) {
        if (copy >= 0)
            close(copy);
        return NULL;
    }
    rewinddir(d);
    char **names = NULL;
    uint32_t n = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        char **grown = realloc(names, sizeof *names * (n + 1));
        char *name = grown ? cli_strdup(e->d_name) : NULL;
        if (grown)
            names = grown;
        if (!name)
            break;
        names[n++] = name;
    }
    closedir(d);
    *count = n;
    return names;
}

static void free_entries(char **names, uint32_t count)
{
    for (uint32_t i = 0; i < count; i++)
        free(names[i]);
    free(names);
}

/* Empties a leftover staging folder (fd, its lock held) of what a run
 * leaves there: files, and PREVIOUS with the files publishing set aside.
 * Anything else (a folder luxel does not make) stays: false then. */
static bool empty_leftover(int fd, bool top)
{
    uint32_t n;
    char **names = folder_entries(fd, &n);
    bool ok = true;
    for (uint32_t i = 0; i < n; i++) {
        struct stat sb;
        if (fstatat(fd, names[i], &sb, AT_SYMLINK_NOFOLLOW) != 0)
            continue;
        if (!S_ISDIR(sb.st_mode)) {
            ok = unlinkat(fd, names[i], 0) == 0 && ok;
        } else if (top && strcmp(names[i], PREVIOUS) == 0) {
            int sub = openat(fd, names[i], O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
            ok = sub >= 0 && empty_leftover(sub, false) && ok;
            if (sub >= 0)
                close(sub);
            ok = unlinkat(fd, names[i], AT_REMOVEDIR) == 0 && ok;
        } else {
            ok = false;
        }
    }
    free_entries(names, n);
    return ok;
}

/* Appends ", name" (the first without the comma) to list while it fits,
 * else counts it in *unlisted. */
static void list_name(char *list, size_t size, const char *name, uint32_t *unlisted)
{
    size_t len = strlen(list);
    if (*unlisted == 0 && len + strlen(name) + 24 < size)
        snprintf(list + len, size - len, "%s%s", len ? ", " : "", name);
    else
        (*unlisted)++;
}

static void end_list(char *list, size_t size, uint32_t unlisted)
{
    size_t len = strlen(list);
    if (unlisted)
        snprintf(list + len, size - len, " and %u more", unlisted);
}

/* Staging folders in the output folder whose lock can be taken: runs that
 * were killed or crashed left them. One warning names them; with clean
 * they are removed instead (an INFO line). Never an error: they hold no
 * output of this run. */
static void handle_leftovers(const cli_stage *st, bool clean, bool clean_option)
{
    int out = open(st->output, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (out < 0)
        return;
    uint32_t n;
    char **names = folder_entries(out, &n);
    char found[400] = "", failed[400] = "";
    uint32_t found_count = 0, found_unlisted = 0, failed_unlisted = 0;
    for (uint32_t i = 0; i < n; i++) {
        if (strlen(names[i]) != STAGE_NAME_LENGTH ||
            strncmp(names[i], STAGE_PREFIX, sizeof STAGE_PREFIX - 1) != 0)
            continue;
        /* a folder, not a link to one: O_NOFOLLOW */
        int fd = openat(out, names[i], O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
        if (fd < 0)
            continue;
        /* held: a running run's; not lockable at all: cannot tell */
        if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
            close(fd);
            continue;
        }
        found_count++;
        list_name(found, sizeof found, names[i], &found_unlisted);
        if (clean && !(empty_leftover(fd, true) && unlinkat(out, names[i], AT_REMOVEDIR) == 0))
            list_name(failed, sizeof failed, names[i], &failed_unlisted);
        close(fd); /* after the rmdir: a new run cannot take it meanwhile */
    }
    free_entries(names, n);
    close(out);
    if (!found_count)
        return;
    end_list(found, sizeof found, found_unlisted);
    bool one = found_count == 1;
    if (clean) {
        lx_log(LX_LOG_INFO, "%s: removing %s left by luxel %s that did not finish: %s", st->output,
               one ? "a staging folder" : "staging folders", one ? "a run" : "runs", found);
        if (failed[0]) {
            end_list(failed, sizeof failed, failed_unlisted);
            lx_log(LX_LOG_WARN,
                   "%s: could not remove all of %s: it holds what luxel does not "
                   "write there",
                   st->output, failed);
        }
    } else {
        lx_log(LX_LOG_WARN, "%s: %s left by %s that did not finish (killed or crashed): %s; %s",
               st->output, one ? "a staging folder" : "staging folders",
               one ? "a luxel run" : "luxel runs", found,
               clean_option ? (one ? "--clean removes it" : "--clean removes them")
                            : (one ? "remove it by hand" : "remove them by hand"));
    }
}

/* The stage begun last and not yet cleared (cli_stage_clear_active). */
static cli_stage *active_stage;

/* cli_stage_begin and cli_stage_begin_set. */
static bool stage_begin(cli_stage *st, const char *output, bool lock, bool clean, bool clean_option)
{
    memset(st, 0, sizeof *st);
    st->output = cli_strdup(output);
    if (!st->output || !find_missing_dirs(st, output)) {
        cli_error("out of memory");
        stage_free(st);
        return false;
    }
    if (!cli_make_dirs(output)) {
        int err = errno;
        cli_error("%s: cannot create the output folder: %s", output,
                  err == ENOTDIR || err == EEXIST ? "something that is not a folder is in the way"
                                                  : strerror(err));
        remove_made(st);
        stage_free(st);
        return false;
    }
    if ((lock && !lock_output(st)) || !make_staging(st)) {
        if (st->dir)
            rmdir(st->dir); /* made, or a template that never was: either way */
        remove_made(st);
        stage_free(st);
        return false;
    }
    handle_leftovers(st, clean, clean_option);
    active_stage = st;
    return true;
}

void cli_stage_clear_active(void)
{
    if (active_stage)
        cli_stage_clear(active_stage);
}

bool cli_stage_begin(cli_stage *st, const char *output)
{
    return stage_begin(st, output, false, false, false);
}

bool cli_stage_begin_set(cli_stage *st, const char *output, bool clean)
{
    return stage_begin(st, output, true, clean, true);
}

bool cli_stage_check(const cli_stage *st, const char *name)
{
    char *to = cli_path_join(st->output, name);
    if (!to) {
        cli_error("out of memory");
        return false;
    }
    struct stat sb;
    bool ok = lstat(to, &sb) != 0 || S_ISREG(sb.st_mode);
    if (!ok)
        cli_error("%s: cannot write: something that is not a file is in the way", to);
    free(to);
    return ok;
}

char *cli_stage_path(cli_stage *st, const char *name)
{
    if (cli_interrupted()) {
        cli_report_interrupt(true);
        return NULL;
    }
    if (!cli_stage_check(st, name))
        return NULL;
    /* two outputs of one name: the second would overwrite the first, and
     * publishing would fail on it after all the work (commands plan their
     * names so that this never happens) */
    for (uint32_t i = 0; i < st->count; i++)
        if (strcmp(st->names[i], name) == 0) {
            cli_error("%s/%s: two outputs of this run have this name", st->output, name);
            return NULL;
        }
    /* named before it exists, so cli_stage_clear removes whatever the
     * writer leaves behind */
    if (st->count == st->capacity) {
        uint32_t capacity = st->capacity ? 2 * st->capacity : 16;
        char **grown = realloc(st->names, sizeof(char *) * capacity);
        if (!grown) {
            cli_error("out of memory");
            return NULL;
        }
        st->names = grown;
        st->capacity = capacity;
    }
    char *copy = cli_strdup(name);
    char *path = cli_path_join(st->dir, name);
    if (!copy || !path) {
        free(copy);
        free(path);
        cli_error("out of memory");
        return NULL;
    }
    st->names[st->count++] = copy;
    return path;
}

bool cli_stage_finish(cli_stage *st, const char *name, lx_status s)
{
    if (s == LX_ERR_CANCELLED) { /* the progress callback saw a signal */
        cli_report_interrupt(true);
        return false;
    }
    if (s != LX_OK) {
        /* the writer's message names the staging path: show the final one */
        const char *msg = lx_last_error();
        size_t n = strlen(st->dir);
        if (strncmp(msg, st->dir, n) == 0)
            cli_error("%s%s", st->output, msg + n);
        else
            cli_error("%s: %s", name, msg);
        return false;
    }
    if (st->count == 1)
        cli_test_pause("write");
    return true;
}

bool cli_stage_image(cli_stage *st, const char *name, const lx_image *img,
                     const lx_image_write_desc *desc)
{
    char *path = cli_stage_path(st, name);
    if (!path)
        return false;
    lx_status s = lx_image_write(path, img, desc);
    free(path);
    return cli_stage_finish(st, name, s);
}

bool cli_stage_text(cli_stage *st, const char *name, const char *text)
{
    char *path = cli_stage_path(st, name);
    if (!path)
        return false;
    /* the staging folder is this run's alone: no temporary name needed */
    FILE *fp = fopen(path, "wb");
    bool ok = fp && fputs(text, fp) >= 0;
    ok = fp && fclose(fp) == 0 && ok;
    if (!ok)
        cli_error("%s/%s: cannot write: %s", st->output, name, strerror(errno));
    free(path);
    return ok && cli_stage_finish(st, name, LX_OK);
}

/* What publishing did to one output: whether an old file was there, and
 * whether the new one is in its place yet. */
typedef struct published {
    bool had_old;  /* OUTPUT/name existed: a copy of it is in PREVIOUS */
    bool old_gone; /* the old file was moved, not linked: OUTPUT/name is missing */
    bool placed;   /* the new file is OUTPUT/name */
} published;

/* Puts back what publishing the first n outputs changed, last first. */
static void restore(const cli_stage *st, const published *done, uint32_t n, const char *previous)
{
    for (uint32_t i = n; i-- > 0;) {
        char *to = cli_path_join(st->output, st->names[i]);
        char *kept = cli_path_join(previous, st->names[i]);
        if (to && kept) {
            if (done[i].had_old && (done[i].placed || done[i].old_gone)) {
                errno = EIO; /* what an injected failure reports */
                if (cli_test_fail_restore() || rename(kept, to) != 0)
                    cli_error("%s: could not put the previous file back (it is in %s): %s", to,
                              kept, strerror(errno));
            } else if (done[i].placed) {
                unlink(to);
            }
        }
        free(to);
        free(kept);
    }
}

bool cli_stage_publish(cli_stage *st)
{
    /* anything but a file in the way would fail its rename half-way */
    for (uint32_t i = 0; i < st->count; i++)
        if (!cli_stage_check(st, st->names[i]))
            return false;
    char *previous = cli_path_join(st->dir, PREVIOUS);
    published *done = calloc(st->count + 1, sizeof *done);
    if (!previous || !done || mkdir(previous, 0700) != 0) {
        cli_error("%s: cannot publish: %s", st->output,
                  previous && done ? strerror(errno) : "out of memory");
        free(previous);
        free(done);
        return false;
    }
    bool ok = true;
    uint32_t i = 0;
    for (; i < st->count && ok; i++) {
        char *from = cli_path_join(st->dir, st->names[i]);
        char *to = cli_path_join(st->output, st->names[i]);
        char *kept = cli_path_join(previous, st->names[i]);
        ok = from && to && kept;
        if (!ok)
            cli_error("out of memory");
        struct stat sb;
        if (ok && lstat(to, &sb) == 0) {
            /* keep the old file: a second name for it (the output stays in
             * place meanwhile), or the file itself where links are refused */
            done[i].had_old = true;
            errno = EPERM; /* what an injected refusal reports */
            if (cli_test_fail_link() || link(to, kept) != 0) {
                done[i].old_gone = rename(to, kept) == 0;
                if (!done[i].old_gone) {
                    cli_error("%s: cannot set the previous file aside: %s", to, strerror(errno));
                    done[i].had_old = false;
                    ok = false;
                }
            }
        }
        if (ok) {
            errno = EIO; /* what an injected failure reports */
            if (cli_test_fail_rename() || rename(from, to) != 0) {
                cli_error("%s: cannot move into place: %s", to, strerror(errno));
                ok = false;
            } else {
                done[i].placed = true;
            }
        }
        free(from);
        free(to);
        free(kept);
    }
    if (!ok)
        restore(st, done, i, previous);
    /* What is left in PREVIOUS: after success, the replaced files; after a
     * failure, only second links to old files that never left their place
     * (restore moved the others back, and one it could not move is the
     * only copy: it stays). */
    for (uint32_t k = 0; k < i; k++) {
        bool spare = ok || (done[k].had_old && !done[k].old_gone && !done[k].placed);
        char *kept = spare ? cli_path_join(previous, st->names[k]) : NULL;
        if (kept)
            unlink(kept);
        free(kept);
    }
    rmdir(previous);
    free(previous);
    free(done);
    st->published = ok;
    return ok;
}

void cli_stage_clear(cli_stage *st)
{
    if (st == active_stage)
        active_stage = NULL;
    if (st->dir) {
        for (uint32_t i = 0; i < st->count; i++) {
            char *path = cli_path_join(st->dir, st->names[i]);
            if (path)
                unlink(path);
            free(path);
        }
        rmdir(st->dir);
    }
    if (!st->published)
        remove_made(st);
    stage_free(st);
}
