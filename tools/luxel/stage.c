/* Staged output for the commands that write several files (bake, ibl):
 * every file goes to DIR/.luxel-<random> first and is moved into DIR only
 * when all of them are written, so a failure or an interrupt leaves DIR as
 * it was. Publishing keeps what it replaces until the last rename is done
 * and restores it if one fails. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* The folder inside the staging folder that holds the replaced outputs
 * while publishing (staged names never start with a dot). */
#define PREVIOUS ".previous"

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
    memset(st, 0, sizeof *st);
}

bool cli_stage_begin(cli_stage *st, const char *output)
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
    /* mkdtemp replaces the template's last six characters, which must be
     * 'X'; they are written in below so the name reads as .luxel-<random> */
    st->dir = cli_path_join(output, ".luxel-123456");
    if (st->dir)
        memset(st->dir + strlen(st->dir) - 6, 'X', 6);
    if (!st->dir || !mkdtemp(st->dir)) {
        int err = errno;
        if (st->dir)
            cli_error("%s: cannot write into the output folder: %s", output, strerror(err));
        else
            cli_error("out of memory");
        free(st->dir);
        st->dir = NULL;
        remove_made(st);
        stage_free(st);
        return false;
    }
    return true;
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
