/* Staged output for the commands that write several files (bake, ibl):
 * every file goes to DIR/.luxel-<6 random characters> first and is moved
 * into DIR only when all of them are written, so a failure or an interrupt
 * leaves DIR as it was. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

bool cli_make_dirs(const char *dir)
{
    if (!dir[0]) {
        errno = ENOENT;
        return false;
    }
    char *p = lx_strdup(dir);
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
    ok = ok && stat(p, &st) == 0 && S_ISDIR(st.st_mode);
    free(p);
    return ok;
}

static char *make_staging(const char *output)
{
    /* mkdtemp's template: six X at the end that it replaces */
    char name[16] = ".luxel-";
    memset(name + 7, 'X', 6);
    char *dir = lx_path_join(output, name);
    if (dir && !mkdtemp(dir)) {
        free(dir);
        return NULL;
    }
    return dir;
}

/* The folders among path and its parents that do not exist yet, deepest
 * first (malloc'd, *count of them): the ones cli_make_dirs will create.
 * NULL with *count 0 when there are none or memory ran out. */
static char **missing_dirs(const char *path, uint32_t *count)
{
    *count = 0;
    char *p = lx_strdup(path);
    char **list = NULL;
    struct stat sb;
    while (p && p[0] && stat(p, &sb) != 0) {
        char **grown = realloc(list, sizeof(char *) * (*count + 1));
        char *copy = grown ? lx_strdup(p) : NULL;
        if (grown)
            list = grown;
        if (!copy)
            break;
        list[(*count)++] = copy;
        char *slash = strrchr(p, '/');
        if (!slash || slash == p)
            break;
        *slash = '\0';
    }
    free(p);
    return list;
}

/* Removes the folders a run made (deepest first; only empty ones go). */
static void remove_made(cli_stage *st)
{
    for (uint32_t i = 0; i < st->made_count; i++)
        rmdir(st->made[i]);
}

static void free_made(cli_stage *st)
{
    for (uint32_t i = 0; i < st->made_count; i++)
        free(st->made[i]);
    free(st->made);
    st->made = NULL;
    st->made_count = 0;
}

static bool stage_begin(cli_stage *st, const char *output);

bool cli_stage_begin(cli_stage *st, const char *output)
{
    /* Ctrl-C waits until the folders exist and are tracked: a signal in
     * between would leave a staging folder the handler does not know. */
    sigset_t block, old;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigprocmask(SIG_BLOCK, &block, &old);
    bool ok = stage_begin(st, output);
    sigprocmask(SIG_SETMASK, &old, NULL);
    return ok;
}

static bool stage_begin(cli_stage *st, const char *output)
{
    memset(st, 0, sizeof *st);
    /* the folders this run makes (the output folder and any missing
     * parents) go again if the run writes nothing */
    st->made = missing_dirs(output, &st->made_count);
    if (!cli_make_dirs(output)) {
        cli_error("%s: cannot create the output folder: %s", output, strerror(errno));
        remove_made(st);
        free_made(st);
        return false;
    }
    st->output = lx_strdup(output);
    if (!st->output) {
        cli_error("out of memory");
        remove_made(st);
        free_made(st);
        return false;
    }
    cli_set_writing(true);
    st->dir = make_staging(output);
    if (!st->dir) {
        cli_error("%s: cannot write into the output folder: %s", output, strerror(errno));
        cli_set_writing(false);
        remove_made(st);
        free_made(st);
        free(st->output);
        st->output = NULL;
        return false;
    }
    st->created = st->made_count > 0;
    cli_track_dir(st->dir, (const char *const *)st->made, st->made_count);
    return true;
}

/* Reports an error from a staged write under the final folder's name. */
static void stage_error(const cli_stage *st)
{
    const char *msg = lx_last_error();
    size_t n = strlen(st->dir);
    if (strncmp(msg, st->dir, n) == 0)
        cli_error("%s%s", st->output, msg + n);
    else
        cli_error("%s", msg);
}

char *cli_stage_path(cli_stage *st, const char *name)
{
    char *path = lx_path_join(st->dir, name);
    if (!path) {
        cli_error("out of memory");
        return NULL;
    }
    /* tracked before it exists: an interrupt right after the rename that
     * completes the file still finds it */
    if (!cli_track_output(path)) {
        free(path);
        cli_error("out of memory");
        return NULL;
    }
    return path;
}

bool cli_stage_finish(cli_stage *st, const char *name, lx_status s)
{
    if (s != LX_OK) {
        stage_error(st);
        return false;
    }
    char **names = realloc(st->names, sizeof(char *) * (st->count + 1));
    if (!names) {
        cli_error("out of memory");
        return false;
    }
    st->names = names;
    st->names[st->count] = lx_strdup(name);
    if (!st->names[st->count]) {
        cli_error("out of memory");
        return false;
    }
    st->count++;
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

static lx_status write_text(const char *path, const char *text)
{
    lx_out_file f;
    lx_status st = lx_out_open(&f, path);
    if (st != LX_OK)
        return st;
    fputs(text, (FILE *)f.fp);
    return lx_out_commit(&f);
}

bool cli_stage_text(cli_stage *st, const char *name, const char *text)
{
    char *path = cli_stage_path(st, name);
    if (!path)
        return false;
    lx_status s = write_text(path, text);
    free(path);
    return cli_stage_finish(st, name, s);
}

bool cli_stage_publish(cli_stage *st)
{
    const char *output = st->output;
    sigset_t block, old;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigprocmask(SIG_BLOCK, &block, &old);
    bool ok = true;
    /* anything but a file in the way would fail its rename half-way through */
    for (uint32_t i = 0; i < st->count && ok; i++) {
        char *to = lx_path_join(output, st->names[i]);
        struct stat sb;
        if (!to || (lstat(to, &sb) == 0 && !S_ISREG(sb.st_mode))) {
            cli_error("%s: cannot write: something that is not a file is in the way",
                      to ? to : output);
            ok = false;
        }
        free(to);
    }
    uint32_t moved = 0;
    for (uint32_t i = 0; i < st->count && ok; i++) {
        char *from = lx_path_join(st->dir, st->names[i]);
        char *to = lx_path_join(output, st->names[i]);
        if (!from || !to || rename(from, to) != 0) {
            cli_error("%s: cannot move into place: %s", to ? to : output, strerror(errno));
            ok = false;
        }
        free(from);
        free(to);
        moved += ok;
    }
    /* a rename that failed anyway: this run's files do not stay half-published */
    for (uint32_t i = 0; i < moved && !ok; i++) {
        char *to = lx_path_join(output, st->names[i]);
        if (to)
            unlink(to);
        free(to);
    }
    if (ok) {
        /* the run is complete: a signal held off until now must not undo it */
        cli_forget_outputs();
        cli_set_writing(false);
        st->created = false;
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
    return ok;
}

void cli_stage_clear(cli_stage *st)
{
    cli_remove_tracked_outputs();
    if (st->dir)
        rmdir(st->dir);
    if (st->created)
        remove_made(st);
    cli_track_dir(NULL, NULL, 0);
    free_made(st);
    for (uint32_t i = 0; i < st->count; i++)
        free(st->names[i]);
    free(st->names);
    free(st->dir);
    free(st->output);
    memset(st, 0, sizeof *st);
}
