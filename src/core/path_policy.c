/* Which files an input may make luxel read. A scene, a lights JSON or a
 * manifest names other files (buffers, textures, material libraries, IES
 * profiles, lightmap pages) and luxel copies some of their bytes into what
 * it writes, so a file downloaded from anywhere could otherwise pull
 * /etc/passwd or ~/.ssh/id_rsa into a .glb. By default a named file must
 * lie in the naming file's folder or below it, judged on the resolved
 * path (symbolic links followed, so a link inside the folder to a file
 * outside is refused too); a caller that trusts its inputs lifts the rule
 * (lx_scene_load_desc.allow_any_path and friends). */
#define _GNU_SOURCE /* realpath */
#include "internal.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A path that does not exist (yet) judged by its text: absolute, or
 * climbing above its start with "..". Backslashes separate too: readers
 * retry a Windows path ("..\\x.png") with slashes. */
static bool climbs_out(const char *relative)
{
    if (relative[0] == '/' || relative[0] == '\\')
        return true;
    long depth = 0;
    const char *p = relative;
    while (*p) {
        size_t n = strcspn(p, "/\\");
        if (n == 2 && p[0] == '.' && p[1] == '.')
            depth--;
        else if (n > 0 && !(n == 1 && p[0] == '.'))
            depth++;
        if (depth < 0)
            return true;
        p += n;
        while (*p == '/' || *p == '\\')
            p++;
    }
    return false;
}

bool lx_path_within(const char *folder, const char *path, const char *relative)
{
    char *root = realpath(folder, NULL);
    char *real = realpath(path, NULL);
    if (!real && strchr(path, '\\')) { /* the form a reader retries */
        char *slashed = lx_strdup(path);
        for (char *q = slashed; q && *q; q++)
            if (*q == '\\')
                *q = '/';
        real = slashed ? realpath(slashed, NULL) : NULL;
        free(slashed);
    }
    bool inside;
    if (root && real) {
        size_t n = strlen(root);
        inside = strncmp(real, root, n) == 0 &&
                 (real[n] == '/' || real[n] == '\0' || (n == 1 && root[0] == '/'));
    } else {
        /* nothing there to resolve: its reader reports it missing */
        inside = !climbs_out(relative ? relative : path);
    }
    free(root);
    free(real);
    return inside;
}

lx_status lx_path_confine(const char *file, const char *what, const char *named, const char *folder,
                          const char *path, bool allow_any)
{
    if (allow_any || lx_path_within(folder, path, named))
        return LX_OK;
    return lx_fail(LX_ERR_INVALID,
                   "%s: %s '%.200s' is outside the folder '%s': refused (--allow-any-path "
                   "reads it)",
                   file, what, named, folder);
}
